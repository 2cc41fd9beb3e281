"""Limited automatic error correction (issue 19, part 1): compile --error-correction, the checking of
section VII in the tick engine, Maintenance Mode, and what a file may not claim about it.

Everything here is measured against something the checking does not compute: the same program
compiled without checking (its torques, bit for bit), the reference Newton-Euler, and the fault
the test injected (which VAMP, from which tick)."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from click.testing import CliRunner
from emulator_util import document, mutated

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain
from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.checking import CheckingTickEngine, check_periods, sweep_periods
from vampc.emulator.faults import parse_fault
from vampc.emulator.host import check_torques, port_values, random_trajectory
from vampc.errors import VampcError, VampcUsageError
from vampc.robot import load_robot

PLANAR = load_robot("examples/planar2.yaml")


def _pair(chain, **opts):
    """(plain, checked) loaded programs of one chain and options."""
    plain = loaded_from_doc(document(chain, **{k: v for k, v in opts.items() if k != "check_cycles"}))
    checked = loaded_from_doc(document(chain, error_correction=True, **opts))
    return plain, checked


def _one_joint():
    """A one-joint arm: the layouts' variants checked over whole sweeps in a second or so."""
    from vampc.robot.random import random_chain
    return random_chain(1, 7, prismatic_fraction=0.0)


def _bits(tau):
    return np.ascontiguousarray(tau).view(np.int64)


LAYOUTS = [
    ("planar2", {}), ("planar2", {"recursion": "log"}),
    ("one", {"layout": "folded"}), ("one", {"layout": "folded", "recursion": "log"}),
    ("one", {"vamps": 4}), ("one", {"interval": 9, "recursion": "log"}),
]   # every example, both recursions and layouts: benchmarks/error_correction.py


@pytest.mark.parametrize("robot, opts", LAYOUTS, ids=[f"{r}-{o}" for r, o in LAYOUTS])
def test_without_faults_checking_gives_the_plain_torques_bit_for_bit_over_a_whole_sweep(robot, opts):
    chain = {"planar2": PLANAR, "one": _one_joint()}[robot]
    plain, checked = _pair(chain, **opts)
    V, w = len(checked.net.vamps), checked.net.checking.warmup
    count = sweep_periods(V, w) + 3 * (w + 1) + 8     # a whole sweep, forward and back, and more
    traj = random_trajectory(chain, count, 3)
    want = emulate(plain, traj, "tick").tau
    engine = CheckingTickEngine(checked, seed=3)           # strict: timing errors raise
    engine.program()
    got = engine.run(port_values(checked, traj), count)
    assert np.array_equal(_bits(got), _bits(want))
    assert engine.detections == [] and engine.sweeps == 1
    assert (engine.checked >= 1).all()                      # every VAMP passed a check
    assert engine.checked[list(checked.net.checking.chain[:2])].tolist() == [2, 2]  # next sweep
    stream = emulate(checked, traj, "stream").tau           # the stream engine runs it too
    assert np.array_equal(_bits(stream), _bits(want))
    assert check_torques(chain, traj, got).ok


def test_the_checked_program_differs_only_by_its_checking():
    plain = document(PLANAR)
    checked = document(PLANAR, error_correction=True)
    assert checked["options"]["error_correction"] is True and "error_correction" not in plain["options"]
    ec = checked["network"]["error_correction"]
    assert ec["chain"] == list(range(len(plain["network"]["vamps"]))) and ec["compare"] == 1
    for key in ("program_stream", "programs", "schedule"):  # the same words, the same schedule
        assert checked[key] == plain[key]
    four = document(PLANAR, error_correction=True, check_cycles=4)
    assert four["network"]["error_correction"]["compare"] == 4 and four["options"]["check_cycles"] == 4


def test_a_warm_up_one_period_short_spoils_a_hand_over():
    """The warm-up is what the slots need (vampc.network.checking): one period less and a VAMP
    taking its role back drives a result of an op it did not run whole (the log recursion of
    planar2 has such a slot), which the tags see."""
    from dataclasses import replace

    import msgspec
    _, ld = _pair(PLANAR, recursion="log")
    w = ld.net.checking.warmup
    assert w == 2
    short = replace(ld, net=replace(ld.net, checking=msgspec.structs.replace(ld.net.checking,
                                                                             warmup=w - 1)))
    count = 2 * sweep_periods(len(ld.net.vamps), w) + 8
    traj = random_trajectory(PLANAR, count, 3)
    engine = CheckingTickEngine(short, seed=3)
    engine.program()
    with pytest.raises(VampcError, match="timing error"):
        engine.run(port_values(short, traj), count)


