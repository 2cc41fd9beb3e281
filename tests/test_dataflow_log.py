"""The logarithmic graph (vampc.dataflow.logarithmic) against the serial RNEA and the paper's figures.

Torques and intermediate values come from vampc.dynamics.reference (the serial Newton-Euler of Table I.1)
and from the linear graph; latencies from the ASAP schedule against the paper's formula (section V,
Appendix C); VAMP counts against section VI's tables for n = 6. Where the graph differs from the paper
the expected value here says why (the module docstring has the derivations).
"""
from __future__ import annotations

import json
import math
from collections import Counter

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vampc.dataflow.evaluate import evaluate, evaluate_nodes
from vampc.dataflow.linear import build_linear
from vampc.dataflow.logarithmic import build_log, relational_nodes
from vampc.dataflow.prefix import prefix_tiers, size
from vampc.dynamics.reference import rnea, rnea_variables
from vampc.errors import VampcError
from vampc.machine.ops import VAMPS_PER_OP, Op
from vampc.robot.chain import JointType
from vampc.robot.random import random_chain, random_state
from vampc.schedule.asap import schedule_asap

SHAPES = ("sklansky", "brent-kung", "kogge-stone", "ladner-fischer", "serial")
HOST_INPUTS = {"A", "zqd", "zqdd", "p_star", "s_star"}
OUTPUT_CORRECTION = 3      # one MV (A_i in the forward leaf): 1 Mult + 2 Addns
TABLE_V1_BACKWARD = {"W", "T1", "omega", "T2", "T3", "T4", "omega_dot", "T5", "R", "T6", "T7", "T8",
                     "S", "T9", "Q", "T10", "T11", "T12", "T13", "T14", "T15", "T16", "T17", "pdd"}
TABLE_V1_FORWARD = {"W", "T5", "R", "T19", "f", "T21", "T22", "T23", "T24", "n"}   # T20 not needed


def clog2(m: int) -> int:
    return math.ceil(math.log2(m)) if m > 1 else 0


def relative_error(got: np.ndarray, want: np.ndarray) -> float:
    """max |got - want| over the largest reference value."""
    return float(np.max(np.abs(got - want))) / max(float(np.max(np.abs(want))), 1e-300)


def vamps(graph, section: str | None = None) -> int:
    return sum(VAMPS_PER_OP[nd.op] for nd in graph.compute_nodes() if section in (None, nd.section))


def per_group(graph, section: str) -> dict[int, Counter]:
    """Ops of every recursion node of a section, in the paper's naming (MTV counted as MV)."""
    out: dict[int, Counter] = {}
    for nd in graph.compute_nodes():
        if nd.section == section:
            out.setdefault(nd.group, Counter())["MV" if nd.op is Op.MTV else nd.op.value] += 1
    return out


def group_vamps(ops: Counter) -> int:
    return sum(k * (3 if op == "MM" else 1) for op, k in ops.items())


def latency(chain, **kwargs):
    s = schedule_asap(build_log(chain, **kwargs))
    return s.latency, s.mults, s.adds


# --- torques ----------------------------------------------------------------------------------------------

@settings(max_examples=6, deadline=None)      # (new draws every run; 10 took 7.6 s of the suite)
@given(st.integers(1, 40), st.integers(0, 10_000), st.sampled_from([0.0, 0.3, 1.0]), st.booleans())
def test_torques_equal_rnea_for_every_shape_and_leaf_style(n, seed, prismatic, endpoints):
    chain = random_chain(n, seed, prismatic_fraction=prismatic, endpoints=endpoints)
    q, qd, qdd = random_state(chain, 3, seed + 1)
    want = rnea(chain, q, qd, qdd)
    for shape in SHAPES:
        for uniform in (False, True):
            got = evaluate(build_log(chain, shape, uniform), chain, q, qd, qdd)
            assert relative_error(got, want) < 1e-9, (shape, uniform)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("options", [dict(ground_o0=False), dict(prune=True),
                                     dict(uniform_leaves=True, ground_o0=False, prune=True)])
