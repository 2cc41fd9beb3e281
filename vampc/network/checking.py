"""Limited automatic error correction (section VII) at compile time: the chain of successors and the
warm-up, recorded in the network (model.Checking) and checked when a file is read back. The
mechanism itself runs in the tick engine (vampc.emulator.checking, whose docstring is the design).

The chain is the VAMPs' logical order, after one extraneous VAMP (index V): the allocator numbers a
systolic network's VAMPs in graph order, so a VAMP's successor is most often its neighbour in the
same pass, and its operand inputs, which the checker's Operand-A' and Operand-B' share, come from
the same VAMPs as its own.

The warm-up: a VAMP that takes over a role (its successor's, to check it, or its own again) at a
period boundary must compute it for `warmup` whole periods before a result of that role is trusted:
compared, or driven onto a line (the line then shows the VAMP's last dump, so that dump must be of
an op run whole after the switch). A slot's op spans s = lead + D ticks from its earlier operand
latch to its dump (lead < P: the slot's next latch would overwrite the operand; D the op's
duration), read off the slot's Cycle-Counter fields; its last dump before the end of `warmup`
periods falls at counter delay-R of the last period, so the op began after the switch when
(warmup - 1)·P + delay-R ≥ s - 1: warmup = 1 + max(0, ⌈(s - 1 - delay-R) / P⌉), the largest over
the slots.
"""
from __future__ import annotations

from vampc.errors import VampcError
from vampc.kinds import TapKind
from vampc.machine import interp as rom
from vampc.network.model import Checking


def span(program, timing, period: int) -> int:
    """Ticks from a slot's earlier operand latch to its dump, inclusive (a Program's fields)."""
    d = rom.duration(program.rom, timing)
    first = (program.delay_r - d + 1) % period
    lead = max((first - program.delay_a) % period, (first - program.delay_b) % period)
    return lead + d


def warmup(programs, timing, period: int) -> int:
    """The periods a VAMP computes a role before its results are those of ops it ran whole."""
    need = 1
    for table in programs:
        for p in table:
            late = span(p, timing, period) - 1 - p.delay_r
            need = max(need, 1 + max(0, -(-late // period)))
    return need


def checking_for(net, programs, timing, compare: int = 1) -> Checking:
    """The Checking a compile with --error-correction adds to `net` (`compare`: --check-cycles)."""
    return Checking(tuple(range(len(net.vamps))), warmup(programs, timing, net.period), compare)


def check_checking(net, programs, timing, enabled: bool, path, cycles: int = 1) -> None:
    """A program file's error correction: present exactly when its options say so, with the
    warm-up its slots need (VampcError naming the field otherwise)."""
    if net.checking is None:
        if enabled:
            raise VampcError(f"{path}: options.error_correction is true but the network has no "
                             "error_correction section")
        return
    if not enabled:
        raise VampcError(f"{path}: network.error_correction is present but options.error_correction "
                         "is not true")
    if net.bus is not None:
        raise VampcError(f"{path}: network.error_correction: error correction is built for "
                         "point-to-point wiring, not the bus")
    want = warmup(programs, timing, net.period)
    if net.checking.warmup != want:
        raise VampcError(f"{path}: network.error_correction.warmup is {net.checking.warmup}, but "
                         f"the slots need {want} period(s) to run an op whole")
    if net.checking.compare != cycles:
        raise VampcError(f"{path}: network.error_correction.compare is {net.checking.compare}, "
                         f"but options.check_cycles is {cycles}")


def unnameable(net) -> list[int]:
    """VAMPs whose result reaches no torque output (through multiplexer inputs and buffers): the
    checking can excise them, but Maintenance Mode cannot carry a number from their lines out."""
    outs = {o.vamp for o in net.outputs}
    src = {b.index: b.source for b in net.buffers}
    readers: dict[int, set] = {}
    for v in net.vamps:
        for op in v.a + v.b:
            for t in op.taps:
                s = t.index if t.kind is TapKind.VAMP else src.get(t.index) \
                    if t.kind is TapKind.BUFFER else None
                if s is not None:
                    readers.setdefault(s, set()).add(v.index)
    reach = set(outs)
    todo = list(outs)
    writers: dict[int, set] = {}
    for s, rs in readers.items():
        for r in rs:
            writers.setdefault(r, set()).add(s)
    while todo:
        v = todo.pop()
        for w in writers.get(v, ()):
            if w not in reach:
                reach.add(w)
                todo.append(w)
    return sorted(set(range(len(net.vamps))) - reach)
