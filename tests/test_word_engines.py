"""Word formats through the whole machine: every engine (tick, numpy stream, graph evaluator) runs
float32 and fixed-point words bit for bit alike; an independent oracle (Python integers, driving the
op table's micro-steps with the rules of tests/test_word_formats.py) agrees on whole torque sets; a
program records its word, and `vampc emulate --word` runs a what-if with the error against float64
reported joint by joint and every overflow counted."""
from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES
from test_word_formats import oracle

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain
from vampc.dataflow.evaluate import evaluate
from vampc.emulator import emulate, load_program, loaded_from_compiled
from vampc.emulator.host import random_trajectory
from vampc.machine.arith import Fixed, Fn, Overflow, Rounding, parse_word
from vampc.robot import load_robot

WORDS = ["float32", "q16.16", "q12.20", "q9.12", "q24.24", "q32.16", "q32.32"]


class OracleWord(Fixed):
    """The fixed-point rules computed one scalar at a time with Python's integers (the test
    oracle), not by vampc.machine.arith's numpy code; `counted` sums the oracle's own overflow
    flags (not Fixed's `overflows`)."""
    counted = 0

    def apply(self, fn: Fn, x, y):
        x, y = np.broadcast_arrays(np.asarray(x), np.asarray(y))
        out = [oracle(fn, int(a), int(b), self.integer, self.fraction, self.rounding,
                      self.overflow) for a, b in zip(x.ravel(), y.ravel())]
        self.counted += sum(flag for _, flag in out)
        return np.array([value for value, _ in out], dtype=np.int64).reshape(x.shape)


@pytest.fixture(scope="module")
def puma():
    return load_robot(EXAMPLES / "puma560.yaml")


@pytest.mark.parametrize("options", [{}, {"recursion": "log"}, {"layout": "folded"},
                                     {"vamps": 12}], ids=["linear", "log", "folded", "budget"])
def test_every_engine_computes_each_word_alike(puma, options, monkeypatch):
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    c = compile_chain(puma, CompileOptions(**options))
    traj = random_trajectory(puma, 12, 5)
    for text in WORDS:
        ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(text))
        stream = emulate(ld, traj, "stream").tau
        tick = emulate(ld, traj, "tick").tau
        evaluated = evaluate(c.graph, puma, traj.q, traj.qd, traj.qdd, arith=ld.arith)
        assert np.array_equal(stream, tick), text
        assert np.array_equal(stream, evaluated), text


@pytest.mark.parametrize("word", [Fixed(16, 16), Fixed(12, 20, Rounding.TRUNCATE, Overflow.WRAP),
                                  Fixed(9, 12), Fixed(32, 32, Rounding.TRUNCATE)],
                         ids=lambda w: repr(w))
def test_whole_torque_sets_are_the_oracles(puma, word, monkeypatch):
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    c = compile_chain(puma, CompileOptions(recursion="log"))
    traj = random_trajectory(puma, 3, 11)
    ld = dataclasses.replace(loaded_from_compiled(c), word=word)
    engines = emulate(ld, traj, "stream").tau
    want = OracleWord(word.integer, word.fraction, word.rounding, word.overflow)
    assert np.array_equal(engines, evaluate(c.graph, puma, traj.q, traj.qd, traj.qdd, arith=want))


def test_q16_16_error_is_what_its_lsb_allows(puma):
    """Puma 560, q16.16: the error against float64 is about 5e-5 of the largest torque (a test
    that the format does what it says, not only that the engines agree)."""
    c = compile_chain(puma, CompileOptions())
    traj = random_trajectory(puma, 200, 2)
    ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word("q16.16"))
    from vampc.dynamics.reference import rnea
    ref = rnea(puma, traj.q, traj.qd, traj.qdd)
    err = np.abs(emulate(ld, traj, "stream").tau - ref).max() / np.abs(ref).max()
    assert 1e-6 < err < 2e-4 and ld.arith.overflows == 0


def test_a_program_records_its_word_and_emulate_checks_against_float64(tmp_path):
    prog = tmp_path / "p.vamp.json"
    run = CliRunner().invoke
    res = run(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--word", "q16.16", "-o",
                     str(prog)])
    assert res.exit_code == 0, res.output
    assert load_program(str(prog)).arith == Fixed(16, 16)
    res = run(main, ["emulate", str(prog), "--random", "300", "--check"])
    assert res.exit_code == 0, res.output
    assert "q16.16 (nearest, saturate) words: 0 overflows" in res.output
    assert "what if" not in res.stderr          # its own word
    assert "tau_shoulder:" in res.output and "tolerance 0.001: OK" in res.output
    # a what-if in a narrower word overflows: counted, reported, and the check fails
    res = run(main, ["emulate", str(prog), "--random", "300", "--check", "--word", "q6.12"])
    assert res.exit_code == 1 and "overflows" in res.output and "FAILED" in res.output
    # said as a what-if, as precision, faults and rtl say it (emulate named the word alone)
    assert f"vampc: warning: {prog} computes in q16.16 (nearest, saturate); it is emulated in " \
        "q6.12 (nearest, saturate) (what if: not the program's own word)\n" in res.stderr, res.stderr
    res = run(main, ["emulate", str(prog), "--random", "3", "--word", "float64"])
    assert res.exit_code == 0 and "; it is emulated in float64 (what if" in res.stderr, res.stderr


