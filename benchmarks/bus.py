"""The Mostly-Local Bus against point-to-point wiring (README, Mostly-Local Bus): the Puma 560, a
32-joint and a 256-joint chain (examples/make_snake.py), both recursions, systolic layout; per
row the tiers, the cycle (interval) and its stretch, the latency and its wait, the share of bus
slots used, pins per VAMP and compile time; every bus program's torques compared bit for bit with
the point-to-point program's on the stream engine. Then the 256-joint log chain compiled with
--bus mlb as a whole `vampc compile` process (the issue's target: under 30 s on 2 cores).

    python benchmarks/bus.py            # everything (about 5 minutes on 2 cores)
    python benchmarks/bus.py --quick    # the Puma and the 32-joint chain only
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vampc.compiler import CompileOptions, compile_chain
from vampc.emulator import emulate, loaded_from_compiled
from vampc.emulator.host import random_trajectory
from vampc.report.mlb import _bus_pins, _p2p_pins
from vampc.robot import load_robot

ROOT = Path(__file__).resolve().parent.parent


def snake(n: int, folder: Path) -> Path:
    path = folder / f"snake{n}.yaml"
    text = subprocess.run([sys.executable, str(ROOT / "examples" / "make_snake.py"), str(n)],
                          check=True, capture_output=True, text=True).stdout
    path.write_text(text)
    return path


def spans(tiers) -> str:
    """'2,2,4,4,8,8,16,16 + 6 x 64' for the table."""
    out, k = [], 0
    while k < len(tiers):
        j = k
        while j < len(tiers) and tiers[j] == tiers[k]:
            j += 1
        out.append(f"{j - k}×{tiers[k]}" if j - k > 2 else ",".join(map(str, tiers[k:j])))
        k = j
    return ",".join(out)


def row(name, rec, chain, wiring, tiers, base_tau, traj):
    t0 = time.perf_counter()
    c = compile_chain(chain, CompileOptions(recursion=rec, bus=wiring, tiers=tiers, verify=False))
    seconds = time.perf_counter() - t0
    net = c.network
    tau = emulate(loaded_from_compiled(c), traj, "stream").tau
    same = base_tau is None or np.array_equal(tau, base_tau)
    if net.bus is None:
        pins = max(_p2p_pins(v) for v in net.vamps)
        cells = ["point-to-point", "–", str(c.schedule.interval), "0", str(c.schedule.latency),
                 "0", "–", str(pins)]
    else:
        T = len(net.bus.tiers)
        slots = sum(t.buses(len(net.vamps)) for t in net.bus.tiers) * net.period
        pins = max(_bus_pins(v, T) for v in net.vamps)
        label = "bus, tuned" if tiers == "auto" else "bus, default"
        cells = [label, f"{T}: {spans([t.span for t in net.bus.tiers])}", str(c.schedule.interval),
                 str(net.bus.stretch), str(c.schedule.latency), str(net.bus.wait),
                 f"{len(net.bus.writes) / slots:.1%}", str(pins)]
    print(f"| {name} | {rec} | {len(net.vamps)} | " + " | ".join(cells)
          + f" | {seconds:.1f} | {'yes' if same else 'NO'} |", flush=True)
    return tau, c


def main(quick: bool) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        robots = [("Puma 560", ROOT / "examples" / "puma560.yaml"), ("32-joint chain", snake(32, folder))]
        if not quick:
            robots.append(("256-joint chain", snake(256, folder)))
        print("| robot | recursion | VAMPs | wiring | tiers | interval | stretch | latency | wait | "
              "bus slots used | pins per VAMP (max) | compile (s) | torques = point-to-point |")
        print("|---|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---|")
        for name, path in robots:
            chain = load_robot(path)
            traj = random_trajectory(chain, 20, 3)
            for rec in ("linear", "log"):
                base, _ = row(name, rec, chain, "p2p", None, None, traj)
                row(name, rec, chain, "mlb", None, base, traj)
                row(name, rec, chain, "mlb", "auto", base, traj)
        if not quick:
            out = folder / "s256.vamp.json.gz"
            t0 = time.perf_counter()
            subprocess.run(["vampc", "compile", str(folder / "snake256.yaml"), "--recursion", "log",
                            "--bus", "mlb", "-o", str(out)], check=True, capture_output=True)
            print(f"\nvampc compile snake256.yaml --recursion log --bus mlb (whole process): "
                  f"{time.perf_counter() - t0:.1f} s (target < 30 s)")


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("--quick", action="store_true", help="the Puma and the 32-joint chain only")
    main(ap.parse_args().quick)