def _faulty_run(ld, spec, count, seed=5):
    traj = random_trajectory(ld.chain, count, seed)
    engine = CheckingTickEngine(ld, seed=seed, faults=[parse_fault(spec)])
    engine.program()
    with np.errstate(all="ignore"):
        tau = engine.run(port_values(ld, traj), count)
    return traj, engine, tau


@pytest.mark.parametrize("kind", ["stuck=result.{c}:63,value=1", "stuck=a.2:62,value=1", "dead"])
def test_a_permanent_fault_is_detected_by_the_predecessor_excised_and_named(kind):
    """On each VAMP a torque is read from: found by its predecessor in the compare periods of its
    stage, excised, its role played so every later set is right by the reference Newton-Euler,
    and named in Maintenance Mode. A stuck data bit the compare periods' data happen to mask can
    instead make the VAMP, once it checks, flag its healthy successor (an escape the campaign
    reports): allowed, and then it is the victim that flags, but not on every output VAMP."""
    _, ld = _pair(PLANAR, check_cycles=2)
    chain = ld.net.checking.order
    P, w, k = ld.period, ld.net.checking.warmup, ld.net.checking.compare
    clean = 0
    for out in ld.net.outputs:
        victim = out.vamp
        pos = chain.index(victim)
        count = check_periods(pos + 1, w, k) + 30
        spec = f"vamp={victim},{kind.format(c='xyz'[out.component])}"   # its torque's sign bit
        traj, engine, tau = _faulty_run(ld, spec, count)
        if not engine.detections:                           # masked: no torque spoiled
            assert "stuck" in kind and check_torques(ld.chain, traj, tau).ok
            continue
        assert len(engine.detections) == 1
        d = engine.detections[0]
        if d["finder"] == victim:                           # the escape, with data masking
            assert "stuck" in kind and d["excised"] == chain[pos + 1]
            continue
        assert d["excised"] == victim and d["finder"] == chain[pos - 1]
        # found in the compare periods of the stage that checks it: the last k of its w + k
        assert (pos - 1) * (w + k) + w <= d["tick"] // P < pos * (w + k)
        after = d["tick"] // P + 1                          # sets entering after the excision
        assert check_torques(ld.chain, _rows(traj, after), tau[after:]).ok
        if kind == "dead":                                  # garbage until then
            assert not check_torques(ld.chain, _rows(traj, 0, after), tau[:after]).ok
        m = engine.maintenance()
        assert m["named"] == [victim] and m["ticks"] > 0
        assert engine.status()["modes"]["inhibited"] == 1
        clean += 1
    assert clean >= 1


def _rows(traj, start, stop=None):
    from vampc.emulator.host import Trajectory
    return Trajectory(traj.q[start:stop], traj.qd[start:stop], traj.qdd[start:stop])


def test_a_fault_in_the_first_vamp_is_found_by_the_extraneous_one():
    _, ld = _pair(PLANAR)
    first = ld.net.checking.chain[0]
    out = ld.net.outputs[0].vamp
    spec = f"vamp={first},dead" if first != out else f"vamp={first},stuck=result.x:62,value=1"
    _, engine, _ = _faulty_run(ld, spec, 20)
    assert engine.detections[0]["finder"] == len(ld.net.vamps)     # E, index V


def test_a_fault_after_its_check_waits_for_the_next_sweep():
    _, ld = _pair(PLANAR)
    V, w, P = len(ld.net.vamps), ld.net.checking.warmup, ld.period
    victim = ld.net.checking.chain[0]
    at = sweep_periods(V, w) * P + 1           # the first sweep is over: it is normal again
    count = sweep_periods(V, w) + 2 * (w + 1) + 10
    _, engine, _ = _faulty_run(ld, f"vamp={victim},dead,at={at}", count)
    d = engine.detections[0]
    assert d["excised"] == victim and engine.sweeps == 1
    assert sweep_periods(V, w) + w <= d["tick"] // P < sweep_periods(V, w) + w + 1


def test_a_vamp_dying_while_it_checks_stalls_the_check_uncaught():
    """An escape by construction (README, Error correction): a dead checker raises neither
    Test-out nor Inhibit-out, and the role it fills is left undriven."""
    _, ld = _pair(PLANAR)
    w, P = ld.net.checking.warmup, ld.period
    victim = ld.net.checking.chain[0]                       # checks from the end of stage 0
    _, engine, _ = _faulty_run(ld, f"vamp={victim},dead,at={(w + 1) * P + 1}", 60)
    assert engine.detections == [] and engine.status()["stage"] == ["fwd", 1]


