"""Before/after benchmark of the one-machine-model work: compile, read, emulate and report speeds.

Uses only what every version since 4d9317d has (vampc.compiler.compile_chain/program_text,
vampc.program.file.write_program, the `vampc` command), so the same script measures an older
checkout too:

    python benchmarks/machine_model.py                 # this checkout
    python benchmarks/machine_model.py OTHER_CHECKOUT  # OTHER_CHECKOUT's vampc first on sys.path

Prints, as medians of --runs (default 5) in one process:

- compile: compile_chain + program_text of the Puma 560 (linear, log), a 512-joint linear chain,
  and a 32-joint log graph on a budget of 943 VAMPs (the issue's reading benchmark);
- read: the reading step of `vampc report PROGRAM` alone (read_program + compiled_from_doc: what
  the report of a program does before building figures) of that 32-joint log graph on budgets of
  943, 600 and 300 VAMPs, each step timed in a fresh process as `vampc compile` and `vampc report`
  run, and on 100 VAMPs (where the scheduler has real work), and its ratio to compiling it (the
  issue's target: under a fifth);
- emulate: `vampc emulate` of the Puma 560 program, 20 000 random states on the stream engine
  (numpy path, VAMPC_NATIVE=0) and 200 on the tick engine, in-process;
- report: `vampc report` of the Puma 560 robot file, in-process.
"""
from __future__ import annotations

import argparse
import inspect
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path


def median_time(fn, runs: int) -> float:
    """Median wall time of `fn()` over `runs` calls."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


# the compile and read steps, timed in a fresh interpreter (imports done before timing)
_PRELUDE = """
import gc, statistics, sys, time
from pathlib import Path
if {checkout!r}:
    sys.path.insert(0, {checkout!r})
from vampc.compiler import CompileOptions, compile_chain, program_text
from vampc.program.document import compiled_from_doc
from vampc.program.file import write_program
try:
    from vampc.program.file import read_program_file as read_program
except ImportError:
    from vampc.program.file import read_program
from vampc.robot.random import random_chain
"""
COMPILE = """
chain, options = random_chain(32, 1), CompileOptions(recursion="log", vamps={k})
path = Path({out!r})
path.unlink(missing_ok=True)
write_program(program_text(compile_chain(chain, options)), str(path))
print(median_time(lambda: program_text(compile_chain(chain, options)), RUNS))
"""
READ = """
path = Path({path!r})
print(median_time(lambda: compiled_from_doc(read_program(path), path), RUNS))
"""


def fresh_time(checkout, code: str, runs: int) -> float:
    """Median seconds of a step timed in a new Python process."""
    import subprocess
    prelude = (_PRELUDE.format(checkout=str(Path(checkout).resolve()) if checkout else "")
               + inspect.getsource(median_time))     # the same timer as this process's
    out = subprocess.run([sys.executable, "-c", prelude + f"RUNS = {runs}\n" + code],
                         capture_output=True, text=True, check=True, env=dict(os.environ))
    return float(out.stdout.split()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkout", nargs="?", help="measure this checkout's vampc instead")
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    if args.checkout:
        sys.path.insert(0, str(Path(args.checkout).resolve()))
    os.environ["VAMPC_PROGRESS"] = "0"
    from click.testing import CliRunner

    import vampc
    from vampc.cli import main as cli
    from vampc.compiler import CompileOptions, compile_chain, program_text
    from vampc.program.document import compiled_from_doc
    from vampc.program.file import write_program
    try:      # the typed reader, where there is one (the dict reader before it)
        from vampc.program.file import read_program_file as read_program
    except ImportError:
        from vampc.program.file import read_program
    from vampc.robot import load_robot
    from vampc.robot.random import random_chain
    # the examples of this script's checkout (an installed vampc has none beside it)
    examples = Path(__file__).resolve().parent.parent / "examples"
    print(f"vampc from {Path(vampc.__file__).parent}")
    puma = load_robot(examples / "puma560.yaml")
    runner = CliRunner()

    def run(*argv):
        res = runner.invoke(cli, list(map(str, argv)))
        assert res.exit_code == 0, res.output

    cases = [("Puma 560, linear", puma, {}), ("Puma 560, log", puma, {"recursion": "log"}),
             ("512 joints, linear", random_chain(512, 1), {}),
             ("32 joints, log, 943 VAMPs", random_chain(32, 1), {"recursion": "log", "vamps": 943})]
    with tempfile.TemporaryDirectory() as tmp:
        for label, chain, opts in cases:
            options = CompileOptions(**opts)
            t = median_time(lambda: program_text(compile_chain(chain, options)), args.runs)
            print(f"compile {label:28s} {t:8.3f} s")
        budget_path = Path(tmp) / "budget.vamp.json"
        # compiling and reading, each in a fresh process as `vampc compile` and `vampc report`
        # run (a long process that has compiled a 512-joint chain reads 1.5x slower: its heap)
        for k in (943, 600, 300):
            c_s = fresh_time(args.checkout, COMPILE.format(k=k, out=str(budget_path)), args.runs)
            r_s = fresh_time(args.checkout, READ.format(path=str(budget_path)), args.runs)
            print(f"read    {f'32 joints, log, {k} VAMPs':28s} {r_s:8.3f} s  ({r_s / c_s:.2f} of "
                  f"compiling it, {c_s:.3f} s; fresh processes)")
        write_program(program_text(compile_chain(cases[3][1], CompileOptions(**cases[3][2]))),
                      str(budget_path))
        try:     # the typed decode alone, beside json.loads of the same text (which checks nothing)
            import gc
            import json

            from vampc.program.format import decode
            text = budget_path.read_bytes()
            gc.disable()
            typed_s = median_time(lambda: decode(text), args.runs)
            plain_s = median_time(lambda: json.loads(text), args.runs)
            gc.enable()
            print(f"decode  {cases[3][0]:28s} {typed_s:8.3f} s typed (msgspec), {plain_s:.3f} s "
                  "json.loads")
        except ImportError:      # a checkout before the typed program file
            pass
        # a budget where the scheduler has real work (compiled once: about 14 s)
        tight = CompileOptions(recursion="log", vamps=100)
        start = time.perf_counter()
        write_program(program_text(compile_chain(cases[3][1], tight)), str(budget_path))
        compile_s = time.perf_counter() - start
        read_s = median_time(lambda: compiled_from_doc(read_program(budget_path), budget_path),
                             args.runs)
        print(f"read    {'32 joints, log, 100 VAMPs':28s} {read_s:8.3f} s  ({read_s / compile_s:.3f} "
              f"of compiling it, {compile_s:.1f} s once)")
        prog = Path(tmp) / "puma.vamp.json"
        run("compile", examples / "puma560.yaml", "-o", prog)
        os.environ["VAMPC_NATIVE"] = "0"
        t = median_time(lambda: run("emulate", prog, "--random", 20000), args.runs)
        print(f"emulate Puma 560, stream (numpy), 20 000 {t:8.3f} s")
        t = median_time(lambda: run("emulate", prog, "--random", 200, "--engine", "tick"),
                        args.runs)
        print(f"emulate Puma 560, tick, 200 sets          {t:8.3f} s")
        os.environ.pop("VAMPC_NATIVE")
        t = median_time(lambda: run("report", examples / "puma560.yaml"), args.runs)
        print(f"report  Puma 560 robot file               {t:8.3f} s")
        t = median_time(lambda: run("report", prog), args.runs)
        print(f"report  Puma 560 program file             {t:8.3f} s")


if __name__ == "__main__":
    main()
