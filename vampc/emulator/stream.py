"""The stream engine: the loaded programs evaluated over a whole trajectory at once.

After the static checks (vampc.emulator.check) have proved that every latch reads the value of the same
torque set, the network is a pure function per set: each VAMP's result is its ROM sequence applied to
its operands. This engine evaluates that function vectorised over all sets, VAMP by VAMP in wiring
order, with the same ROM code as the tick engine, so the two agree bit for bit.
"""
from __future__ import annotations

from graphlib import TopologicalSorter

import numpy as np

from vampc.emulator import rom
from vampc.emulator.load import Loaded

CHUNK = 4096   # torque sets evaluated together: keeps the working set in cache


def wiring_order(ld: Loaded) -> list[int]:
    """VAMP indices, every VAMP after the VAMPs it reads (directly or through buffers)."""
    deps = {}
    for v in ld.net.vamps:
        deps[v.index] = {_source_vamp(ld, t) for t in v.a.taps + v.b.taps} - {None}
    return list(TopologicalSorter(deps).static_order())


def _source_vamp(ld: Loaded, tap):
    if tap.kind == "vamp":
        return tap.index
    if tap.kind == "buffer":
        return ld.net.buffers[tap.index].source
    return None


def run_stream(ld: Loaded, ports: dict[int, np.ndarray], count: int, progress=None) -> np.ndarray:
    """Torques (count, n) given each port's values (count, 3|9) for every set.
    `progress(done, total)` is called after each chunk if given."""
    return StreamEngine(ld, count).run(ports, count, progress)


class StreamEngine:
    """The stream engine prepared once for a run of `total` sets, which may arrive in chunks."""

    def __init__(self, ld: Loaded, total: int):
        # --- native fast path (vampc.emulator.native): the same arithmetic as generated C. None
        # when off (VAMPC_NATIVE=0), when no compiler works, or for a run too short to pay for
        # compiling; numpy does the work then ---
        from vampc.emulator.native import prepare
        self.ld, self.native = ld, prepare(ld, total)
        self.order = None if self.native is not None else wiring_order(ld)

    def run(self, ports: dict[int, np.ndarray], count: int, progress=None) -> np.ndarray:
        """Torques (count, n) of `count` sets given their port values."""
        if self.native is not None:
            return self.native.run(ports, count, progress)
        return run_numpy(self.ld, ports, count, progress, self.order)


def run_numpy(ld: Loaded, ports: dict[int, np.ndarray], count: int, progress=None,
              order=None) -> np.ndarray:
    """The numpy path of run_stream: rom.run per VAMP over chunks of sets."""
    order = wiring_order(ld) if order is None else order
    outs = []
    for lo in range(0, count, CHUNK):
        chunk = {p: a[lo:lo + CHUNK] for p, a in ports.items()}
        outs.append(_run_chunk(ld, order, chunk, min(CHUNK, count - lo)))
        if progress is not None:
            progress(min(lo + CHUNK, count), count)
    return np.concatenate(outs, axis=0) if outs else np.zeros((0, ld.chain.n))


def _run_chunk(ld: Loaded, order, ports, count) -> np.ndarray:
    vals: dict[int, np.ndarray] = {}
    for v in order:
        vamp = ld.net.vamps[v]
        a = _operand(ld, vamp.a, vals, ports, count)
        b = _operand(ld, vamp.b, vals, ports, count)
        vals[v] = rom.run(ld.programs[v].rom, a, b)
    tau = np.empty((count, ld.chain.n))
    for o in ld.net.outputs:
        tau[:, o.joint - 1] = vals[o.vamp][:, o.component]
    return tau


def _operand(ld: Loaded, operand, vals, ports, count) -> np.ndarray:
    taps = operand.taps
    if len(taps) == 3:   # a matrix delivered as three column results of an MM group
        cols = [_tap(ld, t, vals, ports, count)[:, :3] for t in taps]
        return np.stack(cols, axis=-1).reshape(count, 9)
    return _tap(ld, taps[0], vals, ports, count)


def _tap(ld: Loaded, tap, vals, ports, count) -> np.ndarray:
    if tap.kind == "vamp":
        return vals[tap.index]
    if tap.kind == "buffer":
        return vals[ld.net.buffers[tap.index].source]
    if tap.kind == "port":
        return ports[tap.index]
    value = np.asarray(ld.net.consts[tap.index].value)
    return np.broadcast_to(value, (count, value.size))
