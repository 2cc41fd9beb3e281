"""`vampc faults` (issue 19, parts 4 and 5): campaigns classified against the fault-free run, the same
faults with and without error correction, results kept and resumed, local workers and a Dask
cluster giving the same results, and bad input as one line."""
from __future__ import annotations

import io
import json
import re

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.emulator import campaign as cp
from vampc.emulator import load_program
from vampc.emulator.faults import parse_fault
from vampc.errors import VampcError

RUN = CliRunner().invoke


ONE_JOINT = """name: one
joints:
  - {name: j, type: revolute, a: 0.5, alpha: 0.3, d: 0.1, theta: 0.0, mass: 2.0,
     com: [-0.25, 0.02, 0.01], inertia: [0.01, 0.04, 0.04, 0.001, 0.0, 0.0]}
"""
# short runs where that will do; seed 5: masked, silent and detected-corrected runs among the eight
# (seed 0's had come of control faults in bits no register has, drawn before 2026-12-06)
QUICK = ("--campaign", "random", "--count", "8", "--sets", "40", "--seed", "5")
# Shorter still, for the tests that look only at which faults a campaign runs, names or reads back,
# never at a run's class or counts: a single campaign's faults are the same for any --sets (a random
# one's start ticks are drawn within the run, so other draws, of the kinds asked for all the same);
# the cost is not (a single campaign of 60 runs: 1.7 s at 40 sets, 0.5 s at 4)
FEW = "4"


@pytest.fixture(scope="module")
def programs(tmp_path_factory):
    """A one-joint arm with and without checking (every fault of a kind runs in seconds) and
    planar2 with checking."""
    d = tmp_path_factory.mktemp("campaign")
    robot = d / "one.yaml"
    robot.write_text(ONE_JOINT)
    ec, plain, planar = d / "ec.vamp.json", d / "plain.vamp.json", d / "planar.vamp.json"
    for args in ([str(robot), "--error-correction", "-o", str(ec)], [str(robot), "-o", str(plain)],
                 ["examples/planar2.yaml", "--error-correction", "-o", str(planar)]):
        assert RUN(main, ["compile", *args]).exit_code == 0
    return ec, plain, planar


@pytest.fixture(scope="module")
def _quick_file(programs, tmp_path_factory) -> bytes:
    """The results file of the QUICK campaign on the one-joint arm with checking, run once for the
    module. The campaign is deterministic (its seed; the program is named by its digest, not its
    path), so these are the bytes the same command writes in any test's own folder."""
    ec, _, _ = programs
    d = tmp_path_factory.mktemp("quick")
    _campaign(ec, d, *QUICK)
    return (d / "r.jsonl").read_bytes()


@pytest.fixture
def quick_results(_quick_file, tmp_path):
    """tmp_path / r.jsonl: a fresh copy of the QUICK campaign's results file (for the tests that
    edit one or resume from one; each had run the campaign itself to make it)."""
    path = tmp_path / "r.jsonl"
    path.write_bytes(_quick_file)
    return path


def _campaign(program, tmp_path, *args, name="r.jsonl"):
    r = RUN(main, ["faults", str(program), "--format", "json", "--results", str(tmp_path / name),
                   "--workers", "1", *args])
    assert r.exit_code == 0, r.output
    return _json(r.output)


def _json(output: str) -> dict:
    """The JSON report (after a warning a short run draws, when the output mixes stderr in)."""
    return json.loads(output[output.index("{"):])


