"""The README cannot drift: every command of its code blocks runs (exit 0) from a folder holding the
examples and the programs its compile commands make (each read only after a command that makes it),
the files its prose uses are made by commands it gives, and the figures it quotes beside the
paper's are the report's."""
from __future__ import annotations

import json
import re
import shlex
import shutil

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main

README = (EXAMPLES.parent / "README.md").read_text()


def code_block_commands() -> list[str]:
    blocks = re.findall(r"```[a-z]*\n(.*?)```", README, re.S)
    out = []
    for block in blocks:
        for line in block.splitlines():
            command = line.split("  #")[0].strip()
            if command.startswith("vampc ") and "[" not in command:   # not the synopsis
                out.append(command)
    return out


def test_the_readme_has_commands_to_run():
    assert len(code_block_commands()) >= 15


def _programs(command: str) -> tuple[set, set]:
    """(the program files a README command reads, those it writes)."""
    words = shlex.split(command)
    out = {words[k + 1] for k, w in enumerate(words[:-1]) if w in ("-o", "--output")}
    read = {w for w in words if w.endswith((".vamp.json", ".vamp.json.gz")) and w not in out}
    return read, {w for w in out if w.endswith((".vamp.json", ".vamp.json.gz"))}


@pytest.fixture(scope="module")
def readme_folder(tmp_path_factory):
    """A folder holding the examples, where the program files the README's compile commands make
    are made as a command first reads them (below), each by the command that makes it."""
    folder = tmp_path_factory.mktemp("readme")
    shutil.copytree(EXAMPLES, folder / "examples")
    return folder


def test_each_program_a_readme_command_reads_is_made_by_a_command_before_it():
    """The commands run as cases of their own, from a folder holding every program the README's
    compile commands make (below); in the README's order, each program a command reads must have
    been made by an earlier one, as a reader running them one by one needs (the single test that
    ran them in order had checked that)."""
    made = set()
    for command in code_block_commands():
        read, out = _programs(command)
        assert read <= made, f"{command}: reads {sorted(read - made)} before a command makes it"
        made |= out
    assert len(made) >= 5


# one case a command, so that the two test workers share them (the whole README in one test took
# about 30 s, the longest test of the suite, on one worker at the end of the run); a program a
# command reads is made first by the README command that makes it. The single campaign of every
# planar2 VAMP dead (5-6.6 s, the longest case) runs under -m slow: tests/test_fault_campaigns.py
# runs the same command on a one-joint arm and checks each dead VAMP's class, and the README's
# random campaign on planar2 runs here.
SLOW_COMMANDS = ("vampc faults planar2-ec.vamp.json --kinds dead --workers 1",)


@pytest.mark.parametrize("command", [pytest.param(c, marks=pytest.mark.slow) if c in SLOW_COMMANDS else c
                                     for c in code_block_commands()])
def test_every_command_in_the_readme_runs(readme_folder, monkeypatch, command):
    monkeypatch.chdir(readme_folder)
    makers = {name: c for c in code_block_commands() for name in _programs(c)[1]}
    for name in sorted(_programs(command)[0]):
        if not (readme_folder / name).exists():            # (made once a worker, as first read)
            res = CliRunner().invoke(main, shlex.split(makers[name])[1:])
            assert res.exit_code == 0, f"{makers[name]}: {res.stderr}"
    res = CliRunner().invoke(main, shlex.split(command)[1:])
    assert res.exit_code == 0, f"{command}: {res.stderr}"


def test_the_files_the_readme_uses_are_made_by_commands_it_gives():
    text = " ".join(README.split())
    for name, maker in (("snake4096.yaml", "python examples/make_snake.py 4096 > snake4096.yaml"),
                        ("snake4096.vamp.json", "vampc compile snake4096.yaml --recursion log -o "
                                                "snake4096.vamp.json"),
                        ("snake512.yaml", "python examples/make_snake.py 512 > snake512.yaml"),
                        ("snake512.vamp.json", "vampc compile snake512.yaml --recursion log -o "
                                               "snake512.vamp.json")):
        assert name in text and maker in text, name


def _report(*args) -> dict:
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--format", "json",
                                    *args])
    assert res.exit_code == 0, res.stderr
    return json.loads(res.stdout)


def test_the_storage_figures_quoted_are_the_reports():
    """"×2.9 (183 against 63 buffer scalars), log ×1.9 (504 against 261; ×1.6 with
    --uniform-leaves)": systolic against folded delay-buffer scalars, Puma 560."""
    line = next(x for x in README.splitlines() if x.startswith("| systolic against single-device"))
    got = re.search(r"×([\d.]+) \((\d+) against (\d+) buffer scalars\), log ×([\d.]+) \((\d+) "
                    r"against (\d+); ×([\d.]+) with `--uniform-leaves`\)", line)
    assert got, line
    lin_x, lin_s, lin_f, log_x, log_s, log_f, uni_x = got.groups()

    def scalars(rep, name):
        return next(r["scalars"] for r in rep["wiring"]["by_configuration"]
                    if r["configuration"] == name)
    rep = _report()
    assert (scalars(rep, "linear, systolic"), scalars(rep, "linear, folded")) == (int(lin_s),
                                                                                int(lin_f))
    assert (scalars(rep, "log, systolic"), scalars(rep, "log, folded")) == (int(log_s), int(log_f))
    assert f"{int(lin_s) / int(lin_f):.1f}" == lin_x and f"{int(log_s) / int(log_f):.1f}" == log_x
    uni = _report("--recursion", "log", "--uniform-leaves")
    assert f"{scalars(uni, 'log, systolic') / scalars(uni, 'log, folded'):.1f}" == uni_x


