"""The report's engineering figures (issue "The report a hardware engineer trusts", part 4): each
checked against something that is not the report's own arithmetic: busy VAMP-ticks against the
graph's work (every op runs once a set on its VAMPs, whatever the layout), host inputs against what
the emulator's host actually writes, the critical path against networkx's longest path, and the
CPU reference as a measurement (positive, labelled, absent unless asked for)."""
from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES
from test_latency_split import longest_path

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain
from vampc.emulator.host import port_values, random_trajectory
from vampc.emulator.load import loaded_from_compiled
from vampc.report.engineering import engineering
from vampc.robot import load_robot
from vampc.schedule.budget import work


@pytest.mark.parametrize("options", [dict(), dict(layout="folded"), dict(recursion="log"),
                                     dict(vamps=7), dict(recursion="log", layout="folded", share_passes=True)],
                         ids=["systolic", "folded", "log", "budget7", "log-folded-shared"])
def test_utilisation_host_io_and_critical_path(options):
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(**options))
    e = engineering(c, 20e6)
    u = e["utilisation"]
    w = work(c.graph, c.schedule.timing)
    assert u["busy_ticks_per_set"] == w
    assert u["vamp_ticks_per_set"] == c.schedule.interval * len(c.network.vamps)
    assert u["mean"] == pytest.approx(w / u["vamp_ticks_per_set"], abs=1e-4)
    assert 0 < u["min"] <= u["mean"] <= u["max"] <= 1
    # what the emulator's host writes for one set
    ld = loaded_from_compiled(c)
    written = sum(v.shape[1] for v in port_values(ld, random_trajectory(c.chain, 1, 0)).values())
    io = e["host_io"]
    assert io["scalars_in_per_set"] == written and io["scalars_out_per_set"] == 6
    assert io["bits_in_per_set"] == 64 * written
    assert io["scalars_in_per_second"] == pytest.approx(written * 20e6 / c.schedule.interval, rel=1e-5)
    # the critical path, op by op: a chain of operands as long as the longest path (networkx)
    path = e["critical_path"]
    t = c.schedule.timing
    assert sum(x["flops"] for x in path) == longest_path(c.graph, t)
    assert all(a["node"] in c.graph.nodes[b["node"]].args for a, b in zip(path, path[1:]))
    assert all(x["flops"] == t.duration(c.graph.nodes[x["node"]].op) for x in path)
    assert e["cpu_reference"] is None


def test_the_host_reads_each_joints_torque_once_a_set_at_the_clocks_rate():
    """`report --clock 20MHz`'s outputs per second against README's definitions, computed here:
    one flop per tick (--clock), so a set every interval_flops / 20 MHz, each set reading one torque
    per joint of the robot file (its joints counted with PyYAML: a fixed base adds no wrench) in
    words of the program's format (float64 by default: 64 bits). (Scalars out per second had been
    outputs × the interval, and bits out the host's write bits: no test read them.)"""
    import yaml
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--clock", "20MHz",
                                  "--format", "json"])
    assert r.exit_code == 0, r.output
    rep = json.loads(r.output)
    io = rep["engineering"]["host_io"]
    outputs = len(yaml.safe_load((EXAMPLES / "puma560.yaml").read_text())["joints"])
    sets = 20e6 / 1 / rep["interval_flops"]            # Hz / (ticks per flop) / flops per set
    assert outputs == 6 and rep["interval_flops"] > 1
    assert io["scalars_out_per_second"] == pytest.approx(outputs * sets, abs=0.5)
    assert io["bits_out_per_second"] == pytest.approx(64 * outputs * sets, abs=0.5)


def test_the_section_prints_and_the_cpu_reference_is_measured_when_asked():
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--clock", "20MHz",
                                  "--cpu-reference"])
    assert r.exit_code == 0, r.output
    assert "Engineering figures" in r.output and "utilisation    mean 45.0% of the interval" in r.output
    assert "CPU reference  vampc's reference Newton-Euler (numpy), one set at a time:" in r.output
    assert "measured on this machine" in r.output
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--tradeoff", "--cpu-reference"])
    assert r.exit_code == 2 and "--cpu-reference does not apply to --tradeoff" in r.output


def test_the_package_line_counts_multiplexer_pins():
    """Puma --vamps 12: a VAMP needs up to 37 pins, so 12 / 10 packages of 40 pins (the pin-aware
    table's figures), not the paper budget's 3 / 1, which follows as the comparison."""
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--vamps", "12"])
    line = next(x for x in r.output.splitlines() if x.startswith("40-pin packages"))
    assert line.startswith("40-pin packages  12 with separate pins or 10 with shared") and "up to 37" in line
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml")])       # systolic: the same
    assert "40-pin packages  36 (5 VAMPs each, separate pins) or 15 (12 each" in r.output