def test_a_single_campaign_with_and_without_checking(programs, tmp_path):
    ec, plain, _ = programs
    with_ec = _campaign(ec, tmp_path, "--kinds", "dead", name="ec.jsonl")
    without = _campaign(plain, tmp_path, "--kinds", "dead", name="plain.jsonl")
    ld = load_program(str(ec))
    V = len(ld.net.vamps)
    assert len(with_ec["runs"]) == V + 1 and len(without["runs"]) == V
    assert with_ec["sets"] == without["sets"] == cp.default_sets(ld)
    plain_by = {r["fault"]: r for r in without["runs"]}
    for run in with_ec["runs"]:
        assert run["class"] in cp.CLASSES
        if run["vamp"] == V:                                # the extraneous VAMP: no plain twin
            continue
        twin = plain_by[run["fault"]]                       # the same fault, no checking
        if run["kind"] == "dead" and twin["class"] == "silent-corruption":
            # a dead VAMP that spoils torques is found by its predecessor and replaced
            assert run["class"] == "detected-corrected" and run["excised"] == run["vamp"]
            assert run["named"] == [run["vamp"]] and run["corrupted_after"] == 0
        if "detected_tick" in run:
            # the sets run after the detection: from the first set entering after its cycle to the
            # run's stop, a few sets on (corrupted_after counts among them; a new user had read it
            # as what the whole run spoils)
            after = run["sets_run"] - (run["detected_tick"] // ld.period + 1)
            assert run["sets_after"] == max(0, after) and run["corrupted_after"] <= run["sets_after"]
            assert run["sets_after"] <= cp.TAIL + ld.net.latency // ld.period + 1
    s = with_ec["summary"]
    assert s["classes"]["silent-corruption"] < without["summary"]["classes"]["silent-corruption"]
    assert without["summary"]["classes"]["detected-corrected"] == 0


def test_a_corrected_run_is_right_by_the_reference_after_the_excision(programs, tmp_path):
    """The classification against the fault-free run, checked against the reference Newton-Euler:
    the sets after a 'detected-corrected' excision are right, the corrupted ones before are not."""
    from vampc.emulator.checking import CheckingTickEngine
    from vampc.emulator.driver import random_states
    from vampc.emulator.host import check_torques, port_values
    _, _, ec = programs
    ld = load_program(str(ec))
    sets = cp.default_sets(ld)
    traj = random_states(ld.chain, 0, sets, 0)
    ports = port_values(ld, traj)
    setup = cp.Setup(ld, ports, cp.reference_run(ld, ports, sets, 0), sets, 0)
    victim = ld.net.outputs[0].vamp
    run = cp.run_fault(setup, parse_fault(f"vamp={victim},dead"))
    assert run["class"] == "detected-corrected" and run["corrupted_before"] > 0
    engine = CheckingTickEngine(ld, faults=[parse_fault(f"vamp={victim},dead")])
    engine.program()
    with np.errstate(all="ignore"):
        tau = engine.run(ports, sets)
    after = run["detected_tick"] // ld.period + 1
    from vampc.emulator.host import Trajectory
    tail = Trajectory(traj.q[after:], traj.qd[after:], traj.qdd[after:])
    assert check_torques(ld.chain, tail, tau[after:]).ok
    # the sets spoiled before it, counted against the stream engine (not the campaign's reference)
    from vampc.emulator import emulate
    stream = emulate(ld, traj, "stream").tau
    bad = [j for j in range(after) if not np.array_equal(tau[j], stream[j])]
    assert len(bad) == run["corrupted_before"] > 0


def test_the_campaign_resumes_from_its_results_file(programs, tmp_path, monkeypatch):
    ec, _, _ = programs
    args = QUICK
    first = _campaign(ec, tmp_path, *args)
    path = tmp_path / "r.jsonl"
    lines = path.read_bytes().splitlines(keepends=True)
    assert len(lines) == len(first["runs"]) + 1             # the header, a line per run
    path.write_bytes(b"".join(lines[:-5]) + lines[-5][:17])  # five runs lost, one cut mid-line
    calls = []
    real = cp.run_fault
    monkeypatch.setattr(cp, "run_fault", lambda setup, f: calls.append(f) or real(setup, f))
    again = _campaign(ec, tmp_path, *args)
    assert len(calls) == 5                                   # only the missing runs ran
    assert again["runs"] == first["runs"] and again["summary"] == first["summary"]
    assert path.read_bytes() != b"" and len(path.read_bytes().splitlines()) == len(lines)
    calls.clear()
    assert _campaign(ec, tmp_path, *args)["runs"] == first["runs"] and not calls


def test_a_default_results_file_of_other_kinds_is_named_as_the_default(programs, tmp_path):
    """After a default campaign, `--kinds control2` (the README's command) was refused with
    '--results P.single.faults.jsonl: ...', an option the user never gave (a new user's find)."""
    ec, _, _ = programs
    program = tmp_path / "ec.vamp.json"
    program.write_bytes(ec.read_bytes())
    r = RUN(main, ["faults", str(program), *QUICK, "--workers", "1"])
    assert r.exit_code == 0, r.output
    default = tmp_path / "ec.random.faults.jsonl"
    kept = default.read_bytes()
    r = RUN(main, ["faults", str(program), *QUICK, "--kinds", "dead", "--workers", "1"])
    assert r.exit_code == 1, r.output
    # (what differs is said: an earlier vampc's default random campaign, 565 sets a run where it
    # is now 1488, was refused as if --sets had been given: a review's find)
    # (and which faults: "other faults" alone left a new user to guess)
    # (and, the program, campaign and seed being the same, that an earlier vampc's file is also
    # such a file: one from before an upgrade was "another campaign or program" alone, an audit's)
    faults = r"other faults, 8 in the file and 8 here; the first that differs is fault 1: 'vamp=[^']+' " \
             r"in the file, 'vamp=[^']+' here; the same program, campaign and seed: other options, " \
             r"or a file an earlier vampc wrote, which drew other faults or ran other lengths"
    assert re.fullmatch(rf"vampc: error: {re.escape(str(default))}, the default results file, holds the "
                        rf"results of another campaign \({faults}\): give --results FILE for this one, "
                        r"or remove it to start over", r.output.splitlines()[-1]), r.output
    assert "dead" in r.output.splitlines()[-1].split("in the file, ")[-1].split(" here;")[0]
    r = RUN(main, ["faults", str(program), *("41" if x == "40" else x for x in QUICK), "--workers", "1"])
    assert re.fullmatch(rf"vampc: error: {re.escape(str(default))}, the default results file, holds "
                        rf"the results of another campaign \(40 sets a run, not 41, {faults}\): give "
                        r"--results FILE for this one, or remove it to start over",
                        r.output.splitlines()[-1]), r.output
    assert default.read_bytes() == kept


def test_kinds_and_bits_in_another_order_are_the_same_campaign(programs, tmp_path):
    """`--kinds control,dead` refused the results of `--kinds dead,control` (and the other way),
    though they are the same faults (a new user's find): kinds and bits are sets."""
    ec, _, _ = programs
    path = str(tmp_path / "r.jsonl")
    first = RUN(main, ["faults", str(ec), *QUICK, "--kinds", "dead,result", "--workers", "1",
                       "--results", path])
    assert first.exit_code == 0, first.output
    again = RUN(main, ["faults", str(ec), *QUICK, "--kinds", "result,dead", "--workers", "1",
                       "--results", path])
    assert again.exit_code == 0 and "8 run(s) read from" in again.output, again.output
    path = str(tmp_path / "s.jsonl")
    for bits in ("62,52", "52,62"):
        r = RUN(main, ["faults", str(ec), "--kinds", "result", "--bits", bits, "--sets", FEW,
                       "--workers", "1", "--results", path])
        assert r.exit_code == 0, r.output
    assert "read from" in r.output, r.output


def test_another_campaigns_results_file_is_refused_and_kept(programs, quick_results):
    ec, _, _ = programs
    before = quick_results.read_bytes()      # the QUICK campaign's results (made once)
    r = RUN(main, ["faults", str(ec), *("41" if x == "40" else x for x in QUICK), "--results",
                   str(quick_results)])
    errors = [x for x in r.output.splitlines() if not x.startswith("vampc: warning")]
    assert r.exit_code == 1 and "another campaign or program (40 sets a run, not 41" in r.output, r.output
    assert len(errors) == 1
    assert quick_results.read_bytes() == before


def test_workers_give_the_results_one_process_gives(programs, tmp_path):
    _, _, ec = programs
    one = _campaign(ec, tmp_path, *QUICK, name="one.jsonl")
    r = RUN(main, ["faults", str(ec), *QUICK, "--format", "json",
                   "--results", str(tmp_path / "two.jsonl"), "--workers", "2"])
    assert r.exit_code == 0, r.output
    assert _json(r.output)["runs"] == one["runs"]


def test_a_dask_cluster_gives_the_results_one_process_gives(programs, tmp_path):
    distributed = pytest.importorskip("distributed")
    ec, _, _ = programs
    one = _campaign(ec, tmp_path, *QUICK, name="one.jsonl")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        r = RUN(main, ["faults", str(ec), *QUICK, "--format", "json",
                       "--results", str(tmp_path / "dask.jsonl"), "--scheduler",
                       cluster.scheduler_address])
    assert r.exit_code == 0, r.output
    assert _json(r.output)["runs"] == one["runs"]


def test_an_unreachable_scheduler_is_one_line_and_writes_nothing(programs, tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    from vampc import parallel
    monkeypatch.setattr(parallel, "SCHEDULER_TIMEOUT", "1s")
    monkeypatch.setattr(parallel.connect, "__defaults__", ("1s",))
    ec, _, _ = programs
    out = tmp_path / "r.jsonl"
    r = RUN(main, ["faults", str(ec), "--scheduler", "tcp://127.0.0.1:9", "--results", str(out)])
    assert r.exit_code == 1 and "cannot reach a Dask scheduler" in r.output
    assert len(r.output.strip().splitlines()) == 1 and not out.exists()


def test_csv_and_text(programs, tmp_path):
    ec, _, _ = programs
    r = RUN(main, ["faults", str(ec), *QUICK, "--format", "csv", "--results",
                   str(tmp_path / "r.jsonl"), "--workers", "1"])
    assert r.exit_code == 0, r.output
    rows = [x for x in r.output.strip().splitlines() if not x.startswith("vampc: warning")]
    assert rows[0].split(",")[:5] == ["index", "fault", "vamp", "kind", "class"]
    assert len(rows) == 1 + 8
    r = RUN(main, ["faults", str(ec), *QUICK, "--results", str(tmp_path / "r.jsonl")])
    assert "detected and corrected" in r.output and "read from" in r.output


def test_coverage_without_checking_says_nothing_checks(programs, tmp_path):
    # 0.0% without error correction is not a measured failure of the checking: there is none
    ec, plain, _ = programs
    r = RUN(main, ["faults", str(plain), *QUICK, "--results", str(tmp_path / "p.jsonl"), "--workers", "1"])
    line = next(x for x in r.output.splitlines() if x.startswith("coverage"))
    assert "error correction off: nothing checks" in line, r.output
    r = RUN(main, ["faults", str(ec), *QUICK, "--results", str(tmp_path / "e.jsonl"), "--workers", "1"])
    line = next(x for x in r.output.splitlines() if x.startswith("coverage"))
    assert "error correction off" not in line, r.output


@pytest.mark.parametrize("args, says", [
    (["--count", "5"], "--count applies to --campaign random"),
    (["--kinds", "bogus"], "--kinds bogus"),
    (["--campaign", "intermittent", "--rate", "1.5"], "--rate 1.5"),
    (["--workers", "2", "--scheduler", "tcp://x:1"], "give one"),
    (["--campaign", "transient", "--at", "5"], "--at applies"),
    # taken and ignored: control and dead faults have no stuck bit of a word
    (["--kinds", "control", "--bits", "5"], "--bits applies to the result, a and b kinds"),
    (["--kinds", "dead", "--values", "0"], "--values applies to the result, a and b kinds"),
    (["--bits", "٥"], "give bit numbers"),
    # said of the --fault made from it, exit 1 ("bit 99: the register has 64 bits")
    (["--bits", "99"], "--bits 99: bit 99 is beyond the 64-bit words of float64"),
])
def test_usage_errors(programs, args, says):
    ec, _, _ = programs
    r = RUN(main, ["faults", str(ec), *args])
    assert r.exit_code == 2 and says in r.output, r.output


@pytest.mark.parametrize("args, says", [
    (["-o", "f.txt.gz"], "-o writes the report as plain text: not .gz (compress the file afterwards)"),
    (["--format", "csv", "-o", "f.csv.gz"], "-o writes the CSV table as plain text: not .gz"),
    (["--format", "json", "-o", "f.json.bz2"], "-o writes the JSON report as plain text: not .bz2"),
    (["-o", "f.zst"], "not .zst"),
    (["--results", "fr.jsonl.gz"], "--results writes each run's result as plain text (JSON lines, "
                                   "appended to and read back by a re-run): not .gz"),
    (["--results", "fr.jsonl.XZ"], "--results writes each run's result as plain text"),
])
def test_a_compressed_name_for_the_report_or_the_results_is_a_usage_error(programs, tmp_path,
                                                                          monkeypatch, args, says):
    """`faults P --kinds dead -o f.txt.gz` (and --results fr.jsonl.gz) wrote plain text under a
    compressed file's name, exit 0, unsaid (a new user's find; emulate's -o refuses one): refused
    before any run, naming the option, and nothing written (the default results file neither)."""
    ec, _, _ = programs
    monkeypatch.chdir(tmp_path)
    program = tmp_path / "ec.vamp.json"
    program.write_bytes(ec.read_bytes())
    r = RUN(main, ["faults", str(program), "--kinds", "dead", "--sets", FEW, "--workers", "1", *args])
    assert r.exit_code == 2 and says in r.stderr, r.output
    assert len(r.stderr.splitlines()) == 1 and "Traceback" not in r.output
    assert [p.name for p in tmp_path.iterdir()] == ["ec.vamp.json"]


def test_check_cycles_without_error_correction_is_a_usage_error():
    r = RUN(main, ["faults", "examples/planar2.yaml", "--check-cycles", "3"])
    says = "--check-cycles applies with --error-correction"
    assert r.exit_code == 2 and says in r.output, r.output


def test_too_few_sets_for_the_sweep_is_said(programs, tmp_path):
    _, _, ec = programs
    r = RUN(main, ["faults", str(ec), "--campaign", "random", "--count", "2", "--sets", "20",
                   "--results", str(tmp_path / "r.jsonl"), "--workers", "1"])
    assert r.exit_code == 0 and "those that start late cannot be detected" in r.output
    r = RUN(main, ["faults", str(ec), "--kinds", "dead", "--sets", "20", "--results",
                   str(tmp_path / "s.jsonl"), "--workers", "1"])
    assert r.exit_code == 0 and "reaches only part of the chain" in r.output
    # an error in the options is said alone, not after this warning (two lines for one error)
    for bad, code in ((["--at", "999999999"], 1), (["--bits", "64"], 2)):
        r = RUN(main, ["faults", str(ec), "--sets", "20", "--results", str(tmp_path / "b.jsonl"),
                       *bad])
        assert r.exit_code == code and len(r.output.strip().splitlines()) == 1, r.output
        assert "reaches only part" not in r.output


def test_the_results_file_is_never_the_program(programs):
    ec, _, _ = programs
    before = ec.read_bytes()
    r = RUN(main, ["faults", str(ec), "--results", str(ec)])
    assert r.exit_code == 1 and ec.read_bytes() == before


def test_a_last_line_without_its_newline_runs_again(programs, tmp_path):
    ec, _, _ = programs
    first = _campaign(ec, tmp_path, *QUICK)
    path = tmp_path / "r.jsonl"
    path.write_bytes(path.read_bytes().rstrip(b"\n"))       # whole JSON, but cut before its end
    again = _campaign(ec, tmp_path, *QUICK)
    assert again["runs"] == first["runs"]
    assert path.read_bytes().endswith(b"\n") and len(path.read_bytes().splitlines()) == 9


def test_a_header_cut_short_is_a_new_file(programs, tmp_path):
    ec, _, _ = programs
    (tmp_path / "r.jsonl").write_bytes(b'{"vampc_faults": 1, "progr')
    assert len(_campaign(ec, tmp_path, *QUICK)["runs"]) == 8


def test_a_start_tick_after_the_run_is_one_line(programs, tmp_path):
    ec, _, _ = programs
    out = tmp_path / "r.jsonl"
    r = RUN(main, ["faults", str(ec), "--at", "99999", "--results", str(out)])
    # it names the program, as the campaign's other errors of this program do (a new user's find)
    assert r.exit_code == 1 and f"vampc: error: {ec}: --at 99999: the run's last Data-Mode tick" \
        in r.output
    assert not out.exists()


def test_bits_and_values_make_the_single_campaigns_faults():
    from vampc.compiler import CompileOptions, compile_chain
    from vampc.emulator import loaded_from_compiled
    from vampc.robot import load_robot
    ld = loaded_from_compiled(compile_chain(load_robot("examples/planar2.yaml"),
                                            CompileOptions(error_correction=True)))
    V = len(ld.net.vamps) + 1
    faults = cp.faults_of(ld, "single", ["result", "dead", "control2"], bits=[62, 0], values=(0, 1))
    assert len(faults) == V * 4 + V + (V - 1)               # result: 2 bits x 2 values
    texts = {f.text for f in faults}
    assert "vamp=3,stuck=result.x:0,value=0,at=0" in texts and "vamp=3,dead,at=0" in texts
    assert sum(f.register == "control2" for f in faults) == V - 1    # the last VAMP has no copy


def test_a_stall_is_listed_among_the_escapes(programs):
    from vampc.emulator.driver import random_states
    from vampc.emulator.host import port_values
    ec, _, _ = programs
    ld = load_program(str(ec))
    sets = 40
    ports = port_values(ld, random_states(ld.chain, 0, sets, 0))
    setup = cp.Setup(ld, ports, cp.reference_run(ld, ports, sets, 0), sets, 0)
    V = len(ld.net.vamps)
    e = cp.run_fault(setup, parse_fault(f"vamp={V},dead"))      # the extraneous VAMP
    assert e["class"] == "masked" and e["stalled"]["vamp"] == V
    summary = cp.summarise(ld, [e], sets)
    assert [x["fault"] for x in summary["escapes"]] == [e["fault"]]
    # (what an escape is, said: a new user read this "masked" run under "escapes" as a mistake)
    text = cp.render_text("head", summary)
    assert "escapes (1): runs the checking did not handle in full (a torque spoiled unflagged, a " \
        "fault not corrected, the faulty VAMP not named, the checking stalled, or the run hung)\n  " \
        f"{e['fault']}: masked: " in text, text
    # a masked run with coverage at 100%, the checking lost: said beside the coverage (a new
    # user's find), and counted
    assert summary["stalled"] == 1 and summary["coverage"] is None
    assert "checking stalled: in 1 of 1 runs nothing was checked after a point" in text
    quiet = cp.summarise(ld, [cp.run_fault(setup, parse_fault("vamp=0,stuck=result.x:62,value=1"))],
                         sets)
    assert quiet["stalled"] == 0 and "checking stalled" not in cp.render_text("head", quiet)


# Run in a process of its own: a worker killed inside a pytest-xdist worker's pool crashed that
# xdist worker once in CI ("node down: Not properly terminated").
WORKER_DIES = """
import os, signal, sys
import vampc.commands
from vampc.cli import main

real = vampc.commands._fault_task

def dies(setup, item):              # (the workers are forked: they run this)
    if item[0] == 5:
        os.kill(os.getpid(), signal.SIGKILL)
    return real(setup, item)

vampc.commands._fault_task = dies
sys.argv = ["vampc", *sys.argv[1:]]
main()
"""


def test_a_worker_that_dies_keeps_the_runs_finished_and_says_so(programs, tmp_path):
    """A worker killed mid-campaign (out of memory, a signal) is one line that says the finished
    runs are kept and a re-run resumes (it said 'nothing is written', the sweep's words)."""
    import subprocess
    import sys
    _, plain, _ = programs
    results = tmp_path / "r.jsonl"
    done = subprocess.run([sys.executable, "-c", WORKER_DIES, "faults", str(plain), *QUICK,
                           "--results", str(results), "--workers", "2"],
                          capture_output=True, text=True, timeout=300)
    errors = [x for x in done.stderr.splitlines() if not x.startswith("vampc: warning")]
    assert done.returncode == 1 and len(errors) == 1, done.stderr
    # a header and the runs finished before (not all eight), as many as the message says; no file
    # where none had finished (the file made for the run is removed: a review's)
    kept = results.read_text().splitlines() if results.exists() else []
    assert len(kept) < 9 and (len(kept) >= 2 or not results.exists()), kept
    runs = max(len(kept) - 1, 0)
    said = (f"{runs} run{'s' * (runs != 1)} finished this time kept in {results} (a re-run resumes "
            "from them)" if runs else "no run had finished, so nothing is kept")
    assert said in errors[0], errors[0]


def test_what_a_stopped_campaign_keeps_is_what_its_results_file_holds():
    """A campaign on a cluster with no workers said "the runs finished are kept in
    p2ec.single.faults.jsonl", a file it then removed, none having finished (a new user's find)."""
    from types import SimpleNamespace

    from vampc.commands import _runs_kept
    assert _runs_kept(SimpleNamespace(added=0, done={}), "r.jsonl") == "no run had finished, so nothing is kept"
    assert _runs_kept(SimpleNamespace(added=3, done=dict.fromkeys(range(3))), "r.jsonl") == \
        "3 runs finished this time kept in r.jsonl (a re-run resumes from them)"
    assert _runs_kept(SimpleNamespace(added=1, done=dict.fromkeys(range(5))), "r.jsonl") == \
        "1 run finished this time kept in r.jsonl beside 4 before (a re-run resumes from them)"
    assert _runs_kept(SimpleNamespace(added=0, done=dict.fromkeys(range(4))), "r.jsonl") == \
        "no run finished this time; the 4 before are kept in r.jsonl (a re-run resumes from them)"


def test_a_one_line_file_that_is_no_header_of_ours_is_refused_and_kept(programs, tmp_path):
    """A file without a newline was taken for a header cut short and replaced (a user's minified
    JSON, `{"keep":1}`, lost with exit 0); only the start of this campaign's own header is."""
    ec, _, _ = programs
    notes = tmp_path / "r.jsonl"
    notes.write_bytes(b'{"keep":1}')
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(notes)])
    assert r.exit_code == 1 and "not a results file of vampc faults" in r.output, r.output
    assert notes.read_bytes() == b'{"keep":1}'


