"""Hand-edited program files (a new user's run, twelfth round): each edit below made `vampc report`
an internal error (exit 3: an index out of range in the network check, which ran before the
loader's checks that `emulate` has), or went through every command unsaid (a slot's op beside
another ROM pointer; a buffer of a billion stages, which the report counted and the tick engine and
the RTL tried to build; a constant's index that is not its place, an rtl traceback; a port's
size that is not what its entries carry, counted as pins by the report). Now `report`,
`report --tradeoff` and `emulate` each refuse them in one line naming the place. Each test failed
on the code before."""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from program_util import edited_program

from vampc.cli import main

EXAMPLES = Path(__file__).parent.parent / "examples"


def run(*args):
    r = CliRunner().invoke(main, [str(a) for a in args])
    return r.exit_code, r.stderr


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    path = tmp_path_factory.mktemp("p") / "planar2.vamp.json"
    assert run("compile", EXAMPLES / "planar2.yaml", "-o", path)[0] == 0
    return path


def _set(doc, keys, value):
    for k in keys[:-1]:
        doc = doc[k]
    doc[keys[-1]] = value


EDITS = {
    "select": (lambda d: _set(d, ["programs", 3, "slots", 0, "sel_a"], 1),
               {"report": "VAMP 3 (number 4) slot 0: sel-a 1 selects no input (operand A has 1)",
                "emulate": "programs[3] slot 0 lists sel-a 1 but the program stream delivers 0"}),
    "select-b": (lambda d: _set(d, ["programs", 3, "slots", 0, "sel_b"], 2),
                 {"report": "VAMP 3 (number 4) slot 0: sel-b 2 selects no input (operand B has 1)",
                  "emulate": "programs[3] slot 0 lists sel-b 2 but the program stream delivers 0"}),
    "port tap": (lambda d: _set(d, ["network", "vamps", 1, "a", 0, 0], ["port", 99, 0]),
                 "VAMP 1: operand A is wired to a missing port 99"),
    "constant gone": (lambda d: d["network"]["consts"].pop(),
                      "operand A is wired to a missing const 11"),
    "port gone": (lambda d: d["network"]["ports"].pop(), "is wired to a missing port 11"),
    "constant index": (lambda d: _set(d, ["network", "consts", 1, "index"], 5),
                       "network.consts[1].index: 5, but it is entry 1"),
    "stages": (lambda d: _set(d, ["network", "buffers", 2, "stages"], 10 ** 9),
               "network.buffers[2].stages: 1000000000, but no tap reads past stage 2"),
    "op": (lambda d: _set(d, ["programs", 3, "slots", 0, "op"], "SV"),
           "programs[3].slots[0].op: 'SV', but its ROM pointer 0 runs VA"),
    "io clock": (lambda d: _set(d, ["io", "clock"], 8), "io.clock: 8, but network.clock is 4"),
    "io period": (lambda d: _set(d, ["io", "period"], 8), "io.period: 8, but network.period is 4"),
    "port size": (lambda d: _set(d, ["network", "ports", 0, "size"], 9),
                  "network.ports[0].size: 9, but its entries are 3-scalar quantities"),
    "port size A": (lambda d: _set(d, ["network", "ports", 1, "size"], 3),
                    "network.ports[1].size: 3, but its entries are 9-scalar quantities"),
    # (the report lists the constant buffers by name: a renamed one was listed so, exit 0)
    "constant name": (lambda d: _set(d, ["network", "consts", 2, "name"], "zzz"),
                      "network.consts[2].name: 'zzz' names no constant of the graph with its value"),
    # (an option the compiler never writes for a float64 program: taken unseen, and used by a
    # what-if --word run; --rounding on the command line is refused: a new user's find)
    "rounding of a float word": (lambda d: _set(d, ["options", "rounding"], "truncate"),
                                 "options.rounding: 'truncate', which the compiler records only where "
                                 "it applies, and it does not with these options (the file was "
                                 "edited); recompile it"),
    "extra constant": (lambda d: d["network"]["consts"].append(
        {**d["network"]["consts"][0], "index": len(d["network"]["consts"])}),
        "network.consts[12] ('"),
    # (unpacked, it was said as other fields: "delay-b 4095 never matches the Cycle-Counter")
    "negative scalar": (lambda d: _set(d, ["program_stream", 0, "words", 0, 1], -4097.0),
                        "program stream of const 0, word 0: scalar -4097 is negative: a compact word "
                        "packs two fields in each"),
}


