"""The timing rules (vampc.machine.timing), against cases worked out by hand from the hardware's
description (vampc.network.model) and, for the buffer capture, against a clocked shift register
simulated here tick by tick."""
from __future__ import annotations

import math

from vampc.machine.timing import (
    buffer_stage,
    buffer_window,
    capture_counter,
    captures,
    cyclic_gaps,
    next_capture,
    overlapping_spans,
    port_window,
    result_windows,
    step_counter,
)


def test_cyclic_gaps():
    assert cyclic_gaps([3], 8) == [8]                       # alone: a whole period
    assert cyclic_gaps([1, 5], 8) == [4, 4]
    assert cyclic_gaps([6, 1, 3], 8) == [3, 2, 3]           # 6 -> 1 wraps round: 3 ticks
    assert cyclic_gaps([2, 2], 8) == [0, 0]                 # two events in one tick


def test_result_windows_hold_until_the_next_dump():
    # dumps at ticks 9 and 11 of a period of 4: counters 1 and 3; each value shows from the tick
    # after its dump until the other's shows
    assert result_windows([9, 11], 4) == [(10, 12), (12, 14)]
    assert result_windows([5], 4) == [(6, 10)]


def test_buffer_stages_against_a_clocked_shift_register():
    clock, period, stages = 2, 8, 3
    result = list(range(100, 140))                # what the Result shows at each tick
    chain = [None] * (stages + 1)                  # chain[s]: stage s (chain[0] unused)
    shown = {}                                     # (tick, stage) -> value shown during the tick
    for t in range(40):
        for s in range(1, stages + 1):
            shown[(t, s)] = chain[s]
        if captures(t, clock):
            chain = [None, result[t]] + chain[1:stages]
    for t in range(16, 40):
        for s in range(1, stages + 1):
            back = capture_counter(t % period, s, clock, period)
            captured = max(x for x in range(t) if captures(x, clock) and x % period == back)
            assert shown[(t, s)] == result[captured], (t, s)
    # a value on the Result during [emit, next) shows on stage s during buffer_window
    emit, nxt = 5, 9
    for s in range(1, stages + 1):
        lo, hi = buffer_window(emit, nxt, s, clock)
        on = [t for t in range(40) if shown[(t, s)] is not None and emit <= shown[(t, s)] - 100 < nxt]
        assert (lo, hi) == (on[0], on[-1] + 1), s
        assert all(buffer_stage(emit, nxt, t, clock) <= s for t in range(lo, hi))
    assert buffer_stage(emit, nxt, 7, clock) == 0
    assert math.isinf(buffer_window(-math.inf, math.inf, 1, clock)[0])


def test_ports_steps_and_spans():
    assert port_window(3, 5, 4) == (12, 20)
    ends = (1, 2, 3)                               # a three-step op dumping at counter 1
    assert [step_counter(1, ends, j, 8) for j in range(3)] == [7, 0, 1]
    assert overlapping_spans([(0, 3), (3, 2)], 8) is None
    assert overlapping_spans([(0, 3), (2, 2)], 8) == (0, 1)
    assert overlapping_spans([(6, 3), (1, 2)], 8) is None      # ticks 6, 7, 0 and 1, 2
    assert overlapping_spans([(6, 4), (1, 2)], 8) == (0, 1)    # ticks 6, 7, 0, 1 meet 1


def test_next_capture_is_the_next_block_start():
    assert [next_capture(e, 4) for e in (0, 3, 4, 7, 8)] == [4, 4, 8, 8, 12]
    # and a value shown from there on is still captured by the stage: its first capture is at the
    # end of the block it appeared in
    assert all(captures(next_capture(e, 4) - 1, 4) for e in range(20))


def test_every_tap_kind_has_its_window_and_no_other_passes():
    import pytest

    from vampc.errors import VampcInternalError
    from vampc.kinds import TapKind
    from vampc.machine.timing import window
    from vampc.network.model import Tap
    got = {kind: window(Tap(kind, 0, 1), 4, emit=5, next_emit=9, block=1, next_block=2)
           for kind in TapKind if kind is not TapKind.BUS}
    assert got == {TapKind.VAMP: (5, 9), TapKind.BUFFER: (8, 12), TapKind.PORT: (4, 8),
                   TapKind.CONST: (-math.inf, math.inf)}
    # a bus shows whatever its writer drives in that tick: it has no window of its own, and is
    # resolved to its writer's tap first (vampc.network.bus.bus_source)
    with pytest.raises(VampcInternalError, match="resolve"):
        window(Tap(TapKind.BUS, 0), 4)

    class Odd:
        kind = "wire"
        stage = 1
    with pytest.raises(VampcInternalError, match="no branch handles 'wire'"):
        window(Odd(), 4)


def test_port_schedule_shows_the_latest_entry_cyclically():
    from vampc.machine.timing import PortSchedule
    s = PortSchedule([5, 2, 7], 4)          # blocks 5, 2, 7 of a 4-block period: 1, 2, 3
    assert [s.entry_at(b) for b in range(8)] == [2, 0, 1, 2, 2, 0, 1, 2]
    assert s.gap == {0: 1, 1: 1, 2: 2}       # 1 -> 2, 2 -> 3, 3 -> 1 (round the period)
    assert PortSchedule([], 4).entry_at(3) is None
