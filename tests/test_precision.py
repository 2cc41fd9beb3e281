"""`vampc precision` and its analysis (vampc.precision): the bound on every register's magnitude and
on the torque error is never below what random states within the analysed ranges show, on every
example robot and both recursions; the command names the narrowest words."""
from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain
from vampc.dataflow.evaluate import evaluate_nodes
from vampc.dynamics.reference import rnea
from vampc.emulator.driver import random_states
from vampc.errors import VampcError
from vampc.jsontext import loads
from vampc.machine.arith import Rounding
from vampc.precision import Ranges, analyse, fitted

ROBOTS = ["planar2.yaml", "puma560.yaml", "stanford.yaml", "arm6.urdf", "quadruped.urdf",
          "snake64.yaml"]


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_the_bound_is_never_below_what_is_observed(robot, recursion):
    from vampc.robot import load_robot
    chain = load_robot(EXAMPLES / robot)
    graph = compile_chain(chain, CompileOptions(recursion=recursion)).graph
    traj = random_states(chain, 0, 120, 4)
    ref = rnea(chain, traj.q, traj.qd, traj.qdd, traj.base)
    for bits, rounding in ((20, Rounding.NEAREST), (28, Rounding.TRUNCATE), (36, Rounding.NEAREST)):
        got = fitted(graph, chain, bits, rounding, Ranges())
        if got is None:           # no split of this width holds the values: nothing to compare
            continue
        word, bound = got
        vals = evaluate_nodes(graph, chain, traj.q, traj.qd, traj.qdd, traj.base, arith=word)
        tau = word.decode(np.stack([vals[o.node][:, o.component] for o in graph.outputs], axis=1))
        assert word.overflows == 0
        assert np.all(np.abs(tau - ref).max(axis=0) <= bound.tau_error), word.name
        assert np.all(np.abs(ref).max(axis=0) <= bound.tau_max), word.name
        peak = max(float(np.abs(word.decode(v)).max()) for v in vals if v.dtype == np.int64)
        assert peak <= bound.peak


def test_precision_names_the_narrowest_words():
    run = CliRunner().invoke
    res = run(main, ["precision", str(EXAMPLES / "puma560.yaml"), "--sweep", "20:30"])
    assert res.exit_code == 0, res.output
    assert "narrowest word meeting 0.001 by the analysed bound, with no possible overflow: " \
        "q10.16 (26 bits)" in res.output
    assert "  26  q10.16" in res.output
    res = run(main, ["precision", str(EXAMPLES / "planar2.yaml"), "--sweep", "16:18", "--format",
                     "csv"])
    lines = res.output.splitlines()
    assert lines[0] == "bits,word,peak,bound,observed,overflows" and len(lines) == 4
    doc = loads(run(main, ["precision", str(EXAMPLES / "planar2.yaml"), "--sweep", "16:40",
                           "--format", "json", "--tolerance", "1e-6"]).output)
    bound = doc["narrowest_bound"]
    assert bound and all(r["bound"] > 1e-6 for r in doc["rows"] if r["word"] and
                         r["bits"] < int(bound[1:].split(".")[0]) + int(bound.split(".")[1]))


@pytest.mark.parametrize("args, said", [
    (["--sweep", "1:70"], "--sweep 1:70: give A:B"), (["--sweep", "x"], "--sweep x: give A:B"),
    (["--tolerance", "0"], "--tolerance 0.0: give a positive number"),
    (["--acceleration", "-1"], "--acceleration -1.0: give a positive number"),
])
def test_a_precision_option_that_makes_no_sense_is_a_usage_error(args, said):
    res = CliRunner().invoke(main, ["precision", str(EXAMPLES / "planar2.yaml"), *args])
    assert res.exit_code == 2 and said in res.stderr, res.stderr


def test_an_op_without_a_norm_rule_cannot_be_bounded(monkeypatch):
    from dataclasses import replace

    from vampc.machine import ops
    from vampc.robot import load_robot
    chain = load_robot(EXAMPLES / "planar2.yaml")
    graph = compile_chain(chain, CompileOptions()).graph
    monkeypatch.setitem(ops.TABLE, ops.Op.VA, replace(ops.TABLE[ops.Op.VA], norm=None))
    with pytest.raises(VampcError, match="op VA states no norm rule"):
        analyse(graph, chain, fitted(graph, chain, 32, Rounding.NEAREST, Ranges())[0])


def test_precision_analyses_the_rounding_asked_for():
    res = CliRunner().invoke(main, ["precision", str(EXAMPLES / "planar2.yaml"), "--sweep", "22:22",
                                    "--rounding", "truncate"])
    nearest = CliRunner().invoke(main, ["precision", str(EXAMPLES / "planar2.yaml"), "--sweep",
                                        "22:22"])
    assert res.exit_code == nearest.exit_code == 0, res.output
    bound = {r: float(x.output.splitlines()[2].split()[3]) for r, x in (("t", res), ("n", nearest))}
    assert bound["t"] > bound["n"]           # truncating loses up to a whole LSB a product, not half


@pytest.mark.parametrize("option", [["--word", "q16.16"], ["--overflow", "wrap"]])
def test_an_option_precision_does_not_use_is_refused(option):
    res = CliRunner().invoke(main, ["precision", str(EXAMPLES / "planar2.yaml"), *option])
    assert res.exit_code == 2 and f"{option[0]} does not apply to vampc precision" in res.stderr


@pytest.mark.parametrize("args", [["--layout", "folded"], ["--vamps", "5"], ["--bus", "mlb"],
                                  ["--mult-latency", "3"], ["--error-correction"]])
def test_network_options_do_not_apply(args):
    """They were taken and the table was the same (a new user's run): the errors are the graph's."""
    r = CliRunner().invoke(main, ["precision", "examples/planar2.yaml", "--sweep", "20:20", "--sets", "20", *args])
    assert r.exit_code == 2 and f"{args[0]} does not apply to vampc precision" in r.output, r.output


def test_the_options_precision_refuses_are_not_in_its_help():
    """Its --help listed --word, --layout, --vamps and the other compile options it refuses (a
    reader took them for choices); each name refused is a compile option (a misspelt one would
    refuse nothing), and the help still lists what it takes (--rounding, --recursion)."""
    from dataclasses import fields

    from vampc.options import PRECISION_REFUSES
    names = {f.name for f in fields(CompileOptions)}
    assert set(PRECISION_REFUSES) <= names
    text = CliRunner().invoke(main, ["precision", "--help"]).output
    for name in PRECISION_REFUSES:
        assert f"--{name.replace('_', '-')} " not in text and f"--{name.replace('_', '-')}\n" not in text, name
    assert "--rounding" in text and "--recursion" in text
