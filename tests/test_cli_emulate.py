"""`vampc emulate` from the command line: formats, checks, bad input, no partial output files."""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from program_util import edited_program

from vampc.cli import main
from vampc.dynamics.reference import rnea
from vampc.robot import load_robot
from vampc.robot.random import random_state

EXAMPLES = Path(__file__).parent.parent / "examples"
ERROR = re.compile(r"^vampc: error: [^\n]+\n$")


def _run(*args):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    path = tmp_path_factory.mktemp("prog") / "planar.vamp.json"
    assert _run("compile", EXAMPLES / "planar2.yaml", "-o", path).exit_code == 0
    return path


@pytest.fixture(scope="module")
def states():
    chain = load_robot(EXAMPLES / "planar2.yaml")
    return chain, random_state(chain, 25, 4)


def _csv(path, q, qd, qdd, t=None):
    n = q.shape[1]
    head = ([] if t is None else ["t"]) + [f"{p}{i}" for p in ("q", "qd", "qdd") for i in range(1, n + 1)]
    body = np.hstack(([] if t is None else [t[:, None]]) + [q, qd, qdd])
    path.write_text(",".join(head) + "\n" + "\n".join(",".join(repr(float(x)) for x in r) for r in body) + "\n")
    return path


def _read_tau(path, t=None) -> np.ndarray:
    lines = Path(path).read_text().splitlines()
    # planar2's joint names, in order; the trajectory's t column is carried over
    assert lines[0] == ("t," if t is not None else "") + "tau_shoulder,tau_elbow"
    data = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    if t is not None:
        assert np.array_equal(data[:, 0], t)
        data = data[:, 1:]
    return data


def test_trajectory_csv_gives_reference_torques(tmp_path, program, states):
    chain, (q, qd, qdd) = states
    out = tmp_path / "tau.csv"
    res = _run("emulate", program, "--trajectory", _csv(tmp_path / "t.csv", q, qd, qdd), "-o", out, "--check")
    assert res.exit_code == 0, res.output
    assert "OK" in res.output and "one every 4 flops" in res.output
    assert np.allclose(_read_tau(out), rnea(chain, q, qd, qdd), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("fmt", ["csv-t", "npy", "npy-t", "npz"])
def test_trajectory_formats_agree(tmp_path, program, states, fmt):
    chain, (q, qd, qdd) = states
    t = np.arange(len(q)) * 0.01
    if fmt == "csv-t":
        src = _csv(tmp_path / "t.csv", q, qd, qdd, t)
    elif fmt.startswith("npy"):
        src = tmp_path / "t.npy"
        np.save(src, np.hstack(([t[:, None]] if fmt == "npy-t" else []) + [q, qd, qdd]))
    else:
        src = tmp_path / "t.npz"
        np.savez(src, q=q, qd=qd, qdd=qdd, t=t)
    out = tmp_path / "tau.csv"
    assert _run("emulate", program, "--trajectory", src, "-o", out).exit_code == 0
    tau = _read_tau(out, None if fmt == "npy" else t)
    assert np.allclose(tau, rnea(chain, q, qd, qdd), rtol=1e-12, atol=1e-12)


def test_robot_file_compiled_on_the_fly_and_tick_vcd(tmp_path):
    vcd = tmp_path / "w.vcd"
    res = _run("emulate", EXAMPLES / "planar2.yaml", "--random", 5, "--engine", "tick", "--vcd", vcd,
               "--check")
    assert res.exit_code == 0, res.output
    text = vcd.read_text()
    assert text.count("$var real 64") == 3 * text.count("$scope module vamp")
    assert "$enddefinitions $end" in text and re.search(r"^#\d+$", text, re.M)


def _bad(tmp_path, text, name="bad.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize("body,message", [
    ("q1,q2,qd1,qd2,qdd1\n1,2,3,4,5\n", r"header: 5 columns, expected 6 \(expected 6 columns "
     r"q1,q2...qdd2: the program is for 2 joints\)$"),
    ("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,x,0,0,0\n", r"line 2, column qd1: 'x' is not a number"),
    # float() (and np.loadtxt) read non-ASCII digits and spaces: they ran as 1
    ("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,\u0661,0,0,0\n", r"line 2, column qd1: '\u0661' is not a number"),
    ("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,\uff11,0,0,0\n", r"line 2, column qd1: '\uff11' is not a number"),
    ("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,nan,0,0,0\n", r"line 2 \(state 1\), column qd1: nan is not finite"),
    ("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,0,0,0\n", r"line 2: 5 columns, expected 6"),
    ("q1,q2,qd1,qd2,qdd1,qdd2\n", r"no states"),
    ("q1,q2,qd1,qd2,qdd1,qdd2\n9,0,0,0,0,0\n", r"line 2 \(state 1\): joint 1 \(.*\) is outside its limits: "
     r"position 9 above \S+ \(limits q in \[-\S+, \S+\], \|qd\| <= \S+\)"),
    # (which limit, said: a new user compared the numbers by hand, each time a speed limit)
    ("q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,99,0,0\n", r"line 2 \(state 1\): joint 2 \(.*\) is outside its limits: "
     r"speed \|qd\| = 99 beyond \S+ \(limits q in \[\S+, \S+\], \|qd\| <= \S+\)"),
    # (value and limit with the digits that tell them apart: 'speed 3 beyond 3', a review's find)
    ("q1,q2,qd1,qd2,qdd1,qdd2\n0,0,3.0000000001,0,0,0\n", r"joint 1 \(.*\) is outside its limits: "
     r"speed \|qd\| = 3\.0000000001 beyond 3 \("),
])
def test_bad_trajectory(tmp_path, program, body, message):
    out = tmp_path / "tau.csv"
    res = _run("emulate", program, "--trajectory", _bad(tmp_path, body), "-o", out)
    assert res.exit_code == 1
    assert ERROR.match(res.output) and re.search(message, res.output), res.output
    assert "bad.csv" in res.output and not out.exists()
    assert list(tmp_path.iterdir()) == [tmp_path / "bad.csv"]


