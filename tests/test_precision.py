"""`vampc precision` and its analysis (vampc.precision): the bound on every register's magnitude and
on the torque error is never below what random states within the analysed ranges show, on every
example robot and both recursions; the command names the narrowest words."""
from __future__ import annotations

import re

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
from vampc.robot import load_robot

ROBOTS = ["planar2.yaml", "puma560.yaml", "stanford.yaml", "arm6.urdf", "quadruped.urdf",
          "snake64.yaml"]


# (snake64's, 4.6 s of the suite's 4 minutes, under -m slow: the run checks the other five examples)
@pytest.mark.parametrize("robot", [pytest.param(r, marks=pytest.mark.slow) if r == "snake64.yaml" else r
                                   for r in ROBOTS])
@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_the_bound_is_never_below_what_is_observed(robot, recursion):
    from vampc.robot import load_robot
    chain = load_robot(EXAMPLES / robot)
    graph = compile_chain(chain, CompileOptions(recursion=recursion)).graph
    traj = random_states(chain, 0, 120, 4)
    ref = rnea(chain, traj.q, traj.qd, traj.qdd, traj.base)
    compared = 0
    for bits, rounding in ((20, Rounding.NEAREST), (28, Rounding.TRUNCATE), (36, Rounding.NEAREST)):
        got = fitted(graph, chain, bits, rounding, Ranges())
        if got is None:           # no split of this width holds the values: nothing to compare
            continue
        compared += 1
        word, bound = got
        vals = evaluate_nodes(graph, chain, traj.q, traj.qd, traj.qdd, traj.base, arith=word)
        tau = word.decode(np.stack([vals[o.node][:, o.component] for o in graph.outputs], axis=1))
        assert word.overflows == 0
        assert np.all(np.abs(tau - ref).max(axis=0) <= bound.tau_error), word.name
        assert np.all(np.abs(ref).max(axis=0) <= bound.tau_max), word.name
        peak = max(float(np.abs(word.decode(v)).max()) for v in vals if v.dtype == np.int64)
        assert peak <= bound.peak
    # every width holds every example's values but snake64's, whose 64 joints only 36 bits hold
    assert compared == (1 if robot == "snake64.yaml" else 3)


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
    assert lines[0] == "bits,word,peak,bound,observed,overflows,rounding,note,peak_at" and len(lines) == 4
    assert all(",nearest,," in line for line in lines[1:])      # (the rounding analysed; no note)
    narrow = run(main, ["precision", str(EXAMPLES / "planar2.yaml"), "--sweep", "11:13", "--format",
                        "csv", "--sets", "20"]).output.splitlines()
    # a width no word holds the peak in says so, as the text table does (its cells had been empty)
    assert narrow[1:3] == ["11,,,,,,nearest,no qI.F of this width holds the peak,",
                          "12,,,,,,nearest,no qI.F of this width holds the peak,"] and \
        narrow[3].startswith("13,q9.4,") and ",nearest,," in narrow[3], narrow
    doc = loads(run(main, ["precision", str(EXAMPLES / "planar2.yaml"), "--sweep", "16:40",
                           "--format", "json", "--tolerance", "1e-6"]).output)
    bound = doc["narrowest_bound"]
    assert bound and all(r["bound"] > 1e-6 for r in doc["rows"] if r["word"] and
                         r["bits"] < int(bound[1:].split(".")[0]) + int(bound.split(".")[1]))