def test_a_what_if_word_is_another_campaign(programs, tmp_path):
    """The results of the program as compiled were read back for `--word q4.28` (the identity was
    the file's digest alone) and summarised as that word's: a what-if option makes another
    campaign, whose file is refused; the program as compiled still resumes. (q16.16 and q4.28
    are both 32-bit words: the same faults, so the same header before.)"""
    robot = tmp_path / "one.yaml"
    robot.write_text(ONE_JOINT)
    ec = tmp_path / "q16.vamp.json"
    assert RUN(main, ["compile", str(robot), "--word", "q16.16", "--error-correction", "-o",
                      str(ec)]).exit_code == 0
    first = _campaign(ec, tmp_path, *QUICK)
    before = (tmp_path / "r.jsonl").read_bytes()
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--word", "q4.28", "--results",
                   str(tmp_path / "r.jsonl")])
    assert r.exit_code == 1 and "another campaign" in r.output, r.output
    assert (tmp_path / "r.jsonl").read_bytes() == before
    assert _campaign(ec, tmp_path, *QUICK)["runs"] == first["runs"]
    assert _campaign(ec, tmp_path, *QUICK, "--word", "q4.28", name="q.jsonl")["runs"]
    # the program's own word said again is the same machine: it resumes (it was refused)
    for same in (["--word", "q16.16"], ["--rounding", "nearest"], ["--mult-latency", "1"]):
        r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", *same,
                       "--results", str(tmp_path / "r.jsonl")])
        assert r.exit_code == 0 and "8 run(s) read from" in r.output, r.output
    assert _campaign(ec, tmp_path, *QUICK, "--word", "q4.28", "--rounding", "nearest",
                     name="q.jsonl")["runs"]          # q4.28 said either way: one campaign