@pytest.mark.parametrize("name, content, message", [
    # np.load read any file as a pickle, and its refusal said "it holds Python objects"
    ("g.npy", b"hello", r"not a numpy \.npy array file \(it does not start as numpy writes one: b'hello'\)"),
    ("g.npz", b"q1,q2,qd1", r"not a numpy \.npz archive \(it does not start as numpy writes one"),
    ("e.npy", b"", r"not a numpy \.npy array file .*, empty\)"),
])
def test_a_file_that_is_no_numpy_file_says_so(tmp_path, program, name, content, message):
    path = tmp_path / name
    path.write_bytes(content)
    res = _run("emulate", program, "--trajectory", path)
    assert res.exit_code == 1 and re.search(message, res.output), res.output


def test_data_after_a_npy_array_is_refused(tmp_path, program):
    """The bytes numpy would leave unread after the array its header announces (two files joined,
    damage) were dropped without a word."""
    saved = tmp_path / "s.npy"
    assert _run("emulate", program, "--random", 5, "--save-states", saved).exit_code == 0
    joined = tmp_path / "joined.npy"
    joined.write_bytes(saved.read_bytes() + bytes(48))
    res = _run("emulate", program, "--trajectory", joined)
    assert res.exit_code == 1 and re.search(r"its header announces an array of shape \(5, 6\) \(240 bytes\) "
                                            r"but the file holds 288 bytes of data \(damaged, or another "
                                            r"file after it\)", res.output), res.output
    assert _run("emulate", program, "--trajectory", saved).exit_code == 0


def test_out_of_limits_allowed_on_request(tmp_path, program):
    src = _bad(tmp_path, "q1,q2,qd1,qd2,qdd1,qdd2\n9,0,0,0,0,0\n")
    assert _run("emulate", program, "--trajectory", src, "--allow-out-of-limits", "--check").exit_code == 0