def test_a_dead_extraneous_checker_stalls_the_check_and_spoils_nothing():
    plain, ld = _pair(PLANAR)
    count = 40
    traj, engine, tau = _faulty_run(ld, f"vamp={len(ld.net.vamps)},dead", count)
    assert engine.detections == [] and engine.sweeps == 0 and engine.checked.sum() == 0
    assert np.array_equal(_bits(tau), _bits(emulate(plain, traj, "tick", seed=5).tau))


def test_error_correction_on_the_bus_is_a_usage_error():
    with pytest.raises(VampcUsageError, match="point-to-point wiring"):
        compile_chain(PLANAR, CompileOptions(error_correction=True, bus="mlb"))
    r = CliRunner().invoke(main, ["compile", "examples/planar2.yaml", "--error-correction", "--bus",
                                  "mlb", "-o", "-"])
    assert r.exit_code == 2 and "systolic, folded and budget" in r.output


@pytest.mark.parametrize("edit, says", [
    (lambda d: d["network"].pop("error_correction"), "no error_correction section"),
    (lambda d: d["options"].pop("error_correction"), "is not true"),
    (lambda d: d["network"]["error_correction"].update(warmup=3), "need 2 period"),
    (lambda d: d["network"]["error_correction"].update(compare=2), "check_cycles is 1"),
    (lambda d: d["network"]["error_correction"].update(chain=[0] * len(d["network"]["vamps"])),
     "a permutation"),
])
def test_a_file_claiming_other_checking_is_refused(edit, says):
    doc = mutated(document(PLANAR, error_correction=True), edit)
    with pytest.raises(VampcError, match=says):
        loaded_from_doc(doc)


def test_the_extraneous_vamp_takes_faults_but_has_no_control_registers_of_its_own():
    _, ld = _pair(PLANAR)
    V = len(ld.net.vamps)
    from vampc.emulator.faults import check_faults
    check_faults([parse_fault(f"vamp={V},stuck=result.x:3")], ld, 100)
    with pytest.raises(VampcError, match="no control registers"):
        check_faults([parse_fault(f"vamp={V},stuck=control.rom:0")], ld, 100)
    with pytest.raises(VampcError, match="there is no VAMP"):
        check_faults([parse_fault(f"vamp={V + 1},dead")], ld, 100)


def test_emulate_reports_the_checking(tmp_path):
    prog = tmp_path / "p.vamp.json"
    run = CliRunner().invoke
    assert run(main, ["compile", "examples/stanford.yaml", "--error-correction", "-o",
                      str(prog)]).exit_code == 0
    victim = 7
    r = run(main, ["emulate", str(prog), "--random", "80", "--engine", "tick", "--fault",
                   f"vamp={victim},dead"])
    assert r.exit_code == 0, r.output
    assert f"excised VAMP {victim}" in r.output and \
        f"naming its successor in the chain, VAMP {victim}" in r.output
    # the finder's burned-in number with its index, not beside another VAMP's index as if one name
    # ("the finder's VAMP-number 7 (VAMP 6) ..., VAMP 7": a new user's find)
    doc = json.loads(prog.read_text())
    finder = victim - 1               # (the chain runs in logical order: a VAMP checks the next)
    number = doc["network"]["vamps"][finder]["number"]
    assert f"VAMP {finder}'s burned-in number, {number}, emerges" in r.output, r.output
    r = run(main, ["emulate", str(prog), "--random", "80", "--engine", "tick"])
    assert "no mismatch" in r.output and "not run by the stream engine" not in r.output
    # the stream engine (the default) computes the torques without the checking: said, where it
    # said nothing of it and `emulate ROBOT --error-correction` looked taken (an options audit's find)
    for source in ([str(prog)], ["examples/stanford.yaml", "--error-correction"]):
        r = run(main, ["emulate", *source, "--random", "8"])
        assert r.exit_code == 0 and "error correction: not run by the stream engine, which computes " \
            "the same torques without it; --engine tick runs the checking" in r.output, r.output
    r = run(main, ["emulate", "examples/stanford.yaml", "--random", "8"])
    assert "error correction" not in r.output


