"""The Python API: `import vampc` offers every stage the CLI uses."""
from __future__ import annotations

import gc
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import vampc

PUMA = Path(__file__).parent.parent / "examples" / "puma560.yaml"


def test_every_api_name_resolves():
    # each name is the object its module defines under it (not merely something: the getattr
    # raising was the only way this could fail), and a function or class as the API lists it
    import importlib
    for name in vampc.__all__:
        where = vampc._API[name]
        module, attr = where if isinstance(where, tuple) else (where, name)
        got = getattr(vampc, name)
        assert got is getattr(importlib.import_module(module), attr), name
        assert callable(got), name
    assert vampc.render_report is importlib.import_module("vampc.report.text").render


def test_unknown_name():
    with pytest.raises(AttributeError):
        vampc.no_such_stage  # noqa: B018


def test_stages_by_hand_equal_compile_chain():
    chain = vampc.load_robot(PUMA)
    graph = vampc.build_linear(chain)
    sched = vampc.schedule_asap(graph)
    net = vampc.allocate_systolic(graph, sched)
    c = vampc.compile_chain(chain, vampc.CompileOptions())
    assert (sched.latency, len(net.vamps)) == (c.schedule.latency, len(c.network.vamps))
    traj = vampc.random_trajectory(chain, 20, 3)
    tau = vampc.emulate(vampc.loaded_from_doc(vampc.program_document(c)), traj).tau
    assert np.allclose(tau, vampc.rnea(chain, traj.q, traj.qd, traj.qdd), rtol=1e-12, atol=1e-12)


def test_import_is_cheap():
    # Importing the package must not pull in numpy, networkx, jsonschema or yourdfpy.
    code = "import sys, vampc; print(sorted(m for m in ('numpy','networkx','jsonschema','yourdfpy') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_verify_flag_controls_every_stage_check(monkeypatch, recursion):
    # Each stage checks the IR it hands on; --no-verify (verify=False) must skip all of those checks.
    from vampc.dataflow.graph import Graph
    from vampc.errors import VampcInternalError
    from vampc.network.model import Network
    from vampc.schedule.asap import Schedule
    calls = []
    def refuse(name):
        def check(*args, **kwargs):
            calls.append(name)
            raise VampcInternalError(f"{name} ran")
        return check
    monkeypatch.setattr(Graph, "verify", refuse("graph"))
    monkeypatch.setattr(Schedule, "verify", refuse("schedule"))
    monkeypatch.setattr(Network, "verify", refuse("network"))
    chain = vampc.load_robot(PUMA)
    vampc.compile_chain(chain, vampc.CompileOptions(recursion=recursion, verify=False))
    assert calls == []
    with pytest.raises(VampcInternalError, match="graph ran"):
        vampc.compile_chain(chain, vampc.CompileOptions(recursion=recursion))


def test_stages_pause_the_garbage_collector_and_resume_it():
    from vampc.gcpause import gc_paused
    assert gc.isenabled()
    with pytest.raises(RuntimeError), gc_paused():
        assert not gc.isenabled()
        raise RuntimeError
    assert gc.isenabled()
    gc.disable()
    try:
        with gc_paused():
            pass
        assert not gc.isenabled()     # a caller's own pause is left as it was
    finally:
        gc.enable()
    vampc.program_document(vampc.compile_chain(vampc.random_chain(2, 1)))
    assert gc.isenabled()