@pytest.mark.parametrize("change,fix,message", [
    (lambda d: d["programs"][0]["slots"][0].update(delay_a=1), False, r"checksum mismatch"),
    (lambda d: d.pop("io"), True, r"document: object missing required field `io`"),
    (lambda d: d.update(version=7), True, r"version 7 is not supported"),
    (lambda d: d["network"]["vamps"][0]["a"][0].__setitem__(0, ["vamp", 999, 0]), True,
     r"VAMP 0: operand A is wired to a missing vamp 999"),
    # a stage on a tap other than a buffer's, and a fractional control field: the emulator read
    # neither (the stage is not used, int() took 4097.5 as 4097), so both went unseen
    (lambda d: d["network"]["vamps"][1]["a"][0][0].__setitem__(2, 999), True,
     r"VAMP 1: operand A is wired to \w+ \d+ at stage 999 \(only a buffer has stages\)"),
    (lambda d: d["program_stream"][0]["words"][0].__setitem__(1, d["program_stream"][0]["words"][0][1] + 0.5),
     True, r"program stream of \w+ \d+, word 0: scalar \d+\.5 is not an integer"),
    # scalar 1, the VAMP number, likewise: it was said to match no VAMP on the path (a new user's)
    (lambda d: d["program_stream"][0]["words"][0].__setitem__(0, d["program_stream"][0]["words"][0][0] + 1e-7),
     True, r"program stream of \w+ \d+, word 0: scalar 1\.0000001 is not an integer \(every scalar"),
    # a scalar beyond the packing: 1e300 unpacked into a 300-digit delay-R, which the error printed
    # whole (424 characters: a new user's find)
    (lambda d: d["program_stream"][0]["words"][0].__setitem__(2, 1e300), True,
     r"program stream of \w+ \d+, word 0: scalar 1e\+300 does not fit in a 25-bit Program-Mode "
     r"word \(at most 16777215 in magnitude, as this program packs them\)$"),
    # (an integer just past the packing read "1.67772e+07": a hardware audit)
    (lambda d: d["program_stream"][0]["words"][0].__setitem__(2, 16777216.0), True,
     r"program stream of \w+ \d+, word 0: scalar 16777216 does not fit in a 25-bit Program-Mode "
     r"word \(at most 16777215 in magnitude, as this program packs them\)$"),
    # (VAMP 0's delays edited, word and listing: it was said as VAMP 1's operand A re-latched;
    # the VAMP edited is named since 2026-12-07, a new user's find)
    (lambda d: (d["program_stream"][0]["words"][0].__setitem__(1, 3.0),
                d["programs"][d["program_stream"][0]["targets"][0]]["slots"][0].update(delay_a=0,
                                                                                     delay_b=3)),
     True,
     r"VAMP 0 \(number 1, bwd1\.T2\): delay-B 3 latches operand B at counter 3, the schedule has "
     r"tick 0 \(counter 0\)$"),
    # operand B wired to a later VAMP: said of operand A alone, a field the user never touched (a
    # new user's find); the later operand is named
    (lambda d: d["network"]["vamps"][1].update(b=[[["vamp", 2, 0]]]), True,
     r"VAMP 1 \(number 2, bwd1\.omega\): operand A latched at tick 1 is re-latched at tick 5, "
     r"before the micro-step at tick 6 that still reads it \(delay-R 3; the op waits for operand B, "
     r"latched at tick 5\)$"),
])
def test_bad_program_file(tmp_path, program, change, fix, message):
    out = tmp_path / "tau.csv"
    res = _run("emulate", edited_program(program, tmp_path, change, fix), "--random", 3, "-o", out)
    assert res.exit_code == 1
    assert ERROR.match(res.output) and re.search(message, res.output), res.output
    assert not out.exists()


def test_not_json(tmp_path):
    res = _run("emulate", _bad(tmp_path, "{oops", "x.vamp.json"), "--random", 2)
    assert res.exit_code == 1 and ERROR.match(res.output) and "invalid JSON" in res.output


def test_failed_tick_run_leaves_no_vcd(tmp_path, program):
    def slow_clock(d):   # a delay the static check would refuse, run through the tick engine
        d["programs"][0]["delay_r"] = 0
    edited = edited_program(program, tmp_path, slow_clock)
    vcd = tmp_path / "w.vcd"
    res = _run("emulate", edited, "--random", 2, "--engine", "tick", "--vcd", vcd)
    assert res.exit_code in (0, 1)
    assert vcd.exists() == (res.exit_code == 0)
    assert not any(p.name.startswith(".w.vcd") for p in tmp_path.iterdir())