def test_a_float64_program_keeps_its_bytes_and_a_word_is_recorded_only_when_given(tmp_path):
    run = CliRunner().invoke
    plain, again = tmp_path / "a.vamp.json", tmp_path / "b.vamp.json"
    for path, extra in ((plain, []), (again, ["--word", "float64"])):
        res = run(main, ["compile", str(EXAMPLES / "planar2.yaml"), "-o", str(path), *extra])
        assert res.exit_code == 0, res.output
    assert plain.read_bytes() == again.read_bytes() and b'"word"' not in plain.read_bytes()


@pytest.mark.parametrize("args, said", [
    (["--word", "q0.0"], "--word q0.0"), (["--word", "q70.70"], "--word q70.70"),
    (["--word", "float16"], "--word float16"), (["--word", "q16.-1"], "--word q16.-1"),
    (["--word", "q١٦.١٦"], "--word q١٦.١٦"),       # (other scripts' digits: it was q16.16)
    (["--word", "float32", "--overflow", "wrap"], "--overflow applies to fixed-point words"),
    (["--tolerance", "-1", "--check"], "--tolerance -1: give a positive finite number"),
    # (1e-400 reads as 0.0, and was echoed so with no word: a file-safety audit)
    (["--tolerance", "1e-400", "--check"], "--tolerance 0: give a positive finite number (a "
                                            "number below about 5e-324 also reads as 0)"),
    # (1e400 reads as inf: "--tolerance inf: give a positive number" of a positive number written)
    (["--tolerance", "1e400", "--check"], "--tolerance inf: give a positive finite number (a "
                                           "number above about 1.8e308 also reads as inf)"),
])
def test_a_word_option_that_makes_no_sense_is_a_usage_error(args, said):
    res = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "3",
                                    *args])
    assert res.exit_code == 2 and said in res.stderr, res.stderr


@pytest.mark.parametrize("value", ["1", "5"])
@pytest.mark.parametrize("command", ["emulate", "precision", "lookahead"])
def test_a_tolerance_of_one_or_more_is_refused_by_every_command_alike(command, value):
    """An error of the largest |τ| or more lets any torque of that size pass: emulate took 5 (and
    passed), precision named a word for it, lookahead refused it (an options audit's find)."""
    robot = str(EXAMPLES / "planar2.yaml")
    args = {"emulate": ["emulate", robot, "--random", "3", "--check"],
            "precision": ["precision", robot],
            "lookahead": ["lookahead", robot, "--trajectory", str(EXAMPLES / "puma560-path.csv"),
                          "--rate", "1kHz", "--window", "8", "--check", "--word", "float32"]}[command]
    res = CliRunner().invoke(main, [*args, "--tolerance", value])
    assert res.exit_code == 2, (res.output, res.stderr)
    assert f"--tolerance {value}: give an error below 1 (of the largest |τ|)" in res.stderr


@pytest.mark.parametrize("word, rounding, overflow",
                         [("float32", "nearest", "wrap"), ("q16.16", "nearest", "wrap"),
                          ("q32.32", "nearest", "wrap"), ("q32.32", "truncate", "saturate")]
                         + [(w, r, o) for w in ("q5.12", "q9.4")
                            for r in ("nearest", "truncate") for o in ("wrap", "saturate")],
                         ids=lambda v: v)
def test_the_generated_c_computes_each_word_as_numpy_does(word, rounding, overflow, monkeypatch):
    """The stream engine's C path (VAMPC_NATIVE=1: compiled even for a short run) renders the same
    format under every rounding and overflow rule: bit-identical torques and the same overflow
    count. q5.12 (range ±16) overflows hundreds of times on the 2-link arm's 130 sets, so both the
    wrap and the saturate branches of the C run (a saturation to the wrong end differs); q9.4 has
    4 fraction bits, so a product's dropped bits are all ones often enough that a truncation which
    is not the arithmetic shift (towards -inf) differs (q16.16 and q32.32 neither overflow nor,
    with 16 and 32 fraction bits, meet that case here: one rule each, for int64_t and __int128).
    The reference is numpy's Fixed, itself held to the Python-integer oracle in test_word_formats.
    130 is not a whole number of the C path's 64-set blocks."""
    chain = load_robot(EXAMPLES / "planar2.yaml")
    c = compile_chain(chain, CompileOptions())
    traj = random_trajectory(chain, 130, 4)
    got = {}
    for mode in ("0", "1"):
        monkeypatch.setenv("VAMPC_NATIVE", mode)
        ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(word, rounding, overflow))
        got[mode] = (emulate(ld, traj, "stream").tau, ld.arith.overflows)
    assert np.array_equal(got["0"][0], got["1"][0]) and got["0"][1] == got["1"][1]
    if word == "q5.12":
        assert got["0"][1] > 0
    if word == "q9.4" and rounding == "truncate":   # the rounding rule matters on these sets
        ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(word, "nearest", overflow))
        assert not np.array_equal(emulate(ld, traj, "stream").tau, got["0"][0])