def test_grounding_and_pruning_keep_the_torques(n, options):
    for endpoints in (False, True):
        chain = random_chain(n, 10 + n, prismatic_fraction=0.5, endpoints=endpoints)
        q, qd, qdd = random_state(chain, 4, n)
        for shape in SHAPES:
            got = evaluate(build_log(chain, shape, **options), chain, q, qd, qdd)
            assert relative_error(got, rnea(chain, q, qd, qdd)) < 1e-9, shape


def test_single_state_gives_a_vector():
    chain = random_chain(5, 2, endpoints=True)
    q, qd, qdd = (x[0] for x in random_state(chain, 1, 3))
    np.testing.assert_allclose(evaluate(build_log(chain), chain, q, qd, qdd), rnea(chain, q, qd, qdd),
                               rtol=0, atol=1e-9 * np.max(np.abs(rnea(chain, q, qd, qdd))))


# --- intermediate values ----------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("uniform", [False, True])
def test_prefixes_and_suffixes_are_the_linear_variables(shape, uniform):
    chain = random_chain(13, 3, prismatic_fraction=0.4, endpoints=True)
    q, qd, qdd = random_state(chain, 3, 4)
    graph = build_log(chain, shape, uniform)
    vals, lin = evaluate_nodes(graph, chain, q, qd, qdd), rnea_variables(chain, q, qd, qdd)
    ids = relational_nodes(graph)
    for i in range(chain.n):
        for node, key in zip(ids["prefixes"][i], ("omega", "omega_dot", "pdd")):
            assert relative_error(vals[node], lin[key][:, i]) < 1e-12, (i, key)
        A = chain.joints[i].A(q[:, i])     # f', n' are referred to O_{i-1}: A_i f_i, A_i n_i
        for node, key in zip(ids["suffixes"][i], ("f", "n")):
            want = np.einsum("kij,kj->ki", A, lin[key][:, i])
            assert relative_error(vals[node], want) < 1e-12, (i, key)


def test_suffixes_equal_the_linear_graphs_forward_nodes():
    chain = random_chain(9, 8, prismatic_fraction=0.3, endpoints=True)
    q, qd, qdd = random_state(chain, 2, 9)
    lin_graph, log_graph = build_linear(chain), build_log(chain)
    lin, log = (evaluate_nodes(g, chain, q, qd, qdd) for g in (lin_graph, log_graph))
    by_name = {(nd.section, nd.group, nd.name): nd.id for nd in lin_graph.nodes}
    for i, (f, n) in enumerate(relational_nodes(log_graph)["suffixes"], 1):
        assert relative_error(log[f], lin[by_name["fwd", i, "f"]]) < 1e-12
        assert relative_error(log[n], lin[by_name["fwd", i, "n"]]) < 1e-12


def test_non_propagated_nodes_read_the_prefixes():
    chain = random_chain(7, 1, prismatic_fraction=0.3)
    graph = build_log(chain)
    npv = {(nd.group, nd.name): nd for nd in graph.nodes if nd.section == "npv"}
    for i, (w, wd, pdd) in enumerate(relational_nodes(graph)["prefixes"], 1):
        assert (npv[i, "T12"].args[0], npv[i, "T14"].args[0], npv[i, "rdd"].args[1]) == (w, wd, pdd)


# --- structure --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", SHAPES)
def test_graph_hygiene(shape):
    chain = random_chain(11, 5, prismatic_fraction=0.4, endpoints=True)
    graph = build_log(chain, shape)
    graph.verify()
    assert {nd.key.quantity for nd in graph.nodes if nd.op is Op.INPUT} <= HOST_INPUTS
    assert {nd.section for nd in graph.compute_nodes()} == {"bwd", "npv", "fwd"}
    assert all(nd.group >= 1 for nd in graph.compute_nodes())
    for out in graph.outputs:
        prismatic = chain.joints[out.joint - 1].type is JointType.PRISMATIC
        assert (graph.nodes[out.node].name, out.component) == ("f" if prismatic else "n", 2)


