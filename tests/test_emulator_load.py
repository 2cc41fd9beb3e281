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


@pytest.mark.parametrize("how", ["split", "duplicate"])
def test_two_entries_for_one_input_buffer_are_refused_by_both_engines(tmp_path, how):
    """One input buffer's words split into two entries with the same root were run by the stream
    engine with an 8-tick load no buffer could deliver (one word a tick; it needed 13), refused by
    the tick engine, and a whole entry listed twice was taken by both, the report counting 20 input
    buffers for 19 (a hardware audit). The loader refuses a root listed twice, for both engines."""
    import json
    chain = load_robot(EXAMPLES / "planar2.yaml")
    doc = copy.deepcopy(program_document(compile_chain(chain)))
    stream = doc["program_stream"]
    if how == "split":
        i = max(range(len(stream)), key=lambda k: len(stream[k]["words"]))
        e, k = stream[i], len(stream[i]["words"]) // 2
        stream[i:i + 1] = [{**e, **{x: e[x][:k] for x in ("words", "targets", "depth")}},
                           {**e, **{x: e[x][k:] for x in ("words", "targets", "depth")}}]
        doc["io"]["load_ticks"] = max(max(j + 1 + d for j, d in enumerate(e["depth"])) for e in stream)
    else:
        stream.append(copy.deepcopy(stream[0]))
    doc["checksum"] = checksum(doc)
    with pytest.raises(VampcError, match=r"program stream: .* has two entries"):
        loaded_from_doc(doc)
    path = tmp_path / f"{how}.vamp.json"
    path.write_text(json.dumps(doc))
    for engine in ("stream", "tick"):
        res = CliRunner().invoke(main, ["emulate", str(path), "--random", "5", "--engine", engine])
        assert res.exit_code == 1 and "has two entries" in res.stderr, (engine, res.stderr)
    res = CliRunner().invoke(main, ["report", str(path)])
    assert res.exit_code == 1 and "has two entries" in res.stderr, res.stderr