@pytest.mark.parametrize("edit", [('"class": "', '"class": "bogus'), ('"index": 0,', '"index": true,'),
                                  ('"index": 0,', '"index": 1.5,'), ('"fault": "', '"fault": "x'),
                                  ('"kind": "', '"kind": 3, "was": "'),
                                  ('"kind": "', '"kind": "made up", "was": "'),
                                  ('"class": "', '"class": "detected-corrected", "was": "'),
                                  ('"vamp": ', '"vamp": 99999, "was": '),
                                  ('"vamp": ', '"vamp": true, "was": '),
                                  # counts no run of 40 sets can have (a tester's: taken, reported)
                                  ('"sets_run": ', '"sets_run": -4, "was": '),
                                  ('"sets_run": ', '"sets_run": 1000000, "was": ')])
def test_an_edited_run_line_is_one_line_and_the_file_is_kept(programs, quick_results, edit):
    """An edited line of the results file was a KeyError traceback (`"class": "bogus"`) or, with
    `"index": true`, fault 0's run filed as fault 1's, exit 0: every line must be a run of this
    campaign's list (its index, its fault's text, a class), or the command stops naming it."""
    ec, _, _ = programs
    path = quick_results                     # the QUICK campaign's results (made once)
    lines = path.read_text().splitlines(keepends=True)
    assert edit[0] in lines[1]
    lines[1] = lines[1].replace(edit[0], edit[1], 1)
    path.write_text("".join(lines))
    before = path.read_bytes()
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    errors = [x for x in r.output.splitlines() if not x.startswith("vampc: warning")]
    assert r.exit_code == 1 and errors == [f"vampc: error: --results {path}: line 2 is not a run's "
                                           "result (the file was edited; remove it to start over)"]
    assert path.read_bytes() == before


@pytest.mark.parametrize("line, edit", [(3, ('"class": "silent-corruption"', '"class": "masked"')),
                                        (5, ('"class": "masked"', '"class": "silent-corruption"')),
                                        (5, ('"class": "masked"', '"class": "hang"')),
                                        (7, ('"class": "detected-corrected"',
                                             '"class": "detected-not-corrected"'))])
def test_a_class_its_runs_fields_do_not_give_is_refused(programs, quick_results, line, edit):
    """A line whose class was edited (a corrupted run's `"class": "masked"`) was taken, and the
    campaign said so: the class must be the one the line's counts and detection give."""
    ec, _, _ = programs
    path = quick_results                     # the QUICK campaign's results (made once)
    lines = path.read_text().splitlines(keepends=True)
    assert edit[0] in lines[line - 1]
    lines[line - 1] = lines[line - 1].replace(edit[0], edit[1], 1)
    path.write_text("".join(lines))
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    errors = [x for x in r.output.splitlines() if not x.startswith("vampc: warning")]
    assert r.exit_code == 1 and errors == [f"vampc: error: --results {path}: line {line} is not a "
                                           "run's result (the file was edited; remove it to start "
                                           "over)"]


@pytest.mark.parametrize("line, edit", [
    # detected at tick 46 of a 4-tick period, fault at tick 34, 21 sets run: at most 46 // 4 + 1 =
    # 12 sets entered before the detection's cycle ended, and (46 - 34) // 4 = 3 whole cycles
    (7, ('"corrupted_before": 4', '"corrupted_before": 13')),
    (7, ('"corrupted_before": 4', '"corrupted_before": 22')),
    (7, ('"latency_cycles": 3', '"latency_cycles": 4')),
    (9, ('"sets_run": 40', '"sets_run": 28'))])          # 29 sets corrupted of 28 run
def test_counts_a_run_cannot_have_are_refused(programs, quick_results, line, edit):
    """A line's counts were checked against the campaign's sets alone: an edited
    "corrupted_before": 83 of a run of 12 sets, or a latency of 7 cycles for 2, were taken and moved
    the summary's means (a new user's find). The counts must agree with the run's own sets and
    detection tick, by run_fault's rules (worked out by hand in the parameters)."""
    ec, _, _ = programs
    path = quick_results
    lines = path.read_text().splitlines(keepends=True)
    assert edit[0] in lines[line - 1], lines[line - 1]
    assert '"detected_tick": 46' in lines[6] and '"at=34"' not in lines[6] and ",at=34" in lines[6]
    assert '"sets_run": 21' in lines[6] and '"corrupted": 29' in lines[8]
    lines[line - 1] = lines[line - 1].replace(edit[0], edit[1], 1)
    path.write_text("".join(lines))
    before = path.read_bytes()
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    errors = [x for x in r.output.splitlines() if not x.startswith("vampc: warning")]
    assert r.exit_code == 1 and errors == [f"vampc: error: --results {path}: line {line} is not a "
                                           "run's result (the file was edited; remove it to start "
                                           "over)"], r.output
    assert path.read_bytes() == before


def test_a_runs_sets_corrupted_before_and_after_are_within_the_sets_it_ran(quick_results):
    """The sum of a detected run's sets corrupted before and after the detection is within the sets
    it ran, on a line whose class those counts leave as it is (a detected-not-corrected run: the
    edit of a corrected one's corrupted_after is refused for its class already, which left the sum
    untested: a review's find)."""
    lines = quick_results.read_text().splitlines()
    header, run = json.loads(lines[0]), json.loads(lines[6])
    assert run["class"] == "detected-corrected" and run["sets_run"] == 21 and run["corrupted_before"] == 4
    assert run["corrupted_after"] <= run["sets_after"] <= run["sets_run"] - run["corrupted_before"]
    run.update({"class": "detected-not-corrected", "corrupted_after": 17, "sets_after": 17})  # 4 + 17 = 21
    assert cp.run_class(run, run["vamp"]) == run["class"]
    assert cp._a_run_of(run, header["faults"], header["sets"], 4)
    run["sets_after"] = 16              # more sets corrupted after the detection than were run then
    assert not cp._a_run_of(run, header["faults"], header["sets"], 4)
    run["sets_after"] = 22              # more run after it than in all
    assert not cp._a_run_of(run, header["faults"], header["sets"], 4)
    run["sets_after"] = 18
    run["corrupted_after"] = 18                                                  # 22 of 21 sets run
    assert cp.run_class(run, run["vamp"]) == run["class"]
    assert not cp._a_run_of(run, header["faults"], header["sets"], 4)


def test_a_run_on_two_lines_is_refused_naming_both(programs, quick_results):
    """A run's line said again (or a second, edited one) silently replaced the first."""
    ec, _, _ = programs
    path = quick_results                     # the QUICK campaign's results (made once)
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines + [lines[2]]))
    before = path.read_bytes()
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    errors = [x for x in r.output.splitlines() if not x.startswith("vampc: warning")]
    assert r.exit_code == 1 and errors == [f"vampc: error: --results {path}: lines 3 and 10 are "
                                           "both run 1's result (the file was edited; remove it "
                                           "to start over)"]
    assert path.read_bytes() == before


def test_a_kind_or_bit_named_twice_runs_once(programs, tmp_path):
    """`--kinds dead,dead` ran every fault twice and counted it twice (`--bits 1,1` too), as
    `--values 1,1` did not."""
    from vampc.options import FaultsOptions
    assert FaultsOptions(kinds="dead,result,dead").kind_list() == ["result", "dead"]  # (its order)
    assert FaultsOptions(bits="3,1,3").bit_list() == [3, 1]
    ec, _, _ = programs
    twice = _campaign(ec, tmp_path, "--kinds", "dead,dead", "--sets", "3")
    once = _campaign(ec, tmp_path, "--kinds", "dead", "--sets", "3", name="once.jsonl")
    assert twice["runs"] == once["runs"] and len({r["fault"] for r in once["runs"]}) == len(once["runs"])
    # and said, not dropped unsaid (an audit's find): 03 is bit 3 again
    r = RUN(main, ["faults", str(ec), "--kinds", "result,dead,result", "--bits", "3,03,5", "--values",
                   "1,1", "--sets", "3", "--workers", "1", "--results", str(tmp_path / "w.jsonl")])
    said = [x for x in r.output.splitlines() if x.startswith("vampc: warning: --")
            and "--sets" not in x]
    assert r.exit_code == 0 and said == [
        "vampc: warning: --kinds result,dead,result: result given more than once, taken once",
        "vampc: warning: --bits 3,03,5: 3 given more than once, taken once",
        "vampc: warning: --values 1,1: 1 given more than once, taken once"], r.output


