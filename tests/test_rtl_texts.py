"""What `vampc rtl` says about the word it was given and what its Verilog's outputs carry (a new
user's run, thirteenth round: `--word float32` was told 'compiled without --word', a what-if float64
on a q16.16 program 'this program computes in float64', and a floating base's wrench outputs were
described as joint torques)."""
from __future__ import annotations

import importlib.util
from types import SimpleNamespace

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain
from vampc.emulator.load import loaded_from_compiled
from vampc.robot import load_robot

pytestmark = pytest.mark.skipif(importlib.util.find_spec("amaranth") is None,
                                reason="vampc rtl needs Amaranth")


def test_the_word_refused_is_named_as_it_was_given(tmp_path):
    program = tmp_path / "p.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                     "-o", str(program)]).exit_code == 0
    head = "RTL needs a fixed-point word (--word qI.F, e.g. q16.16); "
    for args, said in (([str(EXAMPLES / "planar2.yaml"), "--word", "float32"], "--word float32 is not one"),
                       ([str(program), "--word", "float64"], "--word float64 is not one"),
                       ([str(EXAMPLES / "planar2.yaml")], "compiled without --word, it computes in float64")):
        res = CliRunner().invoke(main, ["rtl", *args, "--cosim", "1"])
        assert res.exit_code == 2 and f"{head}{said} (see" in res.stderr, res.stderr


def test_the_help_says_rtl_needs_a_fixed_point_word_and_lists_no_option_it_refuses():
    """`rtl --help` listed --bus, --tiers, --error-correction and --check-cycles, which make a
    network rtl refuses ("not rendered in RTL yet"), and showed `--word [default: float64]`, a word
    rtl refuses (a new user's find). They are left out of the help (still taken, so the refusal
    says why, as `precision --help` leaves out what it refuses), the help says what is not
    rendered, and --word's says a fixed-point qI.F word is needed, with no default shown."""
    import re
    text = CliRunner().invoke(main, ["rtl", "--help"], terminal_width=1000).stdout
    for option in ("--bus", "--tiers", "--error-correction", "--check-cycles"):
        assert not re.search(rf"^\s+{option}\b", text, re.M), option
    flat = " ".join(text.split())
    assert "(--bus mlb) and error correction (--error-correction) are not rendered in RTL yet" in flat
    word = next(line for line in text.splitlines() if line.strip().startswith("--word"))
    assert "RTL needs signed fixed point, qI.F" in word and "default" not in word, word
    assert "--rounding" in text and "--layout" in text      # (what it takes, still listed)
    # (still taken: the refusal names them)
    res = CliRunner().invoke(main, ["rtl", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                    "--error-correction", "-o", "x.v"])
    assert res.exit_code == 2 and "(--error-correction) is not rendered in RTL yet" in res.stderr, \
        res.stderr
    # the other commands' --word help is the field's own, its default shown
    word = next(line for line in CliRunner().invoke(main, ["emulate", "--help"], terminal_width=1000)
                .stdout.splitlines() if line.strip().startswith("--word"))
    assert "[default: float64]" in word, word


def test_the_header_names_a_floating_bases_wrench_outputs():
    from vampc.rtl.verilog import header
    chain = load_robot(EXAMPLES / "planar2.yaml", floating=True)
    ld = loaded_from_compiled(compile_chain(chain, CompileOptions(word="q16.16")), "<test>")
    text = header(SimpleNamespace(ld=ld, name="planar2"))
    assert "planar2 (2 joints, floating base)" in text
    assert ("tau3..tau8 hold the floating base's wrench, tau3 base_fx, tau4 base_fy, tau5 base_fz, "
            "tau6 base_nx, tau7 base_ny, tau8 base_nz") in text
    fixed = load_robot(EXAMPLES / "planar2.yaml")
    plain = header(SimpleNamespace(ld=loaded_from_compiled(compile_chain(
        fixed, CompileOptions(word="q16.16")), "<test>"), name="planar2"))
    assert "wrench" not in plain and "(2 joints)" in plain


def test_estimates_count_a_vamps_slots_and_inputs(tmp_path):
    """The estimates were per VAMP whatever it held: 6 budget VAMPs of 52-73 slots and 12-39 inputs
    an operand were estimated at 4.4 s (as 6 one-slot VAMPs), under --max-minutes 0.1, and took
    30.6 s to co-simulate. A one-slot network is estimated as before."""
    import subprocess
    import sys
    snake = tmp_path / "snake12.yaml"
    snake.write_text(subprocess.run([sys.executable, str(EXAMPLES / "make_snake.py"), "12"],
                                    capture_output=True, text=True, check=True).stdout)
    res = CliRunner().invoke(main, ["rtl", str(snake), "--word", "q16.16", "--vamps", "6", "--cosim",
                                    "1", "--max-minutes", "0.1"])
    assert res.exit_code == 1 and "co-simulating 1 torque set(s) with amaranth is estimated at" in \
        res.stderr and "beyond --max-minutes 0.1" in res.stderr, res.stderr
    from vampc.commands import ELABORATE_PER_VAMP, SIMULATE_PER_VAMP_TICK, _cosim_estimate, _size
    from vampc.rtl.host import run_ticks
    ld = loaded_from_compiled(compile_chain(load_robot(EXAMPLES / "planar2.yaml"),
                                            CompileOptions(word="q16.16")), "<test>")
    V = len(ld.net.vamps)
    assert _size(ld) == _size(ld, sim=True) == V                       # every VAMP: 1 slot, 1+1
    own = SimpleNamespace(cosim=1, simulator="amaranth")
    assert _cosim_estimate(ld, own) == pytest.approx(
        ELABORATE_PER_VAMP * V + SIMULATE_PER_VAMP_TICK * V * run_ticks(ld, 1))


@pytest.mark.parametrize("options, said", [
    ({"interval": 50}, "layout: budget for an interval of at most 50 ticks"),
    ({"vamps": 1}, "layout: budget of 1 VAMP\n"),
    ({"layout": "folded", "share_passes": True}, "layout: folded, passes shared\n"),
    ({"layout": "folded"}, "layout: folded\n")])
def test_the_header_names_the_programs_layout(options, said):
    """An --interval program (a budget layout on 3 VAMPs) was headed 'layout: systolic', and one
    VAMP was '1 VAMPs' (an audit's)."""
    from vampc.rtl.verilog import header
    chain = load_robot(EXAMPLES / "planar2.yaml")
    c = compile_chain(chain, CompileOptions(word="q16.16", **options))
    text = header(SimpleNamespace(ld=loaded_from_compiled(c, "<test>"), name="planar2"))
    assert said in text, text
    V = len(c.network.vamps)
    assert f"; {V} VAMP{'s' if V != 1 else ''}, period {c.network.period} ticks" in text