def test_the_seed_draws_emulates_random_states(tmp_path):
    """The observed errors were measured on seed 0's states only (no --seed, where emulate, faults
    and rtl have one). With --seed S they are `vampc emulate --random N --seed S`'s: the bound,
    analysed from the limits alone, is the same number of N·m whatever the states, so relative to
    each run's largest |τ| (computed here from emulate's saved states by the reference) it scales
    as those."""
    run = CliRunner().invoke
    robot = str(EXAMPLES / "planar2.yaml")
    chain = load_robot(robot)
    docs, scales = {}, {}
    for seed in (0, 3):
        res = run(main, ["precision", robot, "--sweep", "16:18", "--sets", "300", "--format", "json"]
                  + (["--seed", str(seed)] if seed else []))
        assert res.exit_code == 0, res.output
        docs[seed] = loads(res.output)
        assert (docs[seed]["seed"], docs[seed]["sets"]) == (seed, 300)
        saved = tmp_path / f"states{seed}.npy"
        res = run(main, ["emulate", robot, "--random", "300", "--seed", str(seed), "--save-states",
                         str(saved), "-o", str(tmp_path / f"tau{seed}.csv")])
        assert res.exit_code == 0, res.output
        states = np.load(saved)
        n = chain.n
        scales[seed] = float(np.abs(rnea(chain, states[:, :n], states[:, n:2 * n],
                                         states[:, 2 * n:3 * n])).max())
    assert scales[0] != scales[3]
    for r0, r3 in zip(docs[0]["rows"], docs[3]["rows"]):
        assert r0["word"] == r3["word"]
        assert r0["bound"] * scales[0] == pytest.approx(r3["bound"] * scales[3], rel=1e-12), (r0, r3)
    text = run(main, ["precision", robot, "--sweep", "16:16", "--sets", "50", "--seed", "3"]).output
    assert "of 50 random states (seed 3)" in text.splitlines()[0], text


@pytest.mark.parametrize("args, said", [
    (["--sweep", "1:70"], "--sweep 1:70: give A:B"), (["--sweep", "x"], "--sweep x: give A:B"),
    (["--tolerance", "0"], "--tolerance 0: give a positive finite number"),
    (["--acceleration", "-1"], "--acceleration -1: give a positive finite number"),
    # (the CSV is the table alone: --tolerance was taken, and changed nothing: an options audit)
    (["--tolerance", "1e-4", "--format", "csv"], "--tolerance applies with --format text or json"),
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


def _precision(*args):
    return CliRunner().invoke(main, ["precision", *map(str, args)])


def test_a_program_file_is_analysed_in_its_own_rounding(tmp_path):
    """A program compiled with --rounding truncate was analysed as rounding to nearest: its bound
    approved q10.16 at 1e-3, which the program's own rounding does not meet. Now the program's
    rounding is the default; another --rounding is a what-if, said on stderr."""
    program = tmp_path / "pt.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--word", "q10.16",
                                     "--rounding", "truncate", "-o", str(program)]).exit_code == 0
    args = ("--sweep", "26:26", "--sets", "200", "--format", "json")
    own = _precision(program, *args)
    robot = _precision(EXAMPLES / "puma560.yaml", "--rounding", "truncate", *args)
    assert own.exit_code == 0 and own.stderr == "", own.stderr
    got, want = loads(own.stdout), loads(robot.stdout)
    assert got["rounding"] == "truncate" and got["rows"] == want["rows"]
    assert got["rows"][0]["bound"] > 1e-3 and got["narrowest_bound"] is None
    what_if = _precision(program, "--rounding", "nearest", *args)
    assert what_if.exit_code == 0 and loads(what_if.stdout)["rounding"] == "nearest"
    assert "pt.vamp.json rounds by truncate; --rounding nearest analyses" in what_if.stderr
    assert loads(what_if.stdout)["rows"][0]["bound"] < got["rows"][0]["bound"]
    # --help said "[default: nearest]" (a new user read it so): it says what the run does
    helped = re.sub(r"-\s+", "-", " ".join(
        CliRunner().invoke(main, ["precision", "--help"]).stdout.split()))   # click's wrap at "-"
    assert "[default: nearest]" not in helped
    assert "Default: a fixed-point program file's own, else nearest." in helped


def test_a_robot_whose_torques_are_all_zero_is_not_said_to_have_no_mass(tmp_path):
    """A kilogram spinning on its own axis (its centre of mass on the axis, which is vertical, and
    no inertia about it): every torque is zero, and the error said the robot had no mass (a new
    user's find)."""
    spin = tmp_path / "spin.urdf"
    spin.write_text('<robot name="spin"><link name="base"/><link name="a"><inertial><origin '
                    'xyz="0 0 0.3"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                    'izz="0"/></inertial></link><joint name="spin" type="revolute"><parent '
                    'link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" '
                    'effort="10" velocity="2"/></joint></robot>')
    res = _precision(spin, "--sweep", "16:16", "--sets", "20")
    assert res.exit_code == 1
    assert res.stderr == (f"vampc: error: {spin}: every torque of the 20 random states is zero (the "
                          "joints move no mass or inertia, and hold none against gravity): errors "
                          "relative to the largest |τ| are not defined\n")