def test_the_first_overflows_are_located(tmp_path):
    """Set, tick, VAMP and what overflowed: the host's conversion of an input, an op's result."""
    traj = tmp_path / "t.csv"
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,0,0,1,2\n0.1,0.2,0,0,1,300\n")
    args = ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory", str(traj), "--word",
            "q9.12"]
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 1 and "line 3 (state 2), column qdd2: 300 is beyond q9.12 words, which hold " \
        "[-256, 256)" in res.stderr and res.stderr.count("\n") == 1, res.stderr
    res = CliRunner().invoke(main, args + ["--overflow", "saturate", "--engine", "tick"])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    at = lines.index("q9.12 (nearest, saturate) words: 2 overflows")
    assert lines[at + 1].startswith("  set 2, tick 8: the host's zqdd2 for port ")
    assert lines[at + 2].startswith("  set 2, tick 11: VAMP ") and "the result of VA" in lines[at + 2]


SLIDE = """name: slide
gravity: [0.0, 0.0, -9.81]
joints:
  - {name: s1, type: prismatic, a: 0.0, alpha: 0.0, d: 0.0, theta: 0.0, mass: 1.0,
     com: [0.0, 0.0, -0.1], inertia: [0.01, 0.01, 0.01, 0.0, 0.0, 0.0], limits: {q: [0.0, 200.0], qd: 1.0}}
  - {name: r2, type: revolute, a: 0.5, alpha: 0.0, d: 0.0, theta: 0.0, mass: 1.0,
     com: [-0.25, 0.0, 0.0], inertia: [0.01, 0.02, 0.02, 0.0, 0.0, 0.0], limits: {q: [-3, 3], qd: 1.0}}
"""


def test_a_prismatic_position_whose_host_inputs_a_word_cannot_hold_is_refused(tmp_path):
    """A slide's q = 150 (within its limits) gives p* = [0, 0, 150], which q8.8 words cannot hold:
    it ran, its overflows counted, exit 0, where a q̈ of 150 is refused (an audit's). Refused
    the same way, naming the row and the q column; with --overflow it runs, and each value the
    host converts is one overflow, said once with the ports it is written to."""
    robot = tmp_path / "slide.yaml"
    robot.write_text(SLIDE)
    traj = tmp_path / "t.csv"
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n1,0.5,0,0.5,0,0\n150,0.5,0,0.5,0,0\n")
    out = tmp_path / "tau.csv"
    args = ["emulate", str(robot), "--trajectory", str(traj), "--word", "q8.8", "-o", str(out)]
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 1 and res.stderr.count("\n") == 1, res.output
    assert ("line 3 (state 2), column q1: 150 gives p*_1 = [0, 0, 150] (the host's input for "
            "prismatic joint 1), beyond q8.8 words, which hold [-128, 128)") in res.stderr
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n127.999,0.5,0,0.5,0,0\n")    # rounds to 128
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 1 and "127.999 gives p*_1 = [0, 0, 127.999] (" in res.stderr, res.stderr
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n1,0.5,0,0.5,0,0\n150,0.5,0,0.5,0,0\n")
    assert not out.exists()
    chain = load_robot(robot)
    assert chain.joints[0].p_star(np.array([150.0]))[0, 2] == 150.0     # (what the host writes)
    for engine in ("stream", "tick"):
        res = CliRunner().invoke(main, args + ["--overflow", "saturate", "--engine", engine])
        assert res.exit_code == 0, res.output
        lines = res.output.splitlines()
        at = lines.index("q8.8 (nearest, saturate) words: 2 overflows")
        sites = [x for x in lines[at + 1:] if x.startswith("  set ")]
        assert len(sites) == 2 and any(x.endswith("p_star1 for ports 1 and 13") for x in sites), sites
    # a position the word holds runs as before
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n1,0.5,0,0.5,0,0\n100,0.5,0,0.5,0,0\n")
    assert CliRunner().invoke(main, args).exit_code == 0


def test_the_tick_engine_counts_the_overflows_the_stream_engine_counts(puma, monkeypatch):
    """Once per torque set and op: not the power-on registers' nor an op run again on its set."""
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    c = compile_chain(puma, CompileOptions(recursion="log"))
    traj = random_trajectory(puma, 20, 9)
    counts = []
    for engine in ("stream", "tick"):
        ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word("q6.12", "nearest",
                                                                          "wrap"))
        emulate(ld, traj, engine)
        counts.append(ld.arith.overflows)
    # the oracle's flags over the graph's ops, each run once per set (74 here)
    want = OracleWord(6, 12, Rounding.NEAREST, Overflow.WRAP)
    evaluate(c.graph, puma, traj.q, traj.qd, traj.qdd, arith=want)
    assert counts[0] == counts[1] == want.counted > 0


