"""vampc.memo.keep_last: answers kept by the identity of IR objects and the value of plain ones;
vampc.memo.counting: one int object per value for the IRs of a big network."""
from __future__ import annotations

import numpy as np

from vampc.memo import counting, keep_last
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


def test_counting_grows_and_keeps_the_ints_it_gave():
    small = counting(300)
    assert small[:300] == tuple(range(300))
    big = counting(len(small) + 5000)
    assert big[:len(small) + 5000] == tuple(range(len(small) + 5000))
    assert all(big[k] is small[k] for k in (257, 299, len(small) - 1))   # the same objects


def test_a_compiled_networks_indices_are_one_int_object_per_value():
    """A VAMP's index is the same int object in the layout's placement, the VAMP, the program
    stream's targets and (as the next VAMP's number) the numbering: past 256, Python makes an
    int object per value computed, and a 4096-joint log compile held five copies of a million."""
    from vampc.compiler import CompileOptions, compile_chain
    from vampc.robot.random import random_chain
    c = compile_chain(random_chain(12, 3), CompileOptions(recursion="log"))
    net, placement = c.network, c.layout.vamps_of()
    target = {v: v for e in c.stream for v in e.targets}     # each key's last object
    checked = 0
    for vamp in net.vamps[300:900:37]:
        v = vamp.index
        node = vamp.slots[0].node
        assert v > 256 and v in placement[node]
        assert placement[node][placement[node].index(v)] is v
        assert target[v] is v and c.numbering[v - 1] is v
        assert c.graph.nodes[node].id is counting(node + 1)[node]
        checked += 1
    assert checked > 10
