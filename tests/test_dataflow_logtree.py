"""Log graphs of trees and floating bases: evaluated torques equal the reference on random trees
(n = 1..40, every shape, both leaf styles, every prefix shape), the systolic and folded layouts compile,
both engines agree bit for bit with each other and the reference, and the metadata keeps its meaning."""
import json
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vampc.compiler import CompileOptions, compile_chain, program_document
from vampc.dataflow.evaluate import evaluate
from vampc.dataflow.linear import build_linear
from vampc.dataflow.logarithmic import build_log
from vampc.dynamics.reference import rnea
from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.host import Trajectory, check_torques, random_trajectory
from vampc.robot.random import TREE_SHAPES, random_base, random_state, random_tree

PREFIXES = ["sklansky", "brent-kung", "kogge-stone", "ladner-fischer", "serial"]


def tree(n, seed, shape, floating=False, endpoints=False):
    chain = random_tree(n, seed, shape, prismatic_fraction=0.4, floating=floating, endpoints=endpoints)
    return replace(chain, base_omega=np.zeros(3), base_omega_dot=np.zeros(3)) if floating else chain


def rel(a, b):
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-12)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 40), st.integers(0, 10_000), st.sampled_from(TREE_SHAPES), st.booleans(),
       st.booleans(), st.sampled_from(PREFIXES), st.booleans())
def test_graphs_equal_the_reference(n, seed, shape, floating, uniform, prefix, endpoints):
    chain = tree(n, seed, shape, floating, endpoints)
    q, qd, qdd = random_state(chain, 3, seed)
    base = random_base(3, seed) if floating else None
    want = rnea(chain, q, qd, qdd, base)
    assert rel(evaluate(build_log(chain, prefix, uniform), chain, q, qd, qdd, base), want) < 1e-12
    assert rel(evaluate(build_linear(chain), chain, q, qd, qdd, base), want) < 1e-12


def _head(traj, k):
    return Trajectory(traj.q[:k], traj.qd[:k], traj.qdd[:k], None, None if traj.base is None else traj.base[:k])


@pytest.mark.parametrize("recursion", ["linear", "log"])
@pytest.mark.parametrize("layout", ["systolic", "folded"])
@pytest.mark.parametrize("floating", [False, True])
def test_both_engines_bit_identical(recursion, layout, floating):
    chain = tree(7, 3, "random", floating)
    ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions(recursion=recursion,
                                                                              layout=layout))))
    traj = random_trajectory(chain, 30, 2)
    stream = emulate(ld, traj, "stream")
    tick = emulate(ld, _head(traj, 4), "tick", seed=2)
    assert np.array_equal(stream.tau[:4], tick.tau)
    assert stream.tau.shape == (30, chain.n_outputs)
    assert check_torques(chain, traj, stream.tau).ok


def test_latency_follows_the_deepest_branch():
    """A star of 6 chains of up to 6 joints: the linear latency is about a 6-joint chain's, not n's."""
    star = replace(random_tree(32, 1, "star"), tip_force=np.zeros(3), tip_torque=np.zeros(3))
    from vampc.robot.random import random_chain
    from vampc.schedule.asap import schedule_asap
    arm = random_chain(star.height, 1)
    star_lat = schedule_asap(build_linear(star)).latency
    assert star_lat < schedule_asap(build_linear(random_chain(32, 1))).latency / 3
    assert star_lat <= schedule_asap(build_linear(arm)).latency + 16


def test_metadata_names_the_recursion_nodes():
    graph = build_log(tree(12, 4, "binary"))
    meta = dict(graph.meta)
    depths = json.loads(meta["tree"])
    assert depths["joints"] == 12 and depths["backward_tiers"] == max(r[4] for r in json.loads(meta["bwd_nodes"]))
    groups = {(nd.section, nd.group) for nd in graph.compute_nodes() if nd.section in ("bwd", "fwd")}
    rows = {(s, r[0]) for s in ("bwd", "fwd") for r in json.loads(meta[f"{s}_nodes"])}
    assert groups <= rows


@pytest.mark.parametrize("n", [1, 2, 5, 11, 23, 40])
@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_random_trees_emulate_exactly(n, recursion):
    """Emulated torques (and a floating base's wrench) of random trees against the reference; the tick
    engine bit for bit on the smaller ones."""
    for floating, shape in ((False, "random"), (True, "binary")):
        chain = tree(n, n, shape, floating)
        ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions(recursion=recursion))))
        traj = random_trajectory(chain, 16, n)
        stream = emulate(ld, traj, "stream")
        assert check_torques(chain, traj, stream.tau).max_rel < 1e-12
        if n <= 11:
            assert np.array_equal(emulate(ld, _head(traj, 2), "tick", seed=1).tau, stream.tau[:2])


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("legs", [3, 4, 8])
def test_the_reports_backward_tiers_are_the_graphs(tmp_path, legs, floating):
    """The report counted a ground leaf at position 0 on every tree, and gave a fixed-base tree one
    backward tier more than its graph wherever the heavy path from the base has 2, 4, 8 ... joints
    (two 4-joint legs: 3 against the graph's 2; talos_reduced from its torso: 4 against 3: a trees
    audit). The report's figure is the tier count of the built log graph's backward nodes."""
    from vampc.compiler import CompileOptions, compile_chain
    from vampc.report.counts import summary
    from vampc.robot import load_robot
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
                'ixz="0" iyz="0"/></inertial>')
    links, joints = [f'<link name="trunk">{inertial}</link>'], []
    for side in ("l", "r"):
        parent = "trunk"
        for k in range(legs):
            links.append(f'<link name="{side}{k}">{inertial}</link>')
            joints.append(f'<joint name="{side}j{k}" type="revolute"><parent link="{parent}"/>'
                          f'<child link="{side}{k}"/><origin xyz="0 0.1 -0.1"/><axis xyz="0 1 0"/>'
                          '<limit lower="-1" upper="1" effort="10" velocity="2"/></joint>')
            parent = f"{side}{k}"
    path = tmp_path / "legs.urdf"
    path.write_text(f'<robot name="legs">{"".join(links)}{"".join(joints)}</robot>')
    chain = load_robot(path, floating=floating)
    c = compile_chain(chain, CompileOptions(recursion="log"))
    tiers = max(r[4] for r in json.loads(dict(c.graph.meta)["bwd_nodes"]))
    assert summary(c)["tree"]["backward_tiers"] == tiers
