"""Compile-time benchmark: how the compiler scales with the number of joints.

For random general rotary chains (random Φ_i, revolute joints) it prints the median wall time of
`compile_chain` + `program_text` (everything `vampc compile` does between reading the robot and writing
the file) for n = 6, 64, 512, 4096 (linear recursion) and n = 64, 512, 4096 (logarithmic recursion),
with the growth ratio between successive n (for reference: n log n grows by 12x from 64 to 512 and
10.7x from 512 to 4096, n by 8x). Then whole `vampc compile` processes: examples/puma560.yaml (median
of 5) and a generated N-joint snake (examples/make_snake.py) with --recursion log, once, with its peak
memory (the issue's target: N = 4096 in under a minute).

    python benchmarks/compile_time.py [--runs 3] [--sizes 6,64,512,4096] [--log-process 4096]
                                      [--profile N]

--profile N prints the cProfile hot spots of one linear compile of size N instead.
"""
from __future__ import annotations

import argparse
import cProfile
import importlib.util
import os
import pstats
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from vampc.compiler import CompileOptions, compile_chain, program_text
from vampc.robot.random import random_chain

ROOT = Path(__file__).resolve().parent.parent
SLOW = 30.0


def compile_once(chain, options: CompileOptions) -> float:
    """Seconds for one compile + program text."""
    t0 = time.perf_counter()
    program_text(compile_chain(chain, options))
    return time.perf_counter() - t0


def median_time(n: int, recursion: str, runs: int) -> tuple[float, int]:
    """Median over up to `runs` compiles of a random rotary chain of n joints, and how many ran
    (a compile slower than SLOW seconds is not repeated)."""
    chain = random_chain(n, n, prismatic_fraction=0.0)
    options = CompileOptions(recursion=recursion)
    times = [compile_once(chain, options)]
    while len(times) < runs and times[0] < SLOW:
        times.append(compile_once(chain, options))
    return statistics.median(times), len(times)


def scaling_table(recursion: str, sizes: list[int], runs: int) -> None:
    """One line per n: median seconds and the ratio to the previous n."""
    print(f"{recursion} recursion (median of {runs}):")
    previous = None
    for n in sizes:
        t, count = median_time(n, recursion, runs)
        growth = f"  x{t / previous:5.1f} vs previous n" if previous else ""
        note = "" if count == runs else f"  ({count} run: slower than {SLOW:.0f} s)"
        print(f"  n = {n:5d}  {t:9.3f} s{growth}{note}", flush=True)
        previous = t


def _cli_env() -> dict:
    root = Path(importlib.util.find_spec("vampc").origin).parent.parent
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))


def process_time(runs: int = 5) -> float:
    """Median wall time of `python -m vampc.cli compile examples/puma560.yaml -o ...`."""
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "vampc.cli", "compile", str(ROOT / "examples" / "puma560.yaml"),
               "-o", str(Path(tmp) / "puma.vamp.json")]
        for _ in range(runs):
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, env=_cli_env(), stdout=subprocess.DEVNULL)
            times.append(time.perf_counter() - t0)
    return statistics.median(times)


def log_process(n: int) -> None:
    """One whole `vampc compile snake{n}.yaml --recursion log` process: wall time, peak memory, file.
    Measured by benchmarks/scale.py's `measure`, from a small process of its own: measured from this
    script, after the in-process compiles above had grown it to 3.3 GiB, the compile's 0.9 GiB was
    printed as 3.3 GiB (2026-12-07; Linux gives a child the high-water mark of the process it is
    forked from; the 2.3-2.7 GiB of 2026-11-22 and 11-28 were measured so too)."""
    from scale import measure
    with tempfile.TemporaryDirectory() as tmp:
        robot, out = Path(tmp) / f"snake{n}.yaml", Path(tmp) / f"snake{n}.vamp.json"
        robot.write_text(subprocess.run([sys.executable, str(ROOT / "examples" / "make_snake.py"),
                                         str(n)], check=True, capture_output=True, text=True).stdout)
        got = measure([sys.executable, "-m", "vampc.cli", "compile", robot, "--recursion", "log",
                       "-o", out], Path(tmp), env=_cli_env())
        wall, peak = got["seconds"], got["peak_mib"] / 1024
        size = out.stat().st_size / 1e6
    print(f"vampc compile snake{n}.yaml --recursion log, whole process: {wall:.1f} s, "
          f"peak memory {peak:.1f} GiB, program file {size:.0f} MB", flush=True)


def profile(n: int, recursion: str) -> None:
    """cProfile one compile and print the 25 most expensive functions (cumulative and own time)."""
    chain = random_chain(n, n, prismatic_fraction=0.0)
    prof = cProfile.Profile()
    prof.runcall(lambda: program_text(compile_chain(chain, CompileOptions(recursion=recursion))))
    stats = pstats.Stats(prof).strip_dirs()
    stats.sort_stats("cumulative").print_stats(25)
    stats.sort_stats("tottime").print_stats(15)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="compiles per size (median)")
    parser.add_argument("--sizes", default="6,64,512,4096", help="linear-recursion sizes")
    parser.add_argument("--log-sizes", default="64,512,4096", help="log-recursion sizes")
    parser.add_argument("--log-process", type=int, default=4096, metavar="N",
                        help="joints of the snake compiled by a whole log-recursion process (0: skip)")
    parser.add_argument("--profile", type=int, metavar="N", help="profile one compile of size N")
    parser.add_argument("--recursion", default="linear", help="recursion for --profile")
    args = parser.parse_args()
    if args.profile:
        profile(args.profile, args.recursion)
        return
    scaling_table("linear", [int(x) for x in args.sizes.split(",")], args.runs)
    scaling_table("log", [int(x) for x in args.log_sizes.split(",")], args.runs)
    print(f"vampc compile examples/puma560.yaml, whole process (median of 5): {process_time():.3f} s")
    if args.log_process:
        log_process(args.log_process)


if __name__ == "__main__":
    main()