def test_a_vamp_dying_after_its_check_does_not_stall_it():
    """Fault ticks count in Data Mode: a VAMP dying after its stage has moved on is not taken for
    a dead checker (the review found the stall test reading the absolute tick)."""
    _, ld = _pair(PLANAR)
    w, k, P = ld.net.checking.warmup, ld.net.checking.compare, ld.period
    victim = ld.net.checking.chain[0]                       # checks in stage 1
    end = 2 * (w + k) * P                                   # its stage has ended
    _, engine, _ = _faulty_run(ld, f"vamp={victim},dead,at={end + 1}", 40)
    assert engine.stalled is None or engine.stalled["tick"] >= end


def test_a_fault_in_the_checkers_copy_excises_a_healthy_successor():
    """The paper's 'failures in the error-correcting circuitry itself': a stuck bit in a VAMP's
    second control registers makes its copy of its successor wrong."""
    _, ld = _pair(PLANAR)
    chain = ld.net.checking.order
    checker, healthy = chain[3], chain[4]
    held = ld.programs[healthy][0].rom & 1                  # another op in the copy
    _, engine, _ = _faulty_run(ld, f"vamp={checker},stuck=control2.rom:0,value={1 - held}", 60)
    assert engine.detections[0]["finder"] == checker and engine.detections[0]["excised"] == healthy
    # the campaign's class: the faulty VAMP (the checker) was not the one excised, so the fault is
    # not corrected, whatever the torques after it (README, Error correction: "corrected (the
    # faulty VAMP excised and no set entering after the detection differs)")
    from vampc.emulator import campaign as cp
    sets = 60
    ports = port_values(ld, random_trajectory(ld.chain, sets, 5))
    setup = cp.Setup(ld, ports, cp.reference_run(ld, ports, sets, 5), sets, 5)
    run = cp.run_fault(setup, parse_fault(f"vamp={checker},stuck=control2.rom:0,value={1 - held}"))
    assert run["excised"] == healthy and run["class"] == "detected-not-corrected", run
    # one whose later sets all come out right (the spare plays the healthy VAMP's role): still not
    # corrected, the faulty checker left in place
    checker, healthy = chain[2], chain[3]
    held = ld.programs[healthy][0].rom & 1
    run = cp.run_fault(setup, parse_fault(f"vamp={checker},stuck=control2.rom:0,value={1 - held}"))
    assert run["excised"] == healthy and run["corrupted_after"] == 0, run
    assert run["class"] == "detected-not-corrected", run


def test_a_register_no_vamp_has_is_exit_1():
    r = CliRunner().invoke(main, ["emulate", "examples/planar2.yaml", "--engine", "tick", "--random",
                                  "3", "--fault", "vamp=1,stuck=result.q:3"])
    assert r.exit_code == 1 and "is no register" in r.output
    r = CliRunner().invoke(main, ["emulate", "examples/planar2.yaml", "--engine", "tick", "--random",
                                  "3", "--fault", "vamp=1,stuck=control2.rom:0"])
    assert r.exit_code == 1 and "compile --error-correction" in r.output
    # the chain's last VAMP of a checked program was told to compile --error-correction, as it had
    # (a hardware audit): it has no successor, said
    last = len(compile_chain(PLANAR, CompileOptions(error_correction=True)).network.vamps) - 1
    r = CliRunner().invoke(main, ["emulate", "examples/planar2.yaml", "--error-correction", "--engine",
                                  "tick", "--random", "3", "--fault", f"vamp={last},stuck=control2.rom:0"])
    assert r.exit_code == 1 and f"VAMP {last} is the last of the chain, with no successor" in r.output \
        and "compile --error-correction" not in r.output, r.output