@pytest.mark.parametrize("edit", list(EDITS))
def test_an_edited_section_is_refused_by_every_command(program, tmp_path, edit):
    change, said = EDITS[edit]
    path = edited_program(program, tmp_path, change)
    for command in (["report", path], ["report", path, "--tradeoff", "--workers", "1"],
                    ["emulate", path, "--random", 2]):
        code, err = run(*command)
        assert code == 1 and err.count("\n") == 1 and err.startswith("vampc: error: "), (command, err)
        want = said[command[0]] if isinstance(said, dict) else said   # (emulate compares the
        assert err.startswith(f"vampc: error: {path}: ") and want in err, (command, err)  # stream)


NAMED_EDITS = {
    "vamp number": (lambda d: _set(d, ["network", "vamps", 7, "number"], 4),
                    "VAMPs 3 and 7 share the number 4 (the file was edited); recompile it"),
    "vamp index": (lambda d: _set(d, ["network", "vamps", 2, "index"], 1),
                   "network.vamps[2].index: 1, but it is entry 2 (network.vamps[1] has index 1 "
                   "too)"),
    "constant value": (lambda d: _set(d, ["network", "consts", 2, "value"], [0, 9.82, 0]),
                       {"report": "VAMP 10 slot 0: operand B is wired to const 2 (pdd0), whose value "
                                  "differs from node io0.pdd0's (the file was edited); recompile it",
                        "emulate": "VAMP 10 (number 11, bwd1.T11): operand B holds constant pdd0 "
                                   "(network.consts[2]), whose value [0.0, 9.82, 0.0] differs from "
                                   "graph node 2's [-0.0, 9.81, -0.0] (the file was edited); "
                                   "recompile it"}),
}


@pytest.mark.parametrize("edit", list(NAMED_EDITS))
def test_an_edited_network_entry_is_named_with_what_it_clashes_with(program, tmp_path, edit):
    """Three edits whose messages did not name the place: two VAMPs of one number ("two VAMPs share
    a number": which?), a constant's value ("operand B holds constant pdd0, not graph node 2
    (pdd0)"), a VAMP's index repeated (said as a delay-A timing error of the VAMP it replaced)."""
    change, said = NAMED_EDITS[edit]
    path = edited_program(program, tmp_path, change)
    for command in (["report", path], ["report", path, "--tradeoff", "--workers", "1"],
                    ["emulate", path, "--random", 2]):
        want = said[command[0]] if isinstance(said, dict) else said
        assert run(*command) == (1, f"vampc: error: {path}: {want}\n"), command


def test_the_unedited_program_runs(program):
    for command in (["report", program], ["emulate", program, "--random", 2, "--check"]):
        code, err = run(*command)
        assert code == 0, err


def _relabel(options: str | None, name: str | None):
    def change(doc):
        if options is not None:
            doc["options"]["layout"] = options
        if name is not None:
            doc["layout"]["name"] = name
    return change


@pytest.mark.parametrize("options, name, said", [
    (None, "folded", "layout.name: 'folded', but the file's options compile 'systolic'"),
    ("folded", None, "layout.name: 'systolic', but the file's options compile 'folded'")])
def test_a_layout_name_the_options_do_not_compile_is_refused(program, tmp_path, options, name,
                                                             said):
    """The report's wiring figures follow the layout's name: an edited one changed them (buses into
    a node's VAMPs 24/20/16 -> 48/40/32), exit 0; an edited options.layout showed a systolic
    network as folded."""
    path = edited_program(program, tmp_path, _relabel(options, name))
    code, err = run("report", path)
    assert code == 1 and err.count("\n") == 1 and f"{path}: {said}" in err, err