def test_a_campaign_too_big_for_memory_names_what_faults_can_do(programs, tmp_path, monkeypatch):
    """The advice was "use --engine stream", an option faults does not have."""
    from vampc.emulator import driver
    monkeypatch.setattr(driver, "_available_memory", lambda: 1 << 20)
    ec, _, _ = programs
    r = RUN(main, ["faults", str(ec), "--sets", "100000", "--results", str(tmp_path / "r.jsonl")])
    errors = [x for x in r.output.splitlines() if not x.startswith("vampc: warning")]
    assert r.exit_code == 1 and len(errors) == 1, r.output
    assert errors[0].endswith("give fewer --sets or --workers (a fault campaign runs on the tick "
                              "engine)")
    assert "--engine" not in r.output and not (tmp_path / "r.jsonl").exists()


def test_a_results_link_is_refused_dangling_or_not(programs, tmp_path):
    """A link to a results file was refused ("a link or a device is never written") but a dangling
    one was written through, creating its target: both are refused now, and nothing is made."""
    ec, _, _ = programs
    for target in (tmp_path / "kept.jsonl", tmp_path / "missing.jsonl"):
        link = tmp_path / f"to-{target.name}"
        link.symlink_to(target)
        if target.name == "kept.jsonl":
            target.write_text("")
        r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(link)])
        assert r.exit_code == 1 and "not a regular file (a link or a device is never written)" in r.output
    assert not (tmp_path / "missing.jsonl").exists() and (tmp_path / "kept.jsonl").read_text() == ""


class _FillsUp:
    """A results file's handle on a disk that fills after `room` bytes (ENOSPC, as a full disk)."""

    def __init__(self, fh, room: int):
        self.fh, self.room = fh, room

    def write(self, data):
        import errno
        if len(data) > self.room:
            raise OSError(errno.ENOSPC, "No space left on device")
        self.room -= len(data)
        return self.fh.write(data)

    def __getattr__(self, name):
        return getattr(self.fh, name)


def _filling(monkeypatch, room: int):
    """Results files opened from here on fill after `room` bytes; the real open, to put back."""
    real_open = cp.ResultsFile.open

    def opened(self):
        real_open(self)
        self._fh = _FillsUp(self._fh, room)
    monkeypatch.setattr(cp.ResultsFile, "open", opened)
    return real_open


def test_a_full_disk_under_the_results_file_is_one_line_and_resumes(programs, tmp_path, monkeypatch):
    """A full disk while a campaign wrote its --results file was a traceback and 'internal
    error' (exit 3): one line naming the file, exit 1; the runs written are kept and resumed."""
    ec, _, _ = programs
    whole = _campaign(ec, tmp_path, *QUICK, name="whole.jsonl")
    real_open = _filling(monkeypatch, 1500)
    path = tmp_path / "r.jsonl"
    r = RUN(main, ["faults", str(ec), "--format", "json", "--results", str(path), "--workers", "1",
                   *QUICK])
    err = r.stderr.splitlines()[-1]          # (after the warning a short run draws)
    assert r.exit_code == 1 and err.startswith(f"vampc: error: --results {path}: cannot write: No "
                                               "space left on device (the results written before "
                                               "are kept"), r.stderr
    assert "Traceback" not in r.output and "internal error" not in r.output
    monkeypatch.setattr(cp.ResultsFile, "open", real_open)
    assert 1 < len(path.read_bytes().splitlines()) < len(whole["runs"]) + 1
    assert _campaign(ec, tmp_path, *QUICK)["runs"] == whole["runs"]


def test_a_full_disk_before_any_result_says_nothing_is_kept(programs, tmp_path, monkeypatch):
    """A disk full before the first run's line had been said to keep "the results written before"
    (a new user's find, on a tmpfs filled beside the program): none were."""
    ec, _, _ = programs
    _filling(monkeypatch, 10)
    path = tmp_path / "r.jsonl"
    r = RUN(main, ["faults", str(ec), "--results", str(path), "--workers", "1", *QUICK])
    assert r.exit_code == 1 and r.stderr.splitlines()[-1] == (
        f"vampc: error: --results {path}: cannot write: No space left on device (no run's result "
        "had been written)"), r.stderr


def test_a_what_if_word_is_said_and_csv_files_end_as_standard_output_does(programs, tmp_path):
    """`faults PROGRAM --word q16.16` ran in another word format and neither the summary nor the
    JSON said so; `--format csv -o FILE` ended with a blank line standard output did not have."""
    ec, _, _ = programs
    r = RUN(main, ["faults", str(ec), "--word", "q16.16", "--kinds", "result", "--sets", "3",
                   "--results", str(tmp_path / "w.jsonl"), "--workers", "1"])
    assert r.exit_code == 0, r.output
    assert "words q16.16 (nearest, saturate) (what if: not the program's own word)" in r.stdout
    # (README says a narrower word's summary gives the fault-free run's overflows: 0 was unsaid)
    assert "\n  the fault-free run did not overflow the word\n" in r.stdout, r.stdout
    r = RUN(main, ["faults", str(ec), "--word", "q16.16", "--kinds", "result", "--sets", "3",
                   "--results", str(tmp_path / "w.jsonl"), "--workers", "1", "--format", "json"])
    got = _json(r.output)
    assert got["word"] == "q16.16 (nearest, saturate)" and got["what_if_word"] is True
    own = _campaign(ec, tmp_path, "--kinds", "control", "--sets", "3", name="own.jsonl")
    assert own["word"] == "float64" and own["what_if_word"] is False
    assert own["reference_overflows"] is None and got["reference_overflows"] == 0
    args = ["faults", str(ec), "--kinds", "control", "--sets", "3", "--results",
            str(tmp_path / "c.jsonl"), "--workers", "1", "--format", "csv"]
    out = tmp_path / "c.csv"
    written = RUN(main, [*args, "-o", str(out)])
    assert written.exit_code == 0 and written.stdout == ""
    # (and says where it went: a campaign with -o ended in silence, a new user's find)
    assert re.fullmatch(rf"vampc faults: \d+ runs \(single\); the csv report in {re.escape(str(out))}, "
                        rf"each run's result in {re.escape(str(tmp_path / 'c.jsonl'))}",
                        written.stderr.splitlines()[-1]), written.stderr
    shown = RUN(main, args).stdout
    assert out.read_text() == shown[shown.index("index,"):] and not out.read_text().endswith("\n\n")


def test_drawing_a_big_random_campaign_shows_progress(programs, monkeypatch, capsys):
    """A random campaign of a million faults spent minutes drawing them with nothing shown (the
    README: work over 2 s shows a bar). The faults drawn are the same with the bar."""
    import time

    from vampc import progress
    ec, _, _ = programs
    ld = load_program(str(ec))
    quiet = cp.faults_of(ld, "random", cp.KINDS, 0, 9000, 0.2, 7, 100)
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    real = cp._draw_random

    def slowly(*args):                   # (tqdm redraws at most every 0.1 s)
        drawn = args[-1]
        real(*args[:-1], lambda done, total: (time.sleep(0.15), drawn(done, total)))
    monkeypatch.setattr(cp, "_draw_random", slowly)
    shown = cp.faults_of(ld, "random", cp.KINDS, 0, 9000, 0.2, 7, 100)
    assert [f.text for f in shown] == [f.text for f in quiet]
    assert "drawing faults" in capsys.readouterr().err


def test_the_fault_free_runs_overflows_are_said(tmp_path):
    """A word too narrow for the robot (q4.12 cannot hold g = 9.81): every run was classified
    against the fault-free run's saturated torques and the summary said nothing of it (a new
    user's find). It says the fault-free run's overflow count, `vampc emulate --engine tick`'s on
    the same sets, on a resumed campaign too; float64 says none (JSON null)."""
    robot = tmp_path / "one.yaml"
    robot.write_text(ONE_JOINT)
    program = tmp_path / "q.vamp.json"
    assert RUN(main, ["compile", str(robot), "--word", "q4.12", "-o", str(program)]).exit_code == 0
    em = RUN(main, ["emulate", str(program), "--random", "12", "--engine", "tick"])
    said = int(re.search(r"q4\.12 \(nearest, saturate\) words: (\d+) overflows", em.output)[1])
    assert said > 0
    for _ in range(2):                        # run, then resumed from the results file
        r = RUN(main, ["faults", str(program), "--sets", "12", "--kinds", "dead", "--workers", "1",
                       "--results", str(tmp_path / "r.jsonl")])
        assert r.exit_code == 0, r.output
        assert f"the fault-free run overflowed the word {said} times: its torques are the word's" in r.output
    assert _campaign(program, tmp_path, "--sets", "12", "--kinds", "dead")["reference_overflows"] == said
    plain = tmp_path / "p.vamp.json"
    assert RUN(main, ["compile", str(robot), "-o", str(plain)]).exit_code == 0
    assert _campaign(plain, tmp_path, "--sets", "12", "--kinds", "dead", name="p.jsonl")["reference_overflows"] is None


def test_a_control2_escape_is_not_put_down_to_the_data(programs):
    """The campaigns' control2 fault (the copy's delay-R bit stuck) mostly leaves the compare
    periods seeing equal results while the torques are spoiled: each such escape was explained as
    'the data masked it' (a new user's find, 46 of planar2's 60); it names the checking circuitry.
    The run is silent corruption by the reference run, independent of the reason."""
    from vampc.emulator.driver import random_states
    from vampc.emulator.host import port_values
    _, _, planar = programs
    ld = load_program(str(planar))
    sets = cp.default_sets(ld)
    ports = port_values(ld, random_states(ld.chain, 0, sets, 0))
    setup = cp.Setup(ld, ports, cp.reference_run(ld, ports, sets, 0), sets, 0)
    silent = []
    for f in cp.faults_of(ld, "single", ["control2"]):
        run = cp.run_fault(setup, f)
        if run["class"] == "silent-corruption":
            silent.append(run)
        if len(silent) == 3:
            break
    assert silent
    escapes = cp.summarise(ld, silent, sets)["escapes"]
    assert all("checking circuitry's copy of the successor's control" in e["reason"] for e in escapes), escapes


