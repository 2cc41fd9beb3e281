"""Log-recursion programs through the same back end: every prefix shape and leaf style, both engines,
checked against the reference dynamics and bit-identical between engines."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from emulator_util import loaded, run_both
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vampc.compiler import CompileOptions, compile_chain
from vampc.kinds import Prefix

PREFIXES = Prefix.names()
from vampc.emulator.host import check_torques
from vampc.report.compare import compare_prefixes
from vampc.report.counts import summary
from vampc.robot import load_robot
from vampc.robot.random import random_chain

EXAMPLES = Path(__file__).parent.parent / "examples"


@pytest.mark.parametrize("uniform", [False, True], ids=["table-leaves", "uniform-leaves"])
@pytest.mark.parametrize("prefix", PREFIXES)
def test_every_shape_puma_1000_states(prefix, uniform):
    ld = loaded(load_robot(EXAMPLES / "puma560.yaml"), recursion="log", prefix=prefix,
                uniform_leaves=uniform)
    # (the tick engine on 60 sets: the Puma's log network holds 11 in flight, so the pipeline is
    # full from the 12th; 200 had taken 5 s of the suite's 4 minutes for ten shapes)
    traj, stream, tick = run_both(ld, 1000, tick_count=60)
    assert check_torques(ld.chain, traj, stream.tau).ok
    assert np.array_equal(stream.tau[:60], tick.tau)


def _every_shape(n, seed, prefix, uniform):
    chain = random_chain(n, seed, prismatic_fraction=0.3, endpoints=seed % 3 == 0)
    ld = loaded(chain, recursion="log", prefix=prefix, uniform_leaves=uniform)
    traj, stream, tick = run_both(ld, 1000, seed=seed, tick_count=12)    # (the tick engine's cost)
    assert check_torques(chain, traj, stream.tau).ok
    assert np.array_equal(stream.tau[:12], tick.tau)


# Up to 24 joints in the default run (every prefix shape has several tiers there; the tick engine
# on 40 joints took most of this test's 11 s); 25 to 64 under -m slow. Five draws a run (eight took
# 5.6 s of the suite's 4 minutes; test_every_shape_puma_1000_states runs every shape each run).
@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(n=st.integers(1, 24), seed=st.integers(0, 10**6), prefix=st.sampled_from(PREFIXES),
       uniform=st.booleans())
def test_random_chains_every_shape(n, seed, prefix, uniform):
    _every_shape(n, seed, prefix, uniform)


@pytest.mark.slow
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(n=st.integers(25, 64), seed=st.integers(0, 10**6), prefix=st.sampled_from(PREFIXES),
       uniform=st.booleans())
def test_random_longer_chains_every_shape(n, seed, prefix, uniform):
    _every_shape(n, seed, prefix, uniform)


def _rotary(n):
    return random_chain(n, n, prismatic_fraction=0.0)


@pytest.mark.parametrize("n", range(1, 65))
def test_sklansky_latency_against_paper(n):
    # (the schedule's latency: the compile stops there; allocating and emitting the 64 networks
    # took 60% of this test's time)
    c = compile_chain(_rotary(n), CompileOptions(recursion="log"), until="schedule")
    tiers = math.ceil(math.log2(n + 1))
    paper = (2 * tiers + 5) + (6 * tiers + 10)
    assert c.schedule.latency <= paper + 3          # + the output correction (1 Mult + 2 Addns)


def test_latency_grows_as_log2_n():
    lat = {n: compile_chain(_rotary(n), CompileOptions(recursion="log")).schedule.latency
           for n in (8, 16, 32, 64, 128)}
    steps = [lat[2 * n] - lat[n] for n in (8, 16, 32, 64)]
    assert steps == [8, 8, 8, 8]      # one tier (MV + VA) each way per doubling


def test_n6_vamp_counts_against_section_vi():
    chain = load_robot(EXAMPLES / "puma560.yaml")
    rep = summary(compile_chain(chain, CompileOptions(recursion="log", uniform_leaves=True)))
    assert rep["vamps"]["per_node"] == {"bwd": 26, "npv": 10, "fwd": 12}
    assert (rep["vamps"]["backward"], rep["vamps"]["forward"]) == (398, 169 - 13)


def test_brent_kung_uses_fewer_vamps_than_sklansky_at_64():
    rows = {r["prefix"]: r for r in compare_prefixes(_rotary(64), CompileOptions(recursion="log"))}
    assert rows["brent-kung"]["vamps"] < 0.8 * rows["sklansky"]["vamps"]
    assert rows["serial"]["latency_flops"] > rows["sklansky"]["latency_flops"]
    assert rows["kogge-stone"]["max_fan_out"] <= rows["sklansky"]["max_fan_out"]
