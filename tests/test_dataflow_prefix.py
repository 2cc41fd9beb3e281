"""Prefix-network shapes (vampc.dataflow.prefix): validity, depth, size and fan-out against the textbook
figures, and evaluation with non-commutative associative operators against the serial prefixes.

The checks here replay the tiers themselves rather than calling prefix.verify, so a bug in the module's own
checker cannot hide a bad network. Expected depths and sizes are the known closed forms (Sklansky 1960,
Kogge–Stone 1973, Brent–Kung 1982, Ladner–Fischer 1980 as drawn in Harris's 2003 taxonomy).
"""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vampc.dataflow import prefix
from vampc.errors import VampcError, VampcInternalError

SHAPES = ("sklansky", "brent-kung", "kogge-stone", "ladner-fischer", "serial")
SIZES = range(1, 131)
POWERS = [2 ** L for L in range(1, 8)]


def clog2(m: int) -> int:
    return math.ceil(math.log2(m)) if m > 1 else 0


def replay(tiers, m: int) -> set[tuple[int, int]]:
    """Every range built (leaves included); asserts operands exist before the tier and nothing repeats."""
    have = {(i, i) for i in range(m)}
    for tier in tiers:
        made = [(a, b) for a, _, b in tier]
        for a, k, b in tier:
            assert 0 <= a <= k < b < m
            assert (a, k) in have and (k + 1, b) in have, (a, k, b)
        assert len(set(made)) == len(made) and not have & set(made)
        have |= set(made)
    return have


def count(tiers) -> int:
    return sum(len(t) for t in tiers)


def evaluate(tiers, leaves, op):
    """Value of every built range under `op`, combining left then right as the triple says."""
    val = {(i, i): x for i, x in enumerate(leaves)}
    for tier in tiers:
        for a, k, b in tier:
            val[a, b] = op(val[a, k], val[k + 1, b])
    return val


# --- validity ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", SHAPES)
def test_every_prefix_is_built_from_earlier_ranges(shape):
    for m in SIZES:
        have = replay(prefix.prefix_tiers(shape, m), m)
        assert {(0, i) for i in range(m)} <= have, m


@pytest.mark.parametrize("shape", SHAPES)
def test_mirrored_network_builds_every_suffix(shape):
    for m in SIZES:
        have = replay(prefix.suffix_tiers(shape, m), m)
        assert {(i, m - 1) for i in range(m)} <= have, m


@pytest.mark.parametrize("shape", SHAPES)
def test_tiers_are_asap_levels(shape):
    # A triple sits one tier after its later operand: no tier could be started earlier.
    for m in SIZES:
        level = {(i, i): 0 for i in range(m)}
        for t, tier in enumerate(prefix.prefix_tiers(shape, m), 1):
            assert tier, (m, t)
            for a, k, b in tier:
                assert 1 + max(level[a, k], level[k + 1, b]) == t
                level[a, b] = t


def test_public_generators_are_the_shapes():
    assert prefix.SHAPES["sklansky"] is prefix.sklansky
    assert prefix.sklansky(7) == prefix.prefix_tiers("sklansky", 7)
    assert prefix.serial(4) == (((0, 0, 1),), ((0, 1, 2),), ((0, 2, 3),))


def test_figure_iv2_n7():
    # Figure IV.2, n = 7 (leaves 0..7): X01 X23 X45 X67, then X02 X03 X46 X47, then X04..X07.
    tiers = prefix.sklansky(8)
    assert [[(a, b) for a, _, b in t] for t in tiers] == [
        [(0, 1), (2, 3), (4, 5), (6, 7)], [(0, 2), (0, 3), (4, 6), (4, 7)],
        [(0, 4), (0, 5), (0, 6), (0, 7)]]


# --- depth, size, fan-out ---------------------------------------------------------------------------------

@pytest.mark.parametrize("m", SIZES)
def test_serial_depth_and_size(m):
    tiers = prefix.serial(m)
    assert (len(tiers), count(tiers), prefix.fan_out(tiers)) == (m - 1, m - 1, 1 if m > 1 else 0)


@pytest.mark.parametrize("m", SIZES)
def test_sklansky_depth_and_size(m):
    tiers = prefix.sklansky(m)
    assert len(tiers) == clog2(m)
    # position i is combined once for every level d whose bit i has set (upper half of its block)
    assert count(tiers) == sum(bin(i).count("1") for i in range(m))


@pytest.mark.parametrize("m", SIZES)
def test_kogge_stone_depth_and_size(m):
    tiers, L = prefix.kogge_stone(m), clog2(m)
    assert (len(tiers), count(tiers)) == (L, m * L - 2 ** L + 1)


