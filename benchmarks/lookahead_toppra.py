"""`vampc lookahead --retime` against TOPP-RA (README, vampc lookahead: the table), and the speed of
`--retime window` on a 10-second path at 1 kHz.

    python benchmarks/lookahead_toppra.py [--speed-only] [--rows 10000]

For the Puma 560 (examples/puma560.yaml, limits examples/puma560-limits.csv) and a UR5-type URDF arm
(examples/ur5.urdf, its own limits), three paths each at 1 kHz: one that goes over its limits early,
one late, one slow everywhere. Each path is q(s) = q0 + s Δq + w(s) A sin(2π·2 s), s = t / T, w a
Gaussian bump centred early (0.2), late (0.8) or in the middle (0.5). For each it prints the duration
as given, after `--retime uniform`, after `--retime window` with --window 64 and --futures 1 and 4,
and TOPP-RA's time-optimal duration on the same samples and limits (toppra 0.6, gridpoints = the
path's rows, interpolation (each interval's s̈ checked at both its rows, as vampc plans), starting and ending at rest as vampc's window retiming does), with each
retimed path's violations checked by the reference dynamics. Needs `pip install toppra`.

`--envelope 1,2,4,8` prints instead, per path, `--retime envelope`'s duration over TOPP-RA's for each
--futures R (R candidate futures side by side, --window 64), beside `--retime window`'s at R = 1 (the
same rows in view), with the network's candidate rows a row of the path and the command's time.

`--sweep 1,2,4,5,8` prints instead, per path, the window method's duration over TOPP-RA's with
--window 64 and each --futures R given (64 R rows ahead): how far ahead the host must see to come
within a given distance of the time-optimal duration (README, vampc lookahead).
"""
from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RATE = 1000.0
ROBOTS = {
    "Puma 560": dict(source=ROOT / "examples/puma560.yaml", limits=ROOT / "examples/puma560-limits.csv",
                     dq=[1.2, 0.8, -1.0, 1.5, 1.0, 1.5], amp=[0.3, 0.2, 0.3, 0.4, 0.3, 0.4],
                     T={"early": 2.0, "late": 2.0, "slow": 8.0}),
    "UR5 (URDF)": dict(source=ROOT / "examples/ur5.urdf", limits=None,
                       dq=[1.5, -1.0, 1.2, 1.5, 1.0, 1.5], amp=[0.4, 0.3, 0.4, 0.5, 0.4, 0.5],
                       T={"early": 1.2, "late": 1.2, "slow": 6.0}),
}


def make_path(kind: str, T: float, dq, amp, q0=None):
    """(t, q, q̇, q̈) of the module docstring's path, exact derivatives."""
    dq, amp = np.asarray(dq, float), np.asarray(amp, float)
    q0 = np.zeros(len(dq)) if q0 is None else np.asarray(q0, float)
    t = np.arange(int(round(T * RATE)) + 1) / RATE
    s = t / T
    centre, width, w = {"early": 0.2, "late": 0.8, "slow": 0.5}[kind], 0.12, 2 * np.pi * 2.0
    env = np.exp(-((s - centre) / width) ** 2)
    env_d = env * (-2 * (s - centre) / width ** 2) / T
    env_dd = env * (4 * (s - centre) ** 2 / width ** 4 - 2 / width ** 2) / T ** 2
    sn, cs = np.sin(w * s), np.cos(w * s)
    f, fd = env * sn, env_d * sn + env * cs * w / T
    fdd = env_dd * sn + 2 * env_d * cs * w / T - env * sn * (w / T) ** 2
    q = q0 + np.outer(s, dq) + np.outer(f, amp)
    return t, q, np.outer(np.full_like(s, 1 / T), dq) + np.outer(fd, amp), np.outer(fdd, amp)


