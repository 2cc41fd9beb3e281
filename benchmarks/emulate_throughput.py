"""Torque sets per second of wall time: the stream engine on the Puma 560 beside Python-looped RNEAs.

    python benchmarks/emulate_throughput.py [--states 100000] [--repeat 3] [--reference-states 10000]
                                            [--tick-sets 10000]

Measured in one run (median of --repeat runs each), on one 100 000-point trajectory CSV of random Puma
states within the joint limits (fixed seed):

  (a) the whole process `vampc emulate puma.vamp.json --trajectory traj.csv -o tau.csv`;
  (b) a Python process that reads the same CSV with np.loadtxt, loops pinocchio.rnea over the states
      and saves the torques (.npy), when Pinocchio is installed;
  (c) the same with vampc.dynamics.reference.rnea, one state at a time (on the first
      --reference-states states only: it takes about half a millisecond per state);
  (d) compute only, in this process: the stream engine (native code, then the numpy fallback), the
      batched reference RNEA, Pinocchio's loop, and the host's port values;

and the tick engine on --tick-sets torque sets (target: under a minute). The issue's target is the
ratio (a)/(b) of whole-process rates at least 1.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
PUMA = ROOT / "examples" / "puma560.yaml"
SEED = 560

# Child process (b): read the CSV, loop Pinocchio's RNEA, save the torques. argv: model, csv, out.
PINOCCHIO_CHILD = """
import sys, time, numpy as np, pinocchio as pin
t0 = time.perf_counter()
model = pin.Model(); model.loadFromBinary(sys.argv[1]); data = model.createData()
x = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1, ndmin=2); n = model.nv
t1 = time.perf_counter()
tau = np.empty((x.shape[0], n))
for k, row in enumerate(x):
    tau[k] = pin.rnea(model, data, row[:n], row[n:2 * n], row[2 * n:])
t2 = time.perf_counter()
np.save(sys.argv[3], tau)
print('{"read": %r, "loop": %r, "states": %d}' % (t1 - t0, t2 - t1, x.shape[0]))
"""

# Child process (c): the same with the project's reference RNEA. argv: robot, csv, out, states.
REFERENCE_CHILD = """
import sys, time, numpy as np
from vampc.robot import load_robot
from vampc.dynamics.reference import rnea
t0 = time.perf_counter()
chain = load_robot(sys.argv[1]); n = chain.n
x = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1, ndmin=2)[:int(sys.argv[4])]
t1 = time.perf_counter()
tau = np.empty((x.shape[0], n))
for k, row in enumerate(x):
    tau[k] = rnea(chain, row[:n], row[n:2 * n], row[2 * n:])