@pytest.mark.parametrize("args", [
    ["--random", "3", "--trajectory", "x.csv"], [], ["--random", "3", "--vcd", "w.vcd"],
])
def test_usage_errors_exit_2(program, args):
    assert _run("emulate", program, *args).exit_code == 2


def test_help_explains():
    res = _run("emulate", "--help")
    assert res.exit_code == 0 and "--check" in res.output and "bit for bit" in res.output


def test_a_run_that_writes_no_torques_says_so(program, tmp_path):
    """`emulate P --random 3` computed torques and wrote none, saying nothing (the help says it
    returns torques: a new user's find): a note on stderr, not a warning, where no -o, --save-states,
    --check or --vcd is given; -o's help says so."""
    note = "no torques written: give -o FILE (or -o - for standard output)"
    res = CliRunner().invoke(main, ["emulate", str(program), "--random", "3"])
    assert res.exit_code == 0 and res.stderr == note + "\n", res.stderr
    assert res.stdout.startswith("stream engine: 3 torque sets"), res.stdout
    for args in (["-o", tmp_path / "tau.csv"], ["-o", "-"], ["--save-states", tmp_path / "s.csv"],
                 ["--check"], ["--engine", "tick", "--vcd", tmp_path / "w.vcd"]):
        res = CliRunner().invoke(main, ["emulate", str(program), "--random", "3", *map(str, args)])
        assert res.exit_code == 0 and "no torques written" not in res.output, (args, res.output)
    helped = " ".join(_run("emulate", "--help").stdout.split())
    assert "Without -o no torques are written" in helped


def test_burned_in_numbering_keeps_chips_interchangeable(tmp_path, states):
    # Same network, VAMP numbers shuffled: the program stream changes, the torques do not.
    chain, (q, qd, qdd) = states
    plain, shuffled = tmp_path / "plain.vamp.json", tmp_path / "shuffled.vamp.json"
    assert _run("compile", EXAMPLES / "planar2.yaml", "-o", plain).exit_code == 0
    count = len(json.loads(plain.read_text())["network"]["vamps"])
    numbers = np.random.default_rng(0).permutation(np.arange(1000, 1000 + count))
    (tmp_path / "numbers.txt").write_text("# burned in\n" + "\n".join(map(str, numbers)) + "\n")
    assert _run("compile", EXAMPLES / "planar2.yaml", "-o", shuffled, "--numbering",
                tmp_path / "numbers.txt").exit_code == 0
    doc = json.loads(shuffled.read_text())
    assert [v["number"] for v in doc["network"]["vamps"]] == numbers.tolist()
    src = _csv(tmp_path / "t.csv", q, qd, qdd)
    for prog in (plain, shuffled):
        out = tmp_path / f"{prog.stem}.csv"
        assert _run("emulate", prog, "--trajectory", src, "-o", out, "--engine", "tick").exit_code == 0
    assert (tmp_path / "plain.vamp.csv").read_text() == (tmp_path / "shuffled.vamp.csv").read_text()


def test_other_latencies_emulate_exactly(tmp_path):
    prog = tmp_path / "slow.vamp.json"
    assert _run("compile", EXAMPLES / "planar2.yaml", "--mult-latency", 3, "--add-latency", 2, "-o",
                prog).exit_code == 0
    for engine in ("stream", "tick"):
        res = _run("emulate", prog, "--random", 30, "--engine", engine, "--check")
        assert res.exit_code == 0 and "OK" in res.output, res.output


def test_programs_listing_must_match_the_stream(tmp_path, program):
    res = _run("emulate", edited_program(program, tmp_path,
                                         lambda d: d["programs"][2]["slots"][0].update(rom=0,
                                                                                      op="VA")),
               "--random", 2)
    assert res.exit_code == 1 and ERROR.match(res.output)
    assert re.search(r"programs\[2\] slot 0 lists rom 0 but the program stream delivers 2",
                     res.output), res.output


