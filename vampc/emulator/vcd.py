"""Value Change Dump output of a tick-engine run (readable by GTKWave), written with pyvcd.

One scope per VAMP (inside a top scope `network`), named after its number and graph node, holding its
Result as three `real` signals x, y, z (or, for a fixed-point word with `bits`, three `wire` vectors
holding the words' two's-complement bits); one tick of the emulator is 1 ns of VCD time. The dump starts at
the first sampled tick, whose `$dumpvars` holds every Result; after it only changes are written. Every
value is written with the shortest decimal that reads back as the same float64 (Python's repr), so a
reader gets the emulator's Results bit for bit; NaN and ±inf are written as `nan`, `inf`, `-inf` (what C's
`%g`, which the VCD standard names for reals, prints). The output is deterministic: no `$date`.

The writer writes to a text stream it does not own: opening, renaming into place and removing a failed
run's file are the caller's; a failed write raises OSError from `sample` or `close`.
"""
from __future__ import annotations

import re
from collections.abc import Sequence
from typing import TextIO

import numpy as np
from vcd import VCDWriter

_NOT_IN_NAME = re.compile(r"[^A-Za-z0-9_]")


class _Exact(float):
    """A float that pyvcd writes in full and compares by what it writes.

    pyvcd formats a real change as f"r{value:.16g}", the `%.16g` of IEEE 1364-2005 §18.2.1, and keeps it on
    purpose (pyvcd PR #39 was declined). Sixteen digits do not identify every float64: 0.1 + 0.2 is
    written 0.3, which reads back as another number. Formatting goes through `__format__`, so this
    subclass answers with repr, the shortest text that round-trips. pyvcd also drops a change equal to
    the previous value; comparing by text makes 0.0 → -0.0 a change and NaN → NaN none."""

    __slots__ = ()

    def __format__(self, spec: str) -> str:
        return repr(float(self))

    def __eq__(self, other) -> bool:
        return isinstance(other, float) and repr(float(self)) == repr(float(other))

    def __ne__(self, other) -> bool:
        return not self == other

    __hash__ = float.__hash__


def scope_names(names: Sequence[str]) -> list[str]:
    """The VCD scope name of each VAMP: its name with every character other than a letter, digit or
    underscore replaced by `_`, `_`-prefixed if it would start with a digit or be empty, and suffixed
    `_2`, `_3`, ... where two names would otherwise coincide."""
    out, taken = [], set()
    for name in names:
        base = _NOT_IN_NAME.sub("_", name)
        base = base if base[:1].isalpha() or base[:1] == "_" else "_" + base
        scope, k = base, 1
        while scope in taken:
            k += 1
            scope = f"{base}_{k}"
        taken.add(scope)
        out.append(scope)
    return out


def _changed(new: np.ndarray, old: np.ndarray) -> np.ndarray:
    """Where `new` would be written differently from `old`: the value or the sign of a zero changed
    (NaN to NaN is no change)."""
    same = (new == old) & (np.signbit(new) == np.signbit(old))
    return ~(same | (np.isnan(new) & np.isnan(old)))


class VcdWriter:
    """Streams the Results of a tick-engine run to `stream` as VCD; `names[v]` names VAMP v's scope.
    `bits`: write each scalar as the fixed-point word the network holds, a two's-complement vector
    of that many bits (a `wire`, as the RTL's ports carry it: `vampc emulate --vcd-as word`), not
    as a real."""

    def __init__(self, stream: TextIO, names: Sequence[str], bits: int | None = None):
        self._stream = stream
        self._scopes = scope_names(names)
        self._vcd: VCDWriter | None = None
        self._vars: list[list] = []
        self._bits = bits
        self._last = np.full((len(names), 3), np.nan)
        self._tick = 0

    def sample(self, tick: int, values: np.ndarray) -> None:
        """Record the Results visible from `tick` on (`values`: (V, 3), every VAMP's x, y, z: the
        words, int64, when the writer has `bits`; else their values). Ticks must not decrease."""
        if self._vcd is None:
            self._start(tick, values)
        elif self._bits:
            for v, c in np.argwhere(values != self._last).tolist():
                self._vcd.change(self._vars[v][c], tick, self._word(values[v, c]))
        else:
            for v, c in np.argwhere(_changed(values, self._last)).tolist():
                self._vcd.change(self._vars[v][c], tick, _Exact(values[v, c]))
        self._last[...] = values
        self._tick = tick

    @property
    def words(self) -> bool:
        """Whether `sample` takes the words themselves (a writer with `bits`)."""
        return self._bits is not None

    def _word(self, word) -> int:
        """A word as its `bits`-bit two's-complement pattern."""
        return int(word) & ((1 << self._bits) - 1)

    def _start(self, tick: int, values: np.ndarray) -> None:
        """The header and, at `tick`, the `$dumpvars` of `values` (pyvcd writes both when time first
        moves on or at close)."""
        self._vcd = VCDWriter(self._stream, timescale="1 ns", date="", version="vampc",
                              comment="vampc tick engine: every VAMP's Result; 1 tick = 1 ns",
                              init_timestamp=tick)
        self._last = np.array(values)          # (of the samples' type: words or their values)
        if self._bits:          # (no sample: every bit unknown)
            def init(v, c):
                return "x" if np.isnan(values[v, c]) else self._word(values[v, c])
            self._vars = [[self._vcd.register_var(("network", scope), axis, "wire", size=self._bits,
                                                  init=init(v, c))
                           for c, axis in enumerate("xyz")]
                          for v, scope in enumerate(self._scopes)]
            return
        self._vars = [[self._vcd.register_var(("network", scope), axis, "real",
                                              init=_Exact(values[v, c]))
                       for c, axis in enumerate("xyz")]
                      for v, scope in enumerate(self._scopes)]

    def close(self) -> None:
        """Finish the VCD (up to the last sampled tick) and flush the stream; the stream stays open. A
        run with no sample gets every signal NaN at time 0."""
        if self._vcd is None:
            self._start(0, self._last)
        self._vcd.close(self._tick)


def vamp_names(ld) -> list[str]:
    """One name per VAMP of a loaded program: its burned-in number and its first slot's graph node
    (section, group, name), as `vampc emulate --vcd` names the scopes."""
    nodes = ld.graph.nodes
    return [f"vamp{ld.numbers[v.index]}_{nodes[v.node].section}{nodes[v.node].group}_"
            f"{nodes[v.node].name}" for v in ld.net.vamps]