EXAMPLE_ROBOTS = ["planar2.yaml", "stanford.yaml", "arm6.urdf", "quadruped.urdf"]


@pytest.mark.parametrize("robot", EXAMPLE_ROBOTS)
@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_every_example_robot_is_computed_alike_in_a_fixed_word(robot, recursion, monkeypatch):
    """The other examples (the Puma is above; snake64, 64 joints, takes 90 s for every layout and
    word and is left to a run by hand), systolic, folded and budget layouts."""
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    chain = load_robot(EXAMPLES / robot)
    traj = random_trajectory(chain, 3, 1)
    for layout in ({}, {"layout": "folded"}, {"vamps": 24}):
        c = compile_chain(chain, CompileOptions(recursion=recursion, **layout))
        for text in ("float32", "q16.16"):
            ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(text))
            stream = emulate(ld, traj, "stream").tau
            assert np.array_equal(stream, emulate(ld, traj, "tick").tau)
            if text == "q16.16" and not layout:     # both engines run Fixed.apply: the oracle too
                want = evaluate(c.graph, chain, traj.q, traj.qd, traj.qdd, traj.base,
                                arith=OracleWord(16, 16))
                assert np.array_equal(stream, want)


def test_the_report_gives_the_bits_of_a_word_format(tmp_path):
    from schema_check import schema_errors

    from vampc.jsontext import loads
    from vampc.machine import ops
    run = CliRunner().invoke
    prog = tmp_path / "p.vamp.json"
    assert run(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--word", "q12.20", "-o",
                      str(prog)]).exit_code == 0
    res = run(main, ["report", str(prog), "--format", "json"])
    rep = loads(res.output)
    assert not schema_errors("report", rep)
    c = load_program(str(prog))
    w, V = rep["word"], len(c.net.vamps)
    assert (w["format"], w["bits"], w["rounding"], w["overflow"]) == ("q12.20", 32, "nearest",
                                                                      "saturate")
    assert w["data_register_bits"] == (9 + 9 + 9 + 3) * 32 * V       # A, B, 3 x 3 units, Result
    assert w["delay_line_bits"] == 3 * 32 * sum(b.stages for b in c.net.buffers)
    assert w["host_read_bits_per_set"] == 32 * 6
    # every VAMP: a Cycle-Counter counting 0..P; every slot: a valid bit, delay-A, -B, -R as wide
    # as the counter, a ROM pointer, no select for a one-input mux; the buffers' counter (the RTL's
    # registers: tests/test_rtl.py counts them in the design itself)
    counter, rom = c.net.period.bit_length(), (len(ops.ROM) - 1).bit_length()
    control = sum(counter + len(v.slots) * (1 + 3 * counter + rom) for v in c.net.vamps) + counter + 1
    assert w["control_register_bits"] == control                 # (+ 1: the overflow flag)
    # the Program-Mode stream: each scalar of every word the file's program_stream holds is a word
    # (section VII: a VAMP-number and its program in a 3-vector; only the golden report's bytes had
    # seen a wrong count here, a mutation audit's)
    stream = json.loads(prog.read_text())["program_stream"]
    assert w["program_bits"] == 32 * sum(len(word) for e in stream for word in e["words"]) > 0
    assert all(len(word) == 3 for e in stream for word in e["words"])
    text = run(main, ["report", str(prog)]).output
    assert "q12.20 (nearest, saturate): 32 bits;" in text
    assert f"{30 * 32 * V:,} bits of data registers, {control:,} of control registers, " in text
    plain = tmp_path / "f.vamp.json"
    assert run(main, ["compile", str(EXAMPLES / "puma560.yaml"), "-o", str(plain)]).exit_code == 0
    assert "word" not in loads(run(main, ["report", str(plain), "--format", "json"]).output)


def test_a_floating_base_reads_a_word_for_each_joint_torque_and_each_base_wrench_component(tmp_path):
    """host_read_bits_per_set of a floating-base quadruped in q16.16 is 32 bits for each scalar a
    set reads out: counted here from the URDF itself (its joints that are not fixed, read with
    ElementTree) plus the base wrench's 3 forces and 3 moments, and the same number as the columns
    of the emulator's torque CSV (it had counted the 12 joints alone; a fixed-base arm cannot
    tell)."""
    import xml.etree.ElementTree as ET

    from vampc.jsontext import loads
    run = CliRunner().invoke
    urdf, prog, csv = EXAMPLES / "quadruped.urdf", tmp_path / "q.vamp.json", tmp_path / "t.csv"
    assert run(main, ["compile", str(urdf), "--floating-base", "--word", "q16.16", "-o",
                      str(prog)]).exit_code == 0
    joints = [j for j in ET.parse(urdf).getroot().iter("joint") if j.get("type") != "fixed"]
    outputs = len(joints) + 6
    assert len(joints) == 12
    assert run(main, ["emulate", str(prog), "--random", "2", "-o", str(csv)]).exit_code == 0
    assert len(csv.read_text().splitlines()[0].split(",")) == outputs
    rep = loads(run(main, ["report", str(prog), "--format", "json"]).output)
    assert rep["word"]["host_read_bits_per_set"] == 32 * outputs