def test_the_report_counts_what_the_checking_adds():
    """Against the network read independently: one pin per successor multiplexer input, Result',
    six control pins; a wire per successor input, per Result' and three per link, and the two
    loop-backs at the chain's ends (section VII: the last VAMP's Test-out into its Test-back-in,
    the extraneous one's Test-back-out into its Test-in; left out until a review); no added time."""
    import json

    from schema_check import schema_errors

    from vampc.report.build import build_report
    from vampc.report.checking import checking_pairs
    c = compile_chain(PLANAR, CompileOptions(error_correction=True))
    plain = compile_chain(PLANAR, CompileOptions())
    rep = build_report(c)
    assert not schema_errors("report", json.loads(json.dumps(rep)))
    ec = rep["error_correction"]
    net = c.network
    V = len(net.vamps)
    inputs = [len(v.a) + len(v.b) for v in net.vamps]
    assert ec["extra_vamps"] == 1 and ec["vamps"] == V + 1
    assert ec["pins_per_vamp"]["with"]["max"] == 8 - 2 + max(inputs) + max(inputs) + 1 + 6
    assert ec["wires"]["successor_inputs"] == sum(inputs) and ec["wires"]["total"] == sum(inputs) + 4 * V + 2
    assert ec["wires"]["control"] == 3 * V + 2
    assert ec["registers"]["second_control_registers"] == 4 * V     # one-slot systolic VAMPs
    # folded: a copy of each VAMP's own control registers, selects only where a multiplexer has
    # more than one input (six a slot had been counted on every VAMP of several slots or inputs)
    folded = compile_chain(PLANAR, CompileOptions(error_correction=True, layout="folded"))
    second = build_report(folded)["error_correction"]["registers"]["second_control_registers"]
    assert second == sum(len(v.slots) * (4 + (len(v.a) > 1) + (len(v.b) > 1))
                         for v in folded.network.vamps) == 282
    assert ec["added"] == {"latency_flops": 0, "interval_flops": 0, "load_ticks": 0}
    assert (c.schedule.latency, c.schedule.interval) == (plain.schedule.latency, plain.schedule.interval)
    assert ec["sweep_periods"] == sweep_periods(V, net.checking.warmup)
    assert checking_pairs(ec)[0][0] == "error correction"
    # every package count packs the V + 1 VAMPs (the paper's budget had packed V beside muxed
    # counts of V + 1: 36 and 91 packages for the Puma's 181; a new user's run)
    own = rep["packages"]["rows"][0]["by_pins"][0]
    assert (own["paper_separate"], own["paper_shared"]) == (math.ceil((V + 1) / 5), math.ceil((V + 1) / 12))
    assert rep["packages_40pin"] == {"separate": own["paper_separate"], "shared": own["paper_shared"]}
    # and the table says so: its VAMPs column said V beside counts for V + 1 (a new user's find)
    row = rep["packages"]["rows"][0]
    assert (row["vamps"], row["packaged_vamps"]) == (V, V + 1)
    from vampc.report.sections import packages
    table = packages(rep)
    assert table.rows[0][1] == f"{V} + 1 extraneous"
    assert any(n.startswith("+ extraneous: error correction's extraneous VAMP") for n in table.notes)
    assert "packaged_vamps" not in build_report(plain)["packages"]["rows"][0]


@pytest.mark.parametrize("layout", ["systolic", "folded"])
def test_the_checkings_multiplexers_fan_out_and_registers_are_counted(layout, tmp_path):
    """Against the program file's network section, read here without vampc: a checker selects its
    successor's operands on the primed inputs as the successor does (a copy of its multiplexers:
    their inputs beyond the first), chooses own or primed operands (one more input on each of a
    VAMP's two operands, none on the extraneous VAMP, which has no operands of its own, nor on the
    last in the chain, which checks none), and each
    Result line has a second driver, its predecessor's Result'. Each multiplexer input reading a
    Result has its twin on the reader's checker, and the line is read by its checker's Result':
    2 f + 1 on the busiest line. The storage's control registers include the second tables, modes
    and stage counters (the report had counted 0 mux inputs, fan-out 8 and 1.026 kbit of control
    registers on planar2 systolic, where 178, 17 and 2.171 kbit: a hardware user's find)."""
    from vampc.compiler import program_document
    from vampc.program.file import write_program
    from vampc.report.build import build_report
    c = compile_chain(PLANAR, CompileOptions(error_correction=True, layout=layout))
    write_program(program_document(c), tmp_path / "p.vamp.json")
    net = json.loads((tmp_path / "p.vamp.json").read_text())["network"]
    vamps, chain = net["vamps"], net["error_correction"]["chain"]
    V = len(vamps)
    successors = chain                      # the extraneous VAMP checks chain[0], chain[k] chain[k+1]
    copies = sum(len(vamps[s]["a"]) - 1 + len(vamps[s]["b"]) - 1 for s in successors)
    readers = [0] * V
    for v in vamps:
        for operand in ("a", "b"):
            for wire in v[operand]:
                for kind, index, _ in wire:
                    if kind == "vamp":
                        readers[index] += 1
                    elif kind == "buffer":
                        readers[net["buffers"][index]["source"]] += 1
    rep = build_report(c)
    ec = rep["error_correction"]
    assert ec["multiplexers"] == {"successor_copies": copies, "own_or_primed": 2 * (V - 1),
                                  "result_lines": V, "mux_inputs": copies + 2 * (V - 1) + V}
    assert copies > 0 if layout == "folded" else copies == 0
    # (an MM member reads one column of operand B: the three columns' taps counted here bound it)
    assert 0 < ec["fan_out"]["without"] <= max(readers)
    assert ec["fan_out"]["with"] == 2 * ec["fan_out"]["without"] + 1
    plain = build_report(compile_chain(PLANAR, CompileOptions(layout=layout)))
    assert ec["fan_out"]["without"] == plain["wiring"]["max_fan_out"]
    r, bits = ec["registers"], rep["engineering"]["bits"]
    counter = net["period"].bit_length()      # E's Cycle-Counter counts 0 .. P (README, Word formats)
    added = bits["control_register_bits"] - plain["engineering"]["bits"]["control_register_bits"]
    assert bits["checking_control_bits"] == \
        r["second_control_bits"] + r["mode_bits"] + r["stage_counter_bits"]
    assert added == bits["checking_control_bits"] + counter     # and E's Cycle-Counter
    assert "checking_control_bits" not in plain["engineering"]["bits"]
    from vampc.report.checking import checking_pairs
    said = dict(checking_pairs(ec))
    assert f"{copies + 2 * (V - 1) + V} inputs" in said["  multiplexers"]
    assert f"up to {ec['fan_out']['with']} inputs" in said["  fan-out"]


