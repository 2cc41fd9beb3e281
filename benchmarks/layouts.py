"""Layout benchmark: compile and emulate time of the folded layouts beside the systolic one.

For random general rotary chains of n joints it prints, per recursion and layout, the median wall time
of compile_chain + program_text (what `vampc compile` does between reading and writing), and of
emulating: loading the program text into the typed IRs, the static checks and the stream engine on
100 torque sets (numpy; what `vampc emulate --random 100` does after reading the file), with the VAMP
count, the period and the growth ratio between successive n (n log n grows by 12x from 64 to 512 and
10.7x from 512 to 4096).

    python benchmarks/layouts.py [--runs 3] [--sizes 6,64,512,4096] [--log-sizes 6,64,512]
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import time

from vampc.compiler import CompileOptions, compile_chain, program_text
from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.driver import random_states
from vampc.robot.random import random_chain

LAYOUTS = (("systolic", False), ("folded", False), ("folded", True))
SETS = 100
SLOW = 30.0


def once(chain, options: CompileOptions) -> tuple[float, float, int, int]:
    """(compile seconds, emulate seconds, VAMPs, period) of one run."""
    t0 = time.perf_counter()
    c = compile_chain(chain, options)
    text = program_text(c)
    t1 = time.perf_counter()
    ld = loaded_from_doc(json.loads(text), "<bench>")
    emulate(ld, random_states(ld.chain, 0, SETS, 1))
    t2 = time.perf_counter()
    return t1 - t0, t2 - t1, len(c.network.vamps), c.network.period


def measure(n: int, recursion: str, layout: str, share: bool, runs: int):
    chain = random_chain(n, n, prismatic_fraction=0.0)
    options = CompileOptions(recursion=recursion, layout=layout, share_passes=share)
    results = [once(chain, options)]
    while len(results) < runs and sum(results[0][:2]) < SLOW:
        results.append(once(chain, options))
    comp = statistics.median(r[0] for r in results)
    emu = statistics.median(r[1] for r in results)
    return comp, emu, results[0][2], results[0][3], len(results)


def table(recursion: str, sizes: list[int], runs: int) -> None:
    print(f"\n{recursion} recursion (median of up to {runs}; emulate = load + checks + {SETS} sets)")
    print(f"{'n':>6} {'layout':<22}{'VAMPs':>9}{'period':>8}{'compile':>10}{'growth':>8}"
          f"{'emulate':>10}{'growth':>8}")
    previous: dict = {}
    for n in sizes:
        for layout, share in LAYOUTS:
            label = layout + (", shared passes" if share else "")
            comp, emu, vamps, period, k = measure(n, recursion, layout, share, runs)
            grow = ""
            if label in previous:
                pc, pe = previous[label]
                grow = (f"{comp / pc:>7.1f}x", f"{emu / pe:>7.1f}x")
            previous[label] = (comp, emu)
            g1, g2 = grow if grow else ("", "")
            print(f"{n:>6} {label:<22}{vamps:>9}{period:>8}{comp:>9.3f}s{g1:>8}{emu:>9.3f}s{g2:>8}"
                  + ("" if k == runs else f"  ({k} run)"), flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--sizes", default="6,64,512,4096")
    parser.add_argument("--log-sizes", default="6,64,512")
    args = parser.parse_args()
    os.environ.setdefault("VAMPC_NATIVE", "0")     # 100 sets stay on numpy anyway; no compiler noise
    print(f"layouts benchmark, {time.strftime('%Y-%m-%d')}, {os.cpu_count()} CPUs")
    table("linear", [int(x) for x in args.sizes.split(",")], args.runs)
    if args.log_sizes:
        table("log", [int(x) for x in args.log_sizes.split(",")], args.runs)


if __name__ == "__main__":
    main()
