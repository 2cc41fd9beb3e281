"""`vampc report` (vampc.cli): formats, --clock, --pins, the picture and page outputs, and their
errors — one line, exit 1 or 2, no partial file."""
from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES
from schema_check import schema_errors

from vampc.cli import main

PUMA = EXAMPLES / "puma560.yaml"
PLANAR = EXAMPLES / "planar2.yaml"


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def one_line_error(res, code: int, pattern: str) -> None:
    assert res.exit_code == code, (res.stdout, res.stderr)
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("vampc: error: "), res.stderr
    assert re.search(pattern, lines[0]), lines[0]
    assert res.stdout == ""


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    path = tmp_path_factory.mktemp("prog") / "puma.vamp.json"
    assert run("compile", PUMA, "-o", path).exit_code == 0
    return path


def test_text_report_has_every_section():
    out = run("report", PUMA).stdout
    for title in ("Table O.1a, the paper's formulas", "Table O.1 at n = 6, from the paper's formulas",
                  "Table O.1, vampc's figures for puma560", "Layouts, linear recursion",
                  "VAMPs, linear, n = 6", "Requirements per node", "Packages (section VII)",
                  "Buffering (section VI)", "Wiring (section VI)"):
        assert re.search(rf"^{re.escape(title)}", out, re.M), title
    assert "differs: note 1" in out and "1. Uicker/Kahn (original Lagrangian): Mults:" in out


@pytest.mark.parametrize("layout", ["systolic", "folded"])
def test_the_log_leaves_note_is_said_once(layout):
    # a folded log report said it twice, once in the single-device note's words, once in the
    # general one's (review, 2026-12-02)
    out = run("report", PUMA, "--recursion", "log", "--layout", layout).stdout
    notes = [line for line in out.splitlines() if line.strip().startswith("leaves are Table IV.1")]
    assert len(notes) == 1, notes
    out = run("report", PUMA, "--recursion", "log", "--layout", layout, "--uniform-leaves").stdout
    assert not any(line.strip().startswith("leaves are") for line in out.splitlines())


def test_markdown_report():
    out = run("report", PUMA, "--format", "markdown").stdout
    assert out.startswith("## vampc report: puma560\n")
    assert "### Table O.1 at n = 6, from the paper's formulas" in out
    assert "| Lathrop (linear parallel N.E.) | 15 | 43 | 58 | 15 + 43 | agrees |" in out


def test_json_report_validates_and_carries_the_clock(program):
    res = run("report", program, "--format", "json", "--clock", "20MHz", "--pins", "64")
    rep = json.loads(res.stdout)
    assert not schema_errors("report", rep)
    assert rep["clock"]["latency_us"] == 3.05 and rep["clock"]["sets_per_second"] == 5e6
    assert rep["packages"]["pins"] == [40, 64]
    lin = next(r for r in rep["table_o1"]["measured"] if r["configuration"] == "linear, systolic")
    assert lin["time_us"] == 3.05 and lin["sets_per_second"] == 5e6


def test_each_measured_table_o1_row_gives_its_interval_and_latency_in_time(program):
    """Table O.1's measured rows at --clock 20MHz (one flop per tick, README: 0.05 µs a flop),
    computed here from each row's own flops: interval_us is its interval's flops / 20, time_us its
    latency's; the rows' intervals are not their latencies (it had given the latency's time as the
    interval's: the systolic row's 0.2 µs read 3.05)."""
    rep = json.loads(run("report", program, "--format", "json", "--clock", "20MHz").stdout)
    rows = [r for r in rep["table_o1"]["measured"] if "interval_flops" in r]
    assert rows and any(r["interval_flops"] != r["flops"] for r in rows)
    for row in rows:
        assert row["interval_us"] == pytest.approx(row["interval_flops"] / 20.0, rel=1e-5), row
        assert row["time_us"] == pytest.approx(row["flops"] / 20.0, rel=1e-5), row


@pytest.mark.parametrize("args", [(PUMA, "--vamps", "12"), (PUMA, "--recursion", "log", "--interval", "150"),
                                  (EXAMPLES / "quadruped.urdf",), (PLANAR, "--floating-base")])