def test_a_robot_whose_reference_torques_overflow_is_said_so_not_called_massless(tmp_path):
    """A non-finite number is never a silent result (README): a link of 1e305 kg a kilometre long
    overflows the reference torques of random states, which is the error; unchecked (a mutation
    audit) the largest |τ| came out as 0, and the robot was said to move no mass."""
    huge = tmp_path / "huge.yaml"
    huge.write_text((EXAMPLES / "planar2.yaml").read_text().replace("mass: 2.0", "mass: 1.0e305")
                    .replace("a: 0.5", "a: 1000.0").replace("com: [-0.25,", "com: [-500.0,"))
    res = _precision(huge, "--sweep", "16:16", "--sets", "20")
    assert res.exit_code == 1 and res.stderr == (
        f"vampc: error: {huge}: the reference torques of random states are not finite numbers (the "
        "robot's numbers overflow a float): no word holds them\n"), res.stderr


def test_an_error_over_the_tolerance_never_prints_as_within_it():
    """q10.12's observed 1.014e-03 printed as 1.0e-03 beside a tolerance of 1e-3."""
    args = (EXAMPLES / "puma560.yaml", "--sweep", "20:26")
    text, data = _precision(*args), loads(_precision(*args, "--format", "json").stdout)
    table = [line.split() for line in text.stdout.splitlines()[2:2 + len(data["rows"])]]
    for cells, row in zip(table, data["rows"]):
        for shown, value in ((cells[3], row["bound"]), (cells[4], row["observed"])):
            assert (float(shown) <= 1e-3) == (value <= 1e-3), (shown, value)
    assert any(abs(float(c[4]) - 1e-3) < 1e-4 for c in table)      # (the case that was wrong)


def test_a_massless_robot_and_the_widest_sweep_are_said_as_they_are(tmp_path):
    massless = tmp_path / "massless.yaml"
    massless.write_text("name: massless\njoints:\n" + "  - {type: revolute, a: 0.5, alpha: 0, d: 0, "
                        "theta: 0, mass: 0, com: [0,0,0], inertia: [0,0,0,0,0,0]}\n" * 2)
    res = _precision(massless, "--sweep", "16:18", "--sets", "20")
    assert res.exit_code == 1 and res.stderr == (          # (the robot file's own warning first)
        f"vampc: warning: {massless}: every joint's link has mass 0 and inertia 0: every body is "
        "massless, so every torque is zero but for the tip's load\n"
        f"vampc: error: {massless}: every torque of the 20 random states is zero (the joints move no "
        "mass or inertia, and hold none against gravity): errors relative to the largest |τ| are "
        "not defined\n")
    big = tmp_path / "big.yaml"
    big.write_text((EXAMPLES / "planar2.yaml").read_text().replace("a: 0.5", "a: 1e12"))
    res = _precision(big, "--sweep", "2:64", "--sets", "20")
    assert res.exit_code == 0 and res.stdout.splitlines()[-2:] == [
        "narrowest word meeting 0.001 by the analysed bound, with no possible overflow: none of up "
        "to 64 bits", "narrowest word observed within 0.001 (among those): none of up to 64 bits"]


def test_the_states_are_taken_in_chunks_with_the_same_figures(monkeypatch):
    """Every op's value of every set at once took 15 kB a set for the Puma (--sets 10000000 went
    past 22 GB, a new user's run): the states go through in chunks, and the figures (the largest
    error and |τ| over all the sets, the overflows) are those of one chunk of them all, here in
    chunks of 7 sets and a last of 5; and in words of 4 integer bits fewer than the analysis asks
    for, whose overflows (the constants' among them, which the host writes once a run) add up."""
    from vampc import commands, precision
    from vampc.machine.arith import Fixed
    args = ["precision", str(EXAMPLES / "planar2.yaml"), "--sets", "47", "--sweep", "13:16",
            "--format", "json"]
    nodes = len(compile_chain(load_robot(str(EXAMPLES / "planar2.yaml")), CompileOptions()).graph.nodes)
    right = precision.fitted
    narrow = lambda *a: (lambda w, an: (Fixed(w.integer - 4, w.fraction + 4, w.rounding), an))(   # noqa: E731
        *right(*a))
    runs = []
    for fit in (right, narrow):
        monkeypatch.setattr(precision, "fitted", fit)
        for chunk in (1 << 40, 72 * nodes * 7):
            monkeypatch.setattr(commands, "PRECISION_CHUNK_BYTES", chunk)
            r = CliRunner().invoke(main, args)
            assert r.exit_code == 0, r.output
            runs.append(r.stdout)
    assert runs[0] == runs[1] and runs[2] == runs[3]
    overflows = [row["overflows"] for row in loads(runs[2])["rows"]]
    assert all(n > 0 for n in overflows) and overflows != [row["overflows"] for row in loads(runs[0])["rows"]]


