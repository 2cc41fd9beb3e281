"""One loader for both engines and for both ways in: a program compiled in this process is emulated
from the compiler's IRs (no program document made), bit-equal to the same program read back from its
document; and a damaged Program-Mode stream gets the same verdict from the stream and tick engines."""
from __future__ import annotations

import copy

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain, program_document
from vampc.emulator import emulate, loaded_from_compiled, loaded_from_doc
from vampc.emulator.host import random_trajectory
from vampc.errors import VampcError
from vampc.program.file import checksum
from vampc.robot import load_robot

CONFIGS = [{}, {"recursion": "log"}, {"layout": "folded", "share_passes": True}, {"vamps": 5},
           {"mult_latency": 2, "add_latency": 3}]


@pytest.mark.parametrize("opts", CONFIGS, ids=lambda o: "-".join(f"{k}={v}" for k, v in o.items())
                         or "systolic")
def test_in_process_equals_the_document(opts):
    chain = load_robot(EXAMPLES / "stanford.yaml")
    c = compile_chain(chain, CompileOptions(**opts))
    direct, read = loaded_from_compiled(c), loaded_from_doc(program_document(c))
    assert direct.programs == read.programs and direct.net == read.net
    assert direct.load_ticks == read.load_ticks and direct.options == read.options
    traj = random_trajectory(chain, 50, 4)
    for engine in ("stream", "tick"):
        a = emulate(direct, traj if engine == "stream" else _head(traj), engine).tau
        b = emulate(read, traj if engine == "stream" else _head(traj), engine).tau
        assert np.array_equal(a, b), engine


def _head(traj):
    from vampc.emulator.host import Trajectory
    return Trajectory(traj.q[:3], traj.qd[:3], traj.qdd[:3])


@pytest.mark.parametrize("opts", [{}, {"vamps": 5}], ids=["systolic", "budget"])
def test_a_reversed_stream_gets_one_verdict_from_both_engines(tmp_path, opts):
    chain = load_robot(EXAMPLES / "planar2.yaml")
    doc = copy.deepcopy(program_document(compile_chain(chain, CompileOptions(**opts))))
    for entry in doc["program_stream"]:
        entry["words"] = entry["words"][::-1]
    doc["checksum"] = checksum(doc)
    with pytest.raises(VampcError, match="the stream lists VAMP"):
        loaded_from_doc(doc)
    import json
    path = tmp_path / "reversed.vamp.json"
    path.write_text(json.dumps(doc))
    verdicts = set()
    for engine in ("stream", "tick"):
        res = CliRunner().invoke(main, ["emulate", str(path), "--random", "5", "--check",
                                        "--engine", engine])
        verdicts.add((res.exit_code, res.stderr))
    assert len(verdicts) == 1 and next(iter(verdicts))[0] == 1, verdicts