def test_a_kind_a_vamp_has_no_fault_of_is_said_not_dropped(programs, tmp_path):
    """The single campaign's control fault on the extraneous VAMP (no control registers of its own)
    and control2 on the last VAMP of the check order (no second set) are not run: a new user's
    campaign said 305 faults on 153 VAMPs for two kinds and nothing of the missing one. The
    runs the campaign made are every (VAMP, kind) pair but those two, and both are named."""
    ec, plain, _ = programs
    ld = load_program(str(ec))
    V, last = len(ld.net.vamps), ld.net.checking.order[-1]
    got = _campaign(ec, tmp_path, "--kinds", "control,control2", "--sets", FEW)
    made = {(r["vamp"], r["fault"].split("=")[2].split(".")[0]) for r in got["runs"]}   # stuck=control...
    every = {(v, k) for v in range(V + 1) for k in ("control", "control2")}
    assert every - made == {(V, "control"), (last, "control2")}
    assert got["not_run"] == [f"control on VAMP {V} (the extraneous VAMP has no control registers of its own)",
                              f"control2 on VAMP {last} (the last in the check order: no second set)"]
    r = RUN(main, ["faults", str(ec), "--kinds", "control", "--sets", FEW, "--workers", "1",
                   "--results", str(tmp_path / "t.jsonl")])
    assert r.exit_code == 0 and f"no such fault: control on VAMP {V} (the extraneous" in r.output
    assert _campaign(plain, tmp_path, "--kinds", "control", "--sets", FEW, name="p.jsonl")["not_run"] == []
    # without error correction no VAMP has a second set: control2 beside another kind was dropped
    # on every VAMP, unsaid (a review's find)
    assert _campaign(plain, tmp_path, "--kinds", "control2,dead", "--sets", FEW, name="q.jsonl")["not_run"] == [
        "control2 on every VAMP (no error correction: no VAMP has a second set)"]
    # and control2 alone, no fault left to run, said only that it "gives no fault on this
    # program" (a new user's find): why is said as not_run says it
    r = RUN(main, ["faults", str(plain), "--kinds", "control2", "--sets", FEW, "--workers", "1",
                   "--results", str(tmp_path / "n.jsonl")])
    assert r.exit_code == 1 and r.stderr == (
        f"vampc: error: {plain}: --kinds control2 gives no fault on this program: control2 on every "
        "VAMP (no error correction: no VAMP has a second set)\n") and not (tmp_path / "n.jsonl").exists()


def test_a_random_campaign_runs_only_the_kinds_asked_for(programs, tmp_path):
    """A random draw of a control fault on the extraneous VAMP (no control registers of its own), or
    of control2 on the last VAMP of the check order, became a result fault, unsaid, in a campaign
    of --kinds control (a review's find): it is drawn on a VAMP that has the register now. Without
    error correction, control2 alone is refused, beside other kinds left out with a warning."""
    ec, plain, _ = programs
    got = _campaign(ec, tmp_path, "--campaign", "random", "--count", "60", "--sets", FEW, "--kinds",
                    "control,control2")
    regs = {r["fault"].split(",")[1].split("=")[1].split(".")[0] for r in got["runs"]}
    assert regs == {"control", "control2"}, regs
    V = len(load_program(str(ec)).net.vamps)
    assert all(r["vamp"] < V for r in got["runs"] if ",stuck=control." in r["fault"])
    r = RUN(main, ["faults", str(plain), "--campaign", "random", "--count", "4", "--kinds", "control2",
                   "--results", str(tmp_path / "c2.jsonl")])
    assert r.exit_code == 2 and "no second set of control registers" in r.stderr, r.output
    r = RUN(main, ["faults", str(plain), "--campaign", "random", "--count", "4", "--sets", "40",
                   "--kinds", "control2,dead", "--workers", "1", "--results", str(tmp_path / "c3.jsonl")])
    assert r.exit_code == 0 and "--kinds control2: left out" in r.stderr, r.output


def test_drawn_faults_start_where_the_checking_reaches_them_before_the_run_ends(programs, tmp_path):
    """A random campaign of the default length drew start ticks over the whole run, and the faults
    drawn late were counted as silent corruption "the check did not reach the VAMP after the fault
    within the run's 565 sets" (a new user's: 1 of 4 on the Puma). Now a drawn fault starts in all
    but the run's last reach_sets, a whole sweep there and back and the network's drain, and the
    default run adds those to default_sets: next_check reaches every VAMP in time."""
    ec, _, _ = programs
    ld = load_program(str(ec))
    doc = _campaign(ec, tmp_path, "--campaign", "random", "--count", "12", "--seed", "3")
    sets, P = doc["sets"], ld.period
    assert sets == cp.default_sets(ld) + cp.reach_sets(ld) > cp.default_sets(ld)
    drain = -(-max(o.tick for o in ld.net.outputs) // P) + cp.TAIL + 1   # (sets to leave the network)
    for run in doc["runs"]:
        fault = parse_fault(run["fault"])
        if fault.vamp < len(ld.net.vamps):
            assert fault.at < cp.draw_sets(ld, sets) * P
            assert cp.next_check(ld, fault.vamp, fault.at // P) + drain <= sets, run
        assert "did not reach" not in run.get("reason", ""), run


def test_a_drawn_campaign_shorter_than_its_default_says_where_its_faults_start(programs, tmp_path,
                                                                              monkeypatch):
    """--sets below a drawn campaign's default: past reach_sets the faults start in the first
    sets - reach_sets (warned: they had been drawn over the whole run, unsaid, and those drawn late
    counted as silent corruption); at or below it, anywhere, and those late cannot be detected (a
    review's: no warning came, since it compared with the single campaign's default)."""
    ec, _, _ = programs
    # the warning is said before any run: the first two faults drawn run, and the two that start
    # last, which the checking may not reach before the run ends (all of them took 4 s;
    # test_drawn_faults_start_where_the_checking_reaches_them... runs whole campaigns)
    drawn = cp.faults_of

    def some(*args, **kwargs):
        faults = drawn(*args, **kwargs)
        late = sorted(faults[2:], key=lambda f: f.at)[-2:]
        return faults[:2] + late
    monkeypatch.setattr(cp, "faults_of", some)
    ld = load_program(str(ec))
    reach, whole = cp.reach_sets(ld), cp.campaign_sets(ld, "transient")
    assert reach < whole
    r = RUN(main, ["faults", str(ec), "--campaign", "transient", "--sets", str(reach + 3),
                   "--results", str(tmp_path / "a.jsonl"), "--workers", "1"])
    assert r.exit_code == 0 and (
        f"vampc: warning: --sets {reach + 3}: the faults start in its first 3 sets, so that the "
        f"checking reaches each before the run ends (give --sets {whole} for starts over a whole "
        "first sweep)") in r.stderr, r.output
    r = RUN(main, ["faults", str(ec), "--campaign", "transient", "--sets", "20",
                   "--results", str(tmp_path / "b.jsonl"), "--workers", "1"])
    assert r.exit_code == 0 and (
        f"vampc: warning: --sets 20: the faults start anywhere in the run, and the checking reaches "
        f"a fault within {reach} sets of it: those that start late cannot be detected (give --sets "
        f"{whole} or more)") in r.stderr, r.output


def test_a_campaign_counts_the_memory_of_each_local_worker(programs, tmp_path, monkeypatch):
    """Each local worker runs a tick engine of its own: two that do not fit where one does are
    refused before anything runs, saying --workers helps (the check counted one engine)."""
    from vampc.emulator import driver
    ec, _, _ = programs
    ld = load_program(str(ec))
    sets = cp.default_sets(ld)
    one = driver.TICK_BYTES_PER_STAGE * sum(b.stages for b in ld.net.buffers) + 8 * sets * (
        sum(p.size for p in ld.net.ports) + 2 * ld.chain.n_outputs)
    monkeypatch.setattr(driver, "_available_memory", lambda: 3 * one)     # (half: 1.5 engines)
    args = ["faults", str(ec), "--kinds", "dead", "--sets", str(sets), "--results"]
    r = RUN(main, args + [str(tmp_path / "a.jsonl"), "--workers", "2"])
    assert r.exit_code == 1 and "need about" in r.stderr and "in the tick engines of 2 workers" \
        in r.stderr and "give fewer --sets or --workers" in r.stderr, r.output
    assert not (tmp_path / "a.jsonl").exists()
    assert RUN(main, args + [str(tmp_path / "b.jsonl"), "--workers", "1"]).exit_code == 0


def test_a_silent_run_whose_first_wrong_set_is_not_finite_is_said(tmp_path):
    """A run whose one torque set was inf was counted as silent corruption and nothing more, though
    `vampc emulate` refuses a non-finite torque, naming the set (a hardware audit). It stays silent
    (nothing checked it), and the run and the summary say so; each such run, emulated with its fault
    on the same states, is refused for a non-finite torque, and a silent run of one set without the
    flag runs to its end."""
    program = tmp_path / "planar2.vamp.json"
    assert RUN(main, ["compile", str(EXAMPLES / "planar2.yaml"), "-o", str(program)]).exit_code == 0
    r = RUN(main, ["faults", str(program), "--kinds", "a", "--sets", "8", "--workers", "1",
                   "--format", "json", "--results", str(tmp_path / "r.jsonl")])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output[r.output.index("{"):])
    silent = [x for x in out["runs"] if x["class"] == "silent-corruption"]
    flagged = [x for x in silent if x.get("first_wrong_non_finite")]
    assert out["summary"]["silent_non_finite"] == len(flagged) > 0
    plain = [x for x in silent if not x.get("first_wrong_non_finite") and x["sets_run"] == 1]
    assert plain
    for x in flagged[:3] + plain[:3]:
        e = RUN(main, ["emulate", str(program), "--engine", "tick", "--random", str(x["sets_run"]),
                       "--seed", "0", "--fault", x["fault"], "-o", str(tmp_path / "t.csv")])
        if x in flagged:
            assert e.exit_code == 1 and re.search(r"the torque is (nan|-?inf)", e.output), e.output
        else:
            assert e.exit_code == 0, e.output
    text = RUN(main, ["faults", str(program), "--kinds", "a", "--sets", "8", "--results",
                      str(tmp_path / "r.jsonl")]).output
    assert (f"in {len(flagged)} of them the first wrong torque set holds an inf or NaN, which a host "
            "that checks its torques sees") in text and "not examined" not in text
    # runs kept from an older vampc's results file, which did not look, are said, not taken as
    # finite (a review's find); a flag that is no boolean is an edited line
    lines = (tmp_path / "r.jsonl").read_text().splitlines(keepends=True)
    old = [lines[0]] + [json.dumps({k: v for k, v in json.loads(x).items()
                                    if k != "first_wrong_non_finite"}) + "\n" for x in lines[1:]]
    (tmp_path / "old.jsonl").write_text("".join(old))
    text = RUN(main, ["faults", str(program), "--kinds", "a", "--sets", "8", "--results",
                      str(tmp_path / "old.jsonl")]).output
    assert f"; {len(silent)} read from a results file of an older vampc were not examined" in text
    edited = [lines[0]] + [x.replace('"first_wrong_non_finite": false', '"first_wrong_non_finite": 0')
                           for x in lines[1:]]
    assert edited != lines
    (tmp_path / "edited.jsonl").write_text("".join(edited))
    r = RUN(main, ["faults", str(program), "--kinds", "a", "--sets", "8", "--results",
                   str(tmp_path / "edited.jsonl")])
    assert r.exit_code == 1 and "is not a run's result (the file was edited" in r.output


def test_a_results_file_another_run_holds_or_wrote_to_since_is_refused(programs, tmp_path):
    """Two campaigns given one results file at once both ran, 244 lines for 122 runs, and the next
    run called the file edited (a file-safety audit). A run holds its file while it appends: a
    second is refused at once, and one that read the file before another wrote to it is refused
    rather than appending its runs again; the file is the first run's, and resumes."""
    import fcntl
    ec, _, _ = programs
    path = tmp_path / "r.jsonl"
    args = ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)]
    assert RUN(main, args).exit_code == 0
    whole = path.read_bytes()
    lines = whole.splitlines(keepends=True)
    path.write_bytes(b"".join(lines[:-2]))          # two runs to go: a re-run resumes
    with open(path, "ab") as other:                 # another run holding it
        fcntl.flock(other.fileno(), fcntl.LOCK_EX)
        r = RUN(main, args)
        assert r.exit_code == 1 and "is being written by another vampc faults run now" in r.output
    assert path.read_bytes() == b"".join(lines[:-2])
    store = cp.ResultsFile(str(path), json.loads(lines[0]))
    store.load()
    with open(path, "ab") as other:                 # another run wrote to it after this one read it
        other.write(lines[-2])
    with pytest.raises(VampcError, match="was written by another vampc faults run after this one "
                                         "read it: run the command again"):
        store.open()
    assert path.read_bytes() == b"".join(lines[:-1])
    r = RUN(main, args)
    assert r.exit_code == 0 and path.read_bytes() == whole, r.output