def test_a_systolic_label_on_a_network_of_several_slots_a_vamp_is_refused(tmp_path):
    folded = tmp_path / "folded.vamp.json"
    assert run("compile", EXAMPLES / "planar2.yaml", "--layout", "folded", "-o", folded)[0] == 0
    path = edited_program(folded, tmp_path, _relabel("systolic", "systolic"))
    code, err = run("report", path)
    assert code == 1 and err.count("\n") == 1, err
    assert f"{path}: layout.name: 'systolic', but VAMP 0 runs 2 slots" in err


EVERY_READER = {   # each command that reads a program file, with what it needs besides
    "emulate": ["--random", 2, "--check"], "precision": ["--sets", 2],
    "lookahead": ["--trajectory", "{trajectory}", "--rate", "1kHz", "--window", 2],
    "rtl": ["--word", "q16.16", "-o", "{out}/net.v"], "faults": ["--results", "{out}/r.jsonl"],
    "report": []}

WHOLE_FILE_EDITS = {
    "operand after": (lambda d: _set(d, ["graph", "nodes", 80, "args", 0], 81),
                      "node fwd1.n: operand 81 not before it (the file was edited); recompile it"),
    "operand huge": (lambda d: _set(d, ["graph", "nodes", 80, "args", 0], 10 ** 400),
                     # (the whole 401-digit number had been the line)
                     "node fwd1.n: operand 100000000000... (401 digits) not before it (the file "
                     "was edited); recompile it"),
    "id": (lambda d: _set(d, ["graph", "nodes", 13, "id"], 500),
           "node bwd1.T7: id 500 at position 13 (the file was edited); recompile it"),
    "duplicate id": (lambda d: _set(d, ["graph", "nodes", 6, "id"], 5),
                     "node io1.p_star1: id 5 at position 6 (the file was edited); recompile it"),
    "input key": (lambda d: d["graph"]["nodes"][3].pop("key"),
                  "node io1.A1: missing input key / constant value (the file was edited); "
                  "recompile it"),
    "constant value": (lambda d: d["graph"]["nodes"][0].pop("value"),
                       "node io0.omega0: missing input key / constant value (the file was "
                       "edited); recompile it"),
    "phi entry": (lambda d: _set(d, ["robot", "joints", 1, "phi", 0, 0], 2 ** 31),
                  "robot.joints[1].phi: not a proper rotation (the file was edited); recompile it"),
    "phi scaled": (lambda d: _set(d, ["robot", "joints", 1, "phi"],
                                  [[2, 0, 0], [0, 2, 0], [0, 0, 2]]),
                   "robot.joints[1].phi: not a proper rotation (the file was edited); recompile it"),
    "graph meta": (lambda d: _set(d, ["graph", "meta", "convention"], "mine"),
                   "graph.meta.convention: 'mine', but the file's options compile 'f, n referred "
                   "to O_{i-1}' (the file was edited); recompile it"),
    # (a torque column 'tau_': a robot file's blank joint name is refused)
    "joint name blank": (lambda d: _set(d, ["robot", "joints", 1, "name"], ""),
                         "robot.joints[1].name: '' is blank (the file was edited); recompile it"),
    # (a floating base adds the base wrench's 6 outputs: emulate read past the graph's, exit 3)
    "floating on": (lambda d: d["robot"].update(floating=True, base_mass=1.0, base_com=[0, 0, 0],
                                                base_inertia=[[1, 0, 0], [0, 1, 0], [0, 0, 1]]),
                    "robot.floating: true, but the graph has 2 outputs, not the 8 of 2 torques and "
                    "the base wrench (the file was edited); recompile it"),
    # (the axis is Φ's last row: an edited one was read by nobody, the same torques, exit 0)
    "axis": (lambda d: _set(d, ["robot", "joints", 1, "axis"], [0, 1, 0]),
             "robot.joints[1].axis: [0.0, 1.0, 0.0] is not the joint's axis, Φ's last row [0.0, "
             "0.0, 1.0] (the file was edited; the axis is written for readers and follows from Φ); "
             "recompile it"),
    "joint name": (lambda d: _set(d, ["robot", "joints", 1, "name"], "shoulder"),
                   "robot.joints[1].name: duplicate joint name 'shoulder' (the file was edited); "
                   "recompile it"),
}


