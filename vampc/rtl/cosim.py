"""Co-simulation: the generated design run by a simulator on the host's writes (vampc.rtl.host),
its torque words compared bit for bit with the emulator's.

Simulators: "amaranth" (Amaranth's own, pip only: the default), "icarus" (Icarus Verilog on the
Verilog `vampc rtl` writes, when `iverilog` is on the PATH: faster on long runs, the same words).
"""
from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass

import numpy as np

from vampc.errors import VampcError
from vampc.rtl.host import HostRun, host_run, pack

SIMULATORS = ("amaranth", "icarus")


@dataclass(frozen=True)
class CosimResult:
    """Torque words from the design, those of the emulator, and how they compare."""

    simulator: str
    words: np.ndarray          # (sets, outputs) raw words the design's outputs held
    expected: np.ndarray       # the same from `vampc emulate` (the stream engine)
    ticks: int
    seconds: float
    overflows: int = 0         # the emulator's run of the same sets: results and host words
                               # beyond the word, counted (both then hold the word's values)
    result_overflows: int = 0  # of those, the VAMPs' results (the host's conversions left out)
    flag: bool = False         # the design's overflow output after the run (NetworkDesign)

    @property
    def mismatches(self) -> int:
        return int(np.count_nonzero(self.words != self.expected))

    @property
    def flag_agrees(self) -> bool:
        """The design raised its overflow output exactly when a VAMP's result overflowed in the
        emulator's run of the same sets."""
        return self.flag == (self.result_overflows > 0)

    @property
    def ok(self) -> bool:
        return self.mismatches == 0 and self.flag_agrees

    def first_mismatch(self) -> tuple[int, int] | None:
        bad = np.argwhere(self.words != self.expected)
        return None if not bad.size else (int(bad[0][0]), int(bad[0][1]))


def expected_words(ld, traj) -> tuple[np.ndarray, int, int]:
    """The emulator's torque words for `traj` (stream engine), as raw integers, output by output;
    how many overflows its run counted (the constants' conversion included, as `vampc emulate`
    counts them); and how many of them were the VAMPs' results (the run's less the host's
    conversions of the constants and of the inputs, each value once, as the run counts them)."""
    from vampc.emulator import emulate
    from vampc.emulator.host import port_values
    from vampc.emulator.stream import constant_overflows, count_overflows_from_here
    ld.arith.overflows = 0
    port_values(ld, traj)
    host = int(ld.arith.overflows) + constant_overflows(ld)
    count_overflows_from_here(ld)
    tau = emulate(ld, traj, engine="stream").tau
    raw = tau * 2.0 ** ld.word.fraction           # exact: a W-bit word, W <= 64, F fraction bits
    cols = [o.joint - 1 for o in ld.net.outputs]
    total = int(ld.arith.overflows)
    return np.rint(raw[:, cols]).astype(np.int64), total, total - host


def cosimulate(ld, traj, simulator: str = "amaranth", design=None, progress=None,
               workdir: str | None = None) -> CosimResult:
    """Run the design for `ld` on `traj` with `simulator` and compare with the emulator."""
    import time

    from vampc.rtl.design import NetworkDesign
    design = design or NetworkDesign(ld)
    run = host_run(ld, traj, design.inputs)
    start = time.perf_counter()
    if simulator == "amaranth":      # (each: the torque words, and the overflow output at the end)
        from vampc.rtl.deep import deep
        words, flag = deep(_amaranth, design, run, progress)
    elif simulator == "icarus":
        words, flag = _icarus(design, run, workdir)
    else:
        raise VampcError(f"unknown simulator {simulator!r} ({', '.join(SIMULATORS)})")
    seconds = time.perf_counter() - start
    expected, overflows, results = expected_words(ld, traj)
    return CosimResult(simulator, words, expected, run.ticks, seconds, overflows, results, flag)


def _amaranth(design, run: HostRun, progress=None) -> tuple[np.ndarray, bool]:
    from amaranth.sim import Simulator
    W = design.arith.W
    words = np.zeros((run.count, len(design.tau)), dtype=np.int64)
    sim = Simulator(design)
    sim.add_clock(1e-6)

    async def bench(ctx):
        raised = []
        for T in range(-1, run.ticks):
            for k in raised:
                ctx.set(design.host_we[k], 0)
            raised = []
            for k, value in run.writes.get(T + 1, ()):     # shows from the next tick
                ctx.set(design.host[k], pack(value, W))
                ctx.set(design.host_we[k], 1)
                raised.append(k)
            ctx.set(design.program, T < 0 or run.program(T))
            ctx.set(design.global_reset, T < 0 or run.global_reset(T))
            for k, s in run.samples.get(T, ()):
                words[s, k] = ctx.get(design.tau[k])
            if progress is not None and T % 256 == 0:
                progress(T + 1, run.ticks)
            await ctx.tick()
        flag.append(bool(ctx.get(design.overflow)))

    flag: list[bool] = []
    sim.add_testbench(bench)
    sim.run()
    return words, flag[0]


