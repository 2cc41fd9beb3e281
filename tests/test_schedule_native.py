"""The list schedule in C (vampc.schedule.native) against the Python loops it replaces for big graphs
(vampc.schedule.layout.schedule_bound): the same priorities and the same start of every node, on the
example robots, random chains and trees, non-unit latencies and crowded random bindings (a few units
for many ops, so the first-fit search and the one-dump-per-block rule both bind)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vampc.compiler import CompileOptions, build_graph
from vampc.emulator import native as emulator_native
from vampc.machine.ops import Timing
from vampc.robot import load_robot
from vampc.robot.random import random_chain, random_tree
from vampc.schedule import layout, native
from vampc.schedule.asap import schedule_asap

pytestmark = pytest.mark.skipif(emulator_native.compiler() is None, reason="no C compiler")

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _both(graph, timing, units, sizes, clock, monkeypatch):
    """schedule_bound with the Python loops and with C."""
    asap = schedule_asap(graph, timing, verify=False)
    out = []
    for mode in ("0", "1"):
        monkeypatch.setenv("VAMPC_NATIVE", mode)
        layout._heights.forget()
        out.append(layout.schedule_bound(graph, timing, asap, units, sizes, clock=clock))
        monkeypatch.setenv("VAMPC_NATIVE", "1" if mode == "0" else "0")   # (only a kept answer
        ran_c = layout._heights(graph, timing.durations)[1] is not None     # stays as it was)
        assert ran_c == (mode == "1")      # the path asked for ran
    layout._heights.forget()
    return out


CASES = [("puma560.yaml", "linear"), ("puma560.yaml", "log"), ("stanford.yaml", "log"),
         ("quadruped.urdf", "linear"), ("quadruped.urdf", "log"), ("snake64.yaml", "log")]


@pytest.mark.parametrize("share", [False, True])
@pytest.mark.parametrize("robot,recursion", CASES)
def test_folded_schedules_agree(robot, recursion, share, monkeypatch):
    graph = build_graph(load_robot(EXAMPLES / robot), CompileOptions(recursion=recursion))
    units, sizes = layout.folded_binding(graph, share)
    python, c = _both(graph, Timing(), units, sizes, Timing().cycle, monkeypatch)
    assert python == c


@pytest.mark.parametrize("seed", range(6))
def test_random_robots_latencies_and_crowded_units(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 30))
    chain = random_chain(n, seed) if seed % 2 else random_tree(n, seed)
    recursion = ("linear", "log")[seed % 3 == 0]
    graph = build_graph(chain, CompileOptions(recursion=recursion))
    timing = Timing(mult=int(rng.integers(1, 4)), add=int(rng.integers(1, 4)))
    compute = [nd for nd in graph.nodes if nd.op.is_compute]
    # units drawn at random among a few, sized as their first op needs (an MM takes three VAMPs)
    count = max(1, len(compute) // int(rng.integers(3, 12)))
    units = [-1] * len(graph.nodes)
    sizes: dict[int, int] = {}
    for nd in compute:
        size = 3 if nd.op.name == "MM" else 1
        unit = int(rng.integers(0, count)) * 2 + (size == 3)
        units[nd.id] = unit
        sizes[unit] = size
    sizes_list = tuple(sizes.get(u, 1) for u in range(2 * count + 2))
    for clock in (1, timing.cycle, 7):
        python, c = _both(graph, timing, units, sizes_list, clock, monkeypatch)
        assert python == c
        assert python.latency > schedule_asap(graph, timing, verify=False).latency or count > 50


def test_longest_to_end_matches(monkeypatch):
    graph = build_graph(random_tree(12, 3), CompileOptions(recursion="log"))
    duration = Timing(mult=2, add=3).durations
    assert native.longest_to_end(graph, duration) == layout._longest_to_end(graph, duration)


def test_small_graphs_stay_in_python(monkeypatch):
    monkeypatch.delenv("VAMPC_NATIVE", raising=False)
    assert not native.wanted(native.MIN_NODES - 1) and native.wanted(native.MIN_NODES)
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    assert not native.wanted(10 ** 7)


def test_without_a_compiler_the_python_loops_run(monkeypatch):
    # no C compiler here (the library could not be built): the same schedule, from Python
    graph = build_graph(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(recursion="log"))
    units, sizes = layout.folded_binding(graph, False)
    asap = schedule_asap(graph, Timing(), verify=False)
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    layout._heights.forget()
    want = layout.schedule_bound(graph, Timing(), asap, units, sizes, clock=Timing().cycle)
    monkeypatch.delenv("VAMPC_NATIVE")
    monkeypatch.setattr(native, "MIN_NODES", 1)
    monkeypatch.setattr(native, "_LIB", [None])
    layout._heights.forget()
    got = layout.schedule_bound(graph, Timing(), asap, units, sizes, clock=Timing().cycle)
    monkeypatch.setenv("VAMPC_NATIVE", "1")          # a recomputed answer would now use C
    monkeypatch.setattr(native, "_LIB", [])
    assert layout._heights(graph, Timing().durations)[1] is None and got == want
    layout._heights.forget()
