"""Golden dump of the planar2 linear graph and its ASAP schedule (tests/golden/planar2-linear.txt).

The dump is canonical: one node per line in id order, `id op args section group name start finish`,
then the outputs and the schedule summary; no floating-point values, no memory ids. Rewrite it only
with `pytest --update-golden`, then read the diff against Table III.1 before committing.
"""
from __future__ import annotations

from pathlib import Path

from conftest import EXAMPLES

from vampc.dataflow.linear import build_linear
from vampc.robot import load_robot
from vampc.schedule.asap import schedule_asap


def dump(graph, sched) -> str:
    """The canonical text of a graph and its schedule."""
    lines = [f"# {graph.recursion} graph, n = {graph.n}: id op args section group name start finish"]
    for nd in sorted(graph.nodes, key=lambda nd: nd.id):
        args = ",".join(map(str, nd.args)) or "-"
        lines.append(f"{nd.id} {nd.op.value} {args} {nd.section} {nd.group} {nd.name} "
                     f"{sched.start[nd.id]} {sched.finish[nd.id]}")
    lines += [f"output tau{o.joint} = node {o.node} component {o.component}"
              for o in sorted(graph.outputs, key=lambda o: o.joint)]
    lines.append(f"latency {sched.latency} = {sched.mults} M + {sched.adds} A, interval {sched.interval}")
    lines.append("critical path " + " ".join(map(str, sched.critical_path)))
    return "\n".join(lines) + "\n"


def test_planar2_linear_golden(golden):
    chain = load_robot(EXAMPLES / "planar2.yaml")
    graph = build_linear(chain)
    golden("planar2-linear.txt", dump(graph, schedule_asap(graph)))


# --- the IR dumps of `vampc compile --dump-after STAGE` ----------------------------------------------

import pytest  # noqa: E402

from vampc.compiler import CompileOptions, compile_chain  # noqa: E402
from vampc.dump import dump_after  # noqa: E402

DUMPS = [  # (robot, what, stage, options)
    (robot, what, stage, opts)
    for robot in ("planar2", "puma560")
    for what, stage, opts in (
        ("graph-linear", "graph", {}), ("graph-log", "graph", {"recursion": "log"}),
        ("network-systolic", "allocate", {}), ("network-folded", "allocate", {"layout": "folded"}),
        ("program-systolic", "emit", {}),
        ("program-folded", "emit", {"layout": "folded", "share_passes": True}))
]


@pytest.mark.parametrize("robot,what,stage,opts", DUMPS, ids=[f"{r}-{w}" for r, w, _, _ in DUMPS])
def test_ir_dump_golden(robot, what, stage, opts, golden):
    c = compile_chain(load_robot(EXAMPLES / f"{robot}.yaml"), CompileOptions(**opts))
    golden(f"{robot}-{what}.txt", dump_after(stage, c))


# --- every IR dump through `vampc compile --dump-after`, the report text, the usage errors -----------

from click.testing import CliRunner  # noqa: E402

from vampc.cli import main  # noqa: E402

CLI_DUMPS = [  # (golden name, robot, options): schedules of every layout, trees, non-unit latencies
    ("puma560-schedule-systolic", "puma560.yaml", ["--dump-after", "schedule"]),
    ("puma560-schedule-folded", "puma560.yaml", ["--dump-after", "schedule", "--layout", "folded"]),
    ("puma560-schedule-budget7", "puma560.yaml", ["--dump-after", "schedule", "--vamps", "7"]),
    ("puma560-schedule-log-folded", "puma560.yaml",
     ["--dump-after", "schedule", "--recursion", "log", "--layout", "folded"]),
    ("planar2-network-budget3", "planar2.yaml", ["--dump-after", "allocate", "--vamps", "3"]),
    ("planar2-program-budget3", "planar2.yaml", ["--dump-after", "emit", "--vamps", "3"]),
    ("planar2-schedule-latency-3-2", "planar2.yaml",
     ["--dump-after", "schedule", "--mult-latency", "3", "--add-latency", "2"]),
    ("planar2-network-latency-3-2", "planar2.yaml",
     ["--dump-after", "allocate", "--mult-latency", "3", "--add-latency", "2"]),
    ("planar2-program-log-latency-1-4", "planar2.yaml",
     ["--dump-after", "emit", "--recursion", "log", "--mult-latency", "1", "--add-latency", "4"]),
    ("quadruped-graph-linear", "quadruped.urdf", ["--dump-after", "graph"]),
    ("quadruped-graph-log", "quadruped.urdf", ["--dump-after", "graph", "--recursion", "log"]),
    ("quadruped-schedule-budget9", "quadruped.urdf", ["--dump-after", "schedule", "--vamps", "9"]),
]