@pytest.mark.parametrize("default", [False, True], ids=["given", "default"])
def test_a_results_file_of_something_else_is_called_so_and_kept(programs, tmp_path, default):
    """Binary garbage or UTF-16 text in the default results file was "the results of another
    campaign (another program ...)" (a file-safety audit): a file whose first line is no header of
    vampc faults is not a results file, said so, and kept."""
    ec, _, _ = programs
    program = tmp_path / "ec.vamp.json"
    program.write_bytes(ec.read_bytes())
    results = tmp_path / ("ec.random.faults.jsonl" if default else "r.jsonl")
    body = "notes\nmore notes\n".encode("utf-16")
    results.write_bytes(body)
    r = RUN(main, ["faults", str(program), *QUICK, "--workers", "1",
                   *([] if default else ["--results", str(results)])])
    said = (f"{results} (the default results file) is not a results file of vampc faults (never "
            "overwritten; give --results FILE)" if default else
            f"--results {results} is not a results file of vampc faults (never overwritten; give "
            "another --results file)")
    assert r.exit_code == 1 and said in r.output, r.output
    assert results.read_bytes() == body


def test_o_onto_the_default_results_file_names_it_as_the_default(programs, tmp_path):
    """`faults P -o P.single.faults.jsonl` said "--results and -o name the same file", though no
    --results was given (a file-safety audit)."""
    ec, _, _ = programs
    program = tmp_path / "ec.vamp.json"
    program.write_bytes(ec.read_bytes())
    default = tmp_path / "ec.single.faults.jsonl"
    r = RUN(main, ["faults", str(program), "-o", str(default)])
    assert r.exit_code == 1 and r.output.strip().endswith(
        f"{default}: the default results file and -o name the same file"), r.output
    r = RUN(main, ["faults", str(program), "-o", str(default), "--results", str(default)])
    assert r.exit_code == 1 and "--results and -o name the same file" in r.output
    assert not default.exists()


def test_a_file_system_without_locks_runs_the_campaign(programs, tmp_path, monkeypatch):
    """Any error of flock was taken for another run holding the file: on NFS without lockd (ENOLCK)
    every campaign was refused as 'being written by another vampc faults run', an empty file left
    (a review's find). Only a lock held elsewhere refuses; without locks the campaign runs."""
    import errno
    import fcntl

    def no_locks(fd, how):
        raise OSError(errno.ENOLCK, "No locks available")
    monkeypatch.setattr(fcntl, "flock", no_locks)
    ec, _, _ = programs
    path = tmp_path / "r.jsonl"
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    assert r.exit_code == 0 and "another vampc faults run" not in r.output, r.output
    assert len(path.read_text().splitlines()) == 1 + 8


def _adding_then(count: int, act):
    """ResultsFile.add that, once it has added `count` runs this time, calls `act` (a signal)."""
    real = cp.ResultsFile.add

    def add(self, index, run):
        real(self, index, run)
        if self.added == count:
            act()
    return add


def test_an_interrupt_swallowed_on_the_way_still_says_the_runs_kept(programs, tmp_path, monkeypatch):
    """On a Dask cluster a Ctrl-C or SIGTERM often ended a campaign with "vampc: interrupted" alone
    (a new user's find: 5 of 8 tries): the signal's exception was swallowed in the cluster's code
    (a finaliser) and raised again later, at the summary, without what the campaign keeps. Here the
    signal is remembered and its exception lost as the runs go; and a Ctrl-C before any run (the
    fault-free run, or connecting to the cluster) says that nothing is kept."""
    import signal

    from vampc import errors
    ec, _, _ = programs
    path = tmp_path / "r.jsonl"
    real = cp.ResultsFile.add
    # (its KeyboardInterrupt lost on the way)
    monkeypatch.setattr(cp.ResultsFile, "add", _adding_then(2, lambda: errors.remember(signal.SIGINT)))
    try:
        r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    finally:
        errors._terminated.clear()
    assert r.exit_code == 130 and r.stderr.strip().splitlines()[-1] == (
        f"vampc: interrupted; 2 runs finished this time kept in {path} (a re-run resumes from "
        "them)"), r.stderr
    monkeypatch.setattr(cp.ResultsFile, "add", real)

    def reference(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(cp, "reference_run", reference)
    fresh = tmp_path / "fresh.jsonl"
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(fresh)])
    assert r.exit_code == 130 and r.stderr.strip().splitlines()[-1] == (
        "vampc: interrupted; no run had finished, so nothing is kept"), r.stderr
    assert not fresh.exists()