def test_a_detection_after_the_last_set_names_no_set(tmp_path):
    """The check of VAMPs 36/37 comes round after the last of 100 Puma sets has passed them: the
    line said 'set 114' (tick // period). It names the tick only."""
    prog = tmp_path / "pec.vamp.json"
    run = CliRunner().invoke
    assert run(main, ["compile", "examples/puma560.yaml", "--error-correction", "-o", str(prog)]).exit_code == 0
    res = run(main, ["emulate", str(prog), "--random", "100", "--engine", "tick", "--fault",
                     "vamp=37,stuck=result.z:20,value=1,at=100"])
    line = next(x for x in res.output.splitlines() if x.startswith("error correction:"))
    assert "found a mismatch at Data-Mode tick 453 and excised VAMP 37" in line and "(set " not in line, line


@pytest.mark.parametrize("last, word, limit", [(16777215, None, 16777215), (32767, "q9.7", 32767)])
def test_the_extraneous_vamps_number_must_fit(tmp_path, last, word, limit):
    """The extraneous VAMP takes one past the largest number burned in: a numbering ending at
    16777215 made it 16777216 (beyond the 24-bit numbers), and in q9.7 32768 (beyond the 16-bit
    word; "0 overflows" said), each compiled with exit 0. Now refused; one less is taken."""
    from vampc.program.emit import extraneous_number
    from vampc.program.words import PACKING
    assert extraneous_number((3, 1, 2), PACKING) == 4
    numbers = tmp_path / "n.txt"
    numbers.write_text("\n".join(map(str, [*range(1, 60), last])) + "\n")
    args = ["compile", "examples/planar2.yaml", "--numbering", str(numbers), "--error-correction",
            *(["--word", word] if word else []), "-o", str(tmp_path / "p.vamp.json")]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 1 and r.stderr.count("\n") == 1, r.output
    assert f"takes number {last + 1}" in r.stderr and f"at most {limit}" in r.stderr
    assert not (tmp_path / "p.vamp.json").exists()
    numbers.write_text("\n".join(map(str, [*range(1, 60), last - 1])) + "\n")
    assert CliRunner().invoke(main, args).exit_code == 0


@pytest.mark.parametrize("robot, options, sets", [
    ("planar2.yaml", ["--error-correction", "--word", "q16.16"], "60"),
    ("planar2.yaml", ["--error-correction", "--word", "q6.10"], "60"),
    ("puma560.yaml", ["--error-correction", "--word", "q16.16"], "60"),
    ("puma560.yaml", ["--error-correction", "--vamps", "7", "--word", "q5.11"], "6"),
    ("puma560.yaml", ["--recursion", "log", "--vamps", "9", "--word", "q8.16"], "1"),
    ("quadruped.urdf", ["--error-correction", "--vamps", "5", "--word", "q3.21"], "8")],
    ids=["ec-q16", "ec-q6", "puma-ec", "puma-ec-vamps7", "puma-log-vamps9", "quadruped-ec-vamps5"])