def test_the_budget_commands_quoted_are_accepted(tmp_path):
    """The budget-18 point is quoted with the options that make it, --exact needing --vamps; and
    the heuristic's point is what the README says: 18 VAMPs, interval 18, latency 61, every tick
    of every VAMP busy (it only searched the README's text: a review of the tests; CP-SAT's run,
    10 s, is left to the benchmark)."""
    text = " ".join(README.split())
    assert "`--vamps 18 --interval 18`" in text and "`--exact --vamps 18 --interval 18`" in text
    assert "At budget 18 (`--vamps 18 --interval 18`, every tick of every VAMP busy" in text
    assert ("the heuristic reaches latency 61, the latency bound, so `--exact` takes its placement "
            "without running CP-SAT") in text
    exact = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--vamps", "18",
                                      "--interval", "18", "--exact", "--format", "json"])
    assert exact.exit_code == 0, exact.output
    said = json.loads(exact.stdout)
    assert said["latency"]["flops"] == 61 and said["budget"]["proof"].endswith("the solver was not run)")
    out = tmp_path / "b18.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--vamps", "18",
                                  "--interval", "18", "-o", str(out)])
    assert r.exit_code == 0, r.output
    from vampc.program.file import read_program
    doc = read_program(out)
    assert len(doc["network"]["vamps"]) == 18 and doc["schedule"]["interval"] == 18
    assert doc["summary"]["latency"]["flops"] == 61 and doc["schedule"]["latency"] == 61
    budget = doc["summary"]["budget"]       # the graph's work in VAMP-ticks: all 18 × 18 of them
    assert budget["work"] == 324 == 18 * 18 and budget["vamps_used"] == 18


def _readme_report_keys() -> dict[str, set[str] | None]:
    """The report JSON's keys README's "vampc report" section lists (from "The JSON report keeps
    every key it had" to "The schema says what each holds"): each top-level key, with the set of
    its sub-keys where it is written `key{a,b,...}` (a sub-key's own braces skipped), else None."""
    text = " ".join(README.split())
    start = text.index("The JSON report keeps every key it had")
    part = text[start:text.index("The schema says what each holds", start)]
    keys: dict[str, set[str] | None] = {}
    for token in re.findall(r"`([^`]+)`", part):
        name = re.match(r"[a-z_0-9]+", token)
        if not name or (name.end() < len(token) and token[name.end()] != "{"):
            continue                             # an option, a number, a dotted path
        subs = None
        if name.end() < len(token):
            subs, depth, word = set(), 0, ""
            for ch in token[name.end() + 1:-1] + ",":
                if ch == "{":
                    depth += 1
                elif ch == "}":
                    depth -= 1
                elif ch == "," and depth == 0:
                    subs.add(word.strip())
                    word = ""
                elif depth == 0:
                    word += ch
        keys.setdefault(name.group(), subs)
    return keys


def _object_properties(schema: dict) -> set[str] | None:
    """The fixed sub-keys of a report key's schema (through anyOf/oneOf), None if it has none."""
    for alt in [schema, *schema.get("anyOf", ()), *schema.get("oneOf", ())]:
        if alt.get("properties"):
            return set(alt["properties"])
    return None


def test_the_report_keys_listed_are_the_schemas():
    """README listed the report JSON's keys without tip_force, prefix, uniform_leaves, base_rotates,
    mimic, error_correction, word, rtl and tree.log2 (a new user's find). Every top-level key of
    schemas/report.schema.json is listed, and every key with fixed sub-keys is written
    `key{...}` with exactly the schema's."""
    from schema_check import load_schema
    schema = load_schema("report")["properties"]
    listed = _readme_report_keys()
    assert sorted(set(schema) - set(listed)) == []
    for key, sub in schema.items():
        want = _object_properties(sub)
        if want is not None:
            assert listed[key] == want, (key, sorted(want - (listed[key] or set())),
                                         sorted((listed[key] or set()) - want))


def _command_sections() -> dict[str, str]:
    """Each `### \\`vampc NAME ...\\`` section of the README, up to the next heading."""
    parts = re.split(r"^(#{2,3} .*)$", README, flags=re.M)
    return {m.group(1): body for head, body in zip(parts[1::2], parts[2::2])
            if (m := re.match(r"### `vampc (\w+) ", head))}


def _table_options(section: str) -> set[str]:
    cells = [re.split(r"(?<!\\)\|", line)[1] for line in section.splitlines() if line.startswith("| `")]
    return {name for cell in cells for name in re.findall(r"`(--?[a-z][a-z0-9-]*)", cell)} | \
           {name for cell in cells for name in re.findall(r", (--[a-z][a-z0-9-]*)", cell)}


def test_each_commands_own_options_are_in_its_readme_table():
    """Every option a command has beyond the compile options is a row of its section's table (by
    any of its names), and every option a table names is the command's (the report's --tradeoff
    and every option of `vampc faults` had no row: a README audit's find)."""
    import click
    sections = _command_sections()
    assert set(sections) == set(main.commands), sorted(set(main.commands) - set(sections))
    def options(command) -> list[set[str]]:
        return [set(p.opts + p.secondary_opts) for p in command.params if isinstance(p, click.Option)]
    own_of_compile = {"--output", "--numbering", "--dump-after"}
    shared = [o for o in options(main.commands["compile"]) if not o & own_of_compile]
    for name, command in main.commands.items():
        documented = _table_options(sections[name])
        own = options(command) if name == "compile" else [o for o in options(command) if o not in shared]
        missing = [sorted(o) for o in own if not o & documented]
        assert not missing, (name, missing)
        every = set().union(*options(command))
        assert documented <= every, (name, sorted(documented - every))
