"""Time-multiplexed layouts end to end (issue 9): folded and shared-pass programs, every prefix shape,
non-unit latencies — emulated torques against the reference Newton-Euler, both engines bit for bit,
the tick engine from random register contents; the systolic layout unchanged; bad slot programs
reported with the VAMP, slot and field."""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from emulator_util import document, loaded, mutated, run_both
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain
from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.host import check_torques, random_trajectory
from vampc.errors import VampcError
from vampc.robot import load_robot
from vampc.robot.random import random_chain

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
ROBOTS = sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".yaml", ".urdf") and "snake" not in p.name)
PREFIXES = ("sklansky", "brent-kung", "kogge-stone", "ladner-fischer", "serial")
FOLDED = [dict(layout="folded"), dict(layout="folded", share_passes=True)]


def _exact(ld, traj, tau):
    res = check_torques(ld.chain, traj, tau)
    assert res.ok, f"max relative error {res.max_rel:.3e}"


@pytest.mark.parametrize("opts", FOLDED, ids=["folded", "shared"])
@pytest.mark.parametrize("recursion", ["linear", "log"])
@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.name)
def test_examples_folded_both_engines(path, recursion, opts):
    ld = loaded(load_robot(path), recursion=recursion, **opts)
    traj, stream, tick = run_both(ld, 300, tick_count=6)
    _exact(ld, traj, stream.tau)
    assert np.array_equal(stream.tau[:6], tick.tau)
    assert stream.interval == ld.period > ld.schedule.latency   # one set at a time


@pytest.mark.parametrize("share", [False, True])
@pytest.mark.parametrize("prefix", PREFIXES)
def test_every_prefix_shape_folds(prefix, share):
    chain = random_chain(9, 5, prismatic_fraction=0.4, endpoints=True)
    ld = loaded(chain, recursion="log", prefix=prefix, layout="folded", share_passes=share)
    traj, stream, tick = run_both(ld, 100, tick_count=4)
    _exact(ld, traj, stream.tau)
    assert np.array_equal(stream.tau[:4], tick.tau)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])   # (7.5 s at 10)
@given(n=st.integers(1, 40), seed=st.integers(0, 10**6), frac=st.sampled_from([0.0, 0.3, 0.7]),
       recursion=st.sampled_from(["linear", "log"]), share=st.booleans(),
       prefix=st.sampled_from(PREFIXES), uniform=st.booleans())
def test_random_chains_folded(n, seed, frac, recursion, share, prefix, uniform):
    chain = random_chain(n, seed, prismatic_fraction=frac, endpoints=seed % 2 == 0)
    extra = dict(prefix=prefix, uniform_leaves=uniform) if recursion == "log" else {}
    ld = loaded(chain, recursion=recursion, layout="folded", share_passes=share, **extra)
    traj, stream, tick = run_both(ld, 200, seed=seed, tick_count=3)
    _exact(ld, traj, stream.tau)
    assert np.array_equal(stream.tau[:3], tick.tau)


@pytest.mark.parametrize("mult,add", [(2, 1), (3, 2), (1, 4)])
@pytest.mark.parametrize("layout", ["systolic", "folded"])
@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_non_unit_latencies_emulate_exactly(mult, add, layout, recursion):
    chain = random_chain(5, 3, prismatic_fraction=0.4, endpoints=True)
    ld = loaded(chain, recursion=recursion, layout=layout, mult_latency=mult, add_latency=add)
    traj, stream, tick = run_both(ld, 200, tick_count=12)
    _exact(ld, traj, stream.tau)
    assert np.array_equal(stream.tau[:12], tick.tau)
    assert tick.first_tick == ld.schedule.latency and tick.interval == ld.period


def test_the_tick_engine_starts_from_random_registers_for_every_seed():
    ld = loaded(random_chain(4, 2, prismatic_fraction=0.5), layout="folded", share_passes=True)
    traj = random_trajectory(ld.chain, 5, 0)
    runs = [emulate(ld, traj, "tick", seed=seed).tau for seed in range(4)]
    assert all(np.array_equal(runs[0], r) for r in runs[1:])