def test_an_interrupted_campaign_says_the_runs_it_keeps(programs, tmp_path, monkeypatch):
    """Ctrl-C during `faults` said "vampc: interrupted" alone, though the runs finished are kept and
    a re-run resumes from them (a new user's find): the line says how many and where."""
    ec, _, _ = programs
    path = tmp_path / "r.jsonl"
    real = cp.ResultsFile.add

    def interrupt():
        raise KeyboardInterrupt
    monkeypatch.setattr(cp.ResultsFile, "add", _adding_then(3, interrupt))
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    assert r.exit_code == 130 and r.stderr.strip().splitlines()[-1] == (
        f"vampc: interrupted; 3 runs finished this time kept in {path} (a re-run resumes from "
        "them)"), r.stderr
    assert len(path.read_text().splitlines()) == 1 + 3

    def before_any(self, index, run):
        raise KeyboardInterrupt
    monkeypatch.setattr(cp.ResultsFile, "add", before_any)       # resumed, stopped before a run
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    assert r.exit_code == 130 and r.stderr.strip().splitlines()[-1] == (
        f"vampc: interrupted; no run finished this time; the 3 before are kept in {path} (a re-run "
        "resumes from them)"), r.stderr           # (it said "interrupted" alone: a review's find)
    monkeypatch.setattr(cp.ResultsFile, "add", real)
    real_open = cp.ResultsFile.open

    def opening(self):                       # a Ctrl-C as the file is opened, before any count
        raise KeyboardInterrupt
    monkeypatch.setattr(cp.ResultsFile, "open", opening)
    fresh = tmp_path / "fresh.jsonl"
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(fresh)])
    assert r.exit_code == 130 and r.stderr.strip().splitlines()[-1] == (
        "vampc: interrupted; no run had finished, so nothing is kept"), r.stderr
    monkeypatch.setattr(cp.ResultsFile, "open", real_open)
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--results", str(path)])
    assert r.exit_code == 0 and "(3 run(s) read from" in r.output, r.output


def test_a_stall_that_spoils_torques_is_counted_as_stalled_too(programs):
    """A VAMP that dies after the sweep has passed it stalls the checking when the sweep comes back,
    and its torques stay wrong: the run is silent corruption, and the checking stalled. Only the
    stalled runs with no torque spoiled had been counted (2 of 33 in a late dead-VAMP campaign: an
    audit's)."""
    from vampc.emulator.checking import sweep_periods
    from vampc.emulator.driver import random_states
    from vampc.emulator.host import port_values
    ec, _, _ = programs
    ld = load_program(str(ec))
    ck = ld.net.checking
    sweep = sweep_periods(len(ld.net.vamps), ck.warmup, ck.compare)
    sets = 3 * sweep
    ports = port_values(ld, random_states(ld.chain, 0, sets, 0))
    setup = cp.Setup(ld, ports, cp.reference_run(ld, ports, sets, 0), sets, 0)
    runs = [cp.run_fault(setup, parse_fault(f"vamp={v},dead,at={ld.period * sweep // 2}"))
            for v in range(0, len(ld.net.vamps), 4)]
    spoiled = [r for r in runs if r["class"] == "silent-corruption" and "stalled at tick" in r.get("reason", "")]
    assert spoiled, [r.get("reason") for r in runs]          # (the case, met on this program)
    assert all(r["stalled"]["tick"] >= ld.period * sweep // 2 for r in spoiled)
    stalled = [r for r in runs if "the checking stalled at tick" in r.get("reason", "")]
    assert cp.summarise(ld, runs, sets)["stalled"] == len(stalled) == sum(1 for r in runs if r.get("stalled"))


def test_a_fixed_point_run_that_overflowed_says_so(programs, tmp_path):
    """A stuck bit that saturates a q16.16 value: the run's overflows (the network counts them) are
    recorded, and the silent runs that overflowed are said. A run whose fault saturated values was
    silent corruption with no word of it (a faults audit's); `vampc emulate --fault` of the same
    fault, a separate run, counts overflows too."""
    _, plain, _ = programs
    program = tmp_path / "q.vamp.json"
    assert RUN(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16", "-o", str(program)]).exit_code == 0
    ld = load_program(str(program))
    from vampc.emulator.driver import random_states
    from vampc.emulator.host import port_values
    sets = 20
    ports = port_values(ld, random_states(ld.chain, 0, sets, 0))
    setup = cp.Setup(ld, ports, cp.reference_run(ld, ports, sets, 0), sets, 0)
    clean = ld.arith.overflows
    fault = "vamp=0,stuck=result.x:30,value=1"
    run = cp.run_fault(setup, parse_fault(fault))
    assert run["class"] == "silent-corruption" and run["overflows"] > 0
    assert ld.arith.overflows == clean                      # (not carried into the next run)
    quiet = cp.run_fault(setup, parse_fault("vamp=0,stuck=result.x:0,value=1"))
    assert quiet["overflows"] == 0
    summary = cp.summarise(ld, [run, quiet], sets)
    assert summary["silent_overflowed"] == 1
    assert "in 1 of them the word overflowed, which the network's overflow count shows" in \
        cp.render_text("head", summary)
    assert "silent_overflowed" not in cp.summarise(load_program(str(plain)), [], sets)   # float64
    # where the fault-free run overflowed too, the count does not single the run out ("which the
    # network's overflow count shows" had been said of such runs: a new user's find)
    both = cp.summarise(ld, [run, quiet], sets, reference_overflows=579)
    assert both["silent_overflowed"] == 1 and both["reference_overflows"] == 579
    assert "in 1 of them the word overflowed, but so did the fault-free run, so the network's " \
        "overflow count does not single them out" in cp.render_text("head", both)
    # a run kept from an older vampc's results file, which did not count them: said apart
    older = {k: v for k, v in run.items() if k != "overflows"}
    kept = cp.summarise(ld, [older, quiet], sets)
    assert kept["silent_overflowed"] == 0 and kept["silent_overflows_not_examined"] == 1
    assert "1 read from a results file of an older vampc were not examined for overflows" in \
        cp.render_text("head", kept)
    r = RUN(main, ["emulate", str(program), "--engine", "tick", "--random", str(sets), "--fault", fault])
    said = re.search(r"q16\.16 \(nearest, saturate\) words: (\d+) overflows", r.output)
    assert said and int(said[1]) > 0, r.output


def test_a_what_if_words_campaign_beside_the_programs_own_is_said_to_be_another_word(programs,
                                                                                   quick_results):
    """A new user ran a campaign in a what-if --word after the program's own campaign: the default
    results file was refused as holding "another program". It is the same program in another
    word, said so."""
    ec, _, _ = programs
    r = RUN(main, ["faults", str(ec), *QUICK, "--workers", "1", "--word", "q8.15", "--results",
                   str(quick_results)])
    assert r.exit_code == 1 and "holds the results of another campaign or program (another word: " \
        "the program's own in the file, q8.15 (nearest, saturate) here, other faults" in r.stderr, \
        r.stderr
    assert "another program" not in r.stderr


def test_the_csv_gives_each_runs_overflows_as_the_json_does(programs, tmp_path):
    """The JSON's runs carry a fixed-point word's overflows per run; the CSV had no such column (a
    new user's). It is its last column, empty in a float word."""
    import csv
    ec, _, _ = programs
    args = ["faults", str(ec), "--kinds", "result", "--sets", "3", "--word", "q6.10", "--workers",
            "1", "--results", str(tmp_path / "r.jsonl")]
    doc = _json(RUN(main, [*args, "--format", "json"]).output)
    table = RUN(main, [*args, "--format", "csv"]).stdout
    rows = list(csv.DictReader(io.StringIO(table)))
    assert list(rows[0])[-1] == "overflows" and len(rows) == len(doc["runs"])
    assert [int(r["overflows"]) for r in rows] == [run["overflows"] for run in doc["runs"]]
    assert any(run["overflows"] for run in doc["runs"])
    plain = RUN(main, ["faults", str(ec), "--kinds", "result", "--sets", "3", "--workers", "1",
                       "--results", str(tmp_path / "f.jsonl"), "--format", "csv"]).stdout
    assert {r["overflows"] for r in csv.DictReader(io.StringIO(plain))} == {""}


def test_a_fault_free_run_whose_torques_overflow_is_refused_naming_the_set(tmp_path):
    """Masses of 1e300 and a link of 1e200 overflow float64: `emulate` refuses the torques, naming
    the set, and a campaign ran every fault against those NaNs and said 100% coverage, exit 0 (a
    new user's find). It is refused as emulate refuses it, and writes no results file."""
    robot = tmp_path / "huge.yaml"
    robot.write_text((EXAMPLES / "planar2.yaml").read_text().replace("mass: 2.0", "mass: 1.0e300")
                     .replace("a: 0.5", "a: 1.0e200"))
    program = tmp_path / "huge.vamp.json"
    assert RUN(main, ["compile", str(robot), "--error-correction", "-o", str(program)]).exit_code == 0
    em = RUN(main, ["emulate", str(program), "--random", "3"])
    assert em.exit_code == 1 and "set 1, joint 1 (shoulder): the torque is nan" in em.output
    results = tmp_path / "r.jsonl"
    r = RUN(main, ["faults", str(program), "--kinds", "dead", "--workers", "1", "--results",
                   str(results)])
    assert r.exit_code == 1 and r.output == (
        f"vampc: error: {program}: set 1 of the fault-free run, joint 1 (shoulder): the torque is "
        "nan (float64 overflow: the robot's or the state's numbers are too large); the run stopped "
        "and wrote no output file\n"), r.output
    assert not results.exists()