def test_internal_error_asks_for_a_report(monkeypatch):
    # (the bug is put in report_command, which the command imports as it runs: put in
    # vampc.compiler.compile_chain, it stayed in every module first imported meanwhile that binds
    # the name (vampc.report.compare), and later tests of the same pytest worker failed with it)
    import vampc.commands
    def boom(*a, **k):
        raise RuntimeError("simulated bug")
    monkeypatch.setattr(vampc.commands, "report_command", boom)
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml")])
    assert res.exit_code == 3
    assert "this is a bug in vampc" in res.output and "RuntimeError: simulated bug" in res.output


def test_default_output_name_keeps_inner_dots(tmp_path, monkeypatch):
    src = tmp_path / "my.robot.yaml"
    src.write_text((EXAMPLES / "planar2.yaml").read_text())
    monkeypatch.chdir(tmp_path)
    assert _run("compile", src).exit_code == 0
    assert (tmp_path / "my.robot.vamp.json").exists()


def test_messages_a_new_user_read_wrongly(tmp_path):
    """A switch is named as given (it said '--error-correction True: ... compiled with
    --error-correction False'); one set is 'torque set'; a 64-bit word that fails its check for want
    of fraction bits is not told to widen."""
    prog = tmp_path / "q.vamp.json"
    assert _run("compile", EXAMPLES / "planar2.yaml", "--word", "q16.16", "-o", prog).exit_code == 0
    res = _run("emulate", prog, "--random", 2, "--error-correction")
    assert res.exit_code == 2 and f"--error-correction: {prog} was compiled with no " \
        "--error-correction;" in res.output and "True" not in res.output, res.output
    res = _run("emulate", prog, "--random", 1)
    assert res.exit_code == 0 and "stream engine: 1 torque set;" in res.output, res.output
    res = _run("emulate", prog, "--random", 20, "--word", "q64.0", "--check")
    assert res.exit_code == 1 and "64 bits is the widest word" in res.output, res.output
    # overflows: more integer bits, not a wider word (q2.62 was told to widen; an audit's)
    for word, fewer in (("q2.62", " and fewer for the fraction (64 bits is the widest)"),
                        ("q2.30", ""), ("q1.15", "")):       # ("the word's 1 integer bits")
        bits = "1 integer bit" if word == "q1.15" else "2 integer bits"
        res = _run("emulate", prog, "--random", 3, "--word", word, "--check")
        assert res.exit_code == 1 and f"overflows: FAILED (the values outgrew the word's {bits}: " \
            f"a word with more of them{fewer} would hold them; `vampc precision` finds " \
            "one)" in res.output and "wider --word" not in res.output, res.output


def test_a_failed_float64_check_of_an_edited_robot_says_why(tmp_path):
    """A float64 program whose robot mass was edited (checksum made again) failed its check with
    nothing said, emulate and lookahead alike; precision said why (a new user's find)."""
    prog = tmp_path / "p.vamp.json"
    assert _run("compile", EXAMPLES / "planar2.yaml", "-o", prog).exit_code == 0
    edited = edited_program(prog, tmp_path, lambda d: d["robot"]["joints"][1].update(mass=3.0))
    hint = re.compile(r": FAILED \(the program's graph differs from the reference Newton-Euler's by "
                      r"\d\.\de-01 of a set's largest \|τ\| too: was the file's robot or graph edited\? "
                      r"Compile the robot again\)\n")
    res = _run("emulate", edited, "--random", 5, "--check")
    assert res.exit_code == 1 and hint.search(res.output), res.output
    path = tmp_path / "path.csv"
    path.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,0.3,0.4,0.5,0.6\n0.1,0.2,0.3,0.4,0.5,0.6\n")
    res = _run("lookahead", edited, "--trajectory", path, "--rate", "1kHz", "--window", 1, "--check")
    assert res.exit_code == 1 and hint.search(res.output), res.output
    res = _run("emulate", prog, "--random", 5, "--check", "--tolerance", "1e-300")   # rounding only
    assert "was the file's robot" not in res.output, res.output


