"""The benchmarks/ scripts a user runs (README, Scale and the sections that quote them): each says
what it does with --help, and the emulator's throughput script runs through on a small instance.
A new user found `tree_depth.py --help` a traceback, `rtl.py --help` and `error_correction.py
--help` starting runs of 10 and 40 minutes, and `emulate_throughput.py` failing halfway through every
run (an API it used had changed under it)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parent.parent / "benchmarks"
SCRIPTS = sorted(BENCHMARKS.glob("*.py"))


def test_the_scripts_are_found():
    assert len(SCRIPTS) >= 18 and BENCHMARKS / "scale.py" in SCRIPTS


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_every_benchmark_says_what_it_does_with_help(script, tmp_path):
    done = subprocess.run([sys.executable, str(script), "--help"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert done.stdout.startswith(f"usage: {script.name} ") and "--help" in done.stdout, done.stdout
    assert list(tmp_path.iterdir()) == []          # (rtl.py had begun a run, its results file here)


def test_the_throughput_benchmark_runs_through(tmp_path):
    """benchmarks/emulate_throughput.py on 500 states: every section printed, the engines equal."""
    from vampc.emulator import native
    if native.compiler() is None:
        pytest.skip("no C compiler: the script times the stream engine's native code")
    done = subprocess.run([sys.executable, str(BENCHMARKS / "emulate_throughput.py"), "--states",
                           "500", "--repeat", "1", "--reference-states", "50", "--tick-sets", "10"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    for said in ("whole process", "compute only", "(d) stream engine, native code",
                 "native == numpy stream (bit for bit): True",
                 "tick == native stream on its 10 sets (bit for bit): True"):
        assert said in out, out