def _cli(args):
    res = CliRunner().invoke(main, args, prog_name="vampc")
    return res.exit_code, res.stdout, res.stderr


@pytest.mark.parametrize("name,robot,options", CLI_DUMPS, ids=[c[0] for c in CLI_DUMPS])
def test_cli_dump_golden(name, robot, options, golden):
    code, out, err = _cli(["compile", str(EXAMPLES / robot), *options])
    assert code == 0 and err == "", err
    golden(f"{name}.txt", out)


def test_dump_after_stops_before_a_stage_that_would_fail(golden):
    # two VAMPs cannot run an MM: the schedule stage fails, but the graph is dumped
    code, out, err = _cli(["compile", str(EXAMPLES / "puma560.yaml"), "--recursion", "log",
                           "--vamps", "2", "--dump-after", "graph"])
    assert code == 0, err
    golden("puma560-graph-log.txt", out)
    code, _, err = _cli(["compile", str(EXAMPLES / "puma560.yaml"), "--recursion", "log",
                         "--vamps", "2", "--dump-after", "schedule"])
    assert code == 1 and "the smallest network that runs this graph has 3 VAMPs" in err


@pytest.mark.parametrize("robot,options", [("planar2.yaml", []), ("puma560.yaml", []),
                                           ("puma560.yaml", ["--recursion", "log"])],
                         ids=["planar2", "puma560", "puma560-log"])
def test_report_text_golden(robot, options, golden):
    code, out, err = _cli(["report", str(EXAMPLES / robot), *options])
    assert code == 0, err
    golden(f"report-{Path(robot).stem}{'-' if options else ''}{'-'.join(o.lstrip('-') for o in options)}"
           ".txt", out)


USAGE_ERRORS = [  # every rule a user can break with options alone, and what they are told
    ["compile", "ROBOT", "--prefix", "kogge-stone"],
    ["compile", "ROBOT", "--uniform-leaves"],
    ["compile", "ROBOT", "--share-passes"],
    ["compile", "ROBOT", "--vamps", "0"],
    ["compile", "ROBOT", "--interval", "0"],
    ["compile", "ROBOT", "--vamps", "7", "--layout", "folded"],
    ["compile", "ROBOT", "--exact"],
    ["compile", "ROBOT", "--mult-latency", "65"],
    ["compile", "ROBOT", "--recursion", "cubic"],
    ["compile", "ROBOT", "--base", "x"],
    ["compile", "ROBOT", "--dump-after", "graph", "-o", "x.vamp.json"],
    ["compile", "ROBOT", "--dump-after", "parse"],
    ["compile", "ROBOT", "-o", ""],
    ["emulate", "ROBOT"],
    ["emulate", "ROBOT", "--random", "0"],
    ["emulate", "ROBOT", "--random", "3", "--vcd", "x.vcd"],
    ["report", "ROBOT", "--curve", "x.svg"],
    ["report", "ROBOT", "--format", "yaml"],
    ["frobnicate"],
]


def test_usage_errors_golden(golden, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    robot = str(EXAMPLES / "planar2.yaml")
    lines = []
    for args in USAGE_ERRORS:
        code, out, err = _cli([robot if a == "ROBOT" else a for a in args])
        assert code == 2 and out == "" and err.count("\n") == 1, (args, code, err)
        lines.append(f"$ vampc {' '.join(args)}\n{err.replace(robot, 'ROBOT')}")
    assert not list(tmp_path.iterdir())            # nothing written
    golden("usage-errors.txt", "".join(lines))
