"""The command line (vampc.cli): commands, JSON report keys and figures, and error behaviour.

Puma 560 figures come from the paper (n = 6 general rotary arm: 15 M + 43 A linear, 132 + 48 VAMPs,
4-flop interval, serial 852 M + 738 A) plus the documented output correction of 1 M + 2 A; the graph's
serial work is counted by hand from DESIGN §4 (see test_report.py).
"""
from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES, example_paths

from vampc.cli import main
from vampc.program.file import read_program

PUMA = str(EXAMPLES / "puma560.yaml")


def run(*args, cwd=None):
    """Invoke the CLI in-process; stderr is captured separately."""
    runner = CliRunner()
    if cwd is None:
        return runner.invoke(main, [str(a) for a in args])
    old = os.getcwd()
    os.chdir(cwd)
    try:
        return runner.invoke(main, [str(a) for a in args])
    finally:
        os.chdir(old)


def run_process(*args, cwd=None) -> subprocess.CompletedProcess:
    """Run `python -m vampc.cli` as a real process, importing the same vampc as these tests."""
    package_root = Path(importlib.util.find_spec("vampc").origin).parent.parent
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(package_root),
                                                       os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", "vampc.cli", *map(str, args)], capture_output=True,
                          text=True, env=env, cwd=cwd, timeout=120)


def assert_user_error(result, name: str, folder: Path | None = None, before=()):
    """Exit 1, one stderr line `vampc: error: ...` naming the file, nothing on stdout, no new files."""
    assert result.exit_code == 1, result.output
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("vampc: error: "), result.stderr
    assert name in lines[0]
    assert "Traceback" not in result.stderr and result.stdout == ""
    if folder is not None:
        assert sorted(folder.iterdir()) == sorted(before)


# --- the two commands that matter --------------------------------------------------------------------

def test_compile_writes_the_program_file(tmp_path):
    out = tmp_path / "puma.vamp.json"
    result = run("compile", PUMA, "-o", out)
    assert result.exit_code == 0, result.output
    assert result.stdout == (f"{out}: 6 joints, linear recursion, 180 VAMPs, latency 61 flops "
                             "(16 M + 45 A), interval 4 flops\n")
    doc = read_program(out)
    assert doc["robot"]["name"] == "puma560" and len(doc["network"]["vamps"]) == 180


@pytest.mark.parametrize("path", example_paths(), ids=lambda p: p.name)
def test_every_example_compiles(tmp_path, path):
    out = tmp_path / "x.vamp.json"
    result = run("compile", path, "-o", out)
    assert result.exit_code == 0, result.output
    doc = read_program(out)
    assert doc["summary"]["joints"] == doc["robot"]["n"] == len(doc["robot"]["joints"]) >= 1


def test_compile_default_output_name(tmp_path):
    result = run("compile", PUMA, cwd=tmp_path)
    assert result.exit_code == 0, result.output
    assert [p.name for p in tmp_path.iterdir()] == ["puma560.vamp.json"]


def puma_json(*extra) -> dict:
    result = run("report", PUMA, "--format", "json", *extra)
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_report_json_has_the_documented_keys():
    rep = puma_json()
    for key in ("joints", "recursion", "layout", "latency", "paper", "interval_flops", "vamps",
                "buffers", "serial_work"):
        assert key in rep
    assert set(rep["latency"]) >= {"flops", "mults", "adds"}
    assert set(rep["paper"]) >= {"flops", "mults", "adds"}
    assert set(rep["vamps"]) >= {"total", "backward", "forward", "by_op"}
    assert set(rep["serial_work"]) >= {"mults", "adds"}


def test_report_json_puma560_figures():
    rep = puma_json()
    assert (rep["joints"], rep["recursion"], rep["layout"]) == (6, "linear", "systolic")
    assert rep["paper"] == {"flops": 58, "mults": 15, "adds": 43}
    assert rep["latency"] == {"flops": 61, "mults": 16, "adds": 45, "waits": 0}
    assert rep["interval_flops"] == 4
    v = rep["vamps"]
    assert (v["total"], v["backward"], v["forward"]) == (180, 132, 48)
    assert v["by_op"] == {"MTV": 18, "MV": 24, "SV": 6, "VA": 72, "VC": 60}
    assert rep["serial_work"] == {"mults": 756, "adds": 648}
    assert rep["buffers"]["scalars"] == 3 * rep["buffers"]["stages"] > 0


