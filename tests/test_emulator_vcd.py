"""The VCD writer: a tick-engine run written as VCD and read back with vcdvcd (an independent reader)
equals, for every VAMP, axis and sampled tick, the Result the engine showed, bit for bit."""
from __future__ import annotations

import errno
import io
import re
from pathlib import Path

import numpy as np
import pytest
from emulator_util import loaded

from vampc.emulator.host import port_values, random_trajectory
from vampc.emulator.tick import TickEngine
from vampc.emulator.vcd import VcdWriter, scope_names
from vampc.robot import load_robot

vcdvcd = pytest.importorskip("vcdvcd")

EXAMPLES = Path(__file__).parent.parent / "examples"
ROBOTS = ["planar2.yaml", "puma560.yaml"]


class Recorder:
    """Stores every (tick, Results) the engine shows and passes it on to a VcdWriter."""

    def __init__(self, writer: VcdWriter):
        self.writer = writer
        self.ticks: list[int] = []
        self.values: list[np.ndarray] = []

    def sample(self, tick: int, values: np.ndarray) -> None:
        """Record a copy (the engine passes a view of its live registers), then write."""
        self.ticks.append(tick)
        self.values.append(values.copy())
        self.writer.sample(tick, values)


def _cli_names(ld) -> list[str]:
    """Scope names as `vampc emulate --vcd` builds them: number, section, group and node name."""
    from vampc.emulator.vcd import vamp_names
    return vamp_names(ld)


def _odd_names(ld) -> list[str]:
    """The emulator's own VAMP names: spaces, parentheses, commas and dots ("VAMP 0 (number 1, ...)")."""
    return [ld.vamp_name(v.index) for v in ld.net.vamps]


def _run(robot: str, path: Path, names_of=_cli_names, count: int = 3, seed: int = 5):
    """Program and run the tick engine on `count` random sets, writing `path`; (names, Recorder)."""
    ld = loaded(load_robot(EXAMPLES / robot))
    traj = random_trajectory(ld.chain, count, seed)
    names = names_of(ld)
    with open(path, "w") as fh:
        rec = Recorder(VcdWriter(fh, names))
        engine = TickEngine(ld, seed=seed, vcd=rec)
        engine.program()
        engine.run(port_values(ld, traj), count)
        rec.writer.close()
        assert not fh.closed
    return names, rec


def _read_back(vcd, scopes: list[str], ticks: list[int]) -> np.ndarray:
    """(T, V, 3): the value of each signal at each tick, as the reader sees it."""
    out = np.empty((len(ticks), len(scopes), 3))
    for v, scope in enumerate(scopes):
        for c, axis in enumerate("xyz"):
            signal = vcd[f"network.{scope}.{axis}"]
            out[:, v, c] = [float(signal[t]) for t in ticks]
    return out


def _assert_bits_equal(back: np.ndarray, rec: np.ndarray, ticks: list[int], scopes) -> None:
    bad = np.argwhere(back.view(np.uint64) != rec.view(np.uint64))
    if bad.size:
        t, v, c = bad[0]
        raise AssertionError(f"{len(bad)} values differ; first at tick {ticks[t]}, {scopes[v]}."
                             f"{'xyz'[c]}: read {back[t, v, c]!r}, engine {rec[t, v, c]!r}")


@pytest.mark.parametrize("robot", ROBOTS)
def test_tick_run_reads_back_bit_for_bit(tmp_path, robot):
    names, rec = _run(robot, tmp_path / "w.vcd")
    vcd = vcdvcd.VCDVCD(str(tmp_path / "w.vcd"))
    scopes = scope_names(names)
    back = _read_back(vcd, scopes, rec.ticks)
    _assert_bits_equal(back, np.array(rec.values), rec.ticks, scopes)
    assert rec.ticks == list(range(1, len(rec.ticks) + 1))
    assert (vcd.begintime, vcd.endtime) == (rec.ticks[0], rec.ticks[-1])