# --- the paper's single-device figures and the systolic layout unchanged ---------------------------

def _report(*args) -> dict:
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--format", "json",
                                    *args])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


def test_single_device_vamp_counts_reproduce_section_vi():
    linear = _report("--layout", "folded")["vamps"]
    assert (linear["total"], linear["backward"], linear["forward"]) == (30, 22, 8)
    assert _report("--layout", "folded", "--share-passes")["vamps"]["total"] == 22
    log = _report("--recursion", "log", "--uniform-leaves", "--layout", "folded")["vamps"]
    assert (log["backward"], log["forward"]) == (98, 36)     # paper 98 + 39: T20 is not needed


def test_systolic_figures_are_unchanged():
    rep = _report()
    assert rep["latency"] == {"flops": 61, "mults": 16, "adds": 45, "waits": 0}
    assert (rep["vamps"]["backward"], rep["vamps"]["forward"]) == (132, 48)
    assert rep["interval_flops"] == 4 and rep["buffers"]["stages"] == 61
    assert rep["layout"] == "systolic"


def test_folded_latency_and_interval_are_reported_beside_the_systolic():
    rep = _report("--layout", "folded")
    assert rep["layout"] == "folded" and rep["latency"]["flops"] == 61
    assert rep["interval_flops"] == 64
    rows = {r["layout"]: r for r in rep["layout_comparison"]}
    assert rows["systolic"]["interval_flops"] == 4 and rows["systolic"]["vamps"] == 180
    assert rows["folded"]["vamps"] == 30 and rows["folded, shared passes"]["vamps"] == 22
    for r in rows.values():
        assert r["latency_flops"] == r["mults"] + r["adds"] + r["waits"]


def test_share_passes_without_folded_is_a_usage_error():
    res = CliRunner().invoke(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--share-passes"])
    assert res.exit_code == 2 and "--share-passes applies to the folded layout only (add --layout " \
        "folded)" in res.stderr
    # with a budget, whose own layout refuses --layout: not told to add it (an audit's find)
    for budget in (["--vamps", "10"], ["--interval", "8"]):
        res = CliRunner().invoke(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--share-passes",
                                        *budget])
        assert res.exit_code == 2 and "--share-passes applies to the folded layout only, not with " \
            "--vamps or --interval, which make their own (budgeted) layout" in res.stderr, res.stderr


# --- bad slot programs -----------------------------------------------------------------------------

DOC = document(random_chain(3, 4, prismatic_fraction=0.34), layout="folded")
TRAJ = random_trajectory(loaded_from_doc(DOC).chain, 4, 1)


def _refused(change, pattern):
    with pytest.raises(VampcError) as err:
        emulate(loaded_from_doc(mutated(DOC, change)), TRAJ)
    assert re.search(pattern, str(err.value)), str(err.value)


def _multi():
    return next(p["vamp"] for p in DOC["programs"] if len(p["slots"]) > 1)


def test_overlapping_slots_are_reported():
    v = _multi()
    def change(doc):
        slots = doc["programs"][v]["slots"]
        slots[1].update({k: slots[0][k] for k in ("delay_a", "delay_b", "delay_r")})
    _refused(change, rf"programs\[{v}\] slot 1 lists delay-a")      # the stream disagrees
    def consistent(doc):
        change(doc)
        from test_emulator_faults import _set_field
        s0 = doc["programs"][v]["slots"][0]
        for f in ("delay_a", "delay_b", "delay_r"):
            _set_field(v, 1, f, s0[f])(doc)
    # the edited slot's delays are not its schedule's ticks: said of it first (since 2026-12-07)
    _refused(consistent, rf"VAMP {v} slot 1 \(.*\): delay-A \d+ latches operand A at counter \d+, "
                         r"the schedule has tick")
    # and the timing rules alone (the tick engine's, unchecked) see the two slots overlap
    from vampc.emulator import timing
    with pytest.raises(VampcError, match=rf"VAMP {v} slot 0 .* and slot 1 run micro-steps in the "
                                         "same tick"):
        timing.derive(loaded_from_doc(mutated(DOC, consistent)))