t2 = time.perf_counter()
np.save(sys.argv[3], tau)
print('{"read": %r, "loop": %r, "states": %d}' % (t1 - t0, t2 - t1, x.shape[0]))
"""


# --- set-up ---------------------------------------------------------------------------------------

def write_inputs(folder: Path, states: int):
    """The Puma chain, its program file and a trajectory CSV of `states` random states."""
    from vampc.compiler import compile_chain, program_document
    from vampc.emulator.trajectory import header
    from vampc.program.file import write_program
    from vampc.robot import load_robot
    from vampc.robot.random import random_state
    chain = load_robot(str(PUMA))
    write_program(program_document(compile_chain(chain)), folder / "puma.vamp.json")
    x = np.hstack(random_state(chain, states, SEED))
    row = ",".join(["%.17g"] * x.shape[1]) + "\n"
    text = ",".join(header(chain.n)) + "\n" + (row * states) % tuple(x.ravel().tolist())
    (folder / "traj.csv").write_text(text)
    return chain


def pinocchio_model(chain):
    """Pinocchio's model of a vampc Chain (as tests/test_dynamics_reference.py builds it): joint i at
    O_{i-1} with z on its axis; None if Pinocchio is not installed."""
    try:
        import pinocchio as pin
    except ImportError:
        return None
    from vampc.robot.chain import JointType, rot_z
    model, parent, placement = pin.Model(), 0, pin.SE3.Identity()
    for j in chain.joints:
        revolute = j.type is JointType.REVOLUTE
        rot = rot_z(j.offset) @ j.phi if revolute else j.phi
        origin = rot @ j.p_fixed + (0 if revolute else j.offset * np.array([0, 0, 1.0]))
        kind = pin.JointModelRZ() if revolute else pin.JointModelPZ()
        parent = model.addJoint(parent, kind, placement, j.name)
        body = pin.Inertia(j.mass, rot @ j.com + origin, rot @ j.inertia @ rot.T)
        model.appendBodyToJoint(parent, body, pin.SE3.Identity())
        placement = pin.SE3(rot, origin)
    model.gravity.linear = np.asarray(chain.gravity, dtype=float)
    return model


# --- timing ---------------------------------------------------------------------------------------

def median_time(fn, repeat: int):
    """Median wall seconds of `repeat` calls of fn, and the last call's result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def run_child(args) -> dict:
    """Run a process to completion; its last stdout line parsed as JSON when it is JSON."""
    proc = subprocess.run(args, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise SystemExit(f"benchmark child failed: {' '.join(map(str, args))}\n{proc.stderr}")
    last = (proc.stdout.strip().splitlines() or [""])[-1]
    return json.loads(last) if last.startswith("{") else {"stdout": last}


def whole_process(folder: Path, repeat: int, model, ref_states: int) -> dict:
    """(a), (b), (c): wall seconds of each whole process, median of `repeat`."""
    py, csv = sys.executable, str(folder / "traj.csv")
    out = {"a": median_time(lambda: run_child(
        [py, "-m", "vampc.cli", "emulate", str(folder / "puma.vamp.json"), "--trajectory", csv,
         "-o", str(folder / "tau.csv")]), repeat)}
    if model is not None:
        model.saveToBinary(str(folder / "puma.pin"))
        out["b"] = median_time(lambda: run_child(
            [py, "-c", PINOCCHIO_CHILD, str(folder / "puma.pin"), csv, str(folder / "pin.npy")]), repeat)
    out["c"] = median_time(lambda: run_child(
        [py, "-c", REFERENCE_CHILD, str(PUMA), csv, str(folder / "ref.npy"), str(ref_states)]), repeat)
    return out


def native_program(ld, values: dict):
    """The stream engine's native program and its inputs (one per (port, entry) its flow reads) from
    the host's port values."""
    from vampc.emulator import check_program, native
    from vampc.emulator.stream import flow
    fl = flow(ld, check_program(ld))
    return native.build(ld, fl), {i: values[(p, e)] for i, (p, e, _) in enumerate(fl.inputs)}


def compute_only(folder: Path, chain, model, repeat: int) -> dict:
    """(d): seconds of each engine on the whole trajectory, in this process, median of `repeat`."""
    from vampc.dynamics.reference import rnea
    from vampc.emulator import check_program, load_program
    from vampc.emulator.host import port_values, read_trajectory
    from vampc.emulator.stream import flow, run_numpy
    ld = load_program(str(folder / "puma.vamp.json"))
    traj = read_trajectory(folder / "traj.csv", ld.chain)
    out = {"ports": median_time(lambda: port_values(ld, traj), repeat)}
    prog, ports = native_program(ld, out["ports"][1])   # (compiled or found in the cache once,
    out["native"] = median_time(lambda: prog.run(ports, traj.count), repeat)    # outside the timing)
    fl = flow(ld, check_program(ld))
    out["numpy"] = median_time(lambda: run_numpy(ld, fl, ports, traj.count), repeat)
    out["reference"] = median_time(lambda: rnea(chain, traj.q, traj.qd, traj.qdd), repeat)
    if model is not None:
        out["pinocchio"] = median_time(lambda: pinocchio_loop(model, traj), repeat)
    return out


def pinocchio_loop(model, traj) -> np.ndarray:
    """Pinocchio's rnea looped in Python over the states."""
    import pinocchio as pin
    data = model.createData()
    tau = np.empty_like(traj.q)
    for k in range(traj.count):
        tau[k] = pin.rnea(model, data, traj.q[k], traj.qd[k], traj.qdd[k])
    return tau


def tick_engine(folder: Path, sets: int):
    """Seconds for Program Mode plus `sets` torque sets on the tick engine, and its torques."""
    from vampc.emulator import load_program
    from vampc.emulator.host import port_values, random_trajectory
    from vampc.emulator.tick import TickEngine
    ld = load_program(str(folder / "puma.vamp.json"))
    traj = random_trajectory(ld.chain, sets, SEED)
    ports = port_values(ld, traj)

    def run():
        engine = TickEngine(ld, seed=1)
        engine.program()
        return engine.run(ports, traj.count)
    return median_time(run, 1), ld, ports


# --- report ---------------------------------------------------------------------------------------

def line(label: str, seconds: float, states: int, note: str = "") -> str:
    """One row: wall seconds, sets/s and µs/state."""
    return (f"  {label:<52} {seconds:9.3f} s {states / seconds:13,.0f} sets/s "
            f"{1e6 * seconds / states:9.3f} µs/state {note}")


def report_whole(w: dict, states: int, ref_states: int) -> None:
    """Print (a), (b), (c) and the target ratio."""
    print("whole process (subprocess wall time, Python start-up and file reading included):")
    print(line("(a) vampc emulate --trajectory CSV -o tau.csv", w["a"][0], states))
    if "b" in w:
        b = w["b"][1]
        print(line("(b) np.loadtxt + pinocchio.rnea loop (+ np.save)", w["b"][0], states,
                   f"[in it: read {b['read']:.3f} s, loop {1e6 * b['loop'] / states:.3f} µs/state]"))
    c = w["c"][1]
    print(line(f"(c) np.loadtxt + reference rnea loop, {ref_states} states", w["c"][0], ref_states,
               f"[in it: loop {1e6 * c['loop'] / ref_states:.1f} µs/state]"))
    if "b" in w:
        ratio = w["b"][0] / w["a"][0]
        verdict = "meets" if ratio >= 1 else "misses"
        print(f"  ratio stream/pinocchio, whole process: {ratio:.2f} ({verdict} the target >= 1)")
    else:
        print("  Pinocchio is not installed: (b) and the target ratio were skipped")


def report_compute(d: dict, states: int) -> None:
    """Print (d) and the compute-only ratio."""
    print("compute only (in process, trajectory already in memory):")
    print(line("host port values (numpy, before either engine)", d["ports"][0], states))
    print(line("(d) stream engine, native code", d["native"][0], states))
    print(line("(d) stream engine, numpy fallback", d["numpy"][0], states))
    print(line("(d) reference rnea, batched numpy", d["reference"][0], states))
    if "pinocchio" in d:
        print(line("(d) pinocchio.rnea looped in Python", d["pinocchio"][0], states))
        print(f"  ratio stream native/pinocchio, compute only: "
              f"{d['pinocchio'][0] / d['native'][0]:.2f}")


def check_results(folder: Path, d: dict, w: dict, tick) -> None:
    """The engines agree bit for bit and with the references."""
    native, numpy_tau = d["native"][1], d["numpy"][1]
    print(f"native == numpy stream (bit for bit): {np.array_equal(native, numpy_tau)}")
    ref = d["reference"][1]
    print(f"max |stream - reference rnea|: {np.abs(native - ref).max():.3e}")
    if "b" in w:
        pin_tau = np.load(folder / "pin.npy")
        print(f"max |stream - pinocchio|: {np.abs(native - pin_tau).max():.3e}")
    seconds, ld, values = tick
    prog, ports = native_program(ld, values)
    same = np.array_equal(seconds[1], prog.run(ports, seconds[1].shape[0]))
    print(f"tick == native stream on its {seconds[1].shape[0]} sets (bit for bit): {same}")


def main(argv=None) -> None:
    """Parse options, run every measurement and print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--reference-states", type=int, default=10_000)
    ap.add_argument("--tick-sets", type=int, default=10_000)
    args = ap.parse_args(argv)
    ref_states = min(args.reference_states, args.states)
    with tempfile.TemporaryDirectory(prefix="vampc-bench-") as tmp:
        folder = Path(tmp)
        chain = write_inputs(folder, args.states)
        model = pinocchio_model(chain)
        print(f"vampc emulate throughput, Puma 560, {args.states} states, "
              f"{datetime.date.today().isoformat()}, median of {args.repeat}, "
              f"{os.cpu_count()} CPUs, VAMPC_NATIVE={os.environ.get('VAMPC_NATIVE', '(unset)')}")
        w = whole_process(folder, args.repeat, model, ref_states)
        report_whole(w, args.states, ref_states)
        d = compute_only(folder, chain, model, args.repeat)
        report_compute(d, args.states)
        tick = tick_engine(folder, args.tick_sets)
        verdict = "meets" if tick[0][0] < 60 else "misses"
        print(f"tick engine: Program Mode + {args.tick_sets} Puma sets in {tick[0][0]:.1f} s "
              f"({verdict} the target < 60 s)")
        check_results(folder, d, w, tick)


if __name__ == "__main__":
    main()
