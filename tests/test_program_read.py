"""Reading a program never schedules it again: the report of a `--vamps 7 --exact` program (compiled
once, kept in tests/data/) neither imports OR-Tools nor runs the budget scheduler for its own
configuration (the comparison layouts it is set beside, systolic and folded, are still laid out);
the schedule, layout and network are read from the file and checked against each other
(vampc.program.document.compiled_from_doc)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from program_util import edited_program

from vampc.cli import main

EXACT = Path(__file__).resolve().parent / "data" / "puma560-vamps7-exact.vamp.json"


def test_report_of_an_exact_program_imports_no_ortools():
    code = ("import sys\nfrom vampc.cli import main\ntry:\n    main(['report', sys.argv[1]])\n"
            "except SystemExit as e:\n    assert not e.code, e.code\n"
            "print('ortools' in sys.modules, file=sys.stderr)")
    res = subprocess.run([sys.executable, "-c", code, str(EXACT)], capture_output=True, text=True,
                         check=True)
    assert res.stderr.strip() == "False"
    assert "budget, 7 VAMPs, exact" in res.stdout


def test_running_a_program_imports_no_robot_loader_nor_the_tools_of_other_commands(tmp_path):
    """README, Emulator speed: the robot loaders (PyYAML, lxml, yourdfpy, MuJoCo) are not imported
    to run a program, nor pyvcd without --vcd, nor the report's and compiler's libraries: each is
    a start-up cost every `vampc emulate` of a program file would pay (PyYAML came back through the
    check of a program's inertias, about 0.05 s of a 0.25 s run)."""
    code = ("import sys\nfrom vampc.cli import main\ntry:\n    main(sys.argv[1:])\n"
            "except SystemExit as e:\n    assert not e.code, e.code\n"
            "heavy = ('yaml', 'lxml', 'yourdfpy', 'mujoco', 'vcd', 'matplotlib', 'networkx', 'ortools',"
            " 'dask', 'amaranth')\n"
            "print(sorted(m for m in heavy if m in sys.modules), file=sys.stderr)")
    out = tmp_path / "tau.npy"
    res = subprocess.run([sys.executable, "-c", code, "emulate", str(EXACT), "--random", "3", "-o", str(out)],
                         capture_output=True, text=True, check=True)
    assert res.stderr.strip().splitlines()[-1] == "[]", res.stderr
    assert out.exists()


def test_report_of_an_exact_program_does_not_schedule_its_own_configuration(monkeypatch):
    """No budget scheduler, heuristic or exact, runs; the only layouts made are the comparison
    configurations the file does not hold (systolic and folded, each recursion once)."""
    import vampc.report.configs as configs
    import vampc.schedule.budget as budget
    import vampc.schedule.exact as exact

    def refuse(*args, **kwargs):
        raise AssertionError("the program's own budget was scheduled again")
    for module, name in ((budget, "budget_schedule"), (budget, "modulo_schedule"),
                         (exact, "exact_budget")):
        monkeypatch.setattr(module, name, refuse)
    made = []
    real = configs.layout_and_schedule

    def recording(graph, timing, name, request):
        made.append((str(graph.recursion), name, request.share_passes))
        return real(graph, timing, name, request)
    monkeypatch.setattr(configs, "layout_and_schedule", recording)
    res = CliRunner().invoke(main, ["report", str(EXACT), "--format", "json"])
    assert res.exit_code == 0, res.output
    rep = json.loads(res.stdout)
    assert rep["budget"]["exact"] and "proven optimal" in rep["budget"]["proof"]
    assert rep["latency"]["flops"] == 61 and rep["interval_flops"] == 47
    assert sorted(made) == sorted((rec, lay, share) for rec in ("linear", "log")
                                  for lay, share in (("systolic", False), ("folded", False),
                                                     ("folded", True)))


def _edited(tmp_path, change) -> str:
    return str(edited_program(EXACT, tmp_path, change))


def test_a_schedule_that_does_not_run_the_graph_is_refused(tmp_path):
    def later(doc):          # an op that starts a tick late no longer lasts its duration
        doc["schedule"]["start"][doc["schedule"]["critical_path"][0]] += 1
    res = CliRunner().invoke(main, ["report", _edited(tmp_path, later)])
    assert res.exit_code == 1 and "schedule.finish is not the schedule" in res.stderr, res.stderr

    def other_path(doc):
        doc["schedule"]["critical_path"] = doc["schedule"]["critical_path"][1:]
    res = CliRunner().invoke(main, ["report", _edited(tmp_path, other_path)])
    assert res.exit_code == 1 and "schedule.critical_path is not a critical path" in res.stderr


def test_a_slot_off_its_scheduled_tick_is_refused(tmp_path):
    def moved(doc):
        slot = doc["programs"][0]["slots"][0]
        slot["delay_r"] = (slot["delay_r"] + 1) % doc["network"]["period"]
    res = CliRunner().invoke(main, ["report", _edited(tmp_path, moved)])
    assert res.exit_code == 1 and "delay-R" in res.stderr and "is not the schedule's tick" in \
        res.stderr, res.stderr


def test_a_damaged_options_section_is_the_files_error(tmp_path):
    for change, what in ((lambda d: d["options"].update(layout="bogus"), "options.layout"),
                         (lambda d: d["options"].update(vamps="x"), "options.vamps"),
                         (lambda d: d["options"].update(prefix="bogus"), "options.prefix")):
        res = CliRunner().invoke(main, ["report", _edited(tmp_path, change)])
        assert res.exit_code == 1 and what in res.stderr and res.stderr.count("\n") == 1, \
            res.stderr


def test_a_slot_naming_no_graph_node_is_refused(tmp_path):
    def beyond(doc):
        doc["programs"][0]["slots"][0]["node"] = len(doc["graph"]["nodes"]) + 5
    res = CliRunner().invoke(main, ["report", _edited(tmp_path, beyond)])
    assert res.exit_code == 1 and "programs[0].slots[0].node" in res.stderr and \
        "is not a node of the graph" in res.stderr and res.stderr.count("\n") == 1, res.stderr


@pytest.mark.parametrize("value", [999, 5])
def test_a_programs_entry_naming_another_vamp_is_refused_by_every_command(tmp_path, value):
    """programs[3].vamp edited (out of range, a duplicate) with the checksum made again: the listing
    is read by position, so the edit changed nothing the engines ran, and went unnoticed."""
    def renamed(doc):
        doc["programs"][3]["vamp"] = value
    path = _edited(tmp_path, renamed)
    for args in (["report", path], ["emulate", path, "--random", "3", "--check"]):
        res = CliRunner().invoke(main, args)
        assert res.exit_code == 1 and f"programs[3].vamp: {value}, but entry 3 lists VAMP 3" in res.stderr \
            and res.stderr.count("\n") == 1, res.stderr


def test_the_warning_of_a_programs_improper_inertia_imports_no_robot_loader(tmp_path):
    """A program compiled with --accept-improper-inertia is warned of as it is read; its thresholds
    (NEARLY_PSD) were taken from the URDF loader, which brought lxml and PyYAML into that run."""
    import re
    urdf = (Path(__file__).resolve().parent.parent / "examples" / "arm6.urdf").read_text()
    bad = tmp_path / "bad.urdf"
    bad.write_text(re.sub(r"<inertia [^>]*/>",
                          '<inertia ixx="0.01" ixy="0.5" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>', urdf))
    program = tmp_path / "bad.vamp.json"
    made = CliRunner().invoke(main, ["compile", str(bad), "--accept-improper-inertia", "-o", str(program)])
    assert made.exit_code == 0, made.output
    code = ("import sys\nfrom vampc.cli import main\ntry:\n    main(sys.argv[1:])\n"
            "except SystemExit as e:\n    assert not e.code, e.code\n"
            "print(sorted(m for m in ('yaml', 'lxml', 'yourdfpy') if m in sys.modules), file=sys.stderr)")
    res = subprocess.run([sys.executable, "-c", code, "emulate", str(program), "--random", "2",
                          "-o", str(tmp_path / "tau.csv")], capture_output=True, text=True, check=True)
    lines = res.stderr.strip().splitlines()
    assert "robot.joints[0].inertia: inertia is not positive semi-definite" in res.stderr, res.stderr
    assert lines[-1] == "[]", res.stderr