@pytest.mark.parametrize("edit", list(WHOLE_FILE_EDITS))
def test_an_edited_file_is_refused_alike_by_every_reader(program, tmp_path, edit):
    """A tester's hand edits (checksum recomputed). The graph ones made `emulate` and `precision` an
    internal error (exit 3: an index past the graph's nodes, a missing key read as None) or, a
    repeated node id, ran them with exit 0, while `report` refused each in one line (it verified
    the graph; they did not). A robot section whose Φ is not a rotation (`emulate --check` passed:
    its reference used the same Φ; `lookahead` printed a 1.87e9 torque) or whose joint names
    repeat (two torque columns of one name; `compile` refuses that in a DH table) went through
    every command. Now the loading path every command shares checks both: each command refuses
    each edit in the same line. Failed on the code before."""
    change, said = WHOLE_FILE_EDITS[edit]
    path = edited_program(program, tmp_path, change)
    trajectory = tmp_path / "path.csv"
    trajectory.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,0,0,0\n0,0,0,0,0,0\n")
    for command, extra in EVERY_READER.items():
        args = [str(a).format(trajectory=trajectory, out=tmp_path) for a in extra]
        code, err = run(command, path, *args)
        assert (code, err) == (1, f"vampc: error: {path}: {said}\n"), command


def test_an_output_tick_moved_within_its_hold_window_is_refused(program, tmp_path):
    """io.outputs[].tick moved from 29 to 30, within the ticks τ1 holds, read the same torques and
    went through: emulate printed "first set after 30 flops" beside the report's latency 29 (an
    audit's find). The tick must be the one the torque appears at, where the compiler reads it."""
    import json
    doc = json.loads(program.read_text())
    first = doc["io"]["outputs"][0]
    assert first["tick"] == doc["summary"]["latency"]["flops"] == 29
    path = edited_program(program, tmp_path, lambda d: _set(d, ["io", "outputs", 0, "tick"], 30))
    code, err = run("emulate", path, "--random", 2)
    assert code == 1 and err.startswith(f"vampc: error: {path}: τ{first['joint']} is read from VAMP "), err
    assert "at tick 30, but it appears at tick 29, where the compiler reads it (the file was edited); " \
        "recompile it" in err and err.count("\n") == 1, err


@pytest.mark.parametrize("latencies", [[], ["--mult-latency", "3", "--add-latency", "2"]])
def test_a_report_runs_the_static_check_whatever_the_latencies(tmp_path, latencies):
    """A report of a program of Mult/Addn latencies other than 1 skipped the emulator's static
    check: an output tick moved off the torque's was reported with exit 0 (an audit's), where
    `emulate` refused it, and the report of a program of unit latencies refuses it too."""
    import json
    program = tmp_path / "p.vamp.json"
    assert run("compile", EXAMPLES / "planar2.yaml", *latencies, "-o", program)[0] == 0
    tick = json.loads(program.read_text())["io"]["outputs"][0]["tick"]
    path = edited_program(program, tmp_path, lambda d: _set(d, ["io", "outputs", 0, "tick"], tick + 1))
    for command in (["report", path], ["emulate", path, "--random", 2]):
        code, err = run(*command)
        assert code == 1 and f"at tick {tick + 1}, but it appears at tick {tick}, where the compiler " \
            "reads it (the file was edited); recompile it" in err and err.count("\n") == 1, (command, err)
    assert run("report", program)[0] == 0