@pytest.mark.parametrize("change, says", [
    # the robot edited, its checksum made again: observed 3.4e-01 against bounds down to 7.7e-03,
    # exit 0 ("the bound is never below an observation")
    (lambda d: d["robot"]["joints"][0].update(mass=5.0),
     r"the program's graph misses its robot's dynamics: in float64 its torques differ "
     r"from the reference Newton-Euler's by \S+ of the largest \|τ\| \(random state \d+, joint \d\)"),
    # an output read at the wrong tick: refused by report and emulate, analysed by precision
    (lambda d: d["io"]["outputs"][0].update(tick=28), r"τ1 is read from VAMP \d+ .* at tick 28"),
])
def test_an_edited_program_file_is_refused_as_report_and_emulate_refuse_it(tmp_path, change, says):
    """(A new user's finds.) The file's network is checked as `vampc emulate` checks it, and its
    graph against its robot, in float64, before any word is measured."""
    from program_util import edited_program
    program = tmp_path / "p.vamp.json"
    assert _precision_compile(program).exit_code == 0
    edited = edited_program(program, tmp_path, change)
    r = CliRunner().invoke(main, ["precision", str(edited), "--sweep", "16:16", "--sets", "20"])
    assert r.exit_code == 1 and re.match(rf"vampc: error: {re.escape(str(edited))}: {says}", r.output), r.output
    assert len(r.output.strip().splitlines()) == 1
    ok = CliRunner().invoke(main, ["precision", str(program), "--sweep", "16:16", "--sets", "20"])
    assert ok.exit_code == 0, ok.output


def _precision_compile(program):
    return CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "-o", str(program)])


def test_an_acceleration_past_the_float_range_is_no_word_without_a_numpy_warning():
    """--acceleration 1e300: the analysis overflows a float, so no width holds the peak; NumPy's
    own 'RuntimeWarning: overflow encountered in dot' was printed as vampc's warning."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("always")      # (shown once a place by default: an earlier test's
        r = CliRunner().invoke(main, ["precision", str(EXAMPLES / "planar2.yaml"),  # run hid it)
                                      "--acceleration", "1e300", "--sweep", "20:21", "--sets", "10"])
    assert r.exit_code == 0 and not r.stderr, r.output
    assert r.stdout.count("too narrow: no qI.F of this width holds the peak") == 2


def test_a_narrowest_word_at_the_sweeps_first_width_says_a_narrower_one_may_meet_it_too():
    """--sweep 30:34 named q10.20 (30 bits) the narrowest word meeting 1e-3 for the Puma, where the
    default sweep names q10.16 by the bound and a narrower one by observation: the widths below the
    sweep were not tried. A narrowest word at the sweep's first width says so (the text, and the
    JSON's at_sweep_start); one above it (q10.16 in 20:30) does not."""
    robot = EXAMPLES / "puma560.yaml"
    text = _precision(robot, "--sweep", "30:34", "--sets", "200").stdout.splitlines()
    said = ", the sweep's narrowest: a narrower word may meet it too (widen --sweep)"
    assert text[-2:] == [
        "narrowest word meeting 0.001 by the analysed bound, with no possible overflow: q10.20 "
        "(30 bits)" + said, "narrowest word observed within 0.001 (among those): q10.20 (30 bits)"
        + said], text
    doc = loads(_precision(robot, "--sweep", "30:34", "--sets", "200", "--format", "json").stdout)
    assert (doc["narrowest_bound"], doc["narrowest_observed"]) == ("q10.20", "q10.20")
    assert doc["at_sweep_start"] == {"bound": True, "observed": True}
    doc = loads(_precision(robot, "--sweep", "20:30", "--sets", "200", "--format", "json").stdout)
    assert doc["narrowest_bound"] == "q10.16" and doc["rows"][0]["bits"] == 20
    assert doc["at_sweep_start"] == {"bound": False, "observed": False}, doc["narrowest_observed"]
    text = _precision(robot, "--sweep", "20:30", "--sets", "200").stdout
    assert "q10.16 (26 bits)\n" in text and "the sweep's narrowest" not in text