def test_json_report_of_a_budget_or_a_tree_validates(args, tmp_path):
    """Budgeted layouts and trees add keys of their own; their pictures draw too. (The log Puma's
    interval budget of 150 flops: 6 VAMPs; 40 took 3.6 s to find its 20.)"""
    svg = tmp_path / "t.svg"
    res = run("report", *map(str, args), "--format", "json", "--timing", str(svg),
              "--network", str(tmp_path / "n.svg"))
    assert res.exit_code == 0, res.stderr
    rep = json.loads(res.stdout)
    assert not schema_errors("report", rep)
    if "--interval" in args:
        assert rep["layout"] == "budget" and rep["interval_flops"] <= 150
    if "--vamps" in args:
        assert rep["layout"] == "budget" and rep["budget"]["vamps_used"] <= 12
        assert rep["vamps"]["total"] <= 12
        # the timing chart's rows are the budget's VAMPs, one per row
        assert ET.parse(svg).getroot() is not None
    else:
        assert rep["budget"] is None or rep["layout"] == "budget"
    if args[0] != PUMA:
        assert rep["tree"]["outputs"] >= rep["joints"]


def test_clock_says_which_control_rates_are_met():
    out = run("report", PUMA, "--clock", "20MHz").stdout
    assert ("clock            20 MHz: latency 3.05 µs, a torque set every 200 ns (5,000,000 per "
            "second)") in out
    assert "at 20 MHz the design meets 60 Hz, 1 kHz and 10 kHz control" in out
    # 20 MHz / 61 flops / 60 Hz = 5 464.5 (to 3 digits, ×5,460, until 2026-12-05)
    assert "60 Hz control   met (×5,464); the paper's \"about 60Hz or faster\" (section I)" in out
    # 2 GHz / 29 flops / 60 Hz = 1 149 425.3: a whole number (6 digits gave ×1,149,430)
    out = run("report", EXAMPLES / "planar2.yaml", "--clock", "2GHz").stdout
    assert "60 Hz control   met (×1,149,425);" in out


@pytest.mark.parametrize("value", ["fast", "20 MHzz", "0Hz", "-1MHz"])
def test_a_bad_clock_is_one_line(value):
    one_line_error(run("report", PUMA, "--clock", value), 2, r"--clock '.*'")


def test_too_few_pins_is_a_usage_error():
    assert run("report", PUMA, "--pins", "7").exit_code == 2


def test_pictures_and_page_are_written(tmp_path):
    files = {opt: tmp_path / name for opt, name in (("--timing", "t.svg"), ("--network", "n.svg"),
                                                     ("--dot", "n.dot"), ("--html", "p.html"))}
    res = run("report", PLANAR, "--recursion", "log", *[x for kv in files.items() for x in kv])
    assert res.exit_code == 0, res.stderr
    assert res.stdout.startswith("robot            planar2")
    for opt in ("--timing", "--network"):
        ET.fromstring(files[opt].read_text())
    assert files["--dot"].read_text().count("digraph ") == 2
    assert files["--html"].read_text().count("<svg") == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["n.dot", "n.svg", "p.html", "t.svg"]


def test_a_program_draws_what_its_robot_draws(tmp_path, program):
    a, b = tmp_path / "a.svg", tmp_path / "b.svg"
    assert run("report", PUMA, "--timing", a).exit_code == 0
    assert run("report", program, "--timing", b).exit_code == 0
    assert a.read_bytes() == b.read_bytes()


def test_a_picture_over_the_input_is_refused(tmp_path):
    robot = tmp_path / "planar2.yaml"
    robot.write_bytes(PLANAR.read_bytes())
    one_line_error(run("report", robot, "--timing", robot), 1, r"vampc never writes over its inputs")
    assert robot.read_bytes() == PLANAR.read_bytes()


def test_an_unwritable_picture_path_writes_nothing(tmp_path):
    res = run("report", PLANAR, "--timing", tmp_path / "t.svg", "--network",
              tmp_path / "missing" / "n.svg")
    one_line_error(res, 1, r"n\.svg: folder .*missing does not exist")
    assert list(tmp_path.iterdir()) == []


def test_two_pictures_into_one_file_are_refused(tmp_path):
    res = run("report", PLANAR, "--timing", tmp_path / "x.svg", "--network", tmp_path / "x.svg")
    one_line_error(res, 1, r"--network and --timing name the same file")


def test_a_picture_to_stdout_is_refused(tmp_path):
    one_line_error(run("report", PLANAR, "--timing", "-"), 2, r"standard output is not available")   # usage


def test_compile_options_that_contradict_a_program_are_refused(program):
    res = run("report", program, "--recursion", "log", "--timing", "x.svg")
    assert res.exit_code == 2 and "was compiled with --recursion linear" in res.stderr


