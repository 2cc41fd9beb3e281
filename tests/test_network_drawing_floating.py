"""The network drawing of a floating-base robot (a new user's run, thirteenth round): the base's
node 0 (fwd 0, npv 0) was placed at column -1, outside the plot area, so its circles and the six
wrench outputs were clipped away (only their labels showed), and the wrench was labelled as
torques τ13..τ18."""
from __future__ import annotations

import re

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main


@pytest.mark.parametrize("robot, args", [("quadruped.urdf", ["--floating-base"]),
                                         ("planar2.yaml", ["--floating-base"]),
                                         ("planar2.yaml", [])])
def test_every_node_is_inside_the_plot_and_the_wrench_is_named(tmp_path, robot, args):
    out = tmp_path / "n.svg"
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / robot), *args, "--network", str(out)])
    assert res.exit_code == 0, res.stderr
    text = out.read_text()
    clip = re.search(r'<clipPath id="[^"]+">\s*<rect x="([\d.]+)" y="[\d.]+" width="([\d.]+)"', text)
    left, right = float(clip.group(1)), float(clip.group(1)) + float(clip.group(2))
    sites = re.findall(r'<g id="site-[^"]+">.*?<path d="M ([\d.]+) ', text, re.S)
    assert sites and all(left <= float(x) <= right for x in sites), (left, right, sites)
    outputs = re.findall(r'<g id="tau-(\d+)"><title>([^<]+)</title>', text)
    floating = bool(args)
    assert any(t.startswith("base_fx leaves ") for _, t in outputs) == floating
    n = 12 if robot == "quadruped.urdf" else 2
    assert not any(t.startswith(f"τ{n + 1} ") for _, t in outputs)          # (the wrench's first)
    if floating:
        focused = CliRunner().invoke(main, ["report", str(EXAMPLES / robot), *args, "--network",
                                            str(out), "--focus", "fwd 0"])
        assert focused.exit_code == 0 and 'id="site-fwd-0"' in out.read_text(), focused.stderr


def test_a_grouped_drawings_key_names_the_wrench(tmp_path):
    """The key said 'and the floating base's wrench' only when an output marker's first output was
    past the joints: a grouped drawing's group holding the base also holds τ1, so it never did."""
    import subprocess
    import sys
    snake = tmp_path / "snake24.yaml"
    snake.write_text(subprocess.run([sys.executable, str(EXAMPLES / "make_snake.py"), "24"],
                                    capture_output=True, text=True, check=True).stdout)
    out = tmp_path / "s.svg"
    res = CliRunner().invoke(main, ["report", str(snake), "--floating-base", "--network", str(out)])
    assert res.exit_code == 0, res.stderr
    text = out.read_text()
    assert "groups of" in text and "base_fx" in text and "wrench" in text


def test_the_base_motion_ports_are_named_as_readme_names_them(tmp_path):
    """A floating base's ports were labelled omega00, omega_dot00 and pdd00 in the drawing and the
    DOT (a new user's find): omega0, omega_dot0 and pdd0, as README and the trajectory name them."""
    out, dot = tmp_path / "n.svg", tmp_path / "n.dot"
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / "quadruped.urdf"), "--floating-base",
                                    "--network", str(out), "--dot", str(dot)])
    assert res.exit_code == 0, res.stderr
    said = set(re.findall(r"host port \d+: ([a-z_]+\d+)", out.read_text()))
    said |= set(re.findall(r'label="port \d+: ([a-z_]+\d+)', dot.read_text()))
    assert {"omega0", "omega_dot0", "pdd0"} <= said and not {"omega00", "omega_dot00", "pdd00"} & said
    dump = CliRunner().invoke(main, ["compile", str(EXAMPLES / "quadruped.urdf"), "--floating-base",
                                     "--dump-after", "graph"])
    keys = {line.split()[-1] for line in dump.stdout.splitlines() if " INPUT - io 0 " in line}
    assert keys == {"omega0", "omega_dot0", "pdd0"}, keys      # (its key; the node keeps its name)
