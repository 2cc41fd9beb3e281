"""The tree prefix scheme: plans replay (every full prefix made, operands adjacent), a chain's plan is its
prefix shape, range blocks tile ranges, and depths grow as log n on chains, balanced trees and stars."""
import pytest

from vampc.dataflow import treeprefix as tp
from vampc.dataflow.prefix import prefix_tiers
from vampc.robot.random import TREE_SHAPES, tree_parents


@pytest.mark.parametrize("shape", TREE_SHAPES)
@pytest.mark.parametrize("n", [1, 2, 3, 7, 8, 40, 100])
@pytest.mark.parametrize("prefix", ["sklansky", "brent-kung", "kogge-stone", "ladner-fischer", "serial"])
def test_plans_replay(shape, n, prefix):
    """Each plan replayed here with the joints each piece spans (not tp.verify_plan, which checks
    that keys exist, not what they hold: a plan that never joined a branch to its parent's prefix
    passed, a tests audit's): every triple joins a piece ending at k to the piece below k, and
    every joint's key spans its whole path from the root (the ground with `ground`)."""
    parents = tree_parents(n, shape, n)
    above = {j: parents[j - 1] for j in range(1, n + 1)}

    def path(top: int, j: int) -> frozenset:        # the joints from top down to j, both included
        out = [j]
        while out[-1] != top:
            assert out[-1] != 0, (top, j)
            out.append(above[out[-1]])
        return frozenset(out)
    for ground in (True, False):
        tiers, keys = tp.path_prefix_plan(parents, prefix, ground)
        tp.verify_plan(parents, tiers, keys, ground)
        span = {(j, j): frozenset([j]) for j in range(0 if ground else 1, n + 1)}
        for tier in tiers:
            made = {}
            for a, k, b in tier:
                low = [c for c in span if c[1] == b and above.get(c[0]) == k and c[0] != 0]
                assert (a, k) in span and len(low) == 1 and (a, b) not in span, (a, k, b)
                made[(a, b)] = span[(a, k)] | span[low[0]]
                assert made[(a, b)] == path(a, b), (a, k, b)
            span.update(made)
        assert sorted(k[1] for k in keys) == list(range(1, n + 1))
        for top, j in keys:
            whole = path(0, j) if ground else path(_root(above, j), j)
            assert top == (0 if ground else _root(above, j)) and span[(top, j)] == whole, (top, j)


def _root(above: dict, j: int) -> int:
    """The joint at the top of j's branch (its ancestor whose parent is the base)."""
    while above[j] != 0:
        j = above[j]
    return j


@pytest.mark.parametrize("n", [1, 5, 6, 16, 33])
def test_a_chain_is_its_prefix_shape(n):
    tiers, keys = tp.path_prefix_plan(tuple(range(n)), "sklansky", ground=True)
    assert tiers == prefix_tiers("sklansky", n + 1) and keys == [(0, j) for j in range(1, n + 1)]


def test_light_edges_are_at_most_log2_n():
    for shape in TREE_SHAPES:
        for n in (64, 512):
            d = tp.tree_depths(tree_parents(n, shape, 1), "sklansky", True)
            assert d["light_edges"] <= (n).bit_length() - 1


@pytest.mark.parametrize("lo, hi", [(0, 1), (0, 13), (3, 17), (5, 6), (7, 64), (1, 1000)])
def test_range_blocks_tile_the_range(lo, hi):
    covered = []
    for level, index in tp.range_blocks(lo, hi):
        covered += range(index << level, (index + 1) << level)
    assert covered == list(range(lo, hi))
    assert len(tp.range_blocks(lo, hi)) <= 2 * (hi - lo).bit_length()


@pytest.mark.parametrize("shape", ["chain", "binary", "star"])
def test_depth_grows_as_log_n(shape):
    """Backward tiers ≤ 2⌈log2(n+1)⌉ and forward levels ≤ ⌈log2 n⌉ + 2 at n = 64, 512, 4096 (the
    benchmark benchmarks/tree_depth.py prints the whole table)."""
    for n in (64, 512, 4096):
        d = tp.tree_depths(tree_parents(n, shape, 0), "sklansky", True)
        log = (n).bit_length()
        assert d["backward_tiers"] <= 2 * log and d["forward_levels"] <= log + 2


def test_earliest_sum():
    assert tp.earliest_sum([0, 0, 0, 0]) == 2 and tp.earliest_sum([3, 0, 1]) == 4 and tp.earliest_sum([]) == 0