def write_path(path: Path, t, q, qd, qdd) -> None:
    n = q.shape[1]
    head = ",".join(["t"] + [f"{p}{i}" for p in ("q", "qd", "qdd") for i in range(1, n + 1)])
    np.savetxt(path, np.column_stack([t, q, qd, qdd]), delimiter=",", header=head, comments="", fmt="%.17g")


def lookahead(program: Path, path: Path, limits, *extra) -> tuple[float, str]:
    """Run vampc lookahead; the retimed duration (last t of -o) and the summary."""
    out = path.with_suffix(".retimed.csv")
    cmd = ["vampc", "lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz", "--window", "64",
           "--check", "-o", str(out), *extra] + (["--limits", str(limits)] if limits else [])
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {run.returncode}\n{run.stdout}{run.stderr}")
    t = np.loadtxt(out, delimiter=",", skiprows=1, usecols=0)
    return float(t[-1] - t[0]), run.stdout


def toppra_duration(chain, t, q, tau_lim, qd_lim) -> float:
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    from vampc.dynamics.reference import rnea
    ta.setup_logging("ERROR")
    path = ta.SplineInterpolator(t, q)
    cons = [constraint.JointTorqueConstraint(
        lambda a, b, c: rnea(chain, a[None], b[None], c[None])[0], np.column_stack([-tau_lim, tau_lim]),
        np.zeros(len(tau_lim)), discretization_scheme=constraint.DiscretizationType.Interpolation)]
    if any(v is not None for v in qd_lim):
        v = np.array([np.inf if x is None else x for x in qd_lim])
        cons.append(constraint.JointVelocityConstraint(np.column_stack([-v, v])))
    inst = algo.TOPPRA(cons, path, gridpoints=t, parametrizer="ParametrizeConstAccel")
    result = inst.compute_trajectory(0, 0)
    if result is None:
        raise SystemExit("TOPP-RA found no parametrization")
    return float(result.duration)


def paths(tmp: Path):
    """Per robot and path of ROBOTS: (robot name, path kind, T, compiled program, path file,
    limits file or None, TOPP-RA's duration)."""
    from vampc.lookahead import limits_of
    from vampc.robot import load_robot
    for name, spec in ROBOTS.items():
        program = tmp / (spec["source"].stem + ".vamp.json")
        subprocess.run(["vampc", "compile", str(spec["source"]), "-o", str(program)], check=True,
                       capture_output=True)
        chain = load_robot(str(spec["source"]))
        chain = getattr(chain, "chain", chain)
        lim = limits_of(chain, str(spec["limits"]) if spec["limits"] else None)
        for kind, T in spec["T"].items():
            t, q, qd, qdd = make_path(kind, T, spec["dq"], spec["amp"])
            path = tmp / f"{spec['source'].stem}-{kind}.csv"
            write_path(path, t, q, qd, qdd)
            best = toppra_duration(chain, t, q, np.array(lim.tau), lim.qd)
            yield name, kind, T, program, path, spec["limits"], best


def table() -> None:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, kind, T, program, path, limits, best in paths(Path(tmp)):
            uniform, _ = lookahead(program, path, limits, "--retime", "uniform")
            w1, text = lookahead(program, path, limits, "--retime", "window")
            w4, _ = lookahead(program, path, limits, "--retime", "window", "--futures", "4")
            violations = text.splitlines()[0].split(": ")[-1]
            rows.append((name, kind, T, violations, uniform, w1, w4, best))
            print(f"{name} {kind}: as given {T:.3f} s ({violations}), uniform {uniform:.3f}, window R=1 "
                  f"{w1:.3f} ({100 * (w1 / best - 1):+.1f}%), R=4 {w4:.3f} ({100 * (w4 / best - 1):+.1f}%), "
                  f"TOPP-RA {best:.3f}", flush=True)
    print("\n| robot | path | as given (s) | violations as given (row, joint) | uniform (s) | window R = 1 (s) | "
          "window R = 4 (s) | TOPP-RA (s) |")
    print("|---|---|---|---|---|---|---|---|")
    for name, kind, T, v, u, w1, w4, best in rows:
        print(f"| {name} | {kind} | {T:.3f} | {v} | {u:.3f} | {w1:.3f} ({100 * (w1 / best - 1):+.0f}%) | "
              f"{w4:.3f} ({100 * (w4 / best - 1):+.0f}%) | {best:.3f} |")


