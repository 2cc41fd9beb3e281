"""Every URDF of example-robot-data, robot by robot: does vampc compile it, and how close are the
emulated torques to Pinocchio's?

For each URDF file and each base (fixed, floating) it loads the robot, compiles it with both
recursions, emulates random states on the stream engine and compares with Pinocchio's rnea
(tests/pinocchio_util.py: check_against_pinocchio, the function tests/test_example_robot_data.py
asserts with). A robot with mimic joints is run both ways: as ordinary joints (Pinocchio's default
model) and coupled (Pinocchio's mimic=True model where it builds one, and Gᵀ τ of its default model
always). Columns:

    robot, base, joints, mimic (how many coupled), worst error against Pinocchio relative to the
    largest |τ| (both recursions, both mimic modes), vampc's own --check, seconds, notes

    python benchmarks/example_robot_data.py [--states 4] [--only NAME,...]

Needs `pip install pin example-robot-data`.
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from pinocchio_util import check_against_pinocchio, erd_urdfs  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--states", type=int, default=4, help="random states per robot and mode")
    parser.add_argument("--only", default="", help="comma-separated file names (default: all)")
    args = parser.parse_args()
    robots = erd_urdfs()
    if not robots:
        print("example-robot-data is not installed (pip install example-robot-data)")
        return 1
    only = {n.strip() for n in args.only.split(",") if n.strip()}
    print("Each row: both recursions and, where the robot has mimic joints, both --mimic modes. mimic: "
          "joints --mimic couple couples; vs Pinocchio: the worst error relative to the largest |tau|; "
          "--check: vampc's own check against its reference RNEA, likewise; s: seconds for the row.\n")
    print(f"{'robot':34s} {'base':8s} {'joints':>6s} {'mimic':>5s} {'vs Pinocchio':>12s} "
          f"{'--check':>9s} {'s':>6s}  notes")
    tally = {"ok": 0, "skipped": 0, "failed": 0}
    for name, path in robots.items():
        if only and name not in only:
            continue
        for floating in (False, True):
            begun = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    out = check_against_pinocchio(path, floating, count=args.states)
                except Exception as exc:  # noqa: BLE001 - a benchmark lists, it does not stop
                    out = {"failed": " ".join(str(exc).split())[-120:]}
            seconds = time.perf_counter() - begun
            base = "floating" if floating else "fixed"
            if "skip" in out or "failed" in out:
                kind = "skipped" if "skip" in out else "failed"
                tally[kind] += 1
                print(f"{name:34s} {base:8s} {'':>6s} {'':>5s} {'':>12s} {'':>9s} {seconds:6.2f}  "
                      f"{kind}: {out.get('skip') or out.get('failed')}")
                continue
            worst = max(out["errors"].values())
            coupled = out.get("coupled", "")
            notes = []
            if out["accepted"]:
                notes.append("--accept-improper-inertia")
            if "couple refused" in out:
                notes.append(f"--mimic couple refused, as by Pinocchio: {out['couple refused']}")
            ok = worst <= 1e-9 and out["check"] <= 1e-9
            tally["ok" if ok else "failed"] += 1
            print(f"{name:34s} {base:8s} {out['n']:6d} {coupled!s:>5s} {worst:12.2e} {out['check']:9.2e} "
                  f"{seconds:6.2f}  {'; '.join(notes)}{'' if ok else ' FAILED'}")
    print(f"\n{tally['ok']} robot-base pairs within 1e-9 of Pinocchio, {tally['skipped']} skipped (Pinocchio "
          f"refuses the file or it has no movable joint), {tally['failed']} failed")
    return 0 if tally["failed"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
