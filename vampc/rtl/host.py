"""What the host does to the generated design, tick by tick, and when it reads the torques.

The same host as the tick engine's (vampc.emulator.tick): in Program Mode it writes the next word of
each input buffer's stream (then null words); in Data Mode it loads the constant buffers before the
first tick, writes every port entry at the start of its block, pulses Global-Reset at every period's
first tick and reads torque j of set s at the output's tick plus s periods. The design's input
buffers are registers, so what must show during tick T is written in tick T - 1: the run starts with
one tick (-1) before the first Program-Mode tick.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vampc.emulator.host import port_values
from vampc.kinds import TapKind, unhandled
from vampc.machine.timing import port_writes


@dataclass
class HostRun:
    """A whole co-simulation run: per absolute tick T (0 = the first Program-Mode tick)."""

    load: int                       # Program-Mode ticks
    ticks: int                      # all ticks, Program and Data Mode
    writes: dict = field(default_factory=dict)    # T -> [(input buffer, raw words)], shows from T
    samples: dict = field(default_factory=dict)   # T -> [(output, set)]
    count: int = 0
    period: int = 1

    def program(self, T: int) -> bool:
        return T < self.load

    def global_reset(self, T: int) -> bool:
        return T < self.load or (T - self.load) % self.period == 0


def run_ticks(ld, count: int) -> int:
    """All ticks a run of `count` torque sets takes, Program Mode and Data Mode: up to the tick
    the last set's last torque is sampled, or its last op dumps where that is later (an op no
    torque reads may end after the last torque: its overflow, which the emulator counts, was
    never run in the design, and the overflow outputs disagreed)."""
    last_dump = max(ld.schedule.finish) - 1
    return ld.load_ticks + (count - 1) * ld.net.period + \
        max(ld.net.latency, last_dump) + 1


def host_run(ld, traj, inputs) -> HostRun:
    """The host's writes and reads for `traj` on `ld` (`inputs`: the design's input buffers as
    (kind, index, size), NetworkDesign.inputs)."""
    net, word = ld.net, ld.arith
    L, P, B = ld.load_ticks, net.period, net.clock
    count = traj.count
    run = HostRun(L, run_ticks(ld, count), count=count, period=P)
    last = run.ticks - L - 1                     # the last Data-Mode tick (run_ticks)
    where = {(kind, index): k for k, (kind, index, _) in enumerate(inputs)}
    size = [s for _, _, s in inputs]

    def write(T, k, words):
        w = np.zeros(size[k], dtype=np.int64)
        w[:len(words)] = words
        run.writes.setdefault(T, []).append((k, tuple(int(x) for x in w)))

    for e in ld.stream:
        match e.root.kind:
            case TapKind.PORT:
                k = where[("port", e.root.index)]
            case TapKind.CONST:
                k = where[("const", e.root.index)]
            case _:
                unhandled(e.root.kind)
        words = word.program_words(e.words)
        for T in range(L):
            write(T, k, words[T] if T < len(words) else ())
    for c in net.consts:
        write(L, where[("const", c.index)], word.fresh().encode(c.value))
    values = port_values(ld, traj)
    K = P // B
    for t in range(0, last + 1, B):
        block = t // B
        for p in net.ports:
            for j, s in port_writes(p.entries, block, K):
                write(L + t, where[("port", p.index)], values[(p.index, j)][s] if 0 <= s < count
                      else ())
    for k, o in enumerate(net.outputs):
        for s in range(count):
            run.samples.setdefault(L + o.tick + s * P, []).append((k, s))
    return run


def pack(words, W: int) -> int:
    """Raw W-bit words as one integer, word 0 in the low bits."""
    mask = (1 << W) - 1
    out = 0
    for i, w in enumerate(words):
        out |= (int(w) & mask) << (i * W)
    return out