def test_a_waveform_shows_the_values_a_word_stands_for(tmp_path):
    """--vcd writes what a fixed-point word means (raw · 2^-F), not its raw bits."""
    prog, wave = tmp_path / "p.vamp.json", tmp_path / "w.vcd"
    run = CliRunner().invoke
    assert run(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q8.8", "-o",
                      str(prog)]).exit_code == 0
    assert run(main, ["emulate", str(prog), "--random", "2", "--engine", "tick", "--vcd",
                      str(wave)]).exit_code == 0
    values = [float(line[1:].split()[0]) for line in wave.read_text().splitlines()
              if line.startswith("r")]
    assert values and all((v * 256).is_integer() for v in values)      # multiples of 2^-8
    assert all(-128 <= v < 128 for v in values)                          # within q8.8's range


def test_narrow_words_carry_programs_in_more_words():
    from vampc.program.words import PACKING, Packing, Program, apply_word, vamp_words
    assert Packing.of(parse_word("float32")) == Packing.of(parse_word("q16.16")) == PACKING
    assert Packing.of(parse_word("q8.8")) == Packing(128, 32768)
    narrow = Packing.of(parse_word("q4.4"))                  # 8 bits: fields below 8, words below 128
    assert narrow == Packing(8, 128)
    rng = np.random.default_rng(3)
    for _ in range(200):
        slots = tuple(Program(*(int(x) for x in rng.integers(0, 20, 4)),
                              *(int(x) for x in rng.integers(0, 3, 2)))
                      for _ in range(int(rng.integers(1, 4))))
        words = vamp_words(77, slots, narrow)
        assert all(abs(x) < 128 for w in words for x in w)
        table = None
        for w in words:
            table = apply_word(table, w, narrow) if table is not None or w[0] > 0 else table
        assert tuple(Program(*row) for row in table) == slots
        assert len(words) >= len(vamp_words(77, slots))     # never fewer than the wide packing's


def test_a_narrow_program_runs_alike_on_both_engines(monkeypatch, tmp_path):
    """Puma on 12 VAMPs (period 27: delays beyond q5.5's 4-bit compact fields) in 10-bit words."""
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    run = CliRunner().invoke
    wide, narrow = tmp_path / "w.vamp.json", tmp_path / "n.vamp.json"
    for path, word in ((wide, "q16.16"), (narrow, "q5.5")):
        res = run(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--vamps", "12", "--word",
                         word, "-o", str(path)])
        assert res.exit_code == 0, res.output
    a, b = load_program(str(wide)), load_program(str(narrow))
    assert a.programs == b.programs and sum(len(e.words) for e in b.stream) > \
        sum(len(e.words) for e in a.stream)
    traj = random_trajectory(b.chain, 4, 2)
    stream, tick = emulate(b, traj, "stream").tau, emulate(b, traj, "tick").tau
    assert np.array_equal(stream, tick)


def test_a_word_too_narrow_for_the_program_is_one_line(tmp_path):
    run = CliRunner().invoke
    res = run(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--word", "q4.4", "-o",
                     str(tmp_path / "p.vamp.json")])
    assert res.exit_code == 1 and "VAMP number 179 does not fit in a 8-bit Program-Mode word " \
        "(at most 127); give a wider --word" in res.stderr
    res = run(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q4.4", "--vamps", "3",
                     "-o", str(tmp_path / "q.vamp.json")])
    assert res.exit_code == 1 and "beyond what a 8-bit Program-Mode word addresses" in res.stderr


def test_a_constant_the_word_cannot_hold_is_counted_once_and_located(monkeypatch):
    """Stanford arm in q2.8 (range ±2): constants (masses, gravity) overflow at the host's
    conversion; every engine counts each once a run, and the sites name them."""
    chain = load_robot(EXAMPLES / "stanford.yaml")
    c = compile_chain(chain, CompileOptions(word="q2.8", overflow="wrap"))   # packed for 10 bits
    traj = random_trajectory(chain, 100, 3)
    counts = {}
    for name, mode, engine in (("numpy", "0", "stream"), ("C", "1", "stream"),
                               ("tick", "0", "tick")):
        monkeypatch.setenv("VAMPC_NATIVE", mode)
        ld = loaded_from_compiled(c)
        from vampc.emulator.driver import States, run
        outcome = run(ld, States(traj.count, traj), engine=engine)
        counts[name] = outcome.overflows
        if name == "numpy":
            assert any("the host's constant" in site for site in outcome.overflow_sites)
    assert counts["numpy"] == counts["C"] == counts["tick"] > 0