def test_the_states_analysed_are_said_with_the_answer(tmp_path):
    """The narrowest word holds for the states analysed only: --acceleration moved the Puma's from
    q10.16 to q12.17, and neither the text nor the JSON said the acceleration, nor that the Puma
    file has no speed limit, so ±1 was taken (a new user's). A joint given a speed limit is
    analysed within it; the others are named."""
    run = CliRunner().invoke
    res = run(main, ["precision", str(EXAMPLES / "puma560.yaml"), "--sweep", "26:27", "--sets", "20",
                     "--acceleration", "20"])
    assert res.exit_code == 0, res.output
    assert re.search(
        r"random states, [0-9.e+]+ \(N·m or N\); states analysed: positions within their limits; "
        r"speeds within ±1 \(the robot file gives no joint a limit\); accelerations within ±20 "
        r"\(--acceleration\)$", res.output.splitlines()[0]), res.output
    dh = tmp_path / "p.yaml"          # (the elbow without a speed limit)
    dh.write_text((EXAMPLES / "planar2.yaml").read_text().replace("qd: 3.0, tau: 25.0", "tau: 25.0"))
    res = run(main, ["precision", str(dh), "--sweep", "20:20", "--sets", "20"])
    assert res.output.splitlines()[0].endswith(
        "states analysed: positions within their limits; speeds within their limits, else ±1 "
        "(joint elbow: no limit given); accelerations within ±1 (--acceleration)"), res.output
    doc = loads(run(main, ["precision", str(EXAMPLES / "ur5.urdf"), "--sweep", "30:30", "--sets",
                           "20", "--format", "json"]).output)
    assert doc["states"] == {"acceleration": 1.0, "no_position_limit": [], "no_speed_limit": [],
                             "floating_base": False, "coupled": []}


MIMIC_8 = """<robot name="mim">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><origin xyz="0.1 0 0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><mass value="1"/><origin xyz="0.1 0 0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0"/><axis xyz="0 1 0"/><limit lower="-0.2" upper="0.2" effort="10" velocity="0.1"/><mimic joint="j1" multiplier="8" offset="0.1"/></joint>
</robot>"""


def test_a_coupled_follower_is_analysed_as_its_leader_moves_it(tmp_path):
    """With --mimic couple the random states move a follower at its leader's times the multiplier,
    its own limits aside, but the analysis took its own limits: a follower at 8 times its leader
    gave a bound of 7.2e-4 beside an observed 0.33, and 517 overflows in the word named as holding
    every value (an independent check's find). Every width's bound is now at least what is
    observed, with no overflow, and the states line names the follower."""
    robot = tmp_path / "mim.urdf"
    robot.write_text(MIMIC_8)
    res = CliRunner().invoke(main, ["precision", str(robot), "--mimic", "couple", "--sweep", "10:30",
                                    "--sets", "500", "--format", "json"])
    assert res.exit_code == 0, res.output
    doc = loads(res.output)
    rows = [r for r in doc["rows"] if r["word"]]
    assert len(rows) > 10 and all(r["observed"] <= r["bound"] and r["overflows"] == 0 for r in rows), rows
    assert doc["states"]["coupled"] == ["j2"]
    text = CliRunner().invoke(main, ["precision", str(robot), "--mimic", "couple", "--sweep", "20:20",
                                     "--sets", "20"]).output
    assert text.splitlines()[0].endswith("accelerations within ±1 (--acceleration); the coupled joint "
                                         "j2 as its leader moves it, whatever its own limits"), text


