"""Depth of the recursions on trees (issue 12): random trees of 64, 512 and 4096 joints in three shapes
(a chain, a balanced binary tree, a star of ⌈√n⌉ chains), for each the tree's height (the level-by-level
depth), the log recursion's backward combining tiers and forward addition levels beside ⌈log2(n+1)⌉, and
the ASAP latencies (flops, 1 Mult = 1 Addn) of the linear and log graphs.

    python benchmarks/tree_depth.py            # all three sizes (about 6 s on 2 cores, 2026-12-06)
    python benchmarks/tree_depth.py 64 512     # chosen sizes

A chain runs the chain builders (the paper's networks); the other shapes the tree builders.
"""
from __future__ import annotations

import time

from vampc.dataflow.linear import build_linear
from vampc.dataflow.logarithmic import build_log
from vampc.dataflow.treeprefix import tree_depths
from vampc.robot.random import random_tree
from vampc.schedule.asap import schedule_asap


def row(n: int, shape: str) -> str:
    """One line of the table."""
    chain = random_tree(n, 0, shape, prismatic_fraction=0.0)
    d = tree_depths(chain.parent_of, "sklansky", ground=chain.floating or chain.base_rotates,
                    floating=chain.floating)
    start = time.perf_counter()
    linear = schedule_asap(build_linear(chain, verify=False), verify=False).latency
    log = schedule_asap(build_log(chain, verify=False), verify=False).latency
    return (f"{shape:7} {n:5} {d['height']:6} {d['light_edges']:5} {d['backward_tiers']:8} "
            f"{d['forward_levels']:8} {d['log2']:10} {linear:9} {log:7}   ({time.perf_counter() - start:.1f} s)")


def parse(argv=None) -> list[int]:
    """The sizes asked (a traceback for `--help` before: a new user's)."""
    import argparse
    ap = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("sizes", nargs="*", type=int, metavar="N",
                    help="joints of each tree (default: 64 512 4096)")
    return ap.parse_args(argv).sizes or [64, 512, 4096]


def main(sizes) -> None:
    print("shape       n height light bwd-tier fwd-lvls ⌈log2(n+1)⌉ linear-fl  log-fl")
    for n in sizes:
        for shape in ("chain", "binary", "star"):
            print(row(n, shape), flush=True)


if __name__ == "__main__":
    main(parse())