def test_a_what_if_in_a_word_too_narrow_for_the_programs_words_is_one_line(tmp_path):
    run = CliRunner().invoke
    prog = tmp_path / "b.vamp.json"
    assert run(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--vamps", "12", "-o",
                      str(prog)]).exit_code == 0
    for engine in ("stream", "tick"):
        res = run(main, ["emulate", str(prog), "--random", "2", "--word", "q9.7", "--engine",
                         engine])
        # (an option this program cannot take: a usage error, exit 2, as faults --bits beyond its word)
        assert res.exit_code == 2 and "--word q9.7: a Program-Mode word holds" in res.stderr \
            and "compile it with --word q9.7" in res.stderr, (engine, res.stderr)
    # a word too narrow for the network's VAMP numbers: no compile can pack it, so none is advised
    # (the advice to compile with --word q1.1 failed on them: a new user's find)
    res = run(main, ["emulate", str(prog), "--random", "2", "--word", "q2.2"])
    assert res.exit_code == 2 and res.stderr.count("\n") == 1 and \
        re.search(r"--word q2\.2: VAMP number \d+ does not fit in a 4-bit Program-Mode word \(at most 7\): "
                  r"no program of this network can be packed for that word \(see '.* emulate --help'\)$",
                  res.stderr.strip()), res.stderr
    res = run(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--vamps", "12", "--word", "q2.2",
                     "-o", str(tmp_path / "q.vamp.json")])
    assert res.exit_code == 1 and "does not fit in a 4-bit Program-Mode word" in res.stderr, res.stderr


def test_float64_tolerance_tightens_and_loosens_and_words_are_named_canonically(tmp_path):
    """A float64 run's --tolerance is the bound its verdict holds the measured error to: the
    largest relative error the run itself prints (about 2.1e-16 on the 2-link arm, said to 4
    figures) fails a tolerance 0.1% below it and passes one 0.1% above (a tolerance taken as 1000
    times itself passed both, and 1e-30 and 1e-3 could not tell)."""
    run = CliRunner().invoke
    base = ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "20", "--check"]
    res = run(main, base)
    assert res.exit_code == 0, res.output
    said = float(re.search(r"max relative error ([0-9.e+-]+) ", res.output).group(1))
    assert 0 < said < 1e-12
    below = run(main, base + ["--tolerance", repr(said * 0.999)])
    above = run(main, base + ["--tolerance", repr(said * 1.001)])
    assert below.exit_code == 1 and ": FAILED" in below.output, below.output
    assert above.exit_code == 0 and ": OK" in above.output, above.output
    prog = tmp_path / "z.vamp.json"
    assert run(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q016.016", "-o",
                      str(prog)]).exit_code == 0
    assert load_program(str(prog)).options["word"] == "q16.16"


def test_a_value_that_rounds_beyond_the_word_is_refused(tmp_path):
    """255.9999 rounds to 256 in q9.12 (to nearest): the word cannot hold it."""
    traj = tmp_path / "h.csv"
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,0,0,1,255.9999\n")
    args = ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory", str(traj), "--word", "q9.12"]
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 1 and "column qdd2: 255.9999 is beyond q9.12 words" in res.stderr
    assert CliRunner().invoke(main, args + ["--rounding", "truncate"]).exit_code == 0


def test_a_float32_constant_beyond_its_range_is_warned_of_and_said_alike_by_both_paths(tmp_path,
                                                                                      monkeypatch):
    """A gravity of 1e39 is inf in float32: compile said nothing (only fixed-point constants were
    looked at), and the generated C had the literal 'inf', which gcc refused ('inf' undeclared),
    where the numpy path said the torque was nan (an audit's)."""
    robot = tmp_path / "one.yaml"
    robot.write_text("name: one\ngravity: [0.0, 0.0, 1.0e39]\njoints:\n  - {name: j1, type: "
                     "revolute, a: 0.3, alpha: 1.5707963267948966, d: 0.1, theta: 0.0, mass: 1.7, "
                     "com: [-0.15, 0.02, 0.01], inertia: [0.01, 0.02, 0.015, 0.001, 0.0, 0.002], "
                     "limits: {q: [-3, 3], qd: 2}}\n")
    program = tmp_path / "one.vamp.json"
    res = CliRunner().invoke(main, ["compile", str(robot), "--word", "float32", "-o", str(program)])
    assert res.exit_code == 0, res.output
    assert ("1 constant beyond the range of float32 (pdd0): the host's conversion makes it "
            "infinite, and the torques are wrong; give float64") in res.stderr
    said = {}
    for mode in ("0", "1"):
        monkeypatch.setenv("VAMPC_NATIVE", mode)
        res = CliRunner().invoke(main, ["emulate", str(program), "--random", "3"])
        assert res.exit_code == 1 and res.stderr.count("\n") == 1, res.stderr
        said[mode] = res.stderr
    assert said["0"] == said["1"] and "the torque is nan (float32 overflow" in said["1"]
    word = parse_word("float32", "nearest", "saturate")
    assert [word.c_literal(x) for x in (1e39, -1e39, float("nan"))] == [
        "((float)INFINITY)", "(-(float)INFINITY)", "((float)NAN)"]