@pytest.fixture(scope="module")
def log_programs(tmp_path_factory):
    """A log chain's program (the Puma's, Sklansky) and a log tree's (the quadruped's)."""
    out = {}
    for name, robot in (("chain", EXAMPLES / "puma560.yaml"), ("tree", EXAMPLES / "quadruped.urdf")):
        out[name] = tmp_path_factory.mktemp("log") / f"{name}.vamp.json"
        assert run("compile", robot, "--recursion", "log", "-o", out[name])[0] == 0
    return out


def _meta(key, change):
    def edit(doc):
        meta = doc["graph"]["meta"]
        if change is None:
            meta.pop(key)
        else:
            meta[key] = change(meta.get(key))
    return edit


META_EDITS = {
    "prefix name": ("chain", _meta("prefix", lambda v: "brent-kung"),
                    "graph.meta.prefix: 'brent-kung', but the file's options compile 'sklansky'"),
    "tier": ("chain", _meta("fwd_nodes", lambda v: v.replace("[13, 1, 2, 6, 3]", "[13, 1, 2, 6, 9]")),
             "graph.meta.fwd_nodes: row 12 is [13, 1, 2, 6, 9], but the sklansky network over 6 "
             "joints opens [13, 1, 2, 6, 3] there"),
    "table gone": ("chain", _meta("fwd_nodes", None),
                   "graph.meta.fwd_nodes: missing, but the compiler writes it"),
    "table short": ("chain", _meta("bwd_nodes", lambda v: "[[1, 2]]"),
                    "graph.meta.bwd_nodes: row 0 '[1, 2]' is not [group 1, a, k, b, tier]"),
    "not JSON": ("chain", _meta("bwd_nodes", lambda v: "x"), "graph.meta.bwd_nodes: 'x' is not JSON"),
    "extra key": ("chain", _meta("mine", lambda v: "1"),
                  "graph.meta.mine: not a key the compiler writes"),
    "node ids": ("chain", _meta("prefixes", lambda v: "[]"),
                 "graph.meta.prefixes: not 6 rows of 3 node ids (or null)"),
    "leaves": ("chain", _meta("leaves", lambda v: "uniform (Appendix D)"),
               "graph.meta.leaves: 'uniform (Appendix D)', but the file's options compile "
               "'separate (Table IV.1)'"),
    # (a rotating base grounds the recursion in O_-1: an edited base motion, a review's)
    "base motion": ("chain", lambda d: _set(d, ["robot", "base_omega"], [0, 0, 0.5]),
                    "graph.meta.ground: 'O_0', but the robot section's base, which floats or "
                    "rotates, compiles 'O_-1'"),
    "tree row gone": ("tree", _meta("bwd_nodes", lambda v: json.dumps(json.loads(v)[:-1])),
                      "graph.meta.bwd_nodes: no row for group"),
    "tree not pruned": ("tree", _meta("pruned", None),
                        "graph.meta.pruned: missing, but the compiler writes it"),
}


@pytest.mark.parametrize("edit", list(META_EDITS))
def test_an_edited_log_graph_meta_is_refused(log_programs, tmp_path, edit):
    """A log graph's meta: its tables of recursion nodes, which the report places and counts VAMPs
    by, and the prefix network it names. Removing or mangling a table made `report` an internal
    error (exit 3); a changed tier changed the folded layouts' figures and a changed prefix name the
    report's recursion line (exit 0); the rest was read by nobody. Each failed before."""
    which, change, said = META_EDITS[edit]
    path = edited_program(log_programs[which], tmp_path, change)
    for command in (["report", path], ["emulate", path, "--random", 2]):
        code, err = run(*command)
        assert code == 1 and err.startswith(f"vampc: error: {path}: {said}") and \
            err.endswith(" (the file was edited); recompile it\n") and err.count("\n") == 1, \
            (command, err)


