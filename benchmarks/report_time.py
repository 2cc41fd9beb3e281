"""Report benchmark: how long a whole `vampc report` process takes, pictures included.

Generates an N-joint general rotary snake (examples/make_snake.py), compiles it with the log
recursion (not timed), then times whole `vampc report PROGRAM --timing --network --html` processes
(the issue's target: N = 512 under 10 s) — with the program's static check in a forked process, as
`vampc report` does for a big program, and with it inline (VAMPC_FORK=0) — the same with --dot, and
the robot reports of the Puma 560 and of the 64-joint snake with every picture. Prints the median of
--runs runs of each, the user CPU time of the median run (the forked check's included), and the
load average: the machine is shared, and the forked check only shortens the wall time when a second
core is free.

    python benchmarks/report_time.py [--joints 512] [--runs 3] [--profile]

--profile prints the cProfile hot spots of one report of the program instead.
"""
from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _env() -> dict:
    root = Path(importlib.util.find_spec("vampc").origin).parent.parent
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))


def vampc(*args, cwd: Path, env: dict | None = None) -> tuple[float, float]:
    """Run one `python -m vampc.cli ...` process: (wall seconds, user CPU seconds, the forked
    static check's included)."""
    before = os.times()
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "vampc.cli", *map(str, args)], check=True,
                   env={**_env(), **(env or {})}, cwd=cwd, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = os.times()
    return wall, after.children_user - before.children_user


def median_run(label: str, args: list, runs: int, cwd: Path, env: dict | None = None) -> None:
    """Print the median wall time of `runs` runs, with that run's CPU time and the load."""
    results = sorted(vampc(*args, cwd=cwd, env=env) for _ in range(runs))
    wall, user = results[len(results) // 2]
    load = os.getloadavg()[0]
    print(f"  {label:<58} {wall:6.2f} s  (user {user:5.2f} s, load {load:.1f})", flush=True)


def snake_program(n: int, folder: Path) -> Path:
    """Write snake{n}.yaml and compile it with the log recursion."""
    robot, program = folder / f"snake{n}.yaml", folder / f"snake{n}.vamp.json"
    robot.write_text(subprocess.run([sys.executable, str(ROOT / "examples" / "make_snake.py"), str(n)],
                                    check=True, capture_output=True, text=True).stdout)
    vampc("compile", robot, "--recursion", "log", "-o", program, cwd=folder)
    return program


def profile(program: Path, folder: Path) -> None:
    """cProfile one report of the program, pictures included."""
    import cProfile
    import pstats

    from vampc.cli import main as cli
    argv = ["report", str(program), "--timing", str(folder / "t.svg"), "--network",
            str(folder / "n.svg"), "--html", str(folder / "p.html")]
    prof = cProfile.Profile()
    try:
        prof.runcall(cli, argv, standalone_mode=False)
    except SystemExit:
        pass
    stats = pstats.Stats(prof).strip_dirs()
    stats.sort_stats("cumulative").print_stats(30)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=512, help="joints of the log-recursion program")
    parser.add_argument("--runs", type=int, default=3, help="runs per command (median)")
    parser.add_argument("--profile", action="store_true", help="profile one report instead")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        program = snake_program(args.joints, folder)
        if args.profile:
            profile(program, folder)
            return
        pictures = ["--timing", "t.svg", "--network", "n.svg", "--html", "p.html"]
        print(f"whole `vampc report` processes, median of {args.runs}:")
        median_run(f"snake{args.joints} log program, --timing --network --html",
                   ["report", program, *pictures], args.runs, folder)
        median_run("  the same, static check not forked (VAMPC_FORK=0)",
                   ["report", program, *pictures], args.runs, folder, {"VAMPC_FORK": "0"})
        median_run(f"snake{args.joints} log program, pictures and --dot",
                   ["report", program, *pictures, "--dot", "n.dot"], args.runs, folder)
        median_run(f"snake{args.joints} log program, text only", ["report", program], args.runs, folder)
        for robot, extra in (("puma560.yaml", []), ("snake64.yaml", []),
                             ("snake64.yaml", ["--recursion", "log"])):
            median_run(f"{robot} {' '.join(extra)}, every picture",
                       ["report", ROOT / "examples" / robot, *extra, *pictures, "--dot", "n.dot"],
                       args.runs, folder)


if __name__ == "__main__":
    main()