def test_a_check_that_fails_in_float64_too_does_not_advise_a_wider_word(tmp_path):
    """A fixed-point program whose robot was edited (a mass 10% up, checksum made again) failed its
    check 'a wider --word would do better; `vampc precision` finds one', and precision then
    refused the file: the graph misses in float64 too (a new user's find). It says so."""
    prog = tmp_path / "p.vamp.json"
    assert _run("compile", EXAMPLES / "planar2.yaml", "--word", "q16.16", "-o", prog).exit_code == 0
    res = _run("emulate", prog, "--random", 20, "--check")
    assert res.exit_code == 0, res.output                      # as compiled: within its word
    edited = edited_program(prog, tmp_path, lambda d: d["robot"]["joints"][1].update(
        mass=d["robot"]["joints"][1]["mass"] * 1.1))
    res = _run("emulate", edited, "--random", 20, "--check")
    assert res.exit_code == 1 and "wider --word" not in res.output, res.output
    assert re.search(r": FAILED \(not the word's: in float64 the program's graph differs from the "
                     r"reference Newton-Euler's by \d\.\de-02 of the largest \|τ\| too; was the "
                     r"file's robot or graph edited\? Compile the robot again\)\n", res.output), res.output
    # a word too narrow for the robot still gets the advice
    res = _run("emulate", prog, "--random", 20, "--check", "--word", "q16.4")
    assert res.exit_code == 1 and "a wider --word would do better" in res.output, res.output


@pytest.mark.parametrize("word", [[], ["--word", "q16.16"]])
def test_a_reference_that_is_not_finite_is_said_so(tmp_path, program, word):
    """A program file whose robot gravity was edited to 1e308 (checksum made again): the network's
    torques are finite, the reference's overflow; the check said 'max abs error nan' and, in a
    narrower word, advised a wider one (a new user's find). It fails saying why."""
    edited = edited_program(program, tmp_path, lambda d: d["robot"].update(gravity=[0.0, -1e308, 0.0]))
    res = _run("emulate", edited, "--random", 3, "--check", *word)
    assert res.exit_code == 1, res.output
    assert re.search(r"check against reference RNEA: the reference torques are not finite numbers "
                     r"\(the robot's numbers overflow a float\): nothing to compare "
                     r"with: FAILED\n", res.stdout), res.output
    assert "nan" not in res.output and "wider --word" not in res.output


@pytest.mark.parametrize("text, said", [
    ("# t,q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,0,0,0,0\n",
     "the header line starts with '#', which is all that is wrong with it (numpy.savetxt"),
    ("# q1,q2,qd1\n0,0,0\n", "the first line starts with '#': no line is a comment here, the first "
                             "is the header"),
    ("0,0,0,0,0,0,0\n1,0,0,0,0,0,0\n", "the first line is numbers: the header line is missing"),
    ("t,tau_j1,tau_j2\n0,1,2\n", "the file looks like torques (vampc emulate's output), not states"),
    ("joint,tau,qd\nj1,1,2\n", "the file looks like a limits file (joint,tau,qd)"),
    ('{"format": "vampc-program"}\n', "the file looks like JSON (a program file?), not a CSV"),
    ('<?xml version="1.0"?>\n<robot name="r"/>\n', "the file looks like XML (a URDF?), not a CSV"),
    # (a look-ahead user's files: columns split by ';' or tabs, a time column, capitals)
    ("q1;q2;qd1;qd2;qdd1;qdd2\n0;0;0;0;0;0\n", "its columns are separated by semicolons: a CSV "
                                                "table's are by commas"),
    ("t\tq1\tq2\tqd1\tqd2\tqdd1\tqdd2\n0\t0\t0\t0\t0\t0\t0\n", "its columns are separated by tabs"),
    ("time,q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,0,0,0,0\n", "a time column is named t"),
    ("T,Q1,Q2,QD1,QD2,QDD1,QDD2\n0,0,0,0,0,0,0\n", "write the column names in lower case (q1, not Q1)"),
    # (columns named by joint: which joint q1 is went unsaid, a new user's find)
    ("q_shoulder,q_elbow,qd_shoulder,qd_elbow,qdd_shoulder,qdd_elbow\n0,0,0,0,0,0\n",
     "the columns are numbered, not named by joint: q1 is the first joint in joint order"),
    ("q_shoulder,q_elbow,qdot_shoulder,qdot_elbow,qddot_shoulder,qddot_elbow\n0,0,0,0,0,0\n",
     "the columns are numbered, not named by joint"),     # (dropped by 008de49: a review's find)
])
def test_a_header_that_is_not_the_trajectorys_is_said_what_it_seems(tmp_path, text, said):
    """numpy.savetxt's '# t,q1,...' was said to have 't' where 'q1' was expected, as if the t
    column were wrong; a headerless table, a torque file, a limits file, a program file or a URDF
    given as the trajectory were said to start with the wrong column (a new user's find)."""
    traj = tmp_path / "traj.csv"
    traj.write_text(text)
    out = tmp_path / "tau.csv"
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory",
                                  str(traj), "-o", str(out)])
    assert r.exit_code == 1 and ERROR.match(r.stderr), r.stderr
    assert "header:" in r.stderr and said in r.stderr and not out.exists()


