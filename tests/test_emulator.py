"""The emulator against the reference dynamics; the two engines against each other; Program Mode and
the emulator's own timing."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from emulator_util import loaded, run_both
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vampc.dynamics.reference import rnea
from vampc.emulator import emulate
from vampc.emulator.host import check_torques, port_values, random_trajectory
from vampc.emulator.tick import TickEngine, TickStats
from vampc.errors import VampcError
from vampc.robot import load_robot
from vampc.robot.random import random_chain

EXAMPLES = sorted(p for p in Path(__file__).parent.parent.joinpath("examples").iterdir()
                  if p.suffix in (".yaml", ".urdf") and "snake" not in p.name)


def _assert_exact(traj, chain, tau):
    res = check_torques(chain, traj, tau)
    assert res.ok, f"max relative error {res.max_rel:.3e}"


# the stream engine on 1000 states, checked against the reference; the tick engine on the first
# 100 of them, bit for bit (1000 through the tick engine took 7 s of the suite's 4 minutes: after
# the pipeline fills, each set runs the same ops on other values)
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_examples_1000_states_and_the_tick_engine_on_100(path):
    ld = loaded(load_robot(path))
    traj, stream, tick = run_both(ld, 1000, tick_count=100)
    _assert_exact(traj, ld.chain, stream.tau)
    assert np.array_equal(stream.tau[:100], tick.tau)


def test_snake64_stream_and_tick():
    ld = loaded(load_robot(Path(__file__).parent.parent / "examples" / "snake64.yaml"))
    traj, stream, tick = run_both(ld, 1000, tick_count=40)
    _assert_exact(traj, ld.chain, stream.tau)
    assert np.array_equal(stream.tau[:40], tick.tau)


# 8 draws and 20 sets through the tick engine (12 and 60 took 6.2 s of the suite; every run draws
# new chains, and the tick engine's sets are bit for bit the stream engine's after its first few)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(n=st.integers(1, 40), seed=st.integers(0, 10**6), frac=st.sampled_from([0.0, 0.3, 0.7]))
def test_random_chains_both_engines(n, seed, frac):
    chain = random_chain(n, seed, prismatic_fraction=frac, endpoints=seed % 2 == 0)
    ld = loaded(chain)
    traj, stream, tick = run_both(ld, 1000, seed=seed, tick_count=20)
    _assert_exact(traj, chain, stream.tau)
    assert np.array_equal(stream.tau[:20], tick.tau)


def test_reference_is_independent_of_emulator_inputs():
    # The check compares with rnea on the states the host drew, not with anything the network made.
    ld = loaded(random_chain(3, 7))
    traj = random_trajectory(ld.chain, 5, 3)
    tau = emulate(ld, traj).tau
    assert np.allclose(tau, rnea(ld.chain, traj.q, traj.qd, traj.qdd), rtol=0, atol=1e-10)
    assert not check_torques(ld.chain, traj, tau * (1 + 1e-8)).ok


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_program_mode_from_any_state(seed):
    ld = loaded(load_robot(Path(__file__).parent.parent / "examples" / "puma560.yaml"))
    engine = TickEngine(ld, seed=seed)
    assert not np.array_equal(engine.programs(), ld.programs)
    ticks = engine.program()
    assert engine.programs() == ld.programs
    assert ticks == ld.load_ticks > 0


def test_program_mode_needs_the_whole_stream():
    ld = loaded(random_chain(4, 2))
    engine = TickEngine(ld, seed=0)
    with pytest.raises(VampcError, match="saw no word with their number"):
        engine.program(ticks=1)


def test_tick_engine_timing_is_observed_not_scheduled():
    # The emulator's own observation (set tags reaching the output VAMPs) against the schedule.
    ld = loaded(load_robot(Path(__file__).parent.parent / "examples" / "puma560.yaml"))
    traj = random_trajectory(ld.chain, 12, 0)
    engine = TickEngine(ld, seed=4)
    engine.program()
    stats = TickStats()
    engine.run(port_values(ld, traj), traj.count, stats)
    assert stats.first_set_tick == ld.schedule.latency
    assert set(np.diff(stats.appear)) == {4}


def test_emulated_time_is_reported():
    ld = loaded(random_chain(2, 1))
    traj = random_trajectory(ld.chain, 10, 0)
    res = emulate(ld, traj, "tick")
    assert res.interval == 4 and res.first_tick == ld.schedule.latency
    assert res.emulated_flops == res.load_ticks + 9 * 4 + res.first_tick + 1