@pytest.mark.parametrize("shape", SHAPES)
def test_recursion_nodes_follow_the_prefix_shape(shape):
    chain = random_chain(12, 6, prismatic_fraction=0.0)     # still base: grounded in O_0, 12 leaves
    graph = build_log(chain, shape, uniform_leaves=True)
    meta = dict(graph.meta)
    assert (meta["ground"], meta["prefix"]) == ("O_0", shape)
    for section in ("bwd", "fwd"):
        rows = json.loads(meta[f"{section}_nodes"])
        combining = [r for r in rows if r[1] != r[3]]
        assert [r[0] for r in rows] == list(range(1, len(rows) + 1))
        assert len(rows) - len(combining) == 12 and len(combining) == size(prefix_tiers(shape, 12))
        assert set(per_group(graph, section)) == {r[0] for r in rows}
        assert max(r[4] for r in rows) == len(prefix_tiers(shape, 12))


def test_grounding_in_o_minus_1_adds_a_constant_leaf():
    chain = random_chain(6, 0, prismatic_fraction=0.0, endpoints=True)   # rotating base
    graph = build_log(chain, uniform_leaves=True)
    rows = json.loads(dict(graph.meta)["bwd_nodes"])
    assert dict(graph.meta)["ground"] == "O_-1"
    assert [r[1] for r in rows if r[1] == r[3]] == [1, 2, 3, 4, 5, 6]   # leaf 0 is constants only
    assert len(rows) - 6 == size(prefix_tiers("sklansky", 7))


def test_cannot_ground_in_o0_when_the_base_rotates():
    chain = random_chain(3, 0, endpoints=True)
    with pytest.raises(VampcError, match=r"^random3: cannot ground the log recursion in O_0: the base "
                                         r"rotates \(ω0 or ω̇0 nonzero\)$"):
        build_log(chain, ground_o0=True)


def test_unknown_prefix_shape_is_a_user_error():
    with pytest.raises(VampcError, match=r"^unknown prefix shape 'ripple'"):
        build_log(random_chain(3, 0), "ripple")


def test_tip_load_costs_two_additions_in_leaf_n():
    free, loaded = random_chain(5, 3), random_chain(5, 3, endpoints=True)
    names = [{(nd.section, nd.name) for nd in build_log(c).nodes} for c in (free, loaded)]
    assert ("fwd", "Ftip") not in names[0] and ("fwd", "Ntip") not in names[0]
    assert {("fwd", "Ftip"), ("fwd", "Ntip")} <= names[1]


def test_pruning_leaves_only_what_the_torques_read():
    chain = random_chain(10, 2, prismatic_fraction=0.2)
    full, pruned = build_log(chain, uniform_leaves=True), build_log(chain, uniform_leaves=True, prune=True)
    g = pruned.to_networkx()
    needed = set().union(*(nx.ancestors(g, o.node) | {o.node} for o in pruned.outputs))
    assert needed == {nd.id for nd in pruned.nodes}
    assert vamps(pruned) < vamps(full)


# --- counts against section VI ----------------------------------------------------------------------------

def test_n6_uniform_nodes_against_section_vi():
    # Section VI, n = 6, Appendix D leaves, grounded in O_0: 7 combining + 6 leaf nodes each way.
    graph = build_log(random_chain(6, 0, prismatic_fraction=0.0), uniform_leaves=True)
    bwd, npv, fwd = (per_group(graph, s) for s in ("bwd", "npv", "fwd"))
    assert (len(bwd), len(npv), len(fwd)) == (13, 6, 13)
    assert all(ops == {"MV": 6, "VA": 12, "VC": 4, "SV": 1, "MM": 1} for ops in bwd.values())  # 26
    assert all(ops == {"MV": 2, "VA": 3, "VC": 4, "SV": 1} for ops in npv.values())            # 10
    # Paper 5 MV: its T20 = A_{k+1}ᵀ R_{a,k} moves R into f's frame O_{k+1}; with f', n' referred to
    # O_{a-1}, R_{a,k} and f'_{k+1,b} are both in O_k already. 12 VAMPs per node, not 13.
    assert all(ops == {"MV": 4, "VA": 4, "VC": 1, "MM": 1} for ops in fwd.values())
    assert (vamps(graph, "bwd") + vamps(graph, "npv"), vamps(graph, "fwd")) == (398, 169 - 13)
    names = {s: {nd.name for nd in graph.compute_nodes() if nd.section == s} for s in ("bwd", "fwd")}
    assert names == {"bwd": TABLE_V1_BACKWARD, "fwd": TABLE_V1_FORWARD}


