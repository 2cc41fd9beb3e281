"""The scale table of the issue "Fast at every size", measured in one run: each measure a whole
`vampc` process (wall time and peak memory of that process), beside the figure the issue started
from and its target.

    python benchmarks/scale.py [--only NAME,...] [--suite]

Measures (names for --only): compile4096 (a 4096-joint log snake, whole `vampc compile`), program
(that program's size, plain and .gz), report4096 and report16000 (`vampc report` of a URDF chain,
text), emulate (benchmarks/emulate_io.py: UR5, CSV and .npy, against Pinocchio's loop; needs pin and
example-robot-data), tradeoff (`report --tradeoff` of a 64-joint log snake, 2 workers). --suite also
times the test suite (`pytest`, two workers). The whole table takes about 15 minutes on the 2-core
machine; --only picks rows.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

# Run one command, report its wall time and its peak resident memory: the largest of the command's
# process and its children's (ru_maxrss of RUSAGE_CHILDREN is one process's peak, not a sum: a
# report's forked check is not added to the report's own; an audit's).
WRAPPER = """
import json, resource, subprocess, sys, time
begun = time.perf_counter()
done = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
print(json.dumps({"seconds": time.perf_counter() - begun, "rc": done.returncode,
                  "peak_mib": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
                  "stderr": done.stderr[-300:]}))
"""

BEFORE = {"compile4096": "42–47 s, 2.7 GiB", "program": "370 MB", "report4096": "~90 s",
          "report16000": "295 s", "emulate_csv": "1.5×", "emulate_npy": "–", "tradeoff": "97–142 s",
          "suite": "214 s"}
TARGET = {"compile4096": "< 15 s, < 1 GiB", "program": "< 100 MB compact", "report4096": "< 15 s",
          "report16000": "< 60 s", "emulate_csv": "≥ 2×", "emulate_npy": "≥ 5×", "tradeoff": "< 45 s",
          "suite": "< 240 s"}


NAMES = ("compile4096", "program", "report4096", "report16000", "emulate", "tradeoff")


def measure(cmd: list, cwd: Path, env: dict | None = None) -> dict:
    """`cmd`'s wall time and peak memory, run from a small process of its own (WRAPPER; from a big
    one, Linux would give the command that process's high-water mark); `env`: os.environ's by
    default. Children write bytecode caches, as an installed package has them."""
    env = {k: v for k, v in (env or os.environ).items() if k != "PYTHONDONTWRITEBYTECODE"}
    out = subprocess.run([sys.executable, "-c", WRAPPER, *map(str, cmd)], cwd=cwd, env=env,
                         capture_output=True, text=True, check=True)
    got = json.loads(out.stdout)
    if got["rc"] != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed: {got['stderr']}")
    return got


def snake(n: int, folder: Path) -> Path:
    path = folder / f"snake{n}.yaml"
    path.write_text(subprocess.run([sys.executable, str(ROOT / "examples" / "make_snake.py"), str(n)],
                                   capture_output=True, text=True, check=True).stdout)
    return path


def urdf(n: int, folder: Path) -> Path:
    from load_robot import urdf_chain
    path = folder / f"chain{n}.urdf"
    path.write_text(urdf_chain(n))
    return path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", default="", metavar="NAME,...",
                        help=f"comma-separated measure names: {', '.join(NAMES)} (emulate_csv and "
                        "emulate_npy are emulate's two rows)")
    parser.add_argument("--suite", action="store_true", help="also time the test suite")
    args = parser.parse_args()
    only = {x.strip() for x in args.only.split(",") if x.strip()}
    only = {"emulate" if x in ("emulate_csv", "emulate_npy") else x for x in only}
    unknown = sorted(only - set(NAMES))
    if unknown:
        parser.error(f"--only {', '.join(unknown)}: no such measure (choose from {', '.join(NAMES)})")
    from emulate_io import vampc_script
    vampc = vampc_script()       # the console script beside this Python, not a shim found first
    if shutil.which(vampc) is None:
        raise SystemExit(f"scale.py: no vampc beside {sys.executable} nor on PATH: install vampc "
                         "into this Python's environment first (README, Quick start)")

    def wanted(name: str) -> bool:
        return not only or name in only
    now: dict[str, str] = {}
    failed: list[str] = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if wanted("compile4096") or wanted("program"):
            program = folder / "s4096.vamp.json"
            got = measure([vampc, "compile", snake(4096, folder), "--recursion", "log", "-o", program], folder)
            now["compile4096"] = f"{got['seconds']:.1f} s, {got['peak_mib'] / 1024:.2f} GiB"
            packed = measure([vampc, "compile", snake(4096, folder), "--recursion", "log", "-o",
                              str(program) + ".gz"], folder) if wanted("program") else None
            if packed:
                now["program"] = (f"{program.stat().st_size / 1e6:.0f} MB plain, "
                                  f"{Path(str(program) + '.gz').stat().st_size / 1e6:.0f} MB .gz")
        for n in (4096, 16000):
            if wanted(f"report{n}"):
                got = measure([vampc, "report", urdf(n, folder)], folder)
                now[f"report{n}"] = f"{got['seconds']:.1f} s, {got['peak_mib'] / 1024:.2f} GiB"
        if wanted("emulate"):
            done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "emulate_io.py")],
                                  capture_output=True, text=True, check=False)
            out = done.stdout
            ratios = [line for line in out.splitlines() if "ratio CSV" in line]
            if ratios:
                parts = ratios[0].split(";")
                now["emulate_csv"] = parts[0].split(":")[1].split("(")[0].strip()
                now["emulate_npy"] = parts[1].split(":")[1].split("(")[0].strip()
            else:
                # its last line whole (cut to 60 characters it read "(o robot: give ...": a new
                # user's), and the run's exit status 1, as a row not measured is a failure
                said = (out.strip() or done.stderr.strip() or "?").splitlines()[-1]
                now["emulate_csv"] = now["emulate_npy"] = f"not measured ({said})"
                failed.append("emulate")
        if wanted("tradeoff"):
            got = measure([vampc, "report", snake(64, folder), "--recursion", "log", "--tradeoff",
                           "--workers", "2"], folder)
            now["tradeoff"] = f"{got['seconds']:.1f} s"
        if args.suite:
            got = measure([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"], ROOT)
            now["suite"] = f"{got['seconds']:.0f} s"
    labels = {"compile4096": "compile 4096-joint log chain, whole process",
              "program": "program file, 4096-joint log", "report4096": "report (text), 4096-joint URDF chain",
              "report16000": "report (text), 16 000-joint URDF chain",
              "emulate_csv": "emulate 100 000 UR5 states CSV→CSV vs pin.rnea loop",
              "emulate_npy": "emulate 100 000 UR5 states .npy→.npy vs pin.rnea loop",
              "tradeoff": "report --tradeoff 64-joint log, 2 workers", "suite": "test suite, 2 cores"}
    print("| measure | before | now | target |\n|---|---:|---:|---:|")
    for key, label in labels.items():
        if key in now:
            print(f"| {label} | {BEFORE[key]} | {now[key]} | {TARGET[key]} |")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
