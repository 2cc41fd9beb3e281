"""The configurations a report compares (vampc.report.configs): both recursions in every layout,
the report's own among them, allocated only while small."""
from __future__ import annotations

import pytest

from vampc.compiler import CompileOptions, compile_chain
from vampc.report import configs as cfg
from vampc.robot.random import random_chain


@pytest.fixture(scope="module")
def chain():
    return random_chain(4, 5, prismatic_fraction=0.0)


def test_six_configurations_the_compiled_one_reused(chain):
    c = compile_chain(chain, CompileOptions(recursion="log", layout="folded"))
    got = cfg.configurations(c)
    assert [k.name for k in got] == ["linear, systolic", "linear, folded", "linear, folded, shared passes",
                                     "log, systolic", "log, folded", "log, folded, shared passes"]
    mine = cfg.own(got)
    assert mine.name == "log, folded" and mine.network is c.network and mine.schedule is c.schedule
    assert sum(k.own for k in got) == 1
    for k in got:      # every other one compiles to what compile_chain gives for its options
        ref = compile_chain(chain, k.options)
        assert (k.schedule.latency, k.schedule.interval, k.vamps) == \
            (ref.schedule.latency, ref.schedule.interval, len(ref.network.vamps))
        assert len(k.network.vamps) == k.vamps and k.stream


def test_big_graphs_are_scheduled_not_allocated(chain, monkeypatch):
    c = compile_chain(chain)
    monkeypatch.setattr(cfg, "ALLOCATE_LIMIT", len(c.graph.compute_nodes()) + 1)
    got = {k.name: k for k in cfg.configurations(c)}
    assert got["linear, folded"].network is not None            # linear: under the limit
    assert got["log, systolic"].network is None and got["log, systolic"].vamps > 0
    monkeypatch.setattr(cfg, "ALLOCATE_LIMIT", 1)                 # the own graph is over it: none
    assert [k.name for k in cfg.configurations(c) if k.network is not None] == ["linear, systolic"]


def test_layout_label():
    assert cfg.layout_label("folded", True) == "folded, shared passes"
