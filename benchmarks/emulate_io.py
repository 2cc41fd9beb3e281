"""Whole-process `vampc emulate` beside a Python loop of Pinocchio's rnea, CSV in and out and .npy in
and out (issue "Fast at every size", part 3; targets: 2x for CSV, 5x for .npy).

    python benchmarks/emulate_io.py [--robot URDF] [--states 100000] [--repeat 3]

The robot defaults to example-robot-data's ur5_robot.urdf. In one run, on one trajectory of random
states within the joint limits (written by `vampc emulate --random N --save-states`), the median of
--repeat runs of each of:

  (a) `vampc emulate PROGRAM --trajectory traj.csv -o tau.csv`
  (b) python: read traj.csv with np.loadtxt, loop pinocchio.rnea, np.savetxt the torques ("%.17g")
  (c) `vampc emulate PROGRAM --trajectory traj.npy -o tau.npy`
  (d) python: np.load, loop pinocchio.rnea, np.save

Child processes write bytecode caches as an installed package has them (PYTHONDONTWRITEBYTECODE is
removed from their environment: without .pyc files every run of vampc recompiles its modules).
Needs `pip install pin` (and example-robot-data for the default robot).
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PIN_CHILD = """
import sys, numpy as np, pinocchio as pin
model = pin.buildModelFromUrdf(sys.argv[1]); data = model.createData(); n = model.nv
npy = sys.argv[2].endswith(".npy")
raw = np.load(sys.argv[2]) if npy else np.loadtxt(sys.argv[2], delimiter=",", skiprows=1)
tau = np.empty((len(raw), n))
for k, row in enumerate(raw):
    tau[k] = pin.rnea(model, data, row[:n], row[n:2 * n], row[2 * n:])
np.save(sys.argv[3], tau) if npy else np.savetxt(sys.argv[3], tau, delimiter=",", fmt="%.17g")
"""


def vampc_script() -> str:
    """The `vampc` console script installed beside this Python (what a user's venv runs), not
    whatever PATH finds first: a version manager's shim (pyenv's is a shell script) would add
    its own start-up, about 0.1 s here, to every vampc run and to none of Pinocchio's, which run
    sys.executable."""
    import shutil
    beside = Path(sys.executable).parent / "vampc"
    return str(beside) if beside.exists() else (shutil.which("vampc") or "vampc")


def median_time(cmd: list, repeat: int, env: dict) -> float:
    times = []
    for _ in range(repeat):
        begun = time.perf_counter()
        subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - begun)
    return statistics.median(times)


def default_robot() -> str | None:
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from pinocchio_util import erd_urdfs
    return erd_urdfs().get("ur5_robot.urdf")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", default=None, help="a URDF (default: example-robot-data's UR5)")
    parser.add_argument("--states", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    robot = args.robot or default_robot()
    if robot is None:
        print("no robot: give --robot URDF or pip install example-robot-data")
        return 1
    import numpy as np
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    vampc = [vampc_script()]
    with tempfile.TemporaryDirectory() as folder:
        f = Path(folder)
        program, csv, npy = f / "robot.vamp.json", f / "traj.csv", f / "traj.npy"
        subprocess.run([*vampc, "compile", robot, "-o", str(program)], check=True, env=env,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        subprocess.run([*vampc, "emulate", str(program), "--random", str(args.states), "--save-states", str(csv)],
                       check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        np.save(npy, np.loadtxt(csv, delimiter=",", skiprows=1))
        rows = {
            "(a) vampc emulate, CSV -> CSV": [*vampc, "emulate", str(program), "--trajectory", str(csv),
                                             "-o", str(f / "tau.csv")],
            "(b) np.loadtxt + pin.rnea loop + np.savetxt": [sys.executable, "-c", PIN_CHILD, robot, str(csv),
                                                            str(f / "pin.csv")],
            "(c) vampc emulate, .npy -> .npy": [*vampc, "emulate", str(program), "--trajectory", str(npy),
                                               "-o", str(f / "tau.npy")],
            "(d) np.load + pin.rnea loop + np.save": [sys.executable, "-c", PIN_CHILD, robot, str(npy),
                                                      str(f / "pin.npy")],
        }
        for cmd in rows.values():            # warm: caches, compiled C, .pyc files
            subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        got = {label: median_time(cmd, args.repeat, env) for label, cmd in rows.items()}
        same_csv = np.allclose(np.loadtxt(f / "tau.csv", delimiter=",", skiprows=1),
                               np.loadtxt(f / "pin.csv", delimiter=","), rtol=1e-9, atol=1e-9)
        same_npy = np.allclose(np.load(f / "tau.npy"), np.load(f / "pin.npy"), rtol=1e-9, atol=1e-9)
    print(f"{Path(robot).name}, {args.states:,} states, median of {args.repeat} (whole processes):")
    for label, seconds in got.items():
        print(f"  {label:46s} {seconds:6.2f} s  ({args.states / seconds:,.0f} sets/s)")
    labels = list(got)
    print(f"  ratio CSV: {got[labels[1]] / got[labels[0]]:.2f}x (target >= 2); ratio .npy: "
          f"{got[labels[3]] / got[labels[2]]:.2f}x (target >= 5); torques agree with Pinocchio to 1e-9: "
          f"{same_csv and same_npy}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