def test_latency_line_adds_up_and_trees_are_not_held_to_the_chain_formula():
    rep = json.loads(run("report", PUMA, "--recursion", "log", "--layout", "folded",
                         "--format", "json").stdout)
    lat = rep["latency"]
    assert lat["waits"] > 0 and lat["mults"] + lat["adds"] + lat["waits"] == lat["flops"]
    out = run("report", PUMA, "--recursion", "log", "--layout", "folded").stdout
    assert (f"latency          {lat['flops']} flops = {lat['mults']} Mults + {lat['adds']} Addns + "
            f"{lat['waits']} waiting on the critical path") in out
    tree = run("report", EXAMPLES / "quadruped.urdf").stdout
    assert "a tree's or a floating base's latency follows its depth" in tree
    assert "output correction" not in tree.split("interval")[0]


def test_one_vamp_is_singular():
    res = run("compile", PLANAR, "--vamps", "1", "-o", "-")
    assert ", 1 VAMP, latency " in res.stderr, res.stderr
    assert "budget           1 VAMP used of 1 allowed" in run("report", PLANAR, "--vamps", "1").stdout


@pytest.mark.parametrize("option, says", [
    (["--prefix", "sklansky"], "--prefix applies to the log recursion only; .* was compiled with "
                               "--recursion linear"),
    (["--prefix", "serial"], "--prefix applies to the log recursion only"),
    (["--rounding", "nearest"], "--rounding applies to fixed-point words .* computes in float64"),
    (["--overflow", "saturate"], "--overflow applies to fixed-point words"),
    (["--check-cycles", "1"], "--check-cycles applies with --error-correction; .* compiled without it")])
def test_an_option_that_does_not_apply_to_the_program_is_refused(tmp_path, option, says):
    """With a linear float64 program these passed unsaid (the file records no value for them, so
    their defaults were compared), and `--prefix serial` said the program "was compiled with
    --prefix sklansky"; each is a usage error for the robot file compiled so."""
    program = tmp_path / "puma.vamp.json"
    assert run("compile", PUMA, "-o", program).exit_code == 0
    one_line_error(run("report", program, *option), 2, says)


def test_the_trade_off_of_a_bus_program_says_it_sweeps_point_to_point(tmp_path):
    """A program on the Mostly-Local Bus was swept wired point to point with no word (a robot
    file's --bus is refused with --tradeoff)."""
    program = tmp_path / "bus.vamp.json"
    assert run("compile", EXAMPLES / "planar2.yaml", "--recursion", "log", "--bus", "mlb", "-o",
               program).exit_code == 0
    res = run("report", program, "--tradeoff")
    assert res.exit_code == 0 and res.stderr.startswith("vampc: warning: ")
    assert "Mostly-Local Bus: the trade-off sweeps its robot's budgets wired point to point" in res.stderr


@pytest.mark.parametrize("args, section", [(["--recursion", "log", "--bus", "mlb"], "bus"),
                                           (["--word", "q16.16", "--error-correction"], "error_correction")])
def test_the_package_count_packs_the_pins_the_report_says_a_vamp_needs(tmp_path, args, section):
    """A bus program's packages were counted at 9 pins a VAMP beside a bus section of 30, and an
    error-correction program's at 8 for 180 VAMPs beside "181 in all, up to 17 pins": the count
    now packs the pins those sections give, every VAMP (the extraneous one too)."""
    import json
    import math
    program = tmp_path / "p.vamp.json"
    assert run("compile", PLANAR, *args, "-o", program).exit_code == 0
    rep = json.loads(run("report", program, "--format", "json").stdout)
    own = next(row for row in rep["packages"]["rows"] if row["own"])["by_pins"][0]
    pins = rep[section]["pins_per_vamp"]["bus" if section == "bus" else "with"]
    vamps = rep[section]["vamps"] if section == "error_correction" else rep["vamps"]["backward"] + \
        rep["vamps"]["forward"]
    assert own["pins"] == 40 and own["max_pins_per_vamp"] == pins["max"]
    total = round(pins["mean"] * vamps)               # every VAMP's pins, from the section's mean
    assert math.ceil(total / 40) <= own["muxed_separate"] <= vamps
    assert own["muxed_shared"] <= own["muxed_separate"]
    if section == "bus":
        # worked out here from the wiring: a VAMP on the bus keeps the paper's 8 pins but its two
        # operand pins, and has one per tier and one per operand input not on the bus; packed in
        # order into 40-pin packages, a new package when the next VAMP does not fit
        from vampc.emulator.load import load_program
        from vampc.kinds import TapKind
        net = load_program(str(program)).net
        each = [8 - 2 + len(net.bus.tiers) + sum(not any(t.kind is TapKind.BUS for t in op.taps)
                                                 for op in v.a + v.b) for v in net.vamps]
        packages, used = 0, 40
        for need in each:
            packages, used = (packages + 1, need) if used + need > 40 else (packages, used + need)
        assert own["muxed_separate"] == packages and max(each) == own["max_pins_per_vamp"]