def test_joint_limits_a_word_cannot_hold_are_warned_of_at_compile(tmp_path):
    """A slide whose travel reaches q = 200 compiled in q8.8 without a word, its states refused only
    when they came (a new user's q6.10 program of a 40 m slide). Compile warns, naming the joint;
    the warning's bound is the host's own: s*_i at the travel's ends, checked here by the chain."""
    robot = tmp_path / "slide.yaml"
    robot.write_text(SLIDE)
    chain = load_robot(robot)
    ends = np.array(chain.joints[0].limits.q)
    assert np.abs(np.concatenate([chain.joints[0].p_star(ends), chain.joints[0].s_star(ends)])).max() > 128
    for word, warned in (("q8.8", True), ("q9.8", False)):
        res = CliRunner().invoke(main, ["compile", str(robot), "--word", word, "-o",
                                        str(tmp_path / "s.vamp.json")])
        assert res.exit_code == 0, res.output
        said = (f"slide.yaml: joint limits beyond {word} words, which hold [-128, 128): 's1' travel "
                "[0, 200] (its p*1, s*1); states near them are refused")
        assert (said in res.stderr) is warned, res.stderr
    slow = tmp_path / "fast.yaml"                       # a speed limit beyond the word
    slow.write_text(SLIDE.replace("qd: 1.0}}\n  - {name: r2", "qd: 300.0}}\n  - {name: r2"))
    res = CliRunner().invoke(main, ["compile", str(slow), "--word", "q9.8", "-o",
                                    str(tmp_path / "f.vamp.json")])
    assert "'s1' speed limit 300" in res.stderr, res.stderr


def test_each_located_overflow_says_how_many_scalars_it_counts(tmp_path):
    """The count is of scalars, the list of places: a VC overflowing in two components was listed
    once beside a count one more than its lines (5 overflows, 4 places: a new user's find). Each
    place says how many scalars overflowed there, and over the sets listed they add up to the
    count (checked where the first five places are all the run has)."""
    robot = EXAMPLES / "planar2.yaml"
    traj = tmp_path / "t.csv"
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0.3,0.2,20,20,1,1\n")
    res = CliRunner().invoke(main, ["emulate", str(robot), "--trajectory", str(traj), "--word", "q8.8",
                                    "--allow-out-of-limits", "--engine", "tick"])
    lines = res.output.splitlines()
    at = next(i for i, x in enumerate(lines) if x.startswith("q8.8 (nearest, saturate) words: "))
    count = int(re.search(r"words: (\d+) overflows", lines[at]).group(1))
    places = [x for x in lines[at + 1:] if x.startswith("  set ")]
    scalars = [int(m.group(1)) if (m := re.search(r"\((\d+) scalars\)$", x)) else 1 for x in places]
    assert any(n > 1 for n in scalars), places
    assert len(places) < 5 and sum(scalars) == count, (count, places)


def test_a_float32_run_stopped_by_an_overflow_says_where_it_began(tmp_path):
    """A float32 overflow ends in a torque that is not finite, which stops the run: it said neither
    the count nor where, where a fixed-point word's run lists them (a new user's find)."""
    program = tmp_path / "p.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "float32",
                                     "-o", str(program)]).exit_code == 0
    traj = tmp_path / "t.csv"
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0.3,0.2,1,1,1,1\n0.3,0.2,1e20,1,1,1\n")
    res = CliRunner().invoke(main, ["emulate", str(program), "--trajectory", str(traj),
                                    "--allow-out-of-limits", "-o", str(tmp_path / "tau.csv")])
    assert res.exit_code == 1 and res.stderr.count("\n") == 1, res.stderr
    assert re.search(r"set 2 \(line 3 of .*t\.csv\), joint \d \(\w+\): the torque is (nan|-?inf) \(float32 "
                     r"overflow: the robot's or the state's numbers are too large; \d+ overflows by then, "
                     r"the first in set 2, tick \d+: VAMP \d+ \(number \d+, [\w.]+\), the result of \w+",
                     res.stderr), res.stderr
    assert not (tmp_path / "tau.csv").exists()


