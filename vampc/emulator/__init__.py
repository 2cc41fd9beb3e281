"""The VAMP network emulator: load a program file, check it, program the network and run it."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from vampc.emulator.check import check_program
from vampc.emulator.host import Trajectory, checked_trajectory, port_values
from vampc.emulator.load import (
    Loaded,
    load_program,
    loaded_from_compiled,
    loaded_from_doc,
)
from vampc.kinds import Engine, unhandled

ENGINES = Engine.names()


@dataclass(frozen=True)
class Emulation:
    """Torques and the emulated and wall-clock timing of one run."""

    tau: np.ndarray
    engine: str
    load_ticks: int          # Program Mode
    first_tick: int          # Data-Mode tick at which the first torque set is complete
    interval: int            # ticks between successive torque sets
    data_ticks: int          # Data-Mode ticks for the whole trajectory
    wall_seconds: float
    checking: dict | None = None   # error correction: what the checking did (tick engine)

    @property
    def emulated_flops(self) -> int:
        """Program load plus data ticks (1 tick = 1 flop)."""
        return self.load_ticks + self.data_ticks


def emulate(ld: Loaded, traj: Trajectory, engine: str = "stream", seed: int = 0, vcd=None,
            static_check: bool = True, progress=None, stream=None, faults=()) -> Emulation:
    """Run the loaded program on a trajectory with the chosen engine. `vcd` is a VcdWriter (tick
    engine only); `progress(done, total)` reports progress; `stream` is a StreamEngine prepared for
    a longer run this trajectory is a chunk of (vampc.emulator.driver); `faults`: Faults injected
    (tick engine only; vampc.emulator.faults).

    `traj`: q, qd and qdd (states × joints, in the program's joint order: README, Python API),
    optionally t (states) and, on a floating-base program, base (states × 9: ω_0, ω̇_0, a_0 in O_0;
    None: the base at rest); refused (VampcError) where not so (checked_trajectory). Returns the
    torques as `tau` (states × outputs: the joints, then a floating base's wrench)."""
    start = time.perf_counter()
    try:
        engine = Engine(engine)
    except ValueError:
        from vampc.errors import VampcUsageError
        raise VampcUsageError(f"engine {engine!r}: the engines are {', '.join(ENGINES)}") from None
    traj = checked_trajectory(ld.chain, traj)
    match engine:
        case Engine.TICK:
            if static_check:
                check_program(ld)
            return _tick(ld, traj, port_values(ld, traj), seed, vcd, start, progress, faults)
        case Engine.STREAM:
            if faults:
                from vampc.errors import VampcUsageError
                raise VampcUsageError("--fault needs --engine tick (faults are injected into its "
                                      "registers)")
            return _stream(ld, traj, progress, stream or prepare_stream(ld, traj.count,
                                                                        static_check), start)
        case _:
            unhandled(engine)


def _stream(ld, traj, progress, stream, start) -> Emulation:
    values = port_values(ld, traj)
    inputs = {i: values[(p, e)] for i, (p, e, _) in enumerate(stream.flow.inputs)}
    tau = stream.run(inputs, traj.count, progress)
    latency = ld.net.latency
    P = ld.period
    return Emulation(tau, "stream", ld.load_ticks, latency, P, (traj.count - 1) * P + latency + 1,
                     time.perf_counter() - start)


def prepare_stream(ld: Loaded, total: int, static_check: bool = True):
    """The stream engine for `ld`: the static checks (or, without them, the timing derivation that
    resolves every operand), the flow, and the native code if the run is long enough."""
    from vampc.emulator.stream import StreamEngine, flow
    from vampc.emulator.timing import derive
    timing = check_program(ld) if static_check else derive(ld)
    return StreamEngine(ld, flow(ld, timing), total)


def _tick(ld, traj, ports, seed, vcd, start, progress, faults=()) -> Emulation:
    from vampc.emulator.tick import TickEngine, TickStats
    if ld.net.checking is not None:        # --error-correction: the checking mechanism runs
        from vampc.emulator.checking import CheckingTickEngine as TickEngine
    engine = TickEngine(ld, seed=seed, vcd=vcd, faults=faults)
    load = engine.program()
    stats = TickStats()
    tau = engine.run(ports, traj.count, stats, progress)
    appear = np.diff(stats.appear)
    interval = int(appear.max()) if appear.size else ld.period
    checking = None
    if ld.net.checking is not None:
        checking = {**engine.status(), "maintenance": engine.maintenance()}
    return Emulation(tau, "tick", load, stats.first_set_tick, interval, stats.data_ticks,
                     time.perf_counter() - start, checking)


__all__ = ["ENGINES", "Emulation", "Loaded", "Trajectory", "emulate", "load_program",
           "loaded_from_doc", "loaded_from_compiled", "check_program", "prepare_stream"]
