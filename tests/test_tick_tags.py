"""The tick engine's set tags (vampc.emulator.tick): the tag of a value computed from two operands,
worked out without stacking them (_combine2), against the rule written out case by case and against
the general _combine it stands in for."""
from __future__ import annotations

import itertools

import numpy as np

from vampc.emulator.tick import CONST, UNKNOWN, _combine, _combine2

TAGS = [UNKNOWN, CONST, 0, 1, 7]


def _rule(a: int, b: int) -> int:
    """A value's set: unknown if an operand's is; a constant takes the other's; else the common set."""
    if UNKNOWN in (a, b):
        return UNKNOWN
    if a == CONST:
        return b
    if b == CONST:
        return a
    return a if a == b else UNKNOWN


def test_every_pair_of_tags_combines_by_the_rule():
    pairs = list(itertools.product(TAGS, TAGS))
    a = np.array([p[0] for p in pairs], dtype=np.int64)
    b = np.array([p[1] for p in pairs], dtype=np.int64)
    got = _combine2(a, b)
    assert got.tolist() == [_rule(x, y) for x, y in pairs]
    assert np.array_equal(got, _combine(np.stack([a, b], axis=1)))