def test_odd_vamp_names_become_legal_scopes_and_still_read_back(tmp_path):
    names, rec = _run("planar2.yaml", tmp_path / "w.vcd", names_of=_odd_names)
    vcd = vcdvcd.VCDVCD(str(tmp_path / "w.vcd"))
    scopes = scope_names(names)
    assert all(re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", s) for s in scopes)
    assert (names[0], scopes[0]) == ("VAMP 0 (number 1, bwd1.T2)", "VAMP_0__number_1__bwd1_T2_")
    _assert_bits_equal(_read_back(vcd, scopes, rec.ticks), np.array(rec.values), rec.ticks, scopes)


def test_only_changes_are_written(tmp_path):
    names, rec = _run("puma560.yaml", tmp_path / "w.vcd")
    vcd = vcdvcd.VCDVCD(str(tmp_path / "w.vcd"))
    bits = np.array(rec.values).view(np.uint64)
    changes = 1 + (bits[1:] != bits[:-1]).sum(axis=0)       # the $dumpvars value, then each change
    written = np.array([[len(vcd[f"network.{s}.{a}"].tv) for a in "xyz"] for s in scope_names(names)])
    assert np.array_equal(written, changes)
    assert written.sum() < 0.5 * bits.size


def test_header(tmp_path):
    names, _ = _run("planar2.yaml", tmp_path / "w.vcd")
    text = (tmp_path / "w.vcd").read_text()
    vcd = vcdvcd.VCDVCD(str(tmp_path / "w.vcd"))
    assert (vcd.timescale["magnitude"], vcd.timescale["unit"]) == (1, "ns")
    assert re.search(r"^\$timescale 1 ns \$end$", text, re.M)
    assert vcd.signals == [f"network.{s}.{a}" for s in sorted(scope_names(names)) for a in "xyz"]
    assert {(vcd[s].var_type, vcd[s].size) for s in vcd.signals} == {("real", "64")}
    assert text.count("$scope module ") == len(names) + 1
    assert "$date" not in text and text.index("$enddefinitions $end") < text.index("#1\n")


def test_output_is_deterministic(tmp_path):
    _run("planar2.yaml", tmp_path / "a.vcd")
    _run("planar2.yaml", tmp_path / "b.vcd")
    assert (tmp_path / "a.vcd").read_bytes() == (tmp_path / "b.vcd").read_bytes()


def _write(names, samples) -> str:
    out = io.StringIO()
    writer = VcdWriter(out, names)
    for tick, values in samples:
        writer.sample(tick, np.array(values, dtype=float))
    writer.close()
    return out.getvalue()


def test_values_needing_17_digits_and_special_values_round_trip():
    hard = [0.1 + 0.2, 5e-324, -1.7976931348623157e308, 2.0 ** -1074 * 3, 1 / 3]
    samples = [(1, [hard[:3], hard[3:] + [-0.0]]),
               (2, [[np.nan, np.inf, -np.inf], [0.0, -0.0, 179.0]]),
               (3, [[np.nan, np.inf, -np.inf], [-0.0, 0.0, 179.0]])]
    text = _write(["a", "b"], samples)
    vcd = vcdvcd.VCDVCD(vcd_string=text)
    for tick, values in samples:
        back = [[float(vcd[f"network.{s}.{a}"][tick]) for a in "xyz"] for s in "ab"]
        np.testing.assert_array_equal(np.array(back).view(np.uint64)[~np.isnan(back)],
                                      np.array(values).view(np.uint64)[~np.isnan(values)])
        assert np.array_equal(np.isnan(back), np.isnan(values))
    assert len(vcd["network.a.x"].tv) == 2                   # NaN to NaN is no change
    assert len(vcd["network.b.y"].tv) == 3                   # 0.0 to -0.0 and back are


def test_close_without_samples_is_a_valid_vcd_and_leaves_the_stream_open():
    out = io.StringIO()
    VcdWriter(out, ["vamp1_x"]).close()
    vcd = vcdvcd.VCDVCD(vcd_string=out.getvalue())
    assert vcd.signals == ["network.vamp1_x.x", "network.vamp1_x.y", "network.vamp1_x.z"]
    assert vcd["network.vamp1_x.x"][0] == "nan" and not out.closed


def test_scope_names_are_legal_and_unique():
    assert scope_names(["vamp1 a.b", "vamp1_a_b", "", "3x", "ω[2]", "vamp1_a_b_2"]) == \
        ["vamp1_a_b", "vamp1_a_b_2", "_", "_3x", "__2_", "vamp1_a_b_2_2"]


class _FullDisk(io.StringIO):
    def write(self, s):
        raise OSError(errno.ENOSPC, "No space left on device")


def test_a_failed_write_raises_oserror():
    writer = VcdWriter(_FullDisk(), ["a"])
    writer.sample(1, np.zeros((1, 3)))
    with pytest.raises(OSError) as info:
        writer.sample(2, np.ones((1, 3)))
    assert info.value.errno == errno.ENOSPC


def test_vcd_as_word_writes_the_fixed_point_words_as_the_reals_say(tmp_path):
    """`--vcd-as word`: each Result scalar a two's-complement vector of the word's width (a new
    user's: a fixed-point program's waveform was `real 64` signals, which cannot be set beside the
    RTL's 26-bit ports). Read back by vcdvcd, every vector at every tick is the same run's real
    value times 2^F; a float program is refused."""
    from click.testing import CliRunner

    from vampc.cli import main
    robot, run = str(EXAMPLES / "planar2.yaml"), CliRunner().invoke
    common = ["emulate", robot, "--word", "q12.14", "--random", "3", "--engine", "tick", "-o",
              str(tmp_path / "tau.csv")]
    for name, extra in (("real.vcd", []), ("word.vcd", ["--vcd-as", "word"])):
        r = run(main, common + ["--vcd", str(tmp_path / name), *extra])
        assert r.exit_code == 0, r.output
    real, word = (vcdvcd.VCDVCD(str(tmp_path / name)) for name in ("real.vcd", "word.vcd"))
    signals = [s for s in word.signals if s.startswith("network.")]
    assert signals and sorted(signals) == sorted(s for s in real.signals if s.startswith("network."))
    assert {word[s].size for s in signals} == {"26"}
    compared = 0
    for s in signals:
        for t in range(word.begintime, word.endtime + 1):
            bits = int(word[s][t], 2)
            value = (bits - (1 << 26) if bits >> 25 else bits) / 2 ** 14
            assert value == float(real[s][t]), (s, t)
            compared += 1
    assert compared > 1000
    r = run(main, ["emulate", robot, "--random", "3", "--engine", "tick", "--vcd",
                   str(tmp_path / "f.vcd"), "--vcd-as", "word"])
    assert r.exit_code == 2 and "--vcd-as word writes fixed-point words" in r.stderr
    # a fixed-point program run as a float32 what-if: one line, saying the word is --word's (it
    # said the program "computes in float32" after a warning that it computes in q12.14)
    program = tmp_path / "q.vamp.json"
    assert run(main, ["compile", robot, "--word", "q12.14", "-o", str(program)]).exit_code == 0
    r = run(main, ["emulate", str(program), "--word", "float32", "--random", "1", "--engine", "tick",
                   "--vcd", str(tmp_path / "g.vcd"), "--vcd-as", "word"])
    assert r.exit_code == 2 and r.stderr.count("\n") == 1 and r.stderr.startswith(
        f"vampc: error: --vcd-as word writes fixed-point words; {program} is emulated in float32 "
        "(--word float32) (give --word qI.F)"), r.stderr
