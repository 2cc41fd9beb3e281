"""The layout registry (vampc.schedule.registry): a layout defined here — round-robin onto K VAMPs,
nothing under vampc/ edited — is a --layout choice, compiles, emulates with --check on both engines
and reports, like the built-in ones."""
from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.machine.ops import VAMPS_PER_OP
from vampc.schedule.asap import schedule_asap
from vampc.schedule.layout import Layout, schedule_bound
from vampc.schedule.registry import LayoutKind, layout_names, registered_layout

K = 4


def round_robin(graph, timing, request):
    """Ops of one VAMP dealt round K units of one VAMP, in graph order; each 3-VAMP op on one MM
    unit; a list schedule under that binding, one torque set at a time."""
    units, sizes, dealt = [-1] * len(graph.nodes), [1] * K, 0
    for nd in graph.compute_nodes():
        if VAMPS_PER_OP[nd.op] == 1:
            units[nd.id], dealt = dealt % K, dealt + 1
        else:
            if len(sizes) == K:
                sizes.append(VAMPS_PER_OP[nd.op])
            units[nd.id] = K
    asap = schedule_asap(graph, timing, request.verify)
    sched = schedule_bound(graph, timing, asap, units, sizes, clock=timing.cycle,
                           verify=request.verify)
    layout = Layout.of_units("round-robin", units, sizes, sched.interval, timing.cycle)
    if request.verify:
        layout.verify(graph)
    return layout, sched


ROUND_ROBIN = LayoutKind("round-robin", f"ops dealt round {K} VAMPs", round_robin)


def _run(*args):
    res = CliRunner().invoke(main, list(map(str, args)), prog_name="vampc")
    return res.exit_code, res.stdout, res.stderr


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_a_layout_registered_in_a_test_compiles_emulates_and_reports(tmp_path, recursion):
    prog = tmp_path / "rr.vamp.json"
    assert "round-robin" not in layout_names()
    with registered_layout(ROUND_ROBIN):
        code, out, err = _run("compile", EXAMPLES / "puma560.yaml", "--layout", "round-robin",
                              "--recursion", recursion, "-o", prog)
        assert code == 0, err
        vamps = len(json.loads(prog.read_text())["network"]["vamps"])
        assert vamps == K + 3 * (recursion == "log") and f"{vamps} VAMPs" in out
        for engine in ("stream", "tick"):
            code, out, err = _run("emulate", prog, "--random", "50" if engine == "stream" else "3",
                                  "--check", "--engine", engine)
            assert code == 0 and ": OK" in out, err
        code, out, err = _run("report", prog, "--format", "json")
        assert code == 0, err
        rep = json.loads(out)
        assert rep["layout"] == "round-robin" and rep["vamps"]["total"] == vamps
        code, out, err = _run("report", prog, "--timing", tmp_path / "t.svg")
        assert code == 0 and "round-robin" in out, err
    assert "round-robin" not in layout_names()
    code, _, err = _run("compile", EXAMPLES / "puma560.yaml", "--layout", "round-robin")
    assert code == 2 and "'round-robin' is not one of 'systolic', 'folded'" in err


def round_robin_shared(graph, timing, request):
    """As round_robin, but declared ungrouped (a budget-like layout): the report must read its
    placement VAMP by VAMP, not as units."""
    layout, sched = round_robin(graph, timing, request)
    return Layout("shared-rr", layout.placement, layout.period, layout.clock, grouped=False), sched


def test_a_registered_layout_that_is_not_grouped_reports(tmp_path):
    prog = tmp_path / "srr.vamp.json"
    with registered_layout(LayoutKind("shared-rr", "ungrouped round robin", round_robin_shared,
                                      grouped=False)):
        code, _, err = _run("compile", EXAMPLES / "puma560.yaml", "--recursion", "log",
                            "--layout", "shared-rr", "-o", prog)
        assert code == 0, err
        code, out, err = _run("emulate", prog, "--random", "20", "--check")
        assert code == 0 and ": OK" in out, err
        code, out, err = _run("report", prog, "--format", "json")
        assert code == 0, err
        assert json.loads(out)["layout"] == "shared-rr"