def test_constants_a_word_cannot_hold_are_warned_of_at_compile_and_report(tmp_path):
    """q3.13 cannot hold the Puma's link masses m2, m3 or gravity pdd0 (beyond ±4): compile and
    report said nothing, and `vampc emulate` then counted them among its overflows. Both warn now,
    naming them; q16.16 holds every constant and draws no warning."""
    from vampc.emulator.load import load_program
    from vampc.emulator.stream import constant_overflows
    program = tmp_path / "q3.vamp.json"
    res = run("compile", PUMA, "--word", "q3.13", "-o", program)
    assert res.exit_code == 0
    assert "3 constants beyond the range of q3.13 (pdd0, m2, m3): the host's conversion saturates" \
        in res.stderr, res.stderr
    assert constant_overflows(load_program(str(program))) > 0      # the emulator's own count
    assert "beyond the range of q3.13 (pdd0, m2, m3)" in run("report", program).stderr
    res = run("compile", PUMA, "--word", "q16.16", "-o", tmp_path / "q16.vamp.json")
    assert res.exit_code == 0 and "warning" not in res.stderr


def test_a_control_rate_missed_by_a_hair_is_never_shown_as_met():
    """At 609.9 kHz the Puma's 61-flop latency allows 9 998.4 Hz: 10 kHz is missed by 0.016%, and
    the report said "not met (×1)", its JSON margin 1.0 beside met false."""
    from vampc.report.clock import clock_figures, margin_text
    fig = clock_figures(61, 4, 0, 609.9e3)
    ten = next(r for r in fig["control_rates"] if r["hz"] == 10_000)
    assert ten["met"] is False and ten["margin"] < 1 and ten["margin"] == pytest.approx(609.9e3 / 61 / 1e4)
    assert margin_text(ten["margin"]) == "needs a ×1.00017 faster clock"     # (rounded up: 1.000164)
    assert margin_text(0.5) == "needs a ×2 faster clock" and margin_text(3.44) == "×3.44"
    exact = clock_figures(61, 4, 0, 610e3)["control_rates"][2]
    assert exact["met"] is True and exact["margin"] == 1.0


def test_the_option_that_decides_what_applies_is_blamed_first(tmp_path):
    """`--word q16.16 --rounding truncate` on a float64 report blamed --rounding (dropping it only
    led to --word's error); a what-if --word float64 with --rounding said the program computes in
    float64 (it is q16.16; the --word asked for is not fixed point)."""
    program, q16 = tmp_path / "puma.vamp.json", tmp_path / "q16.vamp.json"
    assert run("compile", PUMA, "-o", program).exit_code == 0
    assert run("compile", PUMA, "--word", "q16.16", "-o", q16).exit_code == 0
    one_line_error(run("report", program, "--word", "q16.16", "--rounding", "truncate"), 2,
                   r"^vampc: error: --word q16\.16: .* was compiled with --word float64")
    one_line_error(run("emulate", q16, "--random", "2", "--word", "float64", "--rounding", "truncate"),
                   2, r"--rounding applies to fixed-point words \(qI\.F\) only; --word float64 is not one")


def test_clock_help_and_refusal_agree_on_tradeoff():
    """--clock's help says it does not apply to --tradeoff, which refuses it (it said "adds times
    ... to every figure" and nothing of the sweep)."""
    help_text = " ".join(run("report", "--help").stdout.split())
    assert "torque sets per second to every figure. Does not apply to --tradeoff." in help_text
    one_line_error(run("report", PLANAR, "--tradeoff", "--clock", "50MHz"), 2,
                   r"--clock does not apply to --tradeoff \(see")


def test_packages_say_the_rtl_moves_words_in_parallel():
    """The packages count section VII's pins, a word serially on one pin per operand wire; a new
    user read them as the packages of `vampc rtl`'s Verilog, whose VAMPs take three words in
    parallel on each operand input (26-bit ports, three to an input): the note says so, in the
    report's own word."""
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--word", "q12.14"])
    assert r.exit_code == 0, r.output
    assert ("the Verilog of `vampc rtl` moves them in parallel, three 26-bit words on each operand "
            "input and on the Result (78 wires each), so its VAMPs are not these packages "
            "(README, RTL)") in r.stdout