@pytest.mark.parametrize("text", ["q1,q2,qdot1,qdot2,qddot1,qddot2\n0,0,0,0,0,0\n",
                                  "q1,q2,qd1,qd2,qdd1,qdd2,quality\n0,0,0,0,0,0,0\n"])
def test_a_header_not_named_by_joint_is_not_told_it_is(tmp_path, text):
    """The hint for columns named by joint (q_shoulder, ...) fired on qdot1 and on an extra column
    'quality' (a review's find): only names after q, qd and qdd alike are taken for joints'."""
    traj = tmp_path / "traj.csv"
    traj.write_text(text)
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory", str(traj)])
    assert r.exit_code == 1 and "header:" in r.stderr and "named by joint" not in r.stderr, r.stderr


@pytest.mark.parametrize("name, said", [("tau.csv", "a CSV table is a trajectory (for --trajectory)"),
                                        ("tau.npy", "a NumPy array is a trajectory (for --trajectory)")])
def test_a_table_given_as_the_robot_is_said_to_be_one(tmp_path, name, said):
    table = tmp_path / name
    table.write_text("t,tau_j1,tau_j2\n0,1,2\n")
    r = CliRunner().invoke(main, ["emulate", str(table), "--random", "3"])
    assert r.exit_code == 1 and ERROR.match(r.stderr) and said in r.stderr
    # a robot file saved under such a name is said by its content, as before (a review's)
    table.write_text((EXAMPLES / "ur5.urdf").read_text())
    r = CliRunner().invoke(main, ["emulate", str(table), "--random", "3"])
    assert r.exit_code == 1 and "(it looks like XML (a URDF))" in r.stderr and said not in r.stderr


def test_a_state_whose_torques_cancel_is_not_said_to_be_an_edited_file(tmp_path):
    """A free fall of the Puma (q̇ = 0, q̈ = -M⁻¹ g: torques of 1e-14 N·m, rounding alone): whatever
    the check makes of its 3e-16 N·m, the program just compiled is not said to be edited (the
    graph, tried on the state the check found worst against that state's own largest |τ|, had been
    said to differ by 3.4e-4: a review's). A mass edit is still said (the test above)."""
    chain = load_robot(EXAMPLES / "puma560.yaml")
    q, z = np.array([[0.3, -0.7, 0.4, 0.2, -0.5, 0.1]]), np.zeros((1, 6))
    g = rnea(chain, q, z, z)[0]
    M = np.stack([rnea(chain, q, z, np.eye(6)[[k]])[0] - g for k in range(6)], 1)
    qdd = -np.linalg.solve(M, g)
    assert np.abs(rnea(chain, q, z, qdd[None])).max() < 1e-12 < np.abs(g).max()
    path = tmp_path / "fall.csv"
    path.write_text(",".join([f"{p}{i}" for p in ("q", "qd", "qdd") for i in range(1, 7)]) + "\n"
                    + ",".join(repr(float(v)) for v in np.concatenate([q[0], z[0], qdd])) + "\n")
    prog = tmp_path / "p.vamp.json"
    assert _run("compile", EXAMPLES / "puma560.yaml", "-o", prog).exit_code == 0
    res = _run("emulate", prog, "--trajectory", path, "--check")
    assert "check against reference RNEA" in res.output and "graph differs" not in res.output, res.output
