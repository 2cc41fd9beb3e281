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
    parents = tree_parents(n, shape, n)
    for ground in (True, False):
        tiers, keys = tp.path_prefix_plan(parents, prefix, ground)
        tp.verify_plan(parents, tiers, keys, ground)
        assert len(keys) == n


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
