"""The linear Newton-Euler graph (vampc.dataflow.linear) against the paper and the reference RNEA.

Expected op counts come from the paper's "Requirements Per Node" tables (section VI); expected torques
from vampc.dynamics.reference.rnea, the serial Newton-Euler of Table I.1.
"""
from __future__ import annotations

import re
from collections import Counter

import numpy as np
import pytest
from conftest import EXAMPLES, EXPECTED_EXAMPLES, example_paths
from hypothesis import given, settings
from hypothesis import strategies as st

from vampc.dataflow.evaluate import evaluate
from vampc.dataflow.graph import Graph
from vampc.dataflow.linear import build_linear
from vampc.dynamics.reference import rnea
from vampc.errors import VampcInternalError
from vampc.machine.ops import OPERAND_SHAPES, Op
from vampc.robot.chain import JointType
from vampc.robot.random import random_chain, random_state

# "Requirements Per Node" (section VI), linear case, per revolute joint. The paper writes MV for
# both A_i x and A_iᵀ x; vampc spells the transposed product MTV, so both count as MV here.
PAPER_PER_NODE = {
    "bwd": {"MV": 3, "VA": 5, "VC": 4},            # propagated ω, ω̇, p̈: 12
    "npv": {"MV": 2, "VA": 3, "VC": 4, "SV": 1},   # non-propagated r̈, F, N: 10
    "fwd": {"MV": 2, "VA": 4, "VC": 2},            # f, n: 8
}


def paper_op_counts(graph: Graph, section: str, group: int) -> dict[str, int]:
    """Ops of one recursion node, in the paper's naming (MTV counted as MV)."""
    ops = Counter("MV" if nd.op is Op.MTV else nd.op.value
                  for nd in graph.compute_nodes() if (nd.section, nd.group) == (section, group))
    return dict(ops)


def relative_error(got: np.ndarray, want: np.ndarray) -> float:
    """max |got - want| over the largest reference torque (the torques' own scale)."""
    scale = max(float(np.max(np.abs(want))), 1e-300)
    return float(np.max(np.abs(got - want))) / scale


@pytest.mark.parametrize("n", [1, 2, 6, 13])
def test_per_node_inventory_matches_paper_for_revolute_joints(n):
    graph = build_linear(random_chain(n, n, prismatic_fraction=0.0))
    for i in range(1, n + 1):
        for section, want in PAPER_PER_NODE.items():
            assert paper_op_counts(graph, section, i) == want, (section, i)


def test_general_rotary_arm_totals_match_paper_n6():
    # Section VI, VAMPs - Totals, n = 6: linear backward 132 (72 + 60), forward 48.
    graph = build_linear(random_chain(6, 0, prismatic_fraction=0.0))
    sections = Counter(nd.section for nd in graph.compute_nodes())
    assert sections == {"bwd": 72, "npv": 60, "fwd": 48}


def test_prismatic_joint_adds_the_sigma_bar_terms():
    # Table I.1, σ̄ case: ω and ω̇ lose the z q̇ / z q̈ terms (T2, T4, T5, T6 gone: -3 VA, -1 VC) and
    # p̈ gains A_iᵀ z q̈ + 2 ω × A_iᵀ z q̇ summed into T8 (linear.py docstring): 2 MTV, 1 VC, 1 SV and
    # 2 VA. Net against the revolute node: +2 MV, -1 VA, 0 VC, +1 SV.
    chain = random_chain(3, 5, prismatic_fraction=1.0)
    assert all(j.type is JointType.PRISMATIC for j in chain.joints)
    graph = build_linear(chain)
    assert paper_op_counts(graph, "bwd", 2) == {"MV": 5, "VA": 4, "VC": 4, "SV": 1}
    assert paper_op_counts(graph, "npv", 2) == PAPER_PER_NODE["npv"]
    assert paper_op_counts(graph, "fwd", 2) == PAPER_PER_NODE["fwd"]


def test_prismatic_torque_reads_the_force():
    chain = random_chain(4, 2, prismatic_fraction=0.5)
    graph = build_linear(chain)
    for out in graph.outputs:
        node = graph.nodes[out.node]
        want = "f" if chain.joints[out.joint - 1].type is JointType.PRISMATIC else "n"
        assert (node.name, node.section, node.group, out.component) == (want, "fwd", out.joint, 2)


@pytest.mark.parametrize("n", [1, 5])
def test_graph_verifies_and_is_topological(n):
    graph = build_linear(random_chain(n, 1))
    graph.verify()
    assert [nd.id for nd in graph.nodes] == list(range(len(graph.nodes)))
    assert all(a < nd.id for nd in graph.nodes for a in nd.args)
    assert sorted(o.joint for o in graph.outputs) == list(range(1, n + 1))


def test_verify_rejects_a_node_reading_a_later_node():
    graph = build_linear(random_chain(2, 1))
    nodes = list(graph.nodes)
    first = next(nd for nd in nodes if nd.op.is_compute)
    nodes[first.id] = type(first)(first.id, first.op, (first.args[0], len(nodes) - 1), first.name,
                                  first.section, first.group)
    broken = Graph(tuple(nodes), graph.outputs, graph.n)
    with pytest.raises(VampcInternalError, match=rf"^node bwd1\.{first.name}: operand \d+ not before it$"):
        broken.verify()