@pytest.mark.parametrize("word", ["float64", "float32"])
def test_a_nan_result_is_the_canonical_nan_in_every_engine(word, monkeypatch):
    """IEEE 754 leaves a NaN result's payload open and numpy's loops gave one operand's or the
    other's as the arrays lay in memory (a checker found a mismatch between two NaNs of one op on
    one pair of operands and excised a healthy VAMP: a new user's find). A Result holding a NaN
    holds the canonical quiet NaN: every NaN torque of the numpy (in batches and one op at a time)
    and C stream engines and the tick engine is that one bit pattern (0x7FF8000000000000;
    binary32's 0x7FC00000 widens to it)."""
    import warnings
    chain = load_robot(EXAMPLES / "planar2.yaml")
    c = compile_chain(chain, CompileOptions())
    traj = random_trajectory(chain, 130, 4)
    qd = traj.qd.copy()
    qd[3, 0], qd[5, 1], qd[7, 0] = np.inf, -np.inf, np.nan      # NaNs of either sign come of these
    traj = dataclasses.replace(traj, qd=qd)
    # (emulate refuses such states from a caller; the engines' own NaNs are what is tested here)
    import vampc.emulator
    monkeypatch.setattr(vampc.emulator, "checked_trajectory", lambda chain, traj: traj)
    got = {}
    for native, engine in (("0", "stream"), ("1", "stream"), ("0", "tick")):
        monkeypatch.setenv("VAMPC_NATIVE", native)
        ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(word))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            got[native, engine] = emulate(ld, traj, engine).tau.view(np.uint64)
        if native == "0" and engine == "tick":       # the graph evaluator too
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                got["evaluate"] = evaluate(c.graph, chain, traj.q, traj.qd, traj.qdd,
                                           arith=ld.arith).view(np.uint64)
    # and the numpy stream path's one op at a time (130 sets run in batches of ops above)
    from vampc.emulator import stream
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    monkeypatch.setattr(stream, "BATCHED_BELOW", 1)
    ld = dataclasses.replace(loaded_from_compiled(c), word=parse_word(word))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        got["per op"] = emulate(ld, traj, "stream").tau.view(np.uint64)
    nan = np.isnan(got["0", "stream"].view(np.float64))
    assert nan.sum() >= 3 and nan[[3, 5, 7]].all()
    for name, bits in got.items():
        assert set(bits[nan].tolist()) == {0x7FF8000000000000}, name
        assert np.array_equal(bits, got["0", "stream"]), name


def test_a_result_register_holds_the_canonical_nan_of_any_payload():
    """Against bit patterns written out: NaNs of both signs and several payloads, binary64 and
    binary32, become the positive quiet NaN of payload zero; other values keep their bits."""
    from vampc.machine.arith import Float32, Float64
    for fmt, dtype, view, nans, canonical in (
            (Float64(), np.float64, np.uint64,
             [0x7FF8000000000001, 0xFFF8000000000000, 0x7FFA79E54D9A62C8, 0x7FF0000000000001],
             0x7FF8000000000000),
            (Float32(), np.float32, np.uint32, [0x7FC00001, 0xFFC00000, 0x7FA00000], 0x7FC00000)):
        keep = np.array([1.5, -0.0, np.inf, -np.inf], dtype=dtype).view(view)
        raw = np.array(nans + keep.tolist(), dtype=view)
        out = fmt.result(raw.view(dtype).copy()).view(view)
        assert out.tolist() == [canonical] * len(nans) + keep.tolist(), fmt


def test_torques_below_the_checks_floor_are_said_on_its_verdict(tmp_path):
    """Masses of 1e-300 kg: every torque about 1e-300 N·m, written 0 by a q16.16 word, passed with
    "max error 5e-288 of the largest |τ|" and nothing said of the error being measured against
    1e-12 N·m (an audit's find). The verdict line says so, with the run's largest |τ|."""
    import yaml
    doc = yaml.safe_load((EXAMPLES / "planar2.yaml").read_text())
    for j in doc["joints"]:
        j["mass"] = 1e-300
        j["inertia"] = [1e-300 if x else 0 for x in j.get("inertia", [0] * 6)]
    robot = tmp_path / "tiny.yaml"
    robot.write_text(yaml.safe_dump(doc))
    res = CliRunner().invoke(main, ["emulate", str(robot), "--random", "3", "--check", "--word",
                                    "q16.16"])
    assert res.exit_code == 0, res.output
    assert re.search(r"\(every torque is below 1e-12 N·m, the least the error is measured against: "
                     r"its largest \|τ\| is \d\.\de-30\d\), tolerance 0\.001: OK", res.output), res.output
    # the float64 check, of each set's largest |τ|, and the look-ahead's, of each row's: counted
    # (a review's find: said nothing)
    res = CliRunner().invoke(main, ["emulate", str(robot), "--random", "3", "--check"])
    assert res.exit_code == 0 and "(3 sets whose every torque is below 1e-12 N·m, the least the " \
        "error is measured against), tolerance 1e-9: OK" in res.output, res.output
    path = tmp_path / "path.csv"
    path.write_text("t,q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,0,0,0,0\n0.001,0.1,0,0,0,0,0\n"
                    "0.002,0.2,0,0,0,0,0\n")
    res = CliRunner().invoke(main, ["lookahead", str(robot), "--trajectory", str(path), "--rate",
                                    "1kHz", "--window", "2", "--check"])
    assert res.exit_code == 0 and "(3 rows whose every torque is below 1e-12 N·m" in res.output, \
        res.output
    # a robot of ordinary masses: nothing said of it
    for word in (["--word", "q16.16"], []):
        res = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "3",
                                        "--check", *word])
        assert res.exit_code == 0 and "the least the error is measured against" not in res.output