def test_both_engines_count_the_same_overflows(tmp_path, robot, options, sets):
    """The tick engine counted overflows of a checker's first steps on its successor's program taken
    up mid-op (units holding its own op's values), which the stream engine has not: a checked
    q16.16 planar2 said 1 to 3 overflows and failed --check on the tick engine, 0 and passed on the
    stream engine, with the same torques (a new user's run; the Puma: 1 to 7, every seed). Then (a
    reviewer's runs) it counted a checker's copy of its successor's op again (--vamps 7, q5.11: 63
    against 47), and missed the overflows of ops no torque reads scheduled after the last torque
    (a --vamps 9 log Puma in q8.16: 2 against 4)."""
    program = tmp_path / "p.vamp.json"
    r = CliRunner().invoke(main, ["compile", f"examples/{robot}", *options, "-o", str(program)])
    assert r.exit_code == 0, r.output
    for seed in ("0", "1", "2"):
        said = {}
        for engine in ("tick", "stream"):
            out = tmp_path / f"{engine}.csv"
            r = CliRunner().invoke(main, ["emulate", str(program), "--random", sets, "--seed", seed,
                                          "--engine", engine, "--check", "-o", str(out), "--write-failed"])
            line = next(s for s in r.output.splitlines() if " overflow" in s and "words:" in s)
            said[engine] = (r.exit_code, line, out.read_bytes())
        assert said["tick"] == said["stream"], (seed, said["tick"][:2], said["stream"][:2])


def test_a_checked_program_of_before_the_package_fix_is_not_called_edited(tmp_path):
    """Programs compiled before the extraneous VAMP was packaged store the 40-pin packages of the
    network's own VAMPs: read back, that figure is not taken for an edit; another one is."""
    import json

    from program_util import reported_with_summary
    program = tmp_path / "ec.vamp.json"
    assert CliRunner().invoke(main, ["compile", "examples/planar2.yaml", "--error-correction",
                                     "-o", str(program)]).exit_code == 0
    doc = json.loads(program.read_text())
    V = doc["summary"]["vamps"]["total"]
    for stored, warned in (({"separate": math.ceil(V / 5), "shared": math.ceil(V / 12)}, False),
                           ({"separate": 99, "shared": 99}, True)):
        doc["summary"]["packages_40pin"] = stored
        r = reported_with_summary(doc, tmp_path)
        assert ("the stored summary disagrees with the file's graph, schedule and network "
                "(packages_40pin)" in r.output) == warned, r.output


def test_the_vamp_count_line_gives_the_extraneous_vamp_too():
    """With --error-correction the report's VAMP line said 60 while its packages and its error-
    correction line counted 61, the extraneous VAMP included (a new user's find); the line gives
    both, the extraneous VAMP counted from the report's own error-correction figures."""
    import json
    args = ["report", "examples/planar2.yaml", "--error-correction"]
    rep = json.loads(CliRunner().invoke(main, args + ["--format", "json"]).output)
    text = CliRunner().invoke(main, args).output
    line = next(x for x in text.splitlines() if x.startswith("VAMPs  "))
    assert rep["error_correction"]["vamps"] == rep["vamps"]["total"] + 1
    assert line.endswith(f"and 1 extraneous VAMP for the error correction "
                         f"({rep['error_correction']['vamps']} in all)"), line
    plain = CliRunner().invoke(main, ["report", "examples/planar2.yaml"]).output
    assert "extraneous" not in next(x for x in plain.splitlines() if x.startswith("VAMPs  "))


def test_a_chain_in_another_order_has_its_wires_measured_not_priced_as_neighbours(tmp_path):
    """The loader takes any order of the chain and the emulator runs it, but the report gave the
    wires' length as if each VAMP's successor were its neighbour: 360 pitches for planar2 with two
    VAMPs swapped, whose links 2 -> 4 and 3 -> 5 are two pitches each (a hardware audit). Each
    link is now as long as its VAMPs are apart, counted here from the program file's own lists:
    a link carries its successor's operand wires (an input of several taps, one wire each), the
    Result' line and three control lines."""
    from vampc.program.file import checksum
    doc = document(PLANAR, error_correction=True)
    chain = doc["network"]["error_correction"]["chain"]
    chain[3], chain[4] = chain[4], chain[3]
    doc["checksum"] = checksum(doc)
    path = tmp_path / "swapped.vamp.json"
    path.write_text(json.dumps(doc))
    r = CliRunner().invoke(main, ["report", str(path), "--format", "json"])
    assert r.exit_code == 0, r.output
    wires = json.loads(r.output)["error_correction"]["wires"]
    vamps = {v["index"]: v for v in doc["network"]["vamps"]}

    def into(s):
        return sum(len(taps) for operand in ("a", "b") for taps in vamps[s][operand])
    # counted by hand: with VAMPs 3 and 4 swapped the links 2 -> 4 and 3 -> 5 span two pitches, one
    # more than a neighbour's, each link carrying its successor's operand wires and four lines;
    # 4 -> 3 spans one, as every other link
    assert chain[2:6] == [2, 4, 3, 5]
    # (the two loop-backs at the chain's ends are wires of no length: within a VAMP)
    assert wires["length_pitches"] - (wires["total"] - 2) == (into(4) + 4) + (into(5) + 4)
    r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--error-correction", "--format",
                                  "json"])
    plain = json.loads(r.output)["error_correction"]["wires"]
    assert plain["length_pitches"] == plain["total"] - 2 and plain["total"] == wires["total"]


