"""Limited automatic error correction (README, Error correction), measured.

1. Without faults, a program compiled with --error-correction gives the plain program's torques bit
   for bit on every example, both recursions, the systolic, folded and budget layouts, on both
   engines; the tick engine runs a whole sweep of the checking (every VAMP checked, forward and
   back) with its timing checks on.
2. The Puma 560 single-permanent-fault campaigns (`vampc faults`, every kind on every VAMP), linear
   and log recursion, with and without error correction, and the transient and intermittent
   campaigns with it: classes, coverage, detection latency, corrupted sets, the wall time of each
   whole process on this machine (the issue's target: the linear campaign with checking under 10
   minutes on 2 cores).
3. The linear campaign with checking again through a local Dask cluster (two worker processes),
   and once more interrupted (SIGINT after 40 s) and re-run: both give the runs of part 2.

    python benchmarks/error_correction.py            # everything (about 40 minutes on 2 cores)
    python benchmarks/error_correction.py --quick    # part 1 on the small examples, the linear campaigns
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vampc.compiler import CompileOptions, compile_chain
from vampc.emulator import emulate, loaded_from_compiled
from vampc.emulator.checking import CheckingTickEngine, sweep_periods
from vampc.emulator.host import port_values, random_trajectory
from vampc.robot import load_robot

ROOT = Path(__file__).resolve().parent.parent
LONGEST = 1500     # sets a fault-free tick run takes at most (a sweep of thousands of VAMPs is longer)
CONFIGS = [("linear", {}), ("log", {"recursion": "log"}), ("linear folded", {"layout": "folded"}),
           ("log folded", {"recursion": "log", "layout": "folded"}),
           ("linear budget", {"interval": 12}), ("log budget", {"recursion": "log", "interval": 12})]


def fault_free(quick: bool) -> None:
    examples = sorted(p for p in (ROOT / "examples").iterdir() if p.suffix in (".yaml", ".urdf"))
    if quick:
        examples = [p for p in examples if p.stem in ("planar2", "stanford")]
    print("| robot | configuration | VAMPs | sweep, periods | tick engine | stream engine |")
    print("|---|---|---:|---:|---|---|")
    for path in examples:
        chain = load_robot(str(path))
        for name, opts in CONFIGS:
            try:
                plain = loaded_from_compiled(compile_chain(chain, CompileOptions(**opts)))
                ec = loaded_from_compiled(compile_chain(chain, CompileOptions(error_correction=True,
                                                                              **opts)))
            except Exception as exc:  # noqa: BLE001 - a configuration this robot does not take
                print(f"| {path.stem} | {name} | | | not compiled: {str(exc)[:60]} | |")
                continue
            V, w = len(ec.net.vamps), ec.net.checking.warmup
            count = sweep_periods(V, w) + 3 * (w + 1) + 4
            whole = count <= LONGEST       # snake64's systolic sweeps: their first LONGEST sets
            count = min(count, LONGEST)
            traj = random_trajectory(chain, count, 1)
            want = emulate(plain, traj, "tick").tau
            engine = CheckingTickEngine(ec, seed=1)
            engine.program()
            got = engine.run(port_values(ec, traj), count)
            tick_ok = np.array_equal(got.view(np.int64), want.view(np.int64)) and \
                not engine.detections and (not whole or (engine.checked >= 1).all())
            stream = emulate(ec, traj, "stream").tau
            stream_ok = np.array_equal(stream.view(np.int64), want.view(np.int64))
            sweep = f"{sweep_periods(V, w)}" + ("" if whole else f" (first {count} run)")
            print(f"| {path.stem} | {name} | {V} + 1 | {sweep} | "
                  f"{'bit for bit' if tick_ok else 'DIFFERS'} | "
                  f"{'bit for bit' if stream_ok else 'DIFFERS'} |", flush=True)


def _faults(prog: Path, folder: Path, *args: str) -> tuple[dict, float]:
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "vampc.cli", "faults", str(prog), "--format", "json",
                          *args], check=True, capture_output=True, text=True).stdout
    return json.loads(out), time.perf_counter() - start


def campaigns(quick: bool, folder: Path) -> dict:
    print("\n| Puma 560 | checking | faults | masked | detected, corrected | detected, not corrected | "
          "silent | coverage | named | latency, cycles (median / max) | corrupted before (mean / max) "
          "| wall |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    kept = {}
    runs = [(rec, ec, "single") for rec in (("linear",) if quick else ("linear", "log"))
            for ec in (True, False)]
    runs += [("linear", True, "transient"), ("linear", True, "intermittent")]
    for rec, ec, campaign in runs:
        prog = folder / f"puma-{rec}-{ec}.vamp.json"
        if not prog.exists():
            subprocess.run([sys.executable, "-m", "vampc.cli", "compile",
                            str(ROOT / "examples" / "puma560.yaml"), "--recursion", rec,
                            *(["--error-correction"] if ec else []), "-o", str(prog)],
                           check=True, capture_output=True)
        doc, wall = _faults(prog, folder, "--campaign", campaign, "--results",
                            str(folder / f"{prog.stem}.{campaign}.jsonl"))
        kept[(rec, ec, campaign)] = (prog, doc)
        s = doc["summary"]
        c = s["classes"]
        lat = s.get("latency_cycles") or {}
        cb = s.get("corrupted_before_correction") or {}
        cov = "" if s["coverage"] is None else f"{100 * s['coverage']:.1f}%"
        print(f"| {rec}{'' if campaign == 'single' else ', ' + campaign} | "
              f"{'yes' if ec else 'no'} | {s['runs']} | {c['masked']} | "
              f"{c['detected-corrected']} | {c['detected-not-corrected']} | "
              f"{c['silent-corruption']} | "
              f"{cov} | "
              f"{s.get('named_right', '')} | "
              f"{lat.get('median', '')} / {lat.get('max', '')} | "
              f"{cb.get('mean', 0):.0f} / {cb.get('max', '')} | {wall:.0f} s |", flush=True)
    return kept


def elsewhere(kept: dict, folder: Path) -> None:
    """The linear campaign with checking on a local Dask cluster, and interrupted then resumed."""
    import os
    import signal
    prog, want = kept[("linear", True, "single")]
    from distributed import LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster:
        doc, wall = _faults(prog, folder, "--scheduler", cluster.scheduler_address, "--results",
                            str(folder / "dask.jsonl"))
    print(f"\nDask LocalCluster (2 worker processes): {wall:.0f} s, runs "
          f"{'identical' if doc['runs'] == want['runs'] else 'DIFFERENT'}")
    results = folder / "resume.jsonl"
    proc = subprocess.Popen([sys.executable, "-m", "vampc.cli", "faults", str(prog), "--results",
                             str(results)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    time.sleep(40)
    os.killpg(proc.pid, signal.SIGINT)
    code = proc.wait()
    kept_lines = len(results.read_bytes().splitlines()) - 1
    doc, wall = _faults(prog, folder, "--results", str(results))
    print(f"interrupted after 40 s (exit {code}) with {kept_lines} runs kept; the re-run took "
          f"{wall:.0f} s for the other {len(want['runs']) - kept_lines}; runs "
          f"{'identical' if doc['runs'] == want['runs'] else 'DIFFERENT'}")


def main() -> None:
    import argparse
    ap = argparse.ArgumentParser(description=__doc__,          # (its parts, as the file says them)
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="part 1 on the small examples and the "
                    "linear campaigns only")
    quick = ap.parse_args().quick
    fault_free(quick)
    with tempfile.TemporaryDirectory() as tmp:
        kept = campaigns(quick, Path(tmp))
        if not quick:
            elsewhere(kept, Path(tmp))


if __name__ == "__main__":
    main()