def _icarus(design, run: HostRun, workdir: str | None) -> tuple[np.ndarray, bool]:
    """Icarus Verilog on the design's Verilog and a testbench that replays the host's run from
    memory files and prints every sampled torque word."""
    if shutil.which("iverilog") is None or shutil.which("vvp") is None:
        raise VampcError("--simulator icarus needs Icarus Verilog (iverilog and vvp on the PATH; "
                         "apt-get install iverilog)")
    from vampc.rtl.verilog import verilog_text
    W = design.arith.W
    own = workdir is None
    workdir = workdir or tempfile.mkdtemp(prefix="vampc-rtl-")
    try:
        top = design.name
        with open(os.path.join(workdir, "design.v"), "w") as f:
            f.write(verilog_text(design))
        n_in = len(design.host)
        # one line per tick: program, global_reset, the write enables, then each input's data
        lines = []
        current = [0] * n_in
        for T in range(-1, run.ticks):
            we = [0] * n_in
            for k, value in run.writes.get(T + 1, ()):
                current[k] = pack(value, W)
                we[k] = 1
            ctl = (int(T < 0 or run.program(T)) | int(T < 0 or run.global_reset(T)) << 1
                   | sum(b << (2 + k) for k, b in enumerate(we)))
            lines.append(ctl)
            lines.extend(current[k] if we[k] else 0 for k in range(n_in))
        with open(os.path.join(workdir, "stim.hex"), "w") as f:
            f.write("\n".join(format(x, "x") for x in lines) + "\n")
        sizes = [len(s) for s in design.host]
        widest = max(sizes + [2 + n_in])
        samples = sorted(run.samples.items())
        tb = ["`timescale 1ns/1ps", f"module tb_{top};",     # (never the design's own name)
              "  reg clk = 0; reg rst = 0;",
              "  reg program_mode = 1; reg global_reset = 1;",
              *[f"  reg [{s - 1}:0] host{k} = 0; reg host{k}_we = 0;" for k, s in enumerate(sizes)],
              *[f"  wire signed [{W - 1}:0] tau{i};" for i in range(len(design.tau))],
              "  wire overflow;",
              f"  reg [{widest - 1}:0] mem [0:{len(lines) - 1}];",
              "  integer T, p, out;",
              f"  {top} dut(.clk(clk), .rst(rst), .program_mode(program_mode), .global_reset(global_reset),",
              *[f"    .host{k}(host{k}), .host{k}_we(host{k}_we)," for k in range(n_in)],
              "    " + ", ".join(f".{t.name}(tau{i})" for i, t in enumerate(design.tau))
              + ", .overflow(overflow));",
              "  initial begin",
              '    $readmemh("stim.hex", mem);',
              '    out = $fopen("tau.txt", "w");',
              "    p = 0;",
              "    rst = 1; #1; clk = 1; #1; clk = 0; rst = 0;   // a synchronous reset first",
              f"    for (T = -1; T < {run.ticks}; T = T + 1) begin",
              "      program_mode = mem[p][0]; global_reset = mem[p][1];",
              *[f"      host{k}_we = mem[p][{2 + k}]; if (mem[p][{2 + k}]) host{k} = mem[p + {1 + k}];"
                for k in range(n_in)],
              f"      p = p + {1 + n_in};",
              "      #1;",
              '      $fwrite(out, "%0d", T);',
              *[f'      $fwrite(out, " %0d", tau{i});' for i in range(len(design.tau))],
              '      $fwrite(out, "\\n");',
              "      clk = 1; #1; clk = 0;",
              "    end",
              '    $fwrite(out, "overflow %0d\\n", overflow);',
              "    $fclose(out); $finish;",
              "  end",
              "endmodule", ""]
        del samples
        with open(os.path.join(workdir, "tb.v"), "w") as f:
            f.write("\n".join(tb))
        _run(["iverilog", "-g2005", "-o", "sim.vvp", "tb.v", "design.v"], workdir)
        _run(["vvp", "-n", "sim.vvp"], workdir)
        values, flag = {}, False
        with open(os.path.join(workdir, "tau.txt")) as f:
            for line in f:
                parts = line.split()
                if parts[0] == "overflow":
                    flag = parts[1] == "1"
                    continue
                values[int(parts[0])] = [int(x) for x in parts[1:]]
        words = np.zeros((run.count, len(design.tau)), dtype=np.int64)
        for T, reads in run.samples.items():
            for k, s in reads:
                words[s, k] = values[T][k]
        return words, flag
    finally:
        if own:
            shutil.rmtree(workdir, ignore_errors=True)


def _run(cmd, cwd) -> None:
    from vampc.background import run_tool
    done = run_tool(cmd, cwd=cwd)
    if done.returncode:
        last = (done.stderr or done.stdout).strip().splitlines()[-1:]
        raise VampcError(f"{cmd[0]} failed: {' / '.join(last)}")
