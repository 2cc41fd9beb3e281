"""Word formats: the stream engine's rate in each format, and the torque error each format gives.

    python benchmarks/word_formats.py [--sets N] [--runs R]

Prints, in one run:

- rate: torque sets per second of the stream engine's generated C (compiled once before timing) on
  the Puma 560 in float64, float32 and q16.16, medians of R runs of N random sets, and each rate's
  share of float64's (issue "Hardware word formats": q16.16 at no worse than a third);
- error: for the Puma 560, the Stanford arm, the bundled URDF arm (arm6) and the quadruped (a
  tree on a fixed base, as the URDF is loaded without --floating-base), the largest torque error against the float64 reference RNEA relative to the
  largest |τ| of the run, over 2000 random states within the joint limits, at float32, q16.16,
  q12.20, q20.12, q24.24, each beside the bound vampc.precision analyses for it ("may overflow"
  where the word's integer bits do not cover the analysed peak), and the narrowest word meeting 1e-3
  and 1e-6 by the bound with no possible overflow (as `vampc precision` finds it) beside the
  narrowest observed to (any qI.F, I from 4 to 24, F from 4 to 40, with no overflow in the run).
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time
from pathlib import Path

import numpy as np

from vampc.compiler import CompileOptions, compile_chain
from vampc.dynamics.reference import rnea
from vampc.emulator import emulate, loaded_from_compiled
from vampc.emulator.host import random_trajectory
from vampc.machine.arith import Rounding, parse_word
from vampc.precision import Ranges, analyse, fitted, integer_bits
from vampc.robot import load_robot

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
ROBOTS = [("Puma 560", "puma560.yaml", {}), ("Stanford arm", "stanford.yaml", {}),
          ("arm6 (URDF)", "arm6.urdf", {}), ("quadruped (URDF tree)", "quadruped.urdf", {})]


def error(c, chain, traj, ref, word: str) -> tuple[float, int]:
    """(max error / largest |τ|, overflows) of a run in `word`."""
    ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(word))
    tau = emulate(ld, traj, "stream").tau
    return float(np.abs(tau - ref).max() / np.abs(ref).max()), ld.arith.overflows


def narrowest(c, chain, traj, ref, tolerance: float) -> str:
    """The fewest-bit qI.F meeting `tolerance` with no overflow (fewest integer bits first)."""
    for bits in range(8, 65):
        for integer in range(4, min(bits, 25)):
            fraction = bits - integer
            if fraction > 40:
                continue
            err, over = error(c, chain, traj, ref, f"q{integer}.{fraction}")
            if not over and err <= tolerance:
                return f"q{integer}.{fraction} ({bits} bits: {err:.1e})"
    return "none up to 64 bits"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", type=int, default=100_000)
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    os.environ["VAMPC_NATIVE"] = "1"
    puma = load_robot(EXAMPLES / "puma560.yaml")
    c = compile_chain(puma, CompileOptions())
    traj = random_trajectory(puma, args.sets, 1)
    rates = {}
    for word in ("float64", "float32", "q16.16"):
        ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(word))
        emulate(ld, random_trajectory(puma, 64, 2), "stream")        # compile the C once
        times = []
        for _ in range(args.runs):
            start = time.perf_counter()
            emulate(ld, traj, "stream")
            times.append(time.perf_counter() - start)
        rates[word] = args.sets / statistics.median(times)
        print(f"rate   Puma 560 {word:8s} {rates[word]:12,.0f} sets/s "
              f"({rates[word] / rates['float64']:.2f} of float64)")
    os.environ["VAMPC_NATIVE"] = "0"
    for name, file, opts in ROBOTS:
        chain = load_robot(EXAMPLES / file)
        c = compile_chain(chain, CompileOptions(**opts))
        traj = random_trajectory(chain, 2000, 7)
        ref = rnea(chain, traj.q, traj.qd, traj.qdd, traj.base)
        cells = []
        scale = np.abs(ref).max()
        for word in ("float32", "q16.16", "q12.20", "q20.12", "q24.24"):
            err, over = error(c, chain, traj, ref, word)
            a = analyse(c.graph, chain, parse_word(word))
            fits = not word.startswith("q") or integer_bits(a.peak, int(word.split(".")[1])) <= \
                int(word[1:].split(".")[0])
            cells.append(f"{word} {err:.1e}" + (f" ({over} overflows)" if over else "")
                         + f" [bound {a.tau_error.max() / scale:.1e}"
                         + ("" if fits else ", may overflow") + "]")
        print(f"error  {name}: " + "; ".join(cells))
        by_bound = {}
        for tol in (1e-3, 1e-6):
            for bits in range(8, 65):
                got = fitted(c.graph, chain, bits, Rounding.NEAREST, Ranges())
                if got and got[1].tau_error.max() / scale <= tol:
                    by_bound[tol] = f"{got[0].name} ({bits} bits)"
                    break
        print(f"       narrowest by the bound within 1e-3: {by_bound.get(1e-3)}; within 1e-6: "
              f"{by_bound.get(1e-6)}")
        print(f"       narrowest observed within 1e-3: {narrowest(c, chain, traj, ref, 1e-3)}; "
              f"within 1e-6: {narrowest(c, chain, traj, ref, 1e-6)}")


if __name__ == "__main__":
    main()
