"""vampc.memo.keep_last: answers kept by the identity of IR objects and the value of plain ones."""
from __future__ import annotations

import numpy as np

from vampc.memo import keep_last
from vampc.report.wiring import _distinct


def test_kept_by_identity_and_value_and_only_the_last_few():
    calls = []

    @keep_last(2)
    def f(obj, n):
        calls.append((id(obj), n))
        return [len(obj), n]
    a, b, c = tuple([1, 2]), tuple([1, 2]), (3,)     # a == b, but not the same object
    assert f(a, 1) is f(a, 1) and len(calls) == 1
    f(b, 1)                               # equal, not identical: computed again
    f(a, True)                            # True == 1 but not the same kind of value
    assert len(calls) == 3
    f(c, 1)                               # a third key pushes the oldest out
    f(a, 1)
    assert len(calls) == 5
    f.forget()
    f(c, 1)
    assert len(calls) == 6


def test_distinct_rows_match_a_set_also_past_one_int64_key():
    rng = np.random.default_rng(1)
    for high in (5, 1 << 20, 1 << 40):    # 3 columns of 2^40 values: too wide for one key
        cols = [rng.integers(0, high, 500) for _ in range(3)]
        cols = [np.concatenate([c, c[:100]]) for c in cols]      # some rows twice
        got = set(zip(*(c.tolist() for c in _distinct(*cols))))
        assert got == set(zip(*(c.tolist() for c in cols)))
        assert len(got) == len(_distinct(*cols)[0])
    empty = _distinct(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))
    assert all(len(c) == 0 for c in empty)