def test_n6_table_iv1_leaves():
    graph = build_log(random_chain(6, 0, prismatic_fraction=0.0))
    bwd, fwd = per_group(graph, "bwd"), per_group(graph, "fwd")
    assert bwd[1] == {"MV": 3, "VC": 3, "VA": 2}                  # leaf 1 also rotates gravity in
    assert all(bwd[a] == {"MV": 2, "VC": 3, "VA": 1} for a in range(2, 7))
    assert all(fwd[a] == {"MV": 2, "VC": 1, "VA": 1} for a in range(1, 7))   # 2 MV: output correction
    assert (vamps(graph, "bwd"), vamps(graph, "npv"), vamps(graph, "fwd")) == (7 * 26 + 38, 60, 7 * 12 + 24)


def test_n6_pruned_uniform_nodes():
    graph = build_log(random_chain(6, 0, prismatic_fraction=0.0), uniform_leaves=True, prune=True)
    assert (vamps(graph, "bwd"), vamps(graph, "npv"), vamps(graph, "fwd")) == (278, 60, 116)


def test_brent_kung_needs_clearly_fewer_vamps_than_sklansky_n64():
    chain = random_chain(64, 0, prismatic_fraction=0.0)
    sk, bk = vamps(build_log(chain, "sklansky")), vamps(build_log(chain, "brent-kung"))
    assert bk < 0.75 * sk


# --- latency ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("n", range(1, 65))
def test_sklansky_latency_against_the_paper(n):
    chain = random_chain(n, n, prismatic_fraction=0.0)
    t, L = clog2(n), clog2(n + 1)
    paper = (2 * L + 5) + (6 * L + 10)
    mults, adds = (6, 10) if n == 1 else (2 * t + 6, 6 * t + 12)
    got = latency(chain)
    assert got == (mults + adds, mults, adds)
    assert got[0] <= paper + OUTPUT_CORRECTION
    if n > 1:   # grounded in O_0 the network spans n leaves, one tier fewer when n is a power of 2
        assert got[0] == (paper + OUTPUT_CORRECTION if t == L else paper - 5)
    uniform = latency(chain, uniform_leaves=True)
    assert uniform == (got[0] + 4, mults, adds + 4) if n == 1 else (got[0] + 2, mults, adds + 2)


@pytest.mark.parametrize("n", range(1, 34))
def test_sklansky_latency_grounded_in_o_minus_1(n):
    chain = random_chain(n, n, prismatic_fraction=0.0)
    L = clog2(n + 1)
    want = {1: 21, 2: 29}.get(n, 8 * L + 14 if n & (n - 1) == 0 else 8 * L + 18)
    assert latency(chain, ground_o0=False)[0] == want


@pytest.mark.parametrize("shape", SHAPES)
def test_each_tier_costs_one_mv_plus_va(shape):
    for n in (1, 2, 3, 4, 5, 7, 8, 9, 12, 16, 17, 23, 31, 33, 40):
        chain = random_chain(n, n, prismatic_fraction=0.0)
        bound = 16 if n == 1 else 8 * len(prefix_tiers(shape, n)) + 18
        got = latency(chain, prefix=shape)[0]
        assert got == bound if shape in ("sklansky", "serial") else got <= bound, n


def test_serial_grows_like_the_linear_recursion():
    chains = [random_chain(n, 1, prismatic_fraction=0.0) for n in range(2, 21)]   # n = 1 has no tier
    serial = [latency(c, prefix="serial")[0] for c in chains]
    linear = [schedule_asap(build_linear(c)).latency for c in chains]
    assert set(np.diff(serial)) == set(np.diff(linear)) == {8}    # one MV + VA per joint each way


# --- size and build time ----------------------------------------------------------------------------------

def test_build_is_n_log_n():
    # Sklansky has (m/2) log2 m combining nodes of 24 + 10 ops: about 20 graph nodes per n log2 n.
    # (its build time, about 2 s at n = 2048, is a benchmark's: benchmarks/compile_time.py)
    for n in (64, 512, 2048):
        graph = build_log(random_chain(n, 0))
        assert len(graph.nodes) < 22 * n * math.log2(n)