def test_report_with_other_latencies():
    rep = puma_json("--mult-latency", "2", "--add-latency", "3")
    # Appendix A + 1 MV with VA = 3, SV = 2, VC = 5, MV = 2 + 3 + 3 = 8: 2·5·11 + 2 + 16 + 15 + 24.
    assert rep["latency"]["flops"] == 167
    assert rep["interval_flops"] == 11


def test_report_of_the_program_equals_report_of_the_robot(tmp_path):
    out = tmp_path / "puma.vamp.json"
    assert run("compile", PUMA, "-o", out).exit_code == 0
    result = run("report", out, "--format", "json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout) == puma_json()


def test_text_report_explains_the_difference_to_the_paper():
    result = run("report", PUMA)
    assert result.exit_code == 0, result.output
    text = result.stdout
    assert "latency          61 flops = 16 Mults + 45 Addns on the critical path" in text
    assert "paper            58 flops = 15 Mults + 43 Addns" in text
    assert "+3 flops (+1 Mults, +2 Addns) against the paper's formula" in text
    note = next(line for line in text.splitlines() if "output correction" in line)
    assert all(part in note for part in ("1 Mult + 2 Addns", "τ_i = z_{i-1}·n_i", "A_i n_i", "O_{i-1}"))
    assert "VAMPs            180 = 132 backward + 48 forward" in text


# --- errors ------------------------------------------------------------------------------------------

def bad_robots(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """Broken robot files: name -> (path, text of the one-line message after 'vampc: error: ')."""
    files = {
        "missing": ("gone.yaml", None),
        "extension": ("robot.txt", "name: x\n"),
        "yaml": ("broken.yaml", "name: [unclosed\n"),
        "mass": ("mass.yaml", (EXAMPLES / "planar2.yaml").read_text().replace("mass: 2.0", "mass: -2.0")),
        "json": ("robot.json", "{\"name\": \"x\", \"joints\": [}"),
        "urdf": ("arm.urdf", "<robot name='x'><link name='a'/>"),
        "empty-urdf": ("none.urdf", "<robot name='x'><link name='a'/></robot>"),
    }
    out = {}
    for key, (name, text) in files.items():
        if text is not None:
            (tmp_path / name).write_text(text)
        out[key] = tmp_path / name
    return out


@pytest.mark.parametrize("case", ["missing", "extension", "yaml", "mass", "json", "urdf", "empty-urdf"])
@pytest.mark.parametrize("command", ["compile", "report"])
def test_bad_robot_file_is_one_line_exit_1(tmp_path, case, command):
    path = bad_robots(tmp_path)[case]
    before = list(tmp_path.iterdir())
    args = [command, path] + (["-o", tmp_path / "out.vamp.json"] if command == "compile" else [])
    assert_user_error(run(*args), path.name, tmp_path, before)


def test_negative_mass_names_the_joint(tmp_path):
    path = bad_robots(tmp_path)["mass"]
    result = run("compile", path, "-o", tmp_path / "out.vamp.json")
    assert "joints[0].mass (joint 1)" in result.stderr


def test_output_in_a_missing_folder(tmp_path):
    out = tmp_path / "nowhere" / "puma.vamp.json"
    before = list(tmp_path.iterdir())
    result = run("compile", PUMA, "-o", out)
    assert_user_error(result, str(out), tmp_path, before)
    assert result.stderr == f"vampc: error: {out}: folder {out.parent} does not exist\n"


@pytest.mark.parametrize("text", ["1\n1\n", "1\n2\nthree\n", "5\n"])
def test_bad_numbering_file(tmp_path, text):
    numbers = tmp_path / "numbers.txt"
    numbers.write_text(text)
    before = list(tmp_path.iterdir())
    result = run("compile", PUMA, "--numbering", numbers, "-o", tmp_path / "out.vamp.json")
    assert_user_error(result, str(numbers), tmp_path, before)


def test_dh_table_refuses_urdf_options(tmp_path):
    result = run("report", PUMA, "--tip", "link6")      # an option that does not apply: usage
    assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr.startswith("vampc: error: --tip applies to URDF and MJCF files only; ")
    assert "puma560.yaml is a DH table" in result.stderr


@pytest.mark.parametrize("text", ["", "not json", "{\"format\": \"vampc-program\", \"version\": 9}"])
def test_bad_program_file(tmp_path, text):
    path = tmp_path / "bad.vamp.json"
    path.write_text(text)
    assert_user_error(run("report", path), path.name)


def test_user_error_in_a_real_process_has_no_traceback(tmp_path):
    proc = run_process("compile", tmp_path / "gone.yaml", "-o", tmp_path / "x.vamp.json")
    assert proc.returncode == 1
    assert proc.stderr == f"vampc: error: {tmp_path / 'gone.yaml'}: no such file\n"
    assert proc.stdout == "" and list(tmp_path.iterdir()) == []


def test_compile_in_a_real_process(tmp_path):
    proc = run_process("compile", PUMA, "-o", tmp_path / "puma.vamp.json")
    assert proc.returncode == 0, proc.stderr
    assert read_program(tmp_path / "puma.vamp.json")["summary"]["latency"]["flops"] == 61


@pytest.mark.parametrize("args", [
    ["compile"],
    ["report"],
    ["compile", PUMA, "--recursion", "bogus"],
    ["compile", PUMA, "--mult-latency", "0"],
    ["compile", PUMA, "--add-latency", "65"],
    ["report", PUMA, "--format", "xml"],
    ["compile", PUMA, "--lock", "elbow"],
    ["compile", PUMA, "--no-such-option"],
    ["frobnicate"],
])
def test_usage_errors_exit_2(args):
    result = run(*args)
    assert result.exit_code == 2, result.output
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("vampc: error: "), result.stderr
    assert lines[0].endswith("--help')") and result.stdout == ""


def test_help_works_for_every_command():
    result = run("--help")
    assert result.exit_code == 0 and "Commands:" in result.stdout
    assert {"compile", "report"} <= set(main.commands)
    for name in main.commands:
        result = run(name, "--help")
        assert result.exit_code == 0, (name, result.output)
        assert result.stdout.startswith(f"Usage: main {name} [OPTIONS]")


def test_version():
    result = run("--version")
    assert result.exit_code == 0 and "0.1.0" in result.stdout


def test_report_json_puma560_log_recursion():
    # Paper, n = 6: (2L+5) M + (6L+10) A with L = ⌈log2 7⌉ = 3, i.e. 11 M + 28 A; plus the output
    # correction of 1 M + 2 A (logarithmic.py docstring, as for the linear graph).
    rep = puma_json("--recursion", "log")
    assert (rep["recursion"], rep["prefix"], rep["interval_flops"]) == ("log", "sklansky", 4)
    assert rep["paper"] == {"flops": 39, "mults": 11, "adds": 28}
    assert rep["latency"] == {"flops": 42, "mults": 12, "adds": 30, "waits": 0}


def test_report_json_puma560_log_uniform_leaves_vamps():
    # Section VI, VAMPs - Totals, n = 6, log systolic pipeline with Appendix D's uniform leaves:
    # 398 backward as the paper; forward 169 less one T20 VAMP in each of its 13 nodes (the forward
    # pass is referred to O_{a-1}, logarithmic.py docstring).
    v = puma_json("--recursion", "log", "--uniform-leaves")["vamps"]
    assert (v["backward"], v["forward"], v["total"]) == (398, 169 - 13, 398 + 156)


def test_dump_after_prints_the_ir_and_writes_nothing(tmp_path):
    from vampc.compiler import compile_chain
    from vampc.dump import dump_after
    from vampc.robot import load_robot
    c = compile_chain(load_robot(PUMA))
    for stage in ("graph", "schedule", "allocate", "emit"):
        result = run("compile", PUMA, "--dump-after", stage, cwd=tmp_path)
        assert result.exit_code == 0 and result.stdout == dump_after(stage, c)
    assert list(tmp_path.iterdir()) == []
    assert run("compile", PUMA, "--dump-after", "graph", "-o", tmp_path / "x.vamp.json").exit_code == 2


def test_the_emit_dump_shows_error_corrections_chain():
    """`--dump-after emit --error-correction` printed what the plain compile prints, with no word,
    where the program holds the chain of VAMPs and its periods (a new user's)."""
    from vampc.compiler import CompileOptions, compile_chain
    from vampc.dump import dump_after
    from vampc.robot import load_robot
    plain = run("compile", str(EXAMPLES / "planar2.yaml"), "--dump-after", "emit").stdout
    r = run("compile", str(EXAMPLES / "planar2.yaml"), "--dump-after", "emit", "--error-correction",
            "--check-cycles", "3")
    assert r.exit_code == 0 and r.stderr == "" and r.stdout != plain
    c = compile_chain(load_robot(EXAMPLES / "planar2.yaml"),
                      CompileOptions(error_correction=True, check_cycles=3))
    assert r.stdout == dump_after("emit", c)
    said = [line for line in r.stdout.splitlines() if line.startswith("error correction")]
    chain = " ".join(map(str, c.network.checking.chain))
    assert said == [f"error correction: extraneous vamp 60, then chain {chain}; warm-up "
                    f"{c.network.checking.warmup} periods, compare 3"]
    assert sorted(c.network.checking.chain) == list(range(60))


@pytest.mark.parametrize("stage, args, said", [
    ("graph", ["--vamps", "3", "--interval", "2"], "--vamps, --interval do not apply to --dump-after "
     "graph: they shape a later stage"),
    ("graph", ["--layout", "folded", "--error-correction", "--word", "q8.8"],
     "--layout, --word, --error-correction do not apply"),
    ("allocate", ["--word", "q8.8", "--rounding", "truncate"], "--word, --rounding do not apply to "
     "--dump-after allocate: they shape a later stage, so nothing printed changes"),
])
def test_an_option_of_a_later_stage_than_the_dump_is_warned_of(stage, args, said):
    """(A new user's find.) `--dump-after graph --vamps 3 --interval 2` printed the graph, exit 0,
    saying nothing, where the compile refuses that interval: the options were taken and changed
    nothing. They are still taken (the stage before a failing one can be dumped with the same
    command line), and the dump is the one without them."""
    plain = run("compile", str(EXAMPLES / "planar2.yaml"), "--dump-after", stage)
    r = run("compile", str(EXAMPLES / "planar2.yaml"), "--dump-after", stage, *args)
    assert r.exit_code == 0 and r.stdout == plain.stdout
    assert r.stderr == f"vampc: warning: {said}" + r.stderr.split(said, 1)[1]
    assert len(r.stderr.splitlines()) == 1 and not plain.stderr
    alone = run("compile", str(EXAMPLES / "planar2.yaml"), "--dump-after", stage, "--exact")
    assert alone.exit_code == 2 and "--exact applies with --vamps K" in alone.stderr
    assert "apply to --dump-after" not in alone.stderr       # (one line for one error)
    if "--interval" not in args:            # (an interval of 2 fails the schedule: refused there)
        last = run("compile", str(EXAMPLES / "planar2.yaml"), "--dump-after", "emit", *args)
        assert last.exit_code == 0 and not last.stderr     # every option shapes the last stage


def test_one_joint_is_said_in_the_singular(tmp_path):
    """'1 joints' in compile's line, the report, its pictures' titles and the trade-off's."""
    robot = tmp_path / "one.yaml"
    robot.write_text("name: one\njoints:\n  - {type: revolute, a: 0.5, alpha: 0, d: 0, theta: 0, "
                     "mass: 1, com: [-0.25, 0, 0], inertia: [0.01, 0.01, 0.01, 0, 0, 0]}\n")
    runner = CliRunner()
    out = tmp_path / "one.vamp.json"
    said = [runner.invoke(main, ["compile", str(robot), "-o", str(out)]).stdout,
            runner.invoke(main, ["report", str(out)]).stdout,
            runner.invoke(main, ["report", str(out), "--tradeoff", "--workers", "1", "--curve",
                                 str(tmp_path / "c.svg")]).stdout,
            (tmp_path / "c.svg").read_text()]
    runner.invoke(main, ["report", str(out), "--timing", str(tmp_path / "t.svg")])
    said.append((tmp_path / "t.svg").read_text())
    assert all("1 joint" in text for text in said[:2]) and not any("1 joints" in t for t in said)


def test_a_program_file_named_as_something_else_is_warned_of(tmp_path):
    """`compile -o r.urdf` wrote a program under a robot file's name, saying nothing, where the
    other commands' outputs warn of a name that says otherwise (a new user's find)."""
    for name, warned in (("r.urdf", True), ("r.yaml", True), ("r.vamp.json", False),
                         ("r.json", False), ("r.vamp.json.gz", False)):
        r = run("compile", str(EXAMPLES / "planar2.yaml"), "-o", tmp_path / name)
        assert r.exit_code == 0 and (tmp_path / name).exists(), r.output
        said = f"vampc: warning: -o {tmp_path / name}: writes a program file, whatever the name says (name it .vamp.json)"
        assert (said in r.stderr) == warned and len(r.stderr.splitlines()) == int(warned), r.stderr


def test_data_outputs_named_as_another_format_are_warned_of(tmp_path):
    """emulate -o t.json (CSV written), --save-states s.json, --vcd v.svg, lookahead --torques
    tq.json and -o o.svg, faults --format json -o f.csv and --format csv -o f.json were written
    without a word, where compile -o and the pictures warn (an audit's find). A table (CSV) is
    warned of under another format's name only: .txt or .dat is a table's name too."""
    program, puma = tmp_path / "p.vamp.json", tmp_path / "puma.vamp.json"
    assert run("compile", str(EXAMPLES / "planar2.yaml"), "-o", program).exit_code == 0
    assert run("compile", str(EXAMPLES / "puma560.yaml"), "-o", puma).exit_code == 0
    path = ["--trajectory", str(EXAMPLES / "puma560-path.csv"), "--rate", "1kHz", "--window", "8",
            "--limits", str(EXAMPLES / "puma560-limits.csv")]
    emulate = ["emulate", str(program), "--random", "2"]
    faults = ["faults", str(program), "--campaign", "random", "--count", "2", "--sets", "2",
              "--results", str(tmp_path / "r.jsonl")]
    for args, option, name, kind, right in (
            (emulate, "-o", "t.json", "CSV", ".csv"), (emulate, "-o", "t.txt", None, None),
            (emulate, "-o", "t.npy", None, None), (emulate, "--save-states", "s.json", "CSV", ".csv"),
            (emulate, "-o", "t.tsv", "CSV", ".csv"),      # (tab-separated by name: a new user's)
            (emulate + ["--engine", "tick"], "--vcd", "v.svg", "VCD", ".vcd"),
            (emulate + ["--engine", "tick"], "--vcd", "v.vcd", None, None),
            (["lookahead", str(puma)] + path, "--torques", "tq.json", "CSV", ".csv"),
            (["lookahead", str(puma)] + path, "--torques", "tq.dat", None, None),
            (["lookahead", str(puma), "--retime", "uniform"] + path, "-o", "o.svg", "CSV", ".csv"),
            (faults + ["--format", "json"], "-o", "f.csv", "JSON", ".json"),
            (faults + ["--format", "csv"], "-o", "f.json", "CSV", ".csv"),
            (faults + ["--format", "csv"], "-o", "f.csv", None, None)):
        (tmp_path / "r.jsonl").unlink(missing_ok=True)
        r = run(*args, option, tmp_path / name)
        assert r.exit_code == 0 and (tmp_path / name).exists(), (args, name, r.stderr)
        said = f"vampc: warning: {option} {tmp_path / name}: writes {kind}, whatever the name says (name it {right})"
        assert (said in r.stderr) if kind else "whatever the name says" not in r.stderr, (name, r.stderr)


def test_an_output_over_a_robot_or_program_file_is_refused_and_the_file_kept(tmp_path):
    """`report --timing arm.yaml` replaced the user's DH table with SVG and `emulate -o arm.yaml`
    with torques, exit 0, the warning of the name alone (a new user's slip, found by a trial), and
    `compile -o dh.json` a DH table in JSON with no word (a review's): an output over a robot
    description or a program file, by its content, is refused and the file kept; a program over a
    program (compile -o) is replaced, and so is a text, DOT graph or CSV an earlier run wrote under
    a misnamed name (said YAML by its colons: a review's), warned."""
    program = tmp_path / "p.vamp.json"
    assert run("compile", str(EXAMPLES / "planar2.yaml"), "-o", program).exit_code == 0
    table, urdf, other = tmp_path / "arm.yaml", tmp_path / "arm.urdf", tmp_path / "q.vamp.json"
    table.write_bytes((EXAMPLES / "planar2.yaml").read_bytes())
    urdf.write_bytes((EXAMPLES / "arm6.urdf").read_bytes())
    other.write_bytes(program.read_bytes())
    import yaml
    dh = tmp_path / "dh.json"         # the DH table in JSON, a name a program file may have too
    dh.write_text(json.dumps(yaml.safe_load(table.read_text())))
    kept = {path: path.read_bytes() for path in (table, urdf, other, dh)}
    for args, path, said in (
            (["report", str(program), "--timing"], table, "is a DH table; --timing writes SVG"),
            (["emulate", str(program), "--random", "2", "-o"], table, "is a DH table; -o writes CSV"),
            (["emulate", str(program), "--random", "2", "-o"], urdf, "is a URDF; -o writes CSV"),
            (["emulate", str(program), "--random", "2", "-o"], other, "is a vampc program file; -o writes CSV"),
            (["compile", str(EXAMPLES / "puma560.yaml"), "-o"], urdf, "is a URDF; -o writes a program file"),
            (["compile", str(EXAMPLES / "puma560.yaml"), "-o"], dh, "is a DH table; -o writes a program file")):
        r = run(*args, path)
        assert r.exit_code == 1 and r.stderr.startswith(f"vampc: error: {path}: {said}, and vampc does "
                                                         "not replace it: give another file name (name it ") \
            and r.stderr.count("\n") == 1, (args, r.stderr)
        assert {p: p.read_bytes() for p in kept} == kept
    again = tmp_path / "p.urdf"
    for _ in range(2):       # a program under a robot's name, then the same again: replaced, warned
        r = run("compile", str(EXAMPLES / "planar2.yaml"), "-o", again)
        assert r.exit_code == 0 and "whatever the name says (name it .vamp.json)" in r.stderr, r.stderr
    assert again.read_bytes() == program.read_bytes()
    for args, name in ((["report", str(program), "--dot"], "g.txt"),
                       (["faults", str(program), "--kinds", "dead", "--sets", "2", "--workers", "1",
                         "--format", "text", "-o"], "f.json")):
        for k in range(2):   # an earlier run's own output under a misnamed name: replaced, warned
            (tmp_path / "r.jsonl").unlink(missing_ok=True)
            r = run(*args, tmp_path / name, *(["--results", str(tmp_path / "r.jsonl")]
                                               if args[0] == "faults" else []))
            assert r.exit_code == 0 and "whatever the name says" in r.stderr, (args, k, r.stderr)


def test_an_input_named_dash_where_it_is_a_files_name_says_so(tmp_path, monkeypatch):
    """`-` is standard input for a trajectory only; elsewhere it is a file's name, and a missing one
    said only "-: no such file" (a new user gave `--limits - < lim.csv`)."""
    monkeypatch.chdir(tmp_path)
    hint = ("(standard input is read as `-` only for a trajectory, --trajectory or --accelerations; "
            "give this file's name)")
    for args, said in ((["compile", "-", "-o", "p.vamp.json"], "-: no such file "),
                       (["emulate", "-", "--random", "2"], "-: no such file "),
                       (["report", "-"], "-: no such file "),
                       (["compile", str(EXAMPLES / "planar2.yaml"), "--numbering", "-", "-o",
                         "p.vamp.json"], "-: cannot read numbering file: No such file or directory ")):
        r = run(*args)
        assert r.exit_code == 1 and r.stderr == f"vampc: error: {said}{hint}\n", (args, r.stderr)
    assert not (tmp_path / "p.vamp.json").exists()


def test_the_command_list_gives_each_command_whole():
    """`vampc --help` cut each command's description at "..." (a new user's find): a one-line
    summary each, none cut."""
    res = CliRunner().invoke(main, ["--help"], terminal_width=78)     # (a terminal's, not 80)
    listed = res.output.split("Commands:\n", 1)[1].splitlines()
    assert len(listed) == len(main.commands) and not any(line.endswith("...") for line in listed)


def test_an_option_of_another_command_is_said_to_be_one():
    """`vampc compile --clock` was asked "Did you mean '--lock'?" and `vampc precision --check` was
    offered --check-cycles, which precision then refuses (a new user's find): an unknown option
    that another command takes says which; a misspelt one keeps click's guesses."""
    for args, said in (
            (["compile", PUMA, "--clock", "20MHz"], "No such option '--clock' for vampc compile: "
             "it is an option of vampc lookahead and report (see 'vampc compile --help')"),
            (["precision", PUMA, "--check"], "No such option '--check' for vampc precision: it is "
             "an option of vampc emulate, lookahead and rtl (see 'vampc precision --help')"),
            (["emulate", PUMA, "--tradeoff"], "No such option '--tradeoff' for vampc emulate: it "
             "is an option of vampc report (see 'vampc emulate --help')")):
        r = CliRunner().invoke(main, args, prog_name="vampc")
        assert r.exit_code == 2 and r.stderr == f"vampc: error: {said}\n", r.stderr
    r = run("emulate", PUMA, "--chekc")
    assert r.exit_code == 2 and "Did you mean one of: '--check'" in r.stderr
