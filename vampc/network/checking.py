"""Limited automatic error correction (section VII) at compile time: the chain of successors and the
warm-up, recorded in the network (model.Checking) and checked when a file is read back. The
mechanism itself runs in the tick engine (vampc.emulator.checking, whose docstring is the design).

The chain is the VAMPs' logical order, after one extraneous VAMP (index V): the allocator numbers a
systolic network's VAMPs in graph order, so a VAMP's successor is most often its neighbour in the
same pass, and its operand inputs, which the checker's Operand-A' and Operand-B' share, come from
the same VAMPs as its own.

The warm-up: a VAMP that takes over a role (its successor's, to check it, or its own again) must
compute it for `warmup` whole periods before a result of that role is trusted. An op reads operands
latched at most P - 1 ticks before its first tick (the next latch of its slot would overwrite them)
and dumps D ticks after its first tick, so every op dumped `warmup` periods after the switch began
after it, with warmup = ceil(max over slots (lead + D) / P), lead the ticks from the slot's earlier
latch to its first tick, read off the slot's Cycle-Counter fields.
"""
from __future__ import annotations

from vampc.errors import VampcError
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
    longest = max((span(p, timing, period) for table in programs for p in table), default=1)
    return max(1, -(-longest // period))


def checking_for(net, programs, timing) -> Checking:
    """The Checking a compile with --error-correction adds to `net`."""
    return Checking(tuple(range(len(net.vamps))), warmup(programs, timing, net.period))


def check_checking(net, programs, timing, enabled: bool, path) -> None:
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
