"""Static timing: when, by the tick rules, each VAMP latches, computes and shows set 0's values.

Derived only from the wiring, the delivered programs and the host's port schedule (the rules are in
vampc/network/model.py). Every source shows a set's value during a window of exactly C ticks, so a
latch at Cycle-Counter d falls on exactly one tick of its operand's window. A VAMP then runs its
micro-steps in the ticks ending at the first tick with counter delay-R that leaves room for them after
both latches; its operands must not be re-latched (C ticks after the latch) before its last step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from vampc.emulator.load import Loaded
from vampc.emulator.rom import operand_steps, steps
from vampc.errors import VampcError
from vampc.network.model import window as tap_rule

INF = math.inf


@dataclass(frozen=True)
class VampTiming:
    """Absolute ticks (set 0) of a VAMP: latches, last micro-step; emit = last + 1 (inf: constant)."""

    latch_a: float
    latch_b: float
    last: float

    @property
    def emit(self) -> float:
        """First tick its Result shows set 0's value."""
        return self.last + 1


def derive(ld: Loaded) -> tuple[VampTiming, ...]:
    """Timing of every VAMP; VampcError naming the VAMP, tick and operand on a violation."""
    memo: dict[int, VampTiming] = {}
    for v in range(len(ld.net.vamps)):
        _timing(ld, v, memo, [])
    return tuple(memo[v] for v in range(len(ld.net.vamps)))


def window(ld: Loaded, tap, memo, trail) -> tuple[float, float]:
    """[first, end) ticks in which `tap` shows set 0's value (the rule is network.model.window)."""
    if tap.kind in ("const", "port"):
        port_cycle = ld.net.ports[tap.index].cycle if tap.kind == "port" else 0
        return tap_rule(tap, ld.cycle, port_cycle=port_cycle)
    src = tap.index if tap.kind == "vamp" else ld.net.buffers[tap.index].source
    return tap_rule(tap, ld.cycle, _timing(ld, src, memo, trail).emit)


def _timing(ld: Loaded, v: int, memo, trail) -> VampTiming:
    if v in memo:
        return memo[v]
    if v in trail:
        loop = " -> ".join(ld.vamp_name(x) for x in trail[trail.index(v):] + [v])
        raise VampcError(f"{ld.path}: the wiring has a loop: {loop}")
    trail.append(v)
    vamp, prog = ld.net.vamps[v], ld.programs[v]
    t_a = _latch(ld, v, "A", vamp.a, prog.delay_a, memo, trail)
    t_b = _latch(ld, v, "B", vamp.b, prog.delay_b, memo, trail)
    trail.pop()
    memo[v] = _compute(ld, v, t_a, t_b)
    return memo[v]


def _latch(ld, v, name, operand, delay, memo, trail) -> float:
    if not 0 <= delay < ld.cycle:
        raise VampcError(f"{ld.path}: {ld.vamp_name(v)}: delay-{name} {delay} never matches the "
                         f"Cycle-Counter (0..{ld.cycle - 1}): operand {name} is never latched")
    wins = {window(ld, tap, memo, trail) for tap in operand.taps}
    if len(wins) > 1:
        raise VampcError(f"{ld.path}: {ld.vamp_name(v)}: operand {name} reads matrix columns "
                         f"that show set 0 in different windows {sorted(wins)}")
    lo, _ = wins.pop()
    if lo == -INF:
        return -INF
    return lo + (delay - lo) % ld.cycle


def _compute(ld: Loaded, v: int, t_a: float, t_b: float) -> VampTiming:
    C, prog = ld.cycle, ld.programs[v]
    d = steps(prog.rom)
    if not 0 <= prog.delay_r < C:
        raise VampcError(f"{ld.path}: {ld.vamp_name(v)}: delay-R {prog.delay_r} never matches the "
                         f"Cycle-Counter (0..{C - 1}): the result is never driven")
    if d > C:
        raise VampcError(f"{ld.path}: {ld.vamp_name(v)}: a {d}-step op does not fit a {C}-tick cycle")
    ready = max(t_a, t_b)
    if ready == -INF:
        return VampTiming(-INF, -INF, INF - 1)
    earliest = ready + d - 1
    last = earliest + (prog.delay_r - earliest) % C
    reader = last - d + operand_steps(prog.rom)    # last micro-step that reads the operands
    for name, t in (("A", t_a), ("B", t_b)):
        if t != -INF and reader >= t + C:
            raise VampcError(
                f"{ld.path}: {ld.vamp_name(v)}: operand {name} latched at tick {t:g} is re-latched "
                f"at tick {t + C:g}, before the micro-step at tick {reader:g} that still reads it "
                f"(delay-R {prog.delay_r})")
    return VampTiming(t_a, t_b, last)


def check_outputs(ld: Loaded, timing) -> None:
    """Each τ_i must be readable at its scheduled tick."""
    C = ld.cycle
    for o in ld.net.outputs:
        e = timing[o.vamp].emit
        if not e <= o.tick < e + C:
            raise VampcError(f"{ld.path}: τ{o.joint} is read from {ld.vamp_name(o.vamp)} at tick "
                             f"{o.tick}, but it shows set 0 during ticks [{e:g}, {e + C:g})")
