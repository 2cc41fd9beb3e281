"""The Python API: `import vampc` offers every stage the CLI uses."""
from __future__ import annotations

import gc
import re
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


# --- a library caller's states and options (a new user's script: extra joint columns had been dropped,
# so another robot's trajectory ran; NaN ran into NaN torques; a 1-D state was an IndexError) -------

def _puma_loaded():
    chain = vampc.load_robot(PUMA)
    return chain, vampc.loaded_from_compiled(vampc.compile_chain(chain, vampc.CompileOptions()))


def _bad_states(traj):
    """(label, Trajectory or other, words the error must hold) of each way a caller's states can be
    wrong."""
    T = vampc.Trajectory
    q, qd, qdd = traj.q, traj.qd, traj.qdd
    nan = q.copy()
    nan[1, 5] = np.nan
    one = np.ones((len(q), 1))
    return [
        ("a seventh joint column", T(np.hstack([q, one]), np.hstack([qd, one]), np.hstack([qdd, one])),
         "q has shape (5, 7); it must be (states, 6)"),
        ("a NaN", T(nan, qd, qdd), "state 2, column q6: nan is not finite"),
        ("an infinity", T(q, qd, np.where(q > 0, np.inf, qdd)), "is not finite"),
        ("one 1-D state", T(q[0], qd[0], qdd[0]), "(1, 6) for one state"),
        ("no states", T(q[:0], qd[:0], qdd[:0]), "no states"),
        ("fewer qd rows", T(q, qd[:4], qdd), "qd has 4 states where q has 5"),
        ("complex", T(q + 0j, qd, qdd), "complex"),
        ("text", T(q.astype(str), qd, qdd), "not numbers"),
        ("an integer past 2**53", T(np.full(q.shape, 2 ** 53 + 1), qd, qdd), "state 1, column q1"),
        ("a base on a fixed base", T(q, qd, qdd, None, np.zeros((len(q), 9))), "base applies to a floating"),
        ("a t per state but one", T(q, qd, qdd, np.arange(len(q) - 1.0)), "t has 4 states"),
        ("bare arrays", q, "must be a vampc.Trajectory"),
    ]


@pytest.mark.parametrize("case", range(12))
@pytest.mark.parametrize("engine", ["stream", "tick"])
def test_states_a_library_caller_gives_wrong_are_refused_naming_what_and_where(case, engine):
    chain, ld = _puma_loaded()
    label, bad, words = _bad_states(vampc.random_trajectory(chain, 5, 0))[case]
    with pytest.raises(vampc.VampcError) as err:
        vampc.emulate(ld, bad, engine=engine)
    assert str(err.value).startswith("emulate: ") and words in str(err.value), (label, err.value)
    assert "\n" not in str(err.value)


def test_states_as_lists_or_other_real_dtypes_give_the_same_torques_and_are_not_changed():
    chain, ld = _puma_loaded()
    traj = vampc.random_trajectory(chain, 5, 0)
    tau = vampc.emulate(ld, traj).tau
    listed = vampc.Trajectory(traj.q.tolist(), traj.qd.tolist(), traj.qdd.tolist())
    assert np.array_equal(vampc.emulate(ld, listed).tau, tau)
    fortran = vampc.Trajectory(np.asfortranarray(traj.q), traj.qd[:, ::1], traj.qdd.copy())
    before = fortran.q.copy()
    assert np.array_equal(vampc.emulate(ld, fortran).tau, tau)
    assert np.array_equal(fortran.q, before)
    whole = vampc.Trajectory(np.zeros((2, 6), dtype=np.int32), np.zeros((2, 6)), np.zeros((2, 6)))
    floats = vampc.Trajectory(np.zeros((2, 6)), np.zeros((2, 6)), np.zeros((2, 6)))
    assert np.array_equal(vampc.emulate(ld, whole).tau, vampc.emulate(ld, floats).tau)


def test_an_unknown_engine_names_the_engines():
    chain, ld = _puma_loaded()
    with pytest.raises(vampc.VampcUsageError, match="'TICK': the engines are stream, tick"):
        vampc.emulate(ld, vampc.random_trajectory(chain, 2, 0), engine="TICK")


