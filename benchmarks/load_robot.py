"""Robot-loading benchmark: how `vampc.robot.load_robot` scales with the number of joints.

It writes big robots to a temporary folder and prints the wall time of `load_robot(path)` for each:

- a URDF serial chain of N revolute joints, every link with an <inertial>, a fixed joint (and its link)
  after every fourth revolute one, and a fixed tool link at the end: N = 1000, 4000, 16000, 100000;
- the DH snake of examples/make_snake.py as YAML and as JSON: N = 4096, 16000, 100000.

Small sizes print the median of --runs loads, sizes of SLOW seconds or more a single run. The growth
column is the time ratio to the previous size over the size ratio: about 1 means linear.

    python benchmarks/load_robot.py [--runs 3] [--urdf 1000,4000,16000,100000] [--dh 4096,16000,100000]
                                    [--profile FILE]

--profile FILE prints the cProfile hot spots of one load of FILE (e.g. a file kept with --keep DIR).
"""
from __future__ import annotations

import argparse
import cProfile
import importlib.util
import json
import pstats
import statistics
import sys
import tempfile
import time
from pathlib import Path

from vampc.errors import VampcError
from vampc.robot import load_robot

ROOT = Path(__file__).resolve().parent.parent
SLOW = 5.0


def _snake_module():
    spec = importlib.util.spec_from_file_location("make_snake", ROOT / "examples" / "make_snake.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def urdf_chain(n: int) -> str:
    """A URDF chain of n revolute joints with a fixed joint after every fourth, all links with inertia."""
    parts = ['<?xml version="1.0"?>', f'<robot name="chain{n}">', _link("l0")]
    parent = "l0"
    for k in range(1, n + 1):
        parts += [_joint(f"j{k}", "revolute", parent, f"l{k}", k), _link(f"l{k}")]
        parent = f"l{k}"
        if k % 4 == 0 or k == n:
            child = "tool" if k == n else f"f{k}"
            parts += [_joint(f"fix{k}", "fixed", parent, child, k), _link(child)]
            parent = child
    return "\n".join(parts + ["</robot>", ""])


def _link(name: str) -> str:
    return (f'<link name="{name}"><inertial><origin xyz="0.05 0.01 0" rpy="0 0 0.1"/><mass value="1.5"/>'
            '<inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>')


def _joint(name: str, kind: str, parent: str, child: str, k: int) -> str:
    axis = ("0 0 1", "0 1 0", "1 0 0")[k % 3]
    limit = '<limit lower="-3" upper="3" velocity="2" effort="50"/>' if kind == "revolute" else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="0.1 0 0.02" rpy="0 0.1 0"/><axis xyz="{axis}"/>{limit}</joint>')


def dh_snake(n: int) -> dict:
    """The n-joint snake of examples/make_snake.py as a document (for JSON)."""
    snake = _snake_module()
    return {"name": f"snake{n}", "gravity": [0.0, 0.0, -9.81],
            "joints": [{**snake.joint(i, n), "type": "revolute",
                        "limits": {"q": [-3.14159265, 3.14159265], "qd": 2.0}} for i in range(1, n + 1)]}


def write_robots(folder: Path, urdf_sizes: list[int], dh_sizes: list[int]) -> list[tuple[str, int, Path]]:
    """Write every benchmark robot; returns (kind, n, path) rows in the order they are timed."""
    rows = []
    for n in urdf_sizes:
        rows.append(("urdf", n, folder / f"chain{n}.urdf"))
        rows[-1][2].write_text(urdf_chain(n))
    for n in dh_sizes:
        rows.append(("dh yaml", n, folder / f"snake{n}.yaml"))
        rows[-1][2].write_text(_snake_module().render(n))
    for n in dh_sizes:
        rows.append(("dh json", n, folder / f"snake{n}.json"))
        rows[-1][2].write_text(json.dumps(dh_snake(n)))
    return rows


def load_time(path: Path, runs: int) -> tuple[float, int, str]:
    """Median seconds over up to `runs` loads (one if it takes SLOW seconds), the count, and the outcome
    ("ok" or the refusal's message)."""
    times, outcome = [], "ok"
    while len(times) < runs and (not times or times[0] < SLOW):
        t0 = time.perf_counter()
        try:
            load_robot(path)
        except VampcError as exc:
            outcome = f"refused: {str(exc).split(': ', 1)[1]}"
        times.append(time.perf_counter() - t0)
    return statistics.median(times), len(times), outcome


def table(rows: list, runs: int) -> None:
    """One line per robot: seconds, growth against the previous size of the same kind, outcome."""
    previous = {}
    for kind, n, path in rows:
        t, count, outcome = load_time(path, runs)
        growth = ""
        if kind in previous:
            n0, t0 = previous[kind]
            growth = f"growth {t / t0 / (n / n0):5.2f}"
        previous[kind] = (n, t)
        mb = path.stat().st_size / 1e6
        print(f"  {kind:8s} n = {n:6d} {mb:7.1f} MB {t:9.3f} s ({count} run{'s' * (count > 1)}) "
              f"{growth:12s} {outcome}", flush=True)


def profile(path: Path) -> None:
    """Print the top cumulative-time entries of one load of `path`."""
    profiler = cProfile.Profile()
    profiler.runcall(load_robot, path)
    pstats.Stats(profiler).sort_stats("cumulative").print_stats(25)


def _sizes(text: str) -> list[int]:
    return [int(x) for x in text.split(",") if x]


def main(argv: list[str] | None = None) -> int:
    """Command-line entry."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--urdf", default="1000,4000,16000,100000")
    parser.add_argument("--dh", default="4096,16000,100000")
    parser.add_argument("--keep", type=Path, help="write the robots into this folder and keep them")
    parser.add_argument("--profile", type=Path, help="profile one load of this file instead")
    args = parser.parse_args(argv)
    if args.profile:
        profile(args.profile)
        return 0
    load_robot(ROOT / "examples" / "arm6.urdf")  # import yourdfpy and jsonschema outside the timings
    load_robot(ROOT / "examples" / "planar2.yaml")
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        rows = write_robots(folder, _sizes(args.urdf), _sizes(args.dh))
        print(f"load_robot wall time (median of {args.runs} below {SLOW:.0f} s; growth 1 = linear):")
        table(rows, args.runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
