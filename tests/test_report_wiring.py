"""Buffering and wiring (vampc.report.wiring), measured from compiled networks."""
from __future__ import annotations

import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report.configs import configurations
from vampc.report.wiring import early_forward, wiring
from vampc.robot import load_robot


@pytest.fixture(scope="module")
def puma():
    return load_robot(EXAMPLES / "puma560.yaml")


def _wiring(chain, **opts):
    c = compile_chain(chain, CompileOptions(**opts))
    return wiring(configurations(c), chain), c


def test_linear_systolic_buffers_only_between_the_passes(puma):
    # Section VI: "Passive buffering is only required between backward and forward recursion
    # processors"; T20, T21 (computed from F_i, N_i before the forward recursion arrives) count so.
    w, c = _wiring(puma)
    d = w["delay_buffers"]
    assert (d["chains"], d["stages"], d["scalars"]) == (16, 61, 183)
    assert d["by_flow"]["within_backward"]["stages"] == d["by_flow"]["within_forward"]["stages"] == 0
    assert d["by_flow"]["backward_to_forward"]["stages"] == 61
    early = [c.graph.nodes[i] for i in early_forward(c.graph)]
    assert {nd.name for nd in early if nd.group < 6} == {"T20", "T21"}
    assert len([nd for nd in early if nd.group == 6]) == 8     # the tip node waits for no one


def test_linear_buses_between_nodes_and_inside_them(puma):
    b = _wiring(puma)[0]["buses"]
    # node i reads ω, ω̇, p̈ of node i - 1 (the paper says four vectors); the forward one f, n.
    assert b["between_nodes"] == {"bwd": {"vectors": 3, "wires": 3}, "fwd": {"vectors": 2, "wires": 2}}
    assert b["backward_to_forward"]["vectors"] == 12            # F_i and N_i of six joints
    assert b["internal_max"] == {"bwd": 24, "npv": 20, "fwd": 16}  # 2 per op: paper ≤ 50, 20
    assert b["paper_between_nodes"] == {"bwd": 4, "fwd": 2}


def test_log_buses_between_nodes_match_the_papers_18(puma):
    # A combining node receives W (three vectors), ω, ω̇, Q, R, S, p̈ from each of its two inputs.
    b = _wiring(puma, recursion="log", uniform_leaves=True)[0]["buses"]
    assert b["between_nodes"]["bwd"]["vectors"] == 18 == b["paper_between_nodes"]["bwd"]


def test_input_buffering_breakdown(puma):
    ib = _wiring(puma)[0]["input_buffering"]
    assert ib["scalars"] == 195 == sum(ib["ports"].values()) + sum(ib["constants"].values())
    assert ib["ports"] == {"A": 54, "zqd": 18, "zqdd": 18}
    assert ib["paper"] == 237


def test_program_and_fan_out(puma):
    w, c = _wiring(puma, layout="folded")
    assert w["program"]["load_ticks"] == 527 and w["program"]["words"] > len(c.network.vamps)
    assert w["configuration"] == "linear, folded" and w["max_fan_out"] >= 1
    assert {r["configuration"] for r in w["by_configuration"]} >= {"linear, systolic", "log, folded"}