def test_a_vamp_that_needs_more_pins_than_a_package_has_gets_none():
    """Puma --vamps 7: a VAMP with its multiplexer inputs needs 45 pins, more than 40: no 40-pin
    package holds it, and the line and table say so rather than the paper budget's 2 / 1 alone."""
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--vamps", "7"])
    line = next(x for x in r.output.splitlines() if x.startswith("40-pin packages"))
    assert line.startswith("40-pin packages  none: with each operand wire a pin, a VAMP here "
                           "needs up to 45 pins, more than a 40-pin package has")
    rows = [x for x in r.output.splitlines() if x.startswith("linear, budget, 7 VAMPs (this")]
    assert "none / none" in rows[-1]                         # the packages table's row and "none: a VAMP needs more pins than the package has" in r.output
    wide = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--vamps", "7",
                                     "--pins", "64", "--format", "json"])
    at64 = json.loads(wide.output)["packages"]["rows"]
    own = next(r for r in at64 if r["own"])["by_pins"]
    assert own[0]["muxed_separate"] is None and own[1]["pins"] == 64 and own[1]["muxed_separate"] >= 1


def test_a_cpu_reference_of_torques_past_the_float_range_is_said(tmp_path):
    """A robot whose masses overflow the reference's arithmetic (1.7e308): --cpu-reference printed
    five of NumPy's own overflow lines and a time for work that gave NaN, saying nothing of it (a
    new user's find). One warning says so; the report goes on."""
    robot = tmp_path / "huge.yaml"
    robot.write_text((EXAMPLES / "planar2.yaml").read_text().replace("mass: 2.0", "mass: 1.7e308"))
    assert "1.7e308" in robot.read_text()
    r = CliRunner().invoke(main, ["report", str(robot), "--cpu-reference", "--clock", "1MHz"])
    assert r.exit_code == 0, r.output
    assert r.stderr == ("vampc: warning: --cpu-reference: the reference torques of the timed states "
                        "are not finite numbers (the robot's numbers overflow a float): the times are "
                        "of that arithmetic\n"), r.stderr
    assert "CPU reference" in r.stdout


def test_pinocchio_is_timed_only_on_the_robot_the_network_computes(tmp_path, monkeypatch):
    """--cpu-reference built Pinocchio's model from the URDF file whatever the options: a 9-joint
    Panda was timed beside a network of 7 (--lock), a fixed base beside a floating one, and a
    program whose URDF was gone printed Pinocchio's C++ errors (a new user's find). Now its time is
    left out where the model is not the network's robot, saying why."""
    import shutil
    pytest.importorskip("pinocchio")
    monkeypatch.chdir(tmp_path)
    shutil.copy(EXAMPLES / "arm6.urdf", "arm.urdf")

    def reference(*args):
        res = CliRunner().invoke(main, ["report", *args, "--cpu-reference", "--format", "json"])
        assert res.exit_code == 0, res.output
        return json.loads(res.stdout)["engineering"]["cpu_reference"]
    whole = reference("arm.urdf")
    assert "not_measured" not in whole and any("Pinocchio" in m["what"] for m in whole["measured"])
    for args, why in ((["arm.urdf", "--lock", "wrist_bend=0"], "6 joints in the file against 5 here"),
                      (["arm.urdf", "--floating-base"], "a floating base")):
        got = reference(*args)
        assert why in got["not_measured"] and not any("Pinocchio" in m["what"] for m in got["measured"])
    assert CliRunner().invoke(main, ["compile", "arm.urdf", "-o", "arm.vamp.json"]).exit_code == 0
    (tmp_path / "arm.urdf").unlink()
    got = reference("arm.vamp.json")
    assert "the URDF arm.urdf is not found from here" in got["not_measured"]


def test_the_control_logic_line_gives_each_count_at_its_own_width(tmp_path):
    """The control-logic line, counted from planar2's folded q16.16 program file (section VII: the
    delays "implemented by counters and comparators"): a Cycle-Counter of P.bit_length() bits on
    each VAMP and one for the buffers; three comparators a slot against it; one a block end of the
    buffer clock (P / clock ends a period); a subtractor a slot one bit wider than the counter; two
    comparators of a word a VAMP (its number and its negation); a slot-address comparator a slot.
    Only the golden report's bytes had seen the line's widths and its buffer-clock clause wrong
    (a mutation audit's: the subtractors given the counter's width, the word comparators the
    counter's, the buffer clock's comparators left out)."""
    program = tmp_path / "p.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                  "--layout", "folded", "-o", str(program)])
    assert r.exit_code == 0, r.output
    doc = json.loads(program.read_text())
    P, clock, V = doc["network"]["period"], doc["network"]["clock"], len(doc["network"]["vamps"])
    slots = sum(len(p["slots"]) for p in doc["programs"])
    assert doc["network"]["buffers"] and 1 < clock < P and P % clock == 0
    b = P.bit_length()
    text = CliRunner().invoke(main, ["report", str(program)]).output
    line = next(x for x in text.splitlines() if x.startswith("control logic"))
    assert line.split(None, 2)[2] == (
        f"{V + 1} Cycle-Counters of {b} bits with their incrementers; comparators of {b} bits "
        f"against them: {3 * slots} of the slots' delays (3 a slot), {P // clock} of the buffer "
        f"clock's ticks; {slots} subtractors of {b + 1} bits with their wrap-around adders (the "
        "ticks to a slot's dump, mod the period, addressing the ROM); "
        f"{2 * V} comparators of 32 bits (a VAMP's number and its negation in Program Mode) and "
        f"{slots} of a slot address")
