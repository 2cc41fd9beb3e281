"""What vampc printed and wrote at a fixed commit, kept as digests: outputs must not change.

Each case runs the command line in-process (click's CliRunner) on an example robot: the program file
`vampc compile` writes, the text and JSON of `vampc report` on that program, and the torques of
`vampc emulate` on it (stream engine; and the tick engine for the small robots). The digests at the
base commit were made by running this very file against a checkout of that commit:

    python tests/baseline.py BASE_CHECKOUT > tests/golden/baseline-4d9317d.json

(`BASE_CHECKOUT` goes first on sys.path, so the code measured is that commit's.) Each case runs in
a scratch folder holding a copy of the robot file, named by a relative path, so the digests do not
depend on where the checkout lives. test_baseline.py recomputes every digest with today's code and
compares.
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import sys
import tempfile
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

# (id, robot, compile options, engines): every example, every layout and recursion, a budget, an
# exact budget's neighbour (heuristic), non-unit latencies, a tree and a URDF
CASES = [
    ("planar2-linear-systolic", "planar2.yaml", [], ("stream", "tick")),
    ("planar2-log-systolic", "planar2.yaml", ["--recursion", "log"], ("stream", "tick")),
    ("planar2-linear-folded-shared", "planar2.yaml", ["--layout", "folded", "--share-passes"],
     ("stream", "tick")),
    ("planar2-linear-budget3", "planar2.yaml", ["--vamps", "3"], ("stream", "tick")),
    ("puma560-linear-systolic", "puma560.yaml", [], ("stream", "tick")),
    ("puma560-linear-folded", "puma560.yaml", ["--layout", "folded"], ("stream",)),
    ("puma560-log-systolic", "puma560.yaml", ["--recursion", "log"], ("stream",)),
    ("puma560-log-folded", "puma560.yaml", ["--recursion", "log", "--layout", "folded"], ("stream",)),
    ("puma560-log-brent-kung-uniform", "puma560.yaml",
     ["--recursion", "log", "--prefix", "brent-kung", "--uniform-leaves"], ("stream",)),
    ("puma560-linear-budget7", "puma560.yaml", ["--vamps", "7"], ("stream", "tick")),
    ("puma560-log-budget12", "puma560.yaml", ["--recursion", "log", "--vamps", "12"], ("stream",)),
    ("puma560-linear-latency-3-2", "puma560.yaml", ["--mult-latency", "3", "--add-latency", "2"],
     ("stream", "tick")),
    ("stanford-linear-systolic", "stanford.yaml", [], ("stream",)),
    ("stanford-log-folded-shared", "stanford.yaml",
     ["--recursion", "log", "--layout", "folded", "--share-passes"], ("stream",)),
    ("arm6-linear-systolic", "arm6.urdf", [], ("stream",)),
    ("quadruped-linear-systolic", "quadruped.urdf", [], ("stream",)),
    ("quadruped-log-systolic", "quadruped.urdf", ["--recursion", "log"], ("stream",)),
    ("quadruped-linear-budget9", "quadruped.urdf", ["--vamps", "9"], ("stream",)),
    ("snake64-linear-systolic", "snake64.yaml", [], ("stream",)),
    ("snake64-log-folded", "snake64.yaml", ["--recursion", "log", "--layout", "folded"],
     ("stream",)),
]


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def outputs(case) -> dict[str, str]:
    """The digests of what the commands of one case print and write."""
    name, robot, options, engines = case
    here = os.getcwd()
    with tempfile.TemporaryDirectory() as tmp:
        # the robot file is named by a relative path, so what the program file records of it (its
        # `robot.source`) is the same wherever the checkout lives
        shutil.copy(EXAMPLES / robot, os.path.join(tmp, robot))
        os.chdir(tmp)
        try:
            got = _run_case(name, robot, options, engines)
        finally:
            os.chdir(here)
    return got


def _run_case(name, robot, options, engines) -> dict[str, str]:
    """The digests of one case, run in the current folder (which holds the robot file)."""
    from click.testing import CliRunner

    from vampc.cli import main
    runner = CliRunner()

    def run(args) -> bytes:
        res = runner.invoke(main, args, catch_exceptions=False)
        if res.exit_code != 0:
            raise AssertionError(f"{name}: vampc {' '.join(args)} exited {res.exit_code}: "
                                 f"{res.output}")
        return res.stdout_bytes

    prog = "robot.vamp.json"
    run(["compile", robot, *options, "-o", prog])
    got = {"program": _digest(Path(prog).read_bytes()),
           "report": _digest(run(["report", prog])),
           "report-json": _digest(run(["report", prog, "--format", "json"]))}
    for engine in engines:
        count = "200" if engine == "stream" else "3"
        got[f"torques-{engine}"] = _digest(run(["emulate", prog, "--random", count, "--seed", "3",
                                                "--engine", engine, "-o", "-"]))
    return got


def main(argv) -> None:
    """Print the digests of every case as JSON, with the code of the checkout argv[1] (if given)."""
    if len(argv) > 1:
        sys.path.insert(0, str(Path(argv[1]).resolve()))
    os.environ.setdefault("VAMPC_PROGRESS", "0")
    print(json.dumps({case[0]: outputs(case) for case in CASES}, indent=1, sort_keys=True))


if __name__ == "__main__":
    main(sys.argv)
