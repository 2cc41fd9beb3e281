"""Trade-off benchmark: how long `vampc report --tradeoff` takes, and how close each budgeted point
comes to its bounds.

For the Puma 560 and general rotary chains of 32 and 64 joints (both recursions) it times the sweep
(vampc.report.tradeoff.tradeoff, what the command does after loading the robot), and prints the worst
interval gap (against max(⌈W/K⌉, longest op)) and latency gap (against the level bound) over the
budgeted points, and how many points fall within 5% and 10%; then, for each folded layout, the
budget with the same number of VAMPs beside it (the budget should never be worse).

    python benchmarks/tradeoff.py [--only puma|32|64]
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from vampc.compiler import CompileOptions, build_graph
from vampc.machine.ops import Timing
from vampc.report.tradeoff import THOROUGH_UP_TO, tradeoff
from vampc.robot import load_robot
from vampc.robot.random import random_chain
from vampc.schedule.budget import budget_schedule, vamp_ops

ROOT = Path(__file__).resolve().parent.parent


def one(label: str, chain, recursion: str) -> None:
    t0 = time.perf_counter()
    rows = tradeoff(chain, CompileOptions(recursion=recursion))
    seconds = time.perf_counter() - t0
    budget = [r for r in rows if r["layout"].startswith("budget")]
    worst_i = max(budget, key=lambda r: r["interval_gap_pct"])
    worst_l = max(budget, key=lambda r: r["latency_gap_pct"])
    within_i = sum(r["interval_gap_pct"] <= 5 for r in budget)
    within_l = sum(r["latency_gap_pct"] <= 10 for r in budget)
    print(f"{label:<14}{recursion:<8}{seconds:>8.1f} s  {len(budget):>3} budgets, "
          f"{sum(r['pareto'] for r in rows):>3} Pareto points; interval within 5%: {within_i}/"
          f"{len(budget)} (worst {worst_i['interval_gap_pct']}% at {worst_i['layout']}); latency "
          f"within 10%: {within_l}/{len(budget)} (worst {worst_l['latency_gap_pct']}% at "
          f"{worst_l['layout']})", flush=True)
    graph = build_graph(chain, CompileOptions(recursion=recursion, verify=False))
    for r in rows:
        if r["layout"].startswith("folded"):
            _, sched, _ = budget_schedule(graph, Timing(), r["vamps"], verify=False,
                                          thorough=vamp_ops(graph) <= THOROUGH_UP_TO)
            worse = sched.latency > r["latency_flops"] or sched.interval > r["interval_flops"]
            print(f"{'':22}{r['layout']} on {r['vamps']} VAMPs: latency {r['latency_flops']}, "
                  f"interval {r['interval_flops']}; budget {r['vamps']}: latency {sched.latency}, "
                  f"interval {sched.interval}{'  WORSE' if worse else ''}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("--only", choices=["puma", "32", "64"])
    args = parser.parse_args()
    cases = {"puma": ("Puma 560", lambda: load_robot(ROOT / "examples" / "puma560.yaml")),
             "32": ("32 joints", lambda: random_chain(32, 32, prismatic_fraction=0.0)),
             "64": ("64 joints", lambda: random_chain(64, 64, prismatic_fraction=0.0))}
    print(f"trade-off sweeps, {time.strftime('%Y-%m-%d')}")
    for key, (label, make) in cases.items():
        if args.only in (None, key):
            for recursion in ("linear", "log"):
                one(label, make(), recursion)


if __name__ == "__main__":
    main()