def test_a_select_that_points_nowhere_names_vamp_slot_and_field():
    from test_emulator_faults import _set_field
    v = _multi()
    inputs = len(DOC["network"]["vamps"][v]["b"])
    _refused(_set_field(v, 1, "sel_b", inputs + 2),
             rf"VAMP {v} \(number {v + 1}\) slot 1: sel-b {inputs + 2} selects no input")


def test_a_delay_beyond_the_period_names_vamp_slot_and_field():
    from test_emulator_faults import _set_field
    v = _multi()
    P = DOC["network"]["period"]
    _refused(_set_field(v, 1, "delay_r", P + 3),
             rf"VAMP {v} \(number {v + 1}\) slot 1: delay-r {P + 3} never matches the Cycle-Counter "
             rf"\(0..{P - 1}: the period is {P}\)")


def test_a_period_that_is_not_a_multiple_of_the_clock():
    def change(d):                  # (io.period, the host's copy, must say the same)
        d["network"]["period"] += 1
        d["io"]["period"] = d["network"]["period"]
    _refused(change, r"network.period \d+ is not a multiple of network.clock 4")


def test_compiled_options_round_trip():
    c = compile_chain(random_chain(3, 1), CompileOptions(layout="folded", share_passes=True))
    assert c.layout.share_passes and c.network.period == c.schedule.interval


def _systolic(n: int = 2):
    from vampc.schedule.layout import layout_and_schedule
    c = compile_chain(random_chain(n, 0), CompileOptions(recursion="log", verify=False),
                      until="graph")       # (the log recursion has MM nodes: three VAMPs each)
    layout, _ = layout_and_schedule(c.graph, CompileOptions().timing)
    return c.graph, layout


@pytest.mark.parametrize("kind", ["too few", "negative", "repeated", "input on a VAMP"])
def test_layout_check_rejects_a_bad_placement(kind):
    """Layout.verify: a compute node on as many distinct, non-negative VAMPs as its op takes, an
    input or a constant on none (VampcInternalError naming the node)."""
    import dataclasses

    from vampc.errors import VampcInternalError
    graph, layout = _systolic()
    placement = list(layout.placement)
    if kind == "input on a VAMP":
        nd = next(nd for nd in graph.nodes if not nd.op.is_compute)
        placement[nd.id] = (0,)
    else:
        nd = next(nd for nd in graph.nodes if len(placement[nd.id]) == 3)
        where = placement[nd.id]
        placement[nd.id] = {"too few": where[:2], "negative": (where[0], -1, where[2]),
                            "repeated": (where[0], where[0], where[2])}[kind]
    broken = dataclasses.replace(layout, placement=tuple(placement))
    with pytest.raises(VampcInternalError, match=rf"^node {re.escape(nd.label)}: placed on "):
        broken.verify(graph)
    layout.verify(graph)


def test_layout_check_rejects_two_units_sharing_a_vamp():
    """In a grouped layout, nodes placed on equal VAMPs are one unit (allowed); a VAMP in two
    different units is not."""
    import dataclasses

    from vampc.errors import VampcInternalError
    graph, layout = _systolic()
    placement = list(layout.placement)
    one = [nd.id for nd in graph.nodes if len(placement[nd.id]) == 1]
    mm = next(nd.id for nd in graph.nodes if len(placement[nd.id]) == 3)
    placement[one[1]] = placement[one[0]]       # two nodes on one unit
    dataclasses.replace(layout, placement=tuple(placement)).verify(graph)
    placement[one[2]] = (placement[mm][1],)     # an MM unit's VAMP as a unit of its own
    broken = dataclasses.replace(layout, placement=tuple(placement))
    with pytest.raises(VampcInternalError, match="^layout: a VAMP belongs to two units$"):
        broken.verify(graph)