ROBOT_EDITS = {
    "tip load": ("chain", lambda d: _set(d, ["robot", "tip_force"], [0, 0, -10]),
                 "graph.nodes: 412 nodes, where the robot section compiles to 414 with the file's "
                 "options"),
    "tree tiers": ("tree", _meta("bwd_nodes", lambda v: json.dumps(
        [row[:4] + [min(row[4], 1)] for row in json.loads(v)])), "graph.meta.bwd_nodes: '[["),
}


@pytest.mark.parametrize("edit", list(ROBOT_EDITS))
def test_a_report_refuses_a_robot_section_or_tree_table_its_graph_is_not_compiled_from(
        log_programs, tmp_path, edit):
    """`report` compares configurations compiled from the robot section and places a tree's VAMPs by
    its graph's tables: a tip load or base motion edited into the robot section (388 log systolic
    VAMPs became 389 or 438), or a tree's tiers all set to 1 (170 VAMPs of the shared-passes row
    became 374), changed its figures with exit 0 (a hostile-input audit's). The graph is now built
    again from the robot section and compared. `emulate --check` refused them already: its
    reference is the robot section's."""
    which, change, said = ROBOT_EDITS[edit]
    path = edited_program(log_programs[which], tmp_path, change)
    code, err = run("report", path)
    assert code == 1 and err.startswith(f"vampc: error: {path}: {said}") and err.endswith(
        " (the file was edited); recompile it\n") and err.count("\n") == 1, err


def test_a_report_names_the_constant_an_edited_mass_changed(log_programs, tmp_path):
    """An edited mass was named only as 'graph.nodes[253]: node io2.m2' (a new user's): the
    constant's two values are said, and what is baked into the constants."""
    path = edited_program(log_programs["chain"], tmp_path,
                          lambda d: _set(d, ["robot", "joints", 1, "mass"], 30.0))
    assert run("report", path) == (1, f"vampc: error: {path}: graph.nodes[253]: constant io2.m2 is "
                                      "[17.4, 0.0, 0.0], where the robot section gives [30.0, 0.0, "
                                      "0.0] (a mass, inertia or link vector is baked into the "
                                      "graph's constants; the file was edited); recompile it\n")


def test_a_report_names_the_field_of_a_node_that_was_edited(log_programs, tmp_path):
    """A constant node's group edited: it had been said as its constant, with two equal values (a
    faults audit's); the field is named, with both values."""
    path = edited_program(log_programs["chain"], tmp_path,
                          lambda d: _set(d, ["graph", "nodes", 253, "group"], 0))
    assert run("report", path) == (1, f"vampc: error: {path}: graph.nodes[253]: node io2.m2's group is "
                                      "'0', where the robot section compiles to '2' (the file was "
                                      "edited); recompile it\n")


def test_a_report_says_the_node_count_the_robot_section_compiles_to(log_programs, tmp_path):
    """Parents edited into a chain's robot section: a tree of another size of graph."""
    path = edited_program(log_programs["chain"], tmp_path,
                          lambda d: d["robot"].update(parents=[0, 1, 1, 3, 4, 5]))
    code, err = run("report", path)
    assert code == 1 and err.startswith(f"vampc: error: {path}: graph.") and err.endswith(
        " (the file was edited); recompile it\n") and err.count("\n") == 1, err


def test_a_bus_programs_tiers_option_is_its_networks(tmp_path):
    """options.tiers edited to 2,2,4 beside the network's default tiers: the report added a 'bus,
    these tiers' row of a network never compiled, exit 0 (a hostile-input audit's)."""
    program = tmp_path / "bus.vamp.json"
    assert run("compile", EXAMPLES / "planar2.yaml", "--bus", "mlb", "--layout", "folded", "-o",
               program)[0] == 0
    path = edited_program(program, tmp_path, lambda d: _set(d, ["options", "tiers"], "2,2,4"))
    for command in (["report", path], ["emulate", path, "--random", 2]):
        code, err = run(*command)
        assert (code, err) == (1, f"vampc: error: {path}: options.tiers: --tiers 2,2,4 mean 3 "
                                  "tiers, but network.bus.tiers has 14 (the file was edited); "
                                  "recompile it\n"), command