def test_a_refused_non_finite_torque_still_says_what_the_checking_did(tmp_path, monkeypatch):
    """planar2 with checking, operand B's top exponent bit stuck at 1 on VAMP 6: a campaign finds it
    at tick 81 and excises VAMP 6, but `vampc emulate` of the same fault stopped at set 3's NaN
    torque with no word of the checking (a hardware audit). The checking's line now comes before
    the refusal, and what it says is the campaign's run of that fault."""
    from vampc.emulator import campaign
    prog = tmp_path / "p.vamp.json"
    run = CliRunner().invoke
    assert run(main, ["compile", "examples/planar2.yaml", "--error-correction", "-o",
                      str(prog)]).exit_code == 0
    fault = "vamp=6,stuck=b.0:62,value=1,at=0"
    # the campaign's run of that fault alone (the command's own run of it; the other 60 runs of
    # --kinds b took 5 s)
    drawn = campaign.faults_of
    monkeypatch.setattr(campaign, "faults_of",
                        lambda *a, **k: [f for f in drawn(*a, **k) if f.text == fault])
    r = run(main, ["faults", str(prog), "--kinds", "b", "--workers", "1", "--format", "json",
                   "--results", str(tmp_path / "r.jsonl")])
    found = next(x for x in json.loads(r.output[r.output.index("{"):])["runs"] if x["fault"] == fault)
    r = run(main, ["emulate", str(prog), "--engine", "tick", "--random", str(found["sets_run"]),
                   "--fault", fault, "-o", str(tmp_path / "t.csv")])
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == 1 and "the torque is nan" in lines[-1] and not (tmp_path / "t.csv").exists()
    assert (f"error correction: VAMP {found['finder']} found a mismatch at Data-Mode tick "
            f"{found['detected_tick']} and excised VAMP {found['excised']}") in lines[-2], lines


ARM3P = """name: arm3p
joints:
  - {name: waist, type: revolute, a: 0.1, alpha: 1.5707963, d: 0.4, theta: 0, mass: 5.0, com: [0,-0.05,0.02], inertia: [0.05,0.04,0.03,0.001,0.0,0.002]}
  - {name: shoulder, type: revolute, a: 0.5, alpha: 0, d: 0.05, theta: 0.3, mass: 4.0, com: [-0.25,0,0.01], inertia: [0.01,0.1,0.1,0,0,0]}
  - {name: slide, type: prismatic, a: 0.0, alpha: -1.5707963, d: 0.2, theta: 0.1, mass: 2.0, com: [0,0,-0.1], inertia: [0.02,0.02,0.002,0,0,0]}
"""


def test_two_nans_of_one_op_are_not_a_mismatch(tmp_path):
    """A new user's 3-joint arm on 5 VAMPs: VAMP 1's operand-B bit 62 stuck at 1 makes its results
    NaN, which VAMP 0 reads. The extraneous VAMP, checking VAMP 0 first, computed VAMP 0's op on the
    same NaN operands as VAMP 0 and held a NaN of another payload (numpy's choice of operand as the
    arrays lay), so it found a mismatch and excised the healthy VAMP 0; the campaign listed that
    as an escape. NaN results are the canonical NaN now (vampc.machine.arith): VAMP 0 finds the
    fault in its own check of VAMP 1, as it does for bits 40 and 63 of the same register."""
    robot = tmp_path / "arm3p.yaml"
    robot.write_text(ARM3P)
    program = tmp_path / "arm3p.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(robot), "--vamps", "5", "--error-correction", "-o",
                                  str(program)])
    assert r.exit_code == 0, r.output
    for bit in (40, 62, 63):
        r = CliRunner().invoke(main, ["emulate", str(program), "--engine", "tick", "--random", "26",
                                      "--fault", f"vamp=1,stuck=b.0:{bit},value=1"])
        assert re.search(r"VAMP 0 found a mismatch at Data-Mode tick \d+ and excised VAMP 1\b",
                         r.output), (bit, r.output)
        assert "naming its successor in the chain, VAMP 1" in r.output, (bit, r.output)