def test_the_summary_says_which_value_sets_the_peak():
    """The peak fixes the integer bits, but precision did not say which quantity it is (a new user
    asked, of a UR5's 1 025 and a humanoid's 24 000). The value named is a node of the graph whose
    observed float64 values stay within the peak, in text, JSON and CSV alike. On planar2 it is the
    base joint's force f (fwd1.f): it carries both links' weight and motion (and grows along the
    forward pass, which adds each link's force to the next one's)."""
    import json
    chain = load_robot(EXAMPLES / "planar2.yaml")
    graph = compile_chain(chain).graph
    run = CliRunner().invoke
    args = ["precision", str(EXAMPLES / "planar2.yaml"), "--sweep", "24:26"]
    rows = json.loads(run(main, [*args, "--format", "json"]).output)["rows"]
    assert {r["peak_at"] for r in rows} == {"f of the forward pass's node 1 (fwd1.f)"}
    node = next(nd for nd in graph.nodes if nd.label == "fwd1.f")
    traj = random_states(chain, 0, 200, 4)
    seen = np.abs(evaluate_nodes(graph, chain, traj.q, traj.qd, traj.qdd, traj.base)[node.id]).max()
    assert 0 < seen <= min(r["peak"] for r in rows)
    text = run(main, args).output
    assert "peak: the bound of f of the forward pass's node 1 (fwd1.f)\n" in text
    import csv
    table = list(csv.DictReader(run(main, [*args, "--format", "csv"]).output.splitlines()))
    assert [r["peak_at"] for r in table] == [r["peak_at"] for r in rows]
    # where the value changes with the width, each is said with its widths (", of n ... in narrower
    # words" read as both at once: a new user's find); the UR5's narrowest word's peak is n's
    ur5 = json.loads(run(main, ["precision", str(EXAMPLES / "ur5.urdf"), "--sweep", "17:19",
                                "--format", "json"]).output)["rows"]
    places = [r["peak_at"] for r in ur5]
    assert places[0] != places[1] == places[2]
    text = run(main, ["precision", str(EXAMPLES / "ur5.urdf"), "--sweep", "17:19"]).output
    assert f"peak: the bound of {places[0]} at 17 bits; of {places[1]} at 18 to 19 bits\n" in text


SPINDLE = """<robot name="spindle">
  <link name="base"/>
  <joint name="a1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="2" effort="100"/></joint>
  <link name="l1"><inertial><origin xyz="0.2 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="spin" type="revolute"><parent link="base"/><child link="rotor"/><origin xyz="100 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="10000" effort="100"/></joint>
  <link name="rotor"><inertial><origin xyz="0.01 0 0"/><mass value="1"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
</robot>
"""


def test_the_log_recursions_rounding_on_a_far_fast_branch_is_not_called_an_edit(tmp_path):
    """A rotor 100 m from the base spinning at up to 10 000 rad/s: the log recursion's forward pass
    sums forces about the base and loses digits (README, The log recursion's rounding on trees). The
    program, just compiled, had been said to be an edited file (an audit's)."""
    robot = tmp_path / "spindle.urdf"
    robot.write_text(SPINDLE)
    program = tmp_path / "sp.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(robot), "--recursion", "log", "-o", str(program)]).exit_code == 0
    r = CliRunner().invoke(main, ["precision", str(program)])
    assert r.exit_code == 1 and len(r.output.strip().splitlines()) == 1, r.output
    assert "the log recursion's float64 rounding (it sums forces and moments about the base" in r.output
    assert "compare --recursion linear" in r.output
    # the linear recursion computes it within 1e-9: no such refusal
    linear = tmp_path / "lin.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(robot), "-o", str(linear)]).exit_code == 0
    r = CliRunner().invoke(main, ["emulate", str(linear), "--random", "100", "--check"])
    assert r.exit_code == 0 and ": OK" in r.output, r.output


FAR_MASS = """name: farcom2
gravity: [0.0, 0.0, 0.0]
tip: {force: [-10.0, 5.0, 5.0], torque: [0.0, 0.0, 0.0]}
joints:
  - {name: a, type: revolute, a: 0.3, alpha: 1.5707963267948966, d: 0.0, theta: 0.0, mass: 0.0,
     com: [0.0, 0.0, 0.0], inertia: [0, 0, 0, 0, 0, 0]}
  - {name: b, type: revolute, parent: 0, a: 0.0, alpha: 0.0, d: 0.2, theta: 0.0, mass: 1.0e-6,
     com: [1000.0, 1000.0, -1000.0], inertia: [0, 0, 0, 0, 0, 0], limits: {q: [-1.0, 1.0], qd: 5.0}}
"""