def test_check_torques_refuses_torques_of_another_shape_and_names_the_words_tolerance():
    chain, ld = _puma_loaded()
    traj = vampc.random_trajectory(chain, 5, 0)
    tau = vampc.emulate(ld, traj).tau
    assert vampc.check_torques(chain, traj, tau).ok
    with pytest.raises(vampc.VampcError, match=r"check_torques: tau has shape \(5, 5\)"):
        vampc.check_torques(chain, traj, tau[:, :5])
    assert "check_tolerance" in vampc.check_torques.__doc__


@pytest.mark.parametrize("tol, words", [(0, "0: give a positive"), (-1, "-1: give a positive"),
                                        (float("nan"), "nan: give a positive"),
                                        (2, "2: give an error below 1"), ("1e-3", "give a number"),
                                        (True, "give a number")])
def test_check_torques_refuses_a_tolerance_the_command_line_refuses(tol, words):
    """0, -1 and NaN had failed every check, 2 passed torques 1.5 times the reference's, unsaid,
    where `--tolerance` refuses them all (a new user's find)."""
    chain, ld = _puma_loaded()
    traj = vampc.random_trajectory(chain, 3, 0)
    tau = vampc.emulate(ld, traj).tau
    assert not vampc.check_torques(chain, traj, 2.5 * tau, 0.9).ok
    with pytest.raises(vampc.VampcUsageError, match=re.escape(words)) as exc:
        vampc.check_torques(chain, traj, 2.5 * tau, tol)
    assert str(exc.value).startswith("check_torques: tol ") and "reads as" not in str(exc.value)


def test_a_trajectory_read_in_python_is_held_to_the_joint_limits_as_the_command_lines(tmp_path):
    """`vampc.read_trajectory` makes a Trajectory "as --trajectory does", but ran a state outside the
    joint limits that `vampc emulate --trajectory` refuses (a new user's find): now refused the
    same way, unless allow_out_of_limits; `vampc.check_limits` checks one made in Python."""
    from click.testing import CliRunner

    from vampc.cli import main
    chain, ld = _puma_loaded()
    traj = vampc.random_trajectory(chain, 3, 0)
    q = traj.q.copy()
    q[1, 0] = 100.0                   # the waist, limits ±2.79 rad
    path = tmp_path / "far.csv"
    n = chain.n
    header = ",".join([f"q{i}" for i in range(1, n + 1)] + [f"qd{i}" for i in range(1, n + 1)]
                      + [f"qdd{i}" for i in range(1, n + 1)])
    np.savetxt(path, np.hstack([q, traj.qd, traj.qdd]), delimiter=",", header=header, comments="",
               fmt="%.17g")
    said = CliRunner().invoke(main, ["emulate", str(PUMA), "--trajectory", str(path)]).output
    assert "line 3 (state 2): joint 1 (waist) is outside its limits" in said
    assert said.rstrip().endswith("use --allow-out-of-limits to run anyway"), said   # (the option's)
    with pytest.raises(vampc.VampcError, match=re.escape(f"{path}: line 3 (state 2): joint 1 (waist) "
                                                         "is outside its limits")) as exc:
        vampc.read_trajectory(path, chain)
    assert str(exc.value).endswith("give allow_out_of_limits=True to run anyway")
    far = vampc.read_trajectory(path, chain, allow_out_of_limits=True)
    assert far.q[1, 0] == 100.0
    tau = vampc.emulate(ld, far).tau
    assert vampc.check_torques(chain, far, tau).ok
    with pytest.raises(vampc.VampcError, match=re.escape("check_limits: state 2: joint 1 (waist)")):
        vampc.check_limits(chain, vampc.Trajectory(q, traj.qd, traj.qdd))
    vampc.check_limits(chain, traj)
    # a caller's states are checked as emulate checks them (a list had been an AttributeError, too
    # few columns an IndexError, a NaN passed: a review's find)
    nan = traj.q.copy()
    nan[2, 3] = np.nan
    for bad, says in ((vampc.Trajectory(traj.q.tolist(), traj.qd, traj.qdd), None),
                      (vampc.Trajectory(traj.q[:, :5], traj.qd, traj.qdd), "check_limits: "),
                      (vampc.Trajectory(nan, traj.qd, traj.qdd), "check_limits: ")):
        if says is None:
            vampc.check_limits(chain, bad)          # a list is taken as an array, as emulate takes it
            continue
        with pytest.raises(vampc.VampcError, match=re.escape(says)):
            vampc.check_limits(chain, bad)