@pytest.mark.parametrize("m", SIZES)
def test_brent_kung_size_and_depth_bound(m):
    tiers, L = prefix.brent_kung(m), clog2(m)
    # up-sweep: m - popcount(m) blocks; down-sweep: every prefix i whose i + 1 is not a power of 2
    assert count(tiers) == 2 * m - bin(m).count("1") - (m.bit_length() - 1) - 1
    assert L <= len(tiers) <= max(2 * L - 2, L)


@pytest.mark.parametrize("m", SIZES)
def test_ladner_fischer_size_and_depth_bound(m):
    tiers, L = prefix.ladner_fischer(m), clog2(m)
    assert count(tiers) == m - 1 + count(prefix.sklansky(m // 2))
    assert L <= len(tiers) <= L + 1


@pytest.mark.parametrize("m", POWERS)
def test_power_of_two_figures(m):
    L = clog2(m)
    sk, bk, ks, lf = (prefix.prefix_tiers(s, m) for s in SHAPES[:4])
    assert (len(sk), count(sk), prefix.fan_out(sk)) == (L, m // 2 * L, m // 2)
    assert (len(ks), count(ks), prefix.fan_out(ks)) == (L, m * L - m + 1, L)
    # Brent–Kung: 2L - 1 level-synchronous tiers; ASAP levels overlap the first down-sweep level.
    assert (len(bk), count(bk), prefix.fan_out(bk)) == (max(2 * L - 2, 1), 2 * m - 2 - L, L)
    if m >= 8:
        assert (len(lf), count(lf), prefix.fan_out(lf)) == (L + 1, m - 1 + m // 4 * (L - 1), m // 4 + 1)


def test_kogge_stone_reads_each_range_at_most_twice_per_tier():
    most = []
    for tier in prefix.kogge_stone(64):
        reads = [r for a, k, b in tier for r in ((a, k), (k + 1, b))]
        most.append(max(reads.count(r) for r in set(reads)))
    assert most == [2, 2, 2, 2, 2, 1]   # the last tier only reads finished prefixes on the left


def test_fan_out_counts_readers():
    assert prefix.fan_out(()) == 0
    assert prefix.fan_out((((0, 0, 1), (0, 0, 2)),)) == 2


# --- evaluation with associative, non-commutative operators -----------------------------------------------

def matmul2(x, y):
    """Exact 2x2 integer matrix product (associative, not commutative)."""
    (a, b), (c, d) = x
    (e, f), (g, h) = y
    return ((a * e + b * g, a * f + b * h), (c * e + d * g, c * f + d * h))


matrices = st.tuples(st.tuples(st.integers(-3, 3), st.integers(-3, 3)),
                     st.tuples(st.integers(-3, 3), st.integers(-3, 3)))


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(SHAPES), st.lists(matrices, min_size=1, max_size=70))
def test_matrix_products_equal_the_serial_prefixes(shape, leaves):
    m = len(leaves)
    val = evaluate(prefix.prefix_tiers(shape, m), leaves, matmul2)
    serial = [leaves[0]]
    for x in leaves[1:]:
        serial.append(matmul2(serial[-1], x))
    assert [val[0, i] for i in range(m)] == serial
    suffix = evaluate(prefix.suffix_tiers(shape, m), leaves, matmul2)
    for i in range(m):
        want = leaves[i]
        for x in leaves[i + 1:]:
            want = matmul2(want, x)
        assert suffix[i, m - 1] == want


@pytest.mark.parametrize("shape", SHAPES)
def test_every_range_concatenates_its_leaves(shape):
    # Strings name their leaves, so any range built from the wrong pieces or in the wrong order shows.
    for m in (1, 2, 3, 7, 8, 9, 31, 64, 100):
        leaves = [f"<{i}>" for i in range(m)]
        for tiers in (prefix.prefix_tiers(shape, m), prefix.suffix_tiers(shape, m)):
            for (a, b), s in evaluate(tiers, leaves, str.__add__).items():
                assert s == "".join(leaves[a:b + 1])


def test_mirror_is_an_involution():
    for shape in SHAPES:
        tiers = prefix.prefix_tiers(shape, 13)
        assert prefix.mirror(prefix.mirror(tiers, 13), 13) == tiers


# --- errors -----------------------------------------------------------------------------------------------

def test_unknown_shape_is_a_user_error():
    with pytest.raises(VampcError, match=r"^unknown prefix shape 'hans-carlson' \(choose from sklansky, "):
        prefix.prefix_tiers("hans-carlson", 4)


def test_verify_rejects_broken_networks():
    with pytest.raises(VampcInternalError, match="reads a later range"):
        prefix.verify((((0, 1, 2),), ((0, 0, 1),)), 3)
    with pytest.raises(VampcInternalError, match="built twice"):
        prefix.verify((((0, 0, 1), (0, 0, 1)),), 2)
    with pytest.raises(VampcInternalError, match="misses"):
        prefix.verify((((0, 0, 1),),), 3)
