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