@pytest.mark.parametrize("source", ["compute", "input", "const"])
def test_verify_rejects_an_operand_of_the_wrong_shape(source):
    """An operand wired to an earlier node whose result has the other shape (a matrix for a vector,
    or a vector for a matrix), whatever made it: a compute op, a host input or a constant."""
    graph = build_linear(random_chain(2, 1))
    nodes = list(graph.nodes)
    for nd in nodes:
        if not nd.op.is_compute:
            continue
        want = OPERAND_SHAPES[nd.op][0]
        wrong = [m for m in nodes[:nd.id] if m.shape != want
                 and (m.op.is_compute if source == "compute" else m.op.value == source.upper())]
        if wrong:
            break
    else:
        pytest.fail(f"no node with an earlier {source} node of the other shape")
    nodes[nd.id] = type(nd)(nd.id, nd.op, (wrong[-1].id, nd.args[1]), nd.name, nd.section,
                            nd.group)
    broken = Graph(tuple(nodes), graph.outputs, graph.n)
    with pytest.raises(VampcInternalError,
                       match=rf"^node {re.escape(nd.label)}: operand {re.escape(wrong[-1].label)} "
                             rf"is not '{want}'$"):
        broken.verify()


def test_verify_says_the_first_operand_s_shape_before_looking_at_the_second():
    """A node whose operand A has the wrong shape and whose operand B is not a node at all: the
    check names operand A, as it checks A before B (a review found the in-line check of a
    compute node raising a TypeError on B first)."""
    from vampc.dataflow.graph import InputKey, Node, Output
    from vampc.kinds import Section
    a = Node(0, Op.INPUT, (), "A1", Section.IO, 1, key=InputKey("A", 1))          # a matrix
    z = Node(1, Op.INPUT, (), "zqd1", Section.IO, 1, key=InputKey("zqd", 1))
    bad = Node(2, Op.VA, (0, None), "T", Section("bwd"), 1)
    with pytest.raises(VampcInternalError, match=r"^node bwd1\.T: operand io1\.A1 is not 'v'$"):
        Graph((a, z, bad), (Output(1, 2),), 1).verify()


def test_verify_rejects_a_missing_output():
    graph = build_linear(random_chain(3, 1))
    broken = Graph(graph.nodes, graph.outputs[1:], graph.n)
    with pytest.raises(VampcInternalError, match=r"^outputs cover joints \[2, 3\], expected 1\.\.3$"):
        broken.verify()


def test_the_expected_examples_exist():
    present = {p.name for p in EXAMPLES.glob("*")}
    assert set(EXPECTED_EXAMPLES) <= present


@pytest.mark.parametrize("path", example_paths(), ids=lambda p: p.name)
def test_graph_equals_reference_on_every_example(path):
    from vampc.robot import load_robot
    chain = load_robot(path)
    q, qd, qdd = random_state(chain, 20, 7)
    got = evaluate(build_linear(chain), chain, q, qd, qdd)
    assert relative_error(got, rnea(chain, q, qd, qdd)) < 1e-9


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 40), seed=st.integers(0, 2**32 - 1),
       prismatic=st.sampled_from([0.0, 0.3, 0.7, 1.0]), general=st.booleans())
def test_graph_equals_reference_on_random_chains(n, seed, prismatic, general):
    chain = random_chain(n, seed, prismatic_fraction=prismatic, general=general, endpoints=True)
    q, qd, qdd = random_state(chain, 8, seed + 1)
    got = evaluate(build_linear(chain), chain, q, qd, qdd)
    assert relative_error(got, rnea(chain, q, qd, qdd)) < 1e-9


def test_single_state_gives_one_torque_vector():
    chain = random_chain(3, 4, endpoints=True)
    q, qd, qdd = (x[0] for x in random_state(chain, 1, 4))
    got = evaluate(build_linear(chain), chain, q, qd, qdd)
    assert got.shape == (3,)
    assert relative_error(got, rnea(chain, q, qd, qdd)) < 1e-9


def test_paper_output_convention_would_be_wrong_for_general_frames():
    # DESIGN §5: the third coordinate of n_i (referred to O_i) is not τ_i when Φ_i ≠ I. The graph
    # must not read it; this guards the test above against a reference that shares the mistake.
    chain = random_chain(3, 9, prismatic_fraction=0.0, general=True)
    q, qd, qdd = random_state(chain, 4, 9)
    graph = build_linear(chain)
    tau = rnea(chain, q, qd, qdd)
    A1 = chain.joints[0].A(q[:, 0])
    n1_in_o1 = np.einsum("nji,nj->ni", A1, _node_values(graph, chain, q, qd, qdd, "n", 1))
    assert relative_error(n1_in_o1[:, 2], tau[:, 0]) > 1e-3


def _node_values(graph, chain, q, qd, qdd, name, group):
    from vampc.dataflow.evaluate import evaluate_nodes
    vals = evaluate_nodes(graph, chain, q, qd, qdd)
    node = next(nd for nd in graph.nodes if (nd.name, nd.section, nd.group) == (name, "fwd", group))
    return vals[node.id]