def test_a_failed_float64_check_names_the_log_recursions_rounding_on_the_set_it_failed(tmp_path):
    """A mass 1.7 km from the base on a two-branch tree with a tip load: one set of 1000, whose
    torques are small (5.4e-4 against the run's 2.0), misses the reference by 4.0e-9 of its own largest
    |τ| on the log recursion, and emulate's --check failed saying nothing of why: the graph had been
    tried on 16 other states against their largest |τ| alone (a fuzz audit's). Now tried on the set
    the check found worst too, each set against its own. The linear recursion passes."""
    robot = tmp_path / "farcom2.yaml"
    robot.write_text(FAR_MASS)
    args = ["emulate", str(robot), "--random", "1000", "--check"]
    r = CliRunner().invoke(main, [*args, "--recursion", "log"])
    assert r.exit_code == 1 and "tolerance 1e-9: FAILED (the program's graph differs from the reference " \
        "Newton-Euler's by" in r.output, r.output
    assert "of a set's largest |τ| too: the log recursion's float64 rounding" in r.output
    assert CliRunner().invoke(main, args).exit_code == 0


def test_a_robot_compiled_in_the_run_is_not_told_to_be_compiled_again(tmp_path):
    """The hint after a failed check named an edited file and "Compile the robot again" where the
    command had just compiled the robot file itself (a new user's); a program file still hears it."""
    robot = tmp_path / "farcom2.yaml"
    robot.write_text(FAR_MASS)
    r = CliRunner().invoke(main, ["emulate", str(robot), "--recursion", "log", "--random", "1000", "--check"])
    assert r.exit_code == 1 and "the log recursion's float64 rounding" in r.output, r.output
    assert "edited" not in r.output and "Compile the robot again" not in r.output, r.output
    program = tmp_path / "fc.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(robot), "--recursion", "log", "-o", str(program)]).exit_code == 0
    r = CliRunner().invoke(main, ["emulate", str(program), "--random", "1000", "--check"])
    assert r.exit_code == 1 and "or was the file's robot or graph edited? Compile the robot again" in r.output


def test_the_errors_yardstick_is_said_here_and_by_a_failed_check(tmp_path):
    """A new user's: the word `precision` chose at 1e-3 failed `emulate --check` at 1e-3 on an arm
    holding still, since precision's errors are relative to the largest |τ| of its random states
    and the check's to its run's. Precision gives its yardstick (JSON `tau_max`, and in its text's
    first line); a failed check says its own and how the two tolerances compare."""
    chain = load_robot(EXAMPLES / "planar2.yaml")
    traj = random_states(chain, 0, 300, 0)          # emulate --random's, as precision draws them
    want = float(np.abs(rnea(chain, traj.q, traj.qd, traj.qdd)).max())
    got = _precision(EXAMPLES / "planar2.yaml", "--sets", "300", "--sweep", "20:20", "--format",
                     "json")
    assert got.exit_code == 0 and loads(got.stdout)["tau_max"] == want
    text = _precision(EXAMPLES / "planar2.yaml", "--sets", "300", "--sweep", "20:20")
    assert f"errors relative to the largest |τ| of 300 random states, {want:.4g} (N·m or N); " \
        in text.stdout, text.stdout
    program = tmp_path / "p.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q8.8",
                                     "-o", str(program)]).exit_code == 0
    still = tmp_path / "still.csv"                  # held near hanging down: small torques
    still.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n" + "".join(
        f"{-1.5 + k * 1e-3},0.01,0,0,0,0\n" for k in range(20)))
    q = np.array([[-1.5 + k * 1e-3, 0.01] for k in range(20)])
    scale = float(np.abs(rnea(chain, q, np.zeros_like(q), np.zeros_like(q))).max())
    r = CliRunner().invoke(main, ["emulate", str(program), "--trajectory", str(still), "--check"])
    assert r.exit_code == 1 and ": FAILED (a wider --word would do better; `vampc precision` finds " \
        "one, but its tolerance is relative to the largest |τ| of random states over the joint " \
        f"ranges, this check's to this run's, {scale:.4g}: for a run of smaller torques, scale its " \
        "tolerance down by the ratio)" in r.stdout, r.output