@pytest.mark.parametrize("options, words", [
    (dict(prefix="kogge-stone"), "--prefix applies to the log recursion only"),
    (dict(uniform_leaves=True), "--uniform-leaves applies to the log recursion only"),
    (dict(rounding="truncate"), "--rounding applies to fixed-point words"),
    (dict(overflow="wrap"), "--overflow applies to fixed-point words"),
    (dict(check_cycles=3), "--check-cycles applies with --error-correction"),
])
def test_a_library_callers_option_that_does_not_apply_is_refused_as_on_the_command_line(options, words):
    # (it had been taken and dropped without a word, the program file recording the default)
    chain = vampc.load_robot(PUMA)
    with pytest.raises(vampc.VampcUsageError, match=words):
        vampc.compile_chain(chain, vampc.CompileOptions(**options))
    # where it applies it is taken
    applies = {"prefix": dict(recursion="log"), "uniform_leaves": dict(recursion="log"),
               "rounding": dict(word="q16.16"), "overflow": dict(word="q16.16"),
               "check_cycles": dict(error_correction=True)}[next(iter(options))]
    vampc.compile_chain(chain, vampc.CompileOptions(**options, **applies))


def test_numpy_numbers_and_mappings_are_taken_where_python_ones_are():
    # (the first argument checks took int and float and dict only: the review's find)
    import types
    c = vampc.compile_chain(vampc.load_robot(PUMA))
    import json
    assert json.dumps(vampc.build_report(c, clock_hz=np.float32(2e7))) == \
        json.dumps(vampc.build_report(c, clock_hz=20e6))
    assert json.dumps(vampc.build_report(c, clock_hz=np.int64(20_000_000))) == \
        json.dumps(vampc.build_report(c, clock_hz=20_000_000))
    chain = vampc.load_robot(PUMA.parent / "ur5.urdf", lock=types.MappingProxyType({"wrist_3_joint": 0.0}))
    assert chain.n == 5
    assert vampc.random_trajectory(vampc.load_robot(PUMA), np.int64(2), np.int32(1)).count == 2


def test_the_exported_types_are_the_ones_the_functions_take_and_return():
    chain, ld = _puma_loaded()
    assert isinstance(ld, vampc.Loaded)
    em = vampc.emulate(ld, vampc.random_trajectory(chain, 2, 0))
    assert isinstance(em, vampc.Emulation)
    assert isinstance(vampc.random_trajectory(chain, 2, 0), vampc.Trajectory)
    assert isinstance(vampc.compile_chain(chain), vampc.Compiled)
    assert issubclass(vampc.VampcUsageError, vampc.VampcError)
    assert issubclass(vampc.VampcWarning, Warning)


@pytest.mark.parametrize("call, words", [
    (lambda c: vampc.random_trajectory(c, 2, -1), "random_trajectory: seed -1: give a seed of 0"),
    (lambda c: vampc.random_trajectory(c, 2.0, 0), "count and seed must be integers, not float"),
    (lambda c: vampc.random_trajectory(c, 2, None), "not int and NoneType"),
    (lambda c: vampc.build_report(vampc.compile_chain(c), clock_hz=0), "clock_hz 0: give a clock"),
    (lambda c: vampc.build_report(vampc.compile_chain(c), clock_hz=float("nan")), "clock_hz nan"),
    (lambda c: vampc.build_report(vampc.compile_chain(c), clock_hz=True), "clock_hz True"),
    (lambda c: vampc.random_trajectory(c, -1, 0), "random_trajectory: count -1: give 1 or more"),
    (lambda c: vampc.load_robot(PUMA.parent / "ur5.urdf", mimic="bogus"),
     "mimic 'bogus': give one of ordinary, couple"),
    (lambda c: vampc.load_robot(PUMA.parent / "ur5.urdf", lock=["j=0"]), "lock: give a mapping"),
])
def test_a_library_callers_bad_argument_is_a_vampc_error_naming_it(call, words):
    # (a ValueError from numpy's SeedSequence, a TypeError, "math domain error", an AttributeError:
    # none a VampcError, none naming the argument: a new user's finds)
    with pytest.raises(vampc.VampcError, match=re.escape(words)):
        call(vampc.load_robot(PUMA))