@pytest.fixture(scope="module")
def log_program(tmp_path_factory):
    path = tmp_path_factory.mktemp("log") / "puma-log.vamp.json"
    assert run("compile", EXAMPLES / "puma560.yaml", "--recursion", "log", "--word", "q16.16",
               "-o", path)[0] == 0
    return path


def _matrix_operand(doc, reaching: bool):
    """(VAMP index, operand, taps) of a matrix operand of three taps: on a VAMP whose result reaches
    a torque (the backward pass's), or on one none does (a forward node's unused W product)."""
    for v in doc["network"]["vamps"]:
        for side in ("a", "b"):
            for taps in v[side]:
                if len(taps) == 3 and (v["index"] == 145 if reaching else v["index"] == 342):
                    return v["index"], side, taps
    raise AssertionError("no matrix operand")


@pytest.mark.parametrize("reaching", [True, False])
def test_swapped_matrix_columns_are_refused_by_every_command(log_program, tmp_path, reaching):
    """Two taps of a matrix operand swapped (checksum recomputed): `report` refused the file, but
    `emulate` (both engines) and `lookahead` ran it, computing with the matrix's columns swapped
    (exit 0; a waist torque of -3.3185 for -3.2573), `faults` ran its campaign on it, and on a
    VAMP whose result reaches no torque even `emulate --check` and `rtl --cosim --check` passed (a
    new user's find). Every command refuses it now, in one line naming the VAMP and the tap."""
    def swap(doc):
        _, _, taps = _matrix_operand(doc, reaching)
        taps[0], taps[1] = taps[1], taps[0]
    edited = edited_program(log_program, tmp_path, swap)
    said = (r"VAMP 145 \(number 146, bwd11\.T1\): operand A's tap 0 carries column 1 of node bwd8\.W, "
            r"where column 0 belongs \(the file was edited\)" if reaching else
            r"VAMP 342 \(number 343, fwd10\.W\): operand B's tap 0 carries column 1 of node fwd7\.W, "
            r"where column 0 belongs \(the file was edited\)")
    ex = EXAMPLES
    for args in (["emulate", edited, "--random", "3"], ["emulate", edited, "--random", "3", "--engine", "tick"],
                 ["lookahead", edited, "--trajectory", ex / "puma560-path.csv", "--rate", "1kHz", "--window",
                  "64", "--limits", ex / "puma560-limits.csv"],
                 ["faults", edited, "--campaign", "random", "--count", "2", "--workers", "1", "--results",
                  tmp_path / "r.jsonl"],
                 ["precision", edited], ["rtl", edited, "--cosim", "1"]):
        code, err = run(*args)
        assert code == 1 and err.count("\n") == 1 and re.search(said, err), (args[0], err)
    assert not (tmp_path / "r.jsonl").exists()
    code, err = run("report", edited)
    assert code == 1 and "(the file was edited)" in err, err


def test_a_figure_gone_from_the_stored_summary_is_said_as_an_edit(tmp_path):
    """A float32 program's stored summary without its word figures was reported with no word,
    where one with a changed figure is called edited (a new user's find); a figure the compiler
    writes for the program and the file lacks is an edit too."""
    from program_util import reported_with_summary
    program = tmp_path / "p.vamp.json"
    assert run("compile", EXAMPLES / "planar2.yaml", "--word", "float32", "-o", program)[0] == 0
    doc = json.loads(program.read_text())
    r = reported_with_summary(json.loads(json.dumps(doc)), tmp_path)
    assert "stored summary" not in r.stderr
    for key in ("word", "buffers"):
        edited = json.loads(json.dumps(doc))
        del edited["summary"][key]
        r = reported_with_summary(edited, tmp_path)
        assert (f"the stored summary disagrees with the file's graph, schedule and network ({key} "
                "missing): the file was edited") in r.stderr, r.stderr