def sweep(futures: list[int]) -> None:
    """Per path: `--retime window` over TOPP-RA for --window 64 and each --futures R."""
    print("| robot | path | TOPP-RA (s) | " + " | ".join(f"R = {r} ({64 * r} rows)" for r in futures) + " |")
    print("|---|---|---|" + "---|" * len(futures))
    with tempfile.TemporaryDirectory() as tmp:
        for name, kind, _, program, path, limits, best in paths(Path(tmp)):
            cells = []
            for r in futures:
                took, _ = lookahead(program, path, limits, "--retime", "window", "--futures", str(r))
                cells.append(f"{100 * (took / best - 1):+.1f}%")
            print(f"| {name} | {kind} | {best:.3f} | " + " | ".join(cells) + " |", flush=True)


def envelope(futures: list[int]) -> None:
    """Per path: `--retime envelope` (R candidate futures side by side, --window 64) over TOPP-RA
    for each --futures R, beside `--retime window` (R = 1, the same 64 rows in view); the network's
    candidate rows a row of the path (the summary's), and the whole command's time."""
    print("| robot | path | TOPP-RA (s) | window, R = 1 | "
          + " | ".join(f"envelope, R = {r}" for r in futures) + " |")
    print("|---|---|---|---|" + "---|" * len(futures))
    with tempfile.TemporaryDirectory() as tmp:
        for name, kind, _, program, path, limits, best in paths(Path(tmp)):
            w1, _ = lookahead(program, path, limits, "--retime", "window")
            cells = [f"{100 * (w1 / best - 1):+.1f}%"]
            for r in futures:
                start = time.perf_counter()
                took, text = lookahead(program, path, limits, "--retime", "envelope", "--futures", str(r))
                spent = time.perf_counter() - start
                rows = re.search(r"computed [\d,]+ candidate rows, ([\d.]+) a row", text)[1]
                cells.append(f"{100 * (took / best - 1):+.1f}% ({rows} rows a row, {spent:.1f} s)")
            print(f"| {name} | {kind} | {best:.3f} | " + " | ".join(cells) + " |", flush=True)


def speed(rows: int, repeats: int = 3) -> None:
    """`vampc lookahead --retime window` on `rows` rows at 1 kHz, window 64: whole command, median."""
    spec = ROBOTS["Puma 560"]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        program = tmp / "puma.vamp.json"
        subprocess.run(["vampc", "compile", str(spec["source"]), "-o", str(program)], check=True,
                       capture_output=True)
        path = tmp / "long.csv"
        write_path(path, *make_path("early", (rows - 1) / RATE * 1.0, spec["dq"], spec["amp"]))
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            lookahead(program, path, spec["limits"], "--retime", "window")
            times.append(time.perf_counter() - start)
        print(f"--retime window, {rows} rows, window 64, whole command (compiled program): median "
              f"{statistics.median(times):.2f} s of {repeats} ({', '.join(f'{x:.2f}' for x in times)})")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--speed-only", action="store_true")
    parser.add_argument("--rows", type=int, default=10000)
    parser.add_argument("--sweep", metavar="R,...", help="only the --futures sweep, for these R")
    parser.add_argument("--envelope", metavar="R,...", help="only --retime envelope, for these R")
    args = parser.parse_args()
    if args.envelope:
        envelope([int(r) for r in args.envelope.split(",")])
        return 0
    if args.sweep:
        sweep([int(r) for r in args.sweep.split(",")])
        return 0
    if not args.speed_only:
        table()
    speed(args.rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
