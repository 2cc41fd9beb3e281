"""The `vampc` command line: a thin layer that parses options, calls the library and formats output.

User errors (VampcError) print one line `vampc: error: ...` and exit 1; usage errors exit 2 (click);
warnings (VampcWarning) print one line `vampc: warning: ...` and the work goes on; anything else is a
vampc bug: it is shown in full with a request to report it, and exits 3. Output files follow the
rules of vampc.outputs (README "Output files"), checked before any work is done.
"""
from __future__ import annotations

import functools
import json
import math
import sys
import time
import warnings
from pathlib import Path

import click
from click.core import ParameterSource

from vampc.errors import VampcError, VampcWarning

# Options that only mean something when a robot file is compiled (their CompileOptions names).
COMPILE_OPTIONS = ("recursion", "prefix", "uniform_leaves", "mult_latency", "add_latency", "layout",
                   "share_passes", "vamps", "interval", "exact", "verify")
ROBOT_OPTIONS = ("base", "tip", "lock", "floating_base")
LOG_ONLY = ("prefix", "uniform_leaves")


class FilePath(click.Path):
    """click.Path that refuses an empty name (a shell variable that was never set), rather than
    falling back on a default file or the current folder."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not value.strip():
            self.fail("an empty file name", param, ctx)
        return super().convert(value, param, ctx)


def _robot_options(f):
    """Options shared by every command that reads a robot file."""
    f = click.option("--floating-base", is_flag=True,
                     help="The base floats: its motion (ω, ω̇, linear acceleration, in the base frame) "
                     "is input per torque set, its own inertia counts, and the network also returns "
                     "the base wrench (a URDF whose root joint is floating floats anyway).")(f)
    f = click.option("--lock", "lock", multiple=True, metavar="JOINT=VALUE",
                     help="URDF: lock a joint at a position (radians or metres); repeatable.")(f)
    f = click.option("--tip", metavar="LINK", help="URDF: last link of the chain.")(f)
    f = click.option("--base", metavar="LINK", help="URDF: first link of the chain (default: root).")(f)
    return f


def _compile_options(f):
    """Options that map one-to-one onto vampc.compiler.CompileOptions."""
    opts = [
        click.option("--recursion", type=click.Choice(["linear", "log"]), default="linear",
                     show_default=True, help="Linear (section III) or logarithmic (sections IV-V) "
                     "Newton-Euler recursion."),
        click.option("--prefix", type=click.Choice(["sklansky", "brent-kung", "kogge-stone",
                                                    "ladner-fischer", "serial"]),
                     default="sklansky", show_default=True,
                     help="Prefix-network shape of the log recursion (Sklansky is the paper's)."),
        click.option("--uniform-leaves", is_flag=True,
                     help="Log recursion: handle a = b with the uniform node of Appendix D."),
        click.option("--mult-latency", type=click.IntRange(1, 64), default=1, show_default=True,
                     help="Flops per multiplication."),
        click.option("--add-latency", type=click.IntRange(1, 64), default=1, show_default=True,
                     help="Flops per addition."),
        click.option("--layout", type=click.Choice(["systolic", "folded"]), default="systolic",
                     show_default=True, help="systolic: one VAMP per op, a new torque set every "
                     "4 flops; folded: the paper's single device, one node's (linear) or one tier's "
                     "(log) VAMPs reused for every joint or tier, one torque set at a time."),
        click.option("--share-passes", is_flag=True, help="Folded layout: run the forward pass on "
                     "the backward pass's VAMPs (Figure VI.1b)."),
        click.option("--vamps", type=click.IntRange(1), metavar="K", help="A VAMP budget: schedule "
                     "onto at most K VAMPs at the smallest interval reachable (not below ⌈W/K⌉)."),
        click.option("--interval", type=click.IntRange(1), metavar="T", help="A rate: a new torque "
                     "set every T flops, on the fewest VAMPs (with --vamps: both, or an error "
                     "saying what is feasible)."),
        click.option("--exact", is_flag=True, help="With --vamps: place the ops with OR-Tools CP-SAT "
                     "(pip install \"vampc[exact]\"), proving the best interval and latency for "
                     "small graphs within a time limit (about 30 s per interval)."),
        click.option("--verify/--no-verify", default=True, show_default=True,
                     help="Check every IR's invariants at each stage boundary."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def _parse_lock(items) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        try:
            number = float(value)
        except ValueError:
            sep = ""
        if not sep or not name:
            raise click.BadParameter(f"{item!r} is not JOINT=VALUE", param_hint="--lock")
        if not math.isfinite(number):
            raise click.BadParameter(f"{item!r}: the position must be a finite number",
                                     param_hint="--lock")
        if name in out and out[name] != number:
            raise click.BadParameter(f"joint {name!r} is locked twice, at {out[name]:g} and "
                                     f"{number:g}", param_hint="--lock")
        out[name] = number
    return out


def _handle_errors(f):
    @functools.wraps(f)
    def wrapper(*args, **kwargs):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("always", VampcWarning)
                warnings.showwarning = _show_warning
                return f(*args, **kwargs)
        except VampcError as exc:
            click.echo(f"vampc: error: {exc}", err=True)
            sys.exit(1)
        except KeyboardInterrupt:
            click.echo("vampc: interrupted", err=True)
            sys.exit(130)
        except (click.exceptions.Exit, click.ClickException, SystemExit):
            raise
        except Exception:
            import traceback
            traceback.print_exc()
            click.echo("vampc: internal error: this is a bug in vampc, not in your input; please "
                       "report it with the command line and the input file", err=True)
            sys.exit(3)
    return wrapper


def _show_warning(message, category, *rest):
    if issubclass(category, VampcWarning):
        click.echo(f"vampc: warning: {message}", err=True)
    else:   # a library's own warning (numpy's, say): not ours to silence, but one line
        click.echo(f"vampc: warning: {category.__name__}: {message}", err=True)


def _given(ctx: click.Context, name: str) -> bool:
    """Whether the user gave option `name` (rather than its default)."""
    return ctx.get_parameter_source(name) not in (None, ParameterSource.DEFAULT,
                                                  ParameterSource.DEFAULT_MAP)


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")


def _check_robot_options(ctx: click.Context, opts: dict) -> None:
    """Options that do not apply to the recursion chosen are usage errors, not silence."""
    if opts.get("recursion", "linear") == "linear":
        for name in LOG_ONLY:
            if _given(ctx, name):
                raise click.UsageError(f"{_flag(name)} applies to the log recursion only "
                                       "(add --recursion log)")
    if opts.get("share_passes") and opts.get("layout") != "folded":
        raise click.UsageError("--share-passes applies to the folded layout only (add --layout "
                               "folded)")
    if opts.get("exact") and not opts.get("vamps"):
        raise click.UsageError("--exact applies with --vamps K")
    if (opts.get("vamps") or opts.get("interval")) and _given(ctx, "layout"):
        raise click.UsageError("--vamps and --interval make their own (budgeted) layout: leave out "
                               "--layout")


def _check_program_options(ctx: click.Context, source: str, stored: dict) -> None:
    """Compile options given with a program file must not contradict how it was compiled."""
    for name in ROBOT_OPTIONS + ("verify",):
        if _given(ctx, name):
            raise click.UsageError(f"{_flag(name)} applies when compiling a robot file; {source} is "
                                   "a program file, already compiled")
    for name in COMPILE_OPTIONS:
        if name == "verify" or not _given(ctx, name):
            continue
        value = ctx.params[name]
        if stored.get(name) != value:
            raise click.UsageError(f"{_flag(name)} {value}: {source} was compiled with "
                                   f"{_flag(name)} {stored.get(name)}; compile options apply to robot "
                                   "files (recompile to change them)")


def _compile(robot, base, tip, lock, floating_base=False, until=None, **opts):
    from vampc import progress
    from vampc.compiler import STAGES, CompileOptions, compile_chain
    from vampc.robot import URDF_SUFFIXES, load_robot
    given = [flag for flag, v in (("--base", base), ("--tip", tip), ("--lock", lock)) if v]
    if given and Path(robot).suffix.lower() not in URDF_SUFFIXES:
        raise click.UsageError(f"{', '.join(given)} appl{'ies' if len(given) == 1 else 'y'} to URDF files only; {robot} is not a URDF "
                               "(a DH table is one chain)")
    with progress.stages(f"compiling {Path(robot).name}", ("load",) + STAGES) as stage:
        stage("load")
        chain = load_robot(robot, base=base, tip=tip, lock=_parse_lock(lock), floating=floating_base)
        return compile_chain(chain, CompileOptions(**opts), stage=stage, until=until)


class _Vampc(click.Group):
    """The command group: a usage error (a bad option or value, options that contradict each other)
    is one line on stderr, `vampc: error: ...` with the help to read, exit 2, like every other error."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, False, **extra)
        try:
            code = super().main(args, prog_name, complete_var, False, **extra)
        except click.UsageError as exc:
            if type(exc).__name__ == "NoArgsIsHelpError":      # `vampc` alone: the help
                click.echo(exc.ctx.get_help(), err=True)
                sys.exit(2)
            where = exc.ctx.command_path if exc.ctx is not None else "vampc"
            message = " ".join(exc.format_message().split())
            click.echo(f"vampc: error: {message} (see '{where} --help')", err=True)
            sys.exit(2)
        except click.ClickException as exc:
            exc.show()
            sys.exit(exc.exit_code)
        except click.Abort:
            click.echo("vampc: interrupted", err=True)
            sys.exit(1)
        sys.exit(code if isinstance(code, int) else 0)


@click.group(cls=_Vampc, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="vampc")
def main():
    """Compile a robot description into a program for a network of VAMPs (Lathrop, Parallelism in
    Manipulator Dynamics), emulate it bit-exactly, and report what it costs.

    ROBOT files: a Denavit-Hartenberg table (.yaml, .yml, .json) or a URDF (.urdf, .xml). Outputs
    never replace an input, a folder or a device, and a failed run leaves existing files as they
    were (README "Output files").
    """


@main.command()
@click.argument("robot", type=FilePath(dir_okay=False))
@click.option("-o", "--output", type=FilePath(dir_okay=False, allow_dash=True),
              help="Program file to write (default: ROBOT's name with .vamp.json, in the current "
              "folder; - for standard output).")
@click.option("--numbering", type=FilePath(dir_okay=False),
              help="Burned-in VAMP numbers, one per line, in logical VAMP order.")
@click.option("--dump-after", type=click.Choice(["graph", "schedule", "allocate", "emit"]),
              help="Print the IR that STAGE hands on as canonical text (graph; layout and schedule; "
              "network; programs and Program-Mode stream) and stop: no program file is written.")
@_compile_options
@_robot_options
@click.pass_context
@_handle_errors
def compile(ctx, robot, output, numbering, dump_after, base, tip, lock, **opts):
    """Compile ROBOT into a program file: dataflow graph, schedule, netlist, VAMP program words,
    Program-Mode stream and host I/O schedule."""
    from vampc.compiler import program_text
    from vampc.outputs import plan_outputs
    from vampc.program.file import write_program
    from vampc.textio import count
    _check_robot_options(ctx, opts)
    if dump_after:
        if output is not None:
            raise click.UsageError("--dump-after prints to standard output and writes no program "
                                   "file: leave out -o")
        from vampc.dump import dump_after as dump
        c = _compile(robot, base, tip, lock, numbering=numbering, until=dump_after, **opts)
        click.echo(dump(dump_after, c), nl=False)
        return
    out_path = output if output is not None else Path(robot).stem + ".vamp.json"
    out = plan_outputs([robot, numbering], {"-o": out_path}, stdout_ok=("-o",))["-o"]
    c = _compile(robot, base, tip, lock, numbering=numbering, **opts)
    write_program(program_text(c), out)
    s = c.schedule
    click.echo(f"{out.path}: {c.chain.n} joints, {c.graph.recursion} recursion, "
               f"{count(len(c.network.vamps), 'VAMP')}, latency {count(s.latency, 'flop')} ({s.mults} M + {s.adds} A"
               f"{f' + {s.waits} waiting' if s.waits else ''}), "
               f"interval {count(s.interval, 'flop')}", err=out.is_stdout)


@main.command()
@click.argument("source", type=FilePath(dir_okay=False))
@click.option("--format", "fmt", type=click.Choice(["text", "markdown", "json", "csv"]),
              default="text", show_default=True, help="text: aligned tables; markdown: for a design "
              "review; json: everything (schemas/report.schema.json); csv: with --tradeoff only.")
@click.option("--tradeoff", is_flag=True, help="Sweep VAMP budgets from the smallest network to one "
              "VAMP per op, beside the folded and systolic layouts: latency, interval, buffers and "
              "wiring per point, bounds and gaps, Pareto-optimal points marked.")
@click.option("--clock", metavar="F", help="Clock rate, one flop per tick (Hz, kHz, MHz, GHz: "
              "20MHz): adds latency in µs and torque sets per second to every figure.")
@click.option("--pins", type=click.IntRange(8, 1_000_000), metavar="N", help="Also count packages "
              "of N pins (beside the paper's 40).")
@click.option("--timing", type=FilePath(dir_okay=False), metavar="FILE.svg",
              help="Write the timing chart (Table III.2 style) as SVG.")
@click.option("--network", type=FilePath(dir_okay=False), metavar="FILE.svg",
              help="Write a drawing of the network (Figures III.1, IV.2, VI.3) as SVG.")
@click.option("--dot", type=FilePath(dir_okay=False), metavar="FILE.dot",
              help="Write the network and the dataflow graph as Graphviz digraphs.")
@click.option("--html", type=FilePath(dir_okay=False), metavar="FILE.html",
              help="Write one self-contained HTML page: the tables and both pictures inline.")
@click.option("--curve", type=FilePath(dir_okay=False), metavar="FILE.svg",
              help="With --tradeoff: write the trade-off curve as SVG (latency and interval "
              "against VAMPs, Pareto-optimal points marked, the folded and systolic layouts "
              "labelled).")
@_compile_options
@_robot_options
@click.pass_context
@_handle_errors
def report(ctx, source, fmt, tradeoff, clock, pins, timing, network, dot, html, curve, base, tip,
           lock, **opts):
    """Report flop counts, latency, VAMP, buffer and package counts for SOURCE beside the paper's
    (Table O.1, sections VI and VII): a robot file (compiled on the fly with the options given) or a
    program file written by `vampc compile` (its figures are recomputed from the file's graph,
    schedule and network). Pictures and pages go to the files named. With --tradeoff: the
    trade-off sweep instead."""
    from vampc.gcpause import gc_paused
    from vampc.outputs import plan_outputs
    if fmt == "csv" and not tradeoff:
        raise click.UsageError("--format csv applies to --tradeoff only")
    if tradeoff:
        for name in ("clock", "pins", "timing", "network", "dot", "html"):
            if _given(ctx, name):
                raise click.UsageError(f"{_flag(name)} does not apply to --tradeoff")
        return _tradeoff(ctx, source, fmt, curve, base, tip, lock, **opts)
    if curve is not None:
        raise click.UsageError("--curve applies with --tradeoff (it draws the trade-off sweep)")
    hz = _clock_hz(clock)
    outs = plan_outputs([source], {"--timing": timing, "--network": network, "--dot": dot,
                                   "--html": html})
    with gc_paused():       # millions of small acyclic objects for a big network; freed at exit
        c, figures, check = _report_compiled(ctx, source, base, tip, lock, **opts)
        try:
            from vampc.report.build import build_report
            rep = build_report(c, hz, pins, figures)
            content = _pictures(c, rep, outs)
        except BaseException:
            check.abandon()
            raise
        check.wait()        # a program that fails its static check gets no report and no file
        _write_pictures(outs, content)
    click.echo(_formatted(rep, fmt), nl=False)


def _clock_hz(text: str | None) -> float | None:
    """--clock as Hz; a bad value is one line and exit 2 (a usage error)."""
    if text is None:
        return None
    from vampc.report.clock import parse_clock
    try:
        return parse_clock(text)
    except ValueError as exc:
        click.echo(f"vampc: error: --clock {exc}", err=True)
        sys.exit(2)


def _formatted(rep: dict, fmt: str) -> str:
    if fmt == "json":
        return json.dumps(rep, indent=1, sort_keys=True) + "\n"
    from vampc.report.text import render, render_markdown
    return render_markdown(rep) if fmt == "markdown" else render(rep)


def _tradeoff(ctx, source, fmt, curve, base, tip, lock, **opts) -> None:
    from vampc import progress
    from vampc.compiler import CompileOptions
    from vampc.outputs import plan_outputs
    from vampc.report import tradeoff as tr
    from vampc.robot import load_robot
    from vampc.sniff import is_program
    for name in ("vamps", "interval", "exact", "layout", "share_passes"):
        if _given(ctx, name):
            raise click.UsageError(f"{_flag(name)} does not apply to --tradeoff, which sweeps the "
                                   "layouts and budgets itself")
    outs = plan_outputs([source], {"--curve": curve})
    if is_program(source):
        c, _, check = _program_compiled(ctx, source)
        check.wait()
        chain, options = c.chain, c.options
    else:
        _check_robot_options(ctx, opts)
        floating = opts.pop("floating_base", False)
        chain = load_robot(source, base=base, tip=tip, lock=_parse_lock(lock), floating=floating)
        options = CompileOptions(**opts)
    with progress.counter("trade-off", 1, unit="budget") as bar:
        rows = tr.tradeoff(chain, options, bar)
    if outs:
        from vampc.report.tradeoff_chart import curve_svg
        _write_pictures(outs, {"--curve": curve_svg(rows, f"{chain.name}: {options.recursion} "
                                                          f"recursion, {chain.n} joints")})
    if fmt == "json":
        click.echo(json.dumps({"robot": chain.name, "joints": chain.n,
                               "recursion": options.recursion, "points": rows}, indent=1))
    elif fmt == "csv":
        click.echo(tr.render_csv(rows), nl=False)
    else:
        click.echo(tr.render_text(rows), nl=False)


def _pictures(c, rep: dict, outs: dict) -> dict:
    """The content of every picture and page asked for."""
    if not outs:
        return {}
    from vampc.report import pictures
    return pictures.make(c, rep, set(outs))


def _write_pictures(outs: dict, content: dict) -> None:
    """Write every picture (each atomically); none is committed unless all were written."""
    from vampc.outputs import Pending
    pending = []
    try:
        for option, out in outs.items():
            pending.append(Pending(out, option.lstrip("-"), False))
            pending[-1].fh.write(content[option])
    except OSError as exc:
        for p in pending:
            p.discard()
        raise pending[-1].error(exc) from None
    except BaseException:
        for p in pending:
            p.discard()
        raise
    for p in pending:
        p.commit()


def _report_compiled(ctx, source, base, tip, lock, **opts):
    """The compiled IRs of a report's SOURCE — a program file's, checked, or a robot's — their
    summary figures when already made (None), and the program's static check, which may still be
    running (vampc.background: wait for it before showing anything)."""
    from vampc.background import Deferred
    from vampc.sniff import is_program
    if is_program(source):
        return _program_compiled(ctx, source)
    _check_robot_options(ctx, opts)
    return _compile(source, base, tip, lock, **opts), None, Deferred()


# Programs with more slots than this are statically checked in a forked process while the report
# is built (about a third of the work for a 512-joint log program).
BACKGROUND_CHECK_SLOTS = 20_000


def _program_compiled(ctx, source):
    """A program file's IRs, checked against each other and against its stored summary; their
    summary figures; and the static check that the network implements the graph (vampc.emulator),
    run in the background for a big program."""
    from vampc.program.document import compiled_from_doc
    from vampc.program.file import read_program
    from vampc.report.counts import summary
    doc = read_program(source)
    _check_program_options(ctx, source, doc["options"])
    c = compiled_from_doc(doc, source)
    from vampc.background import Deferred, in_background
    check = Deferred()
    if (doc["schedule"]["mult_latency"], doc["schedule"]["add_latency"]) == (1, 1):
        # decoded once: the report's IRs are the check's
        check = in_background(_static_check, doc, source, c,
                              inline=c.network.slot_count <= BACKGROUND_CHECK_SLOTS)
    fresh = json.loads(json.dumps(summary(c)))
    edited = sorted(k for k, v in doc["summary"].items() if k in fresh and fresh[k] != v)
    if edited:
        warnings.warn(VampcWarning(f"{source}: the stored summary disagrees with the file's graph, "
                                   f"schedule and network ({', '.join(edited)}): the file was "
                                   "edited; showing figures recomputed from them"), stacklevel=1)
    return c, fresh, check


def _static_check(doc: dict, source, c) -> None:
    """The emulator's static checks of a program file: the network implements the graph."""
    from vampc.emulator import check_program, loaded_from_doc
    check_program(loaded_from_doc(doc, source, decoded=(c.chain, c.graph, c.network, c.programs)))


@main.command()
@click.argument("source", type=FilePath(dir_okay=False))
@click.option("--trajectory", type=FilePath(dir_okay=False),
              help="States to run: CSV with header q1..qn,qd1..qdn,qdd1..qddn (optional leading t), "
              ".npy or .npz.")
@click.option("--random", "random_count", type=click.IntRange(1, 1 << 53), metavar="N",
              help="Run N random states (within the joint limits, else ±π, ±1 rad/s, ±1 rad/s²); "
              "drawn and run in chunks, so memory does not grow with N.")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Seed for "
              "--random and for the tick engine's random initial register contents.")
@click.option("--engine", type=click.Choice(["stream", "tick"]), default="stream", show_default=True,
              help="stream: vectorised over the trajectory; tick: one flop at a time from Program Mode "
              "(the hardware specification; slower). They agree bit for bit.")
@click.option("--check", is_flag=True, help="Compare every torque set with the reference Newton-Euler; "
              "exit 1 if any relative error exceeds 1e-9.")
@click.option("--vcd", type=FilePath(dir_okay=False, allow_dash=True), help="Tick engine: write "
              "every VAMP's Result as a VCD waveform (GTKWave).")
@click.option("-o", "--output", type=FilePath(dir_okay=False, allow_dash=True),
              help="Write torques as CSV: a t column if the trajectory has one, then tau_<joint name> "
              "per joint (N·m revolute, N prismatic); - for standard output.")
@click.option("--save-states", type=FilePath(dir_okay=False, allow_dash=True), metavar="FILE",
              help="Write the states run as a trajectory CSV (the --trajectory format), to pair "
              "torques with their inputs.")
@click.option("--write-failed", is_flag=True, help="With --check: write -o even when the check "
              "fails and the file exists (by default a failed check never replaces an existing "
              "torque file).")
@click.option("--allow-out-of-limits", is_flag=True, help="Run states outside the joint limits.")
@_compile_options
@_robot_options
@click.pass_context
@_handle_errors
def emulate(ctx, source, trajectory, random_count, seed, engine, check, vcd, output, save_states,
            write_failed, allow_out_of_limits, base, tip, lock, **opts):
    """Run a program file (or a robot file, compiled on the fly) in the VAMP network emulator and
    return the joint torques it computes."""
    from vampc.emulator.driver import States, run
    from vampc.emulator.host import check_limits, read_trajectory
    from vampc.outputs import plan_outputs
    begun = time.perf_counter()
    _check_emulate_usage(ctx, trajectory, random_count, engine, vcd, save_states, output,
                         write_failed, check)
    outs = plan_outputs([source, trajectory], {"-o": output, "--vcd": vcd,
                                               "--save-states": save_states},
                        stdout_ok=("-o", "--vcd", "--save-states"))
    ld = _loaded(ctx, source, base, tip, lock, **opts)
    if trajectory:
        traj = read_trajectory(trajectory, ld.chain)
        if not allow_out_of_limits:
            check_limits(ld.chain, traj, trajectory)
        states = States(traj.count, traj)
    else:
        states = States.random(random_count, seed)
    sinks = _Sinks(ld, outs, has_t=bool(trajectory) and traj.t is not None)
    info = any(o.is_stdout for o in outs.values())       # keep stdout for the data
    from vampc import progress
    try:
        with progress.counter(f"{engine} engine", states.count) as bar:
            outcome = run(ld, states, engine=engine, seed=seed, vcd=sinks.vcd, check=check,
                          sink=sinks.chunk, progress=bar)
        sinks.finish_vcd()
    except BaseException:
        sinks.discard()
        raise
    _print_emulation(outcome, time.perf_counter() - begun, info)
    ok = outcome.check is None or outcome.check.ok
    sinks.finish(ok, write_failed, info)
    if outcome.check is not None:
        _report_check(outcome.check, info)


def _check_emulate_usage(ctx, trajectory, random_count, engine, vcd, save_states, output,
                         write_failed, check) -> None:
    if (trajectory is None) == (random_count is None):
        raise click.UsageError("give exactly one of --trajectory FILE or --random N")
    if vcd and engine != "tick":
        raise click.UsageError("--vcd needs --engine tick")
    if _given(ctx, "seed") and random_count is None and engine != "tick":
        raise click.UsageError("--seed applies to --random and to the tick engine")
    if write_failed and not (check and output):
        raise click.UsageError("--write-failed applies with --check and -o")
    if save_states and Path(save_states).suffix.lower() in (".npy", ".npz"):
        raise click.UsageError("--save-states writes a CSV trajectory: give a .csv file name")


class _Sinks:
    """The emulate command's output files, written as the chunks of a run arrive."""

    def __init__(self, ld, outs, has_t: bool):
        from vampc.emulator.trajectory import csv_line, header, torque_columns
        from vampc.outputs import Pending
        self.ld, self.outs = ld, outs
        self.tau = Pending(outs["-o"], "torques", False) if "-o" in outs else None
        self.states = Pending(outs["--save-states"], "states", False) if "--save-states" in outs \
            else None
        self.vcd_out = Pending(outs["--vcd"], "waveform", False) if "--vcd" in outs else None
        self.vcd = _Guarded(_vcd_writer(self.vcd_out.fh, ld), self.vcd_out) if self.vcd_out \
            else None
        t = ["t"] if has_t else []
        floating = ld.chain.floating
        self._write(self.tau, lambda fh: fh.write(csv_line(t + torque_columns(
            (j.name for j in ld.chain.joints), floating))))
        self._write(self.states, lambda fh: fh.write(csv_line(t + header(ld.chain.n, floating))))

    def _write(self, pending, action) -> None:
        if pending is None:
            return
        try:
            action(pending.fh)
        except OSError as exc:
            self.discard()
            raise pending.error(exc) from None

    def chunk(self, traj, tau) -> None:
        """One chunk's torques and states."""
        from vampc.emulator.trajectory import format_rows
        self._write(self.tau, lambda fh: fh.write(format_rows(traj.t, tau)))
        self._write(self.states, lambda fh: fh.write(format_rows(traj.t, traj.q, traj.qd, traj.qdd,
                                                                 traj.base)))

    def finish_vcd(self) -> None:
        """The waveform is complete: put it in place."""
        if self.vcd is not None:
            self.vcd.close()
            self.vcd_out.commit()

    def finish(self, ok: bool, write_failed: bool, info: bool) -> None:
        """Put the states and torques in place; torques that failed their check never replace an
        existing file unless asked (--write-failed)."""
        if self.states is not None:
            self.states.commit()
        if self.tau is None:
            return
        out = self.tau.out
        keep_old = not ok and not write_failed and out.kind == "file" and out.target.exists()
        if keep_old:
            self.tau.discard()
            click.echo(f"torques NOT written: the check failed and {out.path} exists (it is "
                       "unchanged; --write-failed replaces it anyway)", err=True)
            return
        self.tau.commit()
        if not ok:
            click.echo(f"torques written to {out.path} although the check failed", err=True)

    def discard(self) -> None:
        """A failed run: drop every output (existing files stay as they were)."""
        for pending in (self.tau, self.states, self.vcd_out):
            if pending is not None:
                pending.discard()


class _Guarded:
    """A VCD writer whose failed writes (a full disk) become the output's one-line error."""

    def __init__(self, writer, pending):
        self.writer, self.pending = writer, pending

    def sample(self, tick, values) -> None:
        """As VcdWriter.sample."""
        try:
            self.writer.sample(tick, values)
        except OSError as exc:
            raise self.pending.error(exc) from None

    def close(self) -> None:
        """As VcdWriter.close."""
        try:
            self.writer.close()
        except OSError as exc:
            raise self.pending.error(exc) from None


def _loaded(ctx, source, base, tip, lock, **opts):
    from vampc.emulator import load_program
    from vampc.emulator.load import loaded_from_compiled
    from vampc.sniff import is_program
    if is_program(source):
        ld = load_program(source)
        _check_program_options(ctx, source, ld.options)
        return ld
    _check_robot_options(ctx, opts)
    return loaded_from_compiled(_compile(source, base, tip, lock, **opts), source)


def _vcd_writer(stream, ld):
    from vampc.emulator.vcd import VcdWriter, vamp_names
    return VcdWriter(stream, vamp_names(ld))


def _print_emulation(r, whole_seconds: float, err: bool) -> None:
    rate = r.count / r.engine_seconds if r.engine_seconds > 0 else float("inf")
    click.echo(f"{r.engine} engine: {r.count} torque sets; program load {r.load_ticks} ticks; first "
               f"set after {r.first_tick} flops, then one every {r.interval} flops; emulated time "
               f"{r.emulated_flops} flops; engine wall time {r.engine_seconds:.3f} s ({rate:,.0f} "
               f"sets/s); whole command {whole_seconds:.3f} s", err=err)


def _report_check(res, err: bool) -> None:
    verdict = "OK" if res.ok else "FAILED"
    click.echo(f"check against reference RNEA: max abs error {res.max_abs:.3e}, max relative error "
               f"{res.max_rel:.3e} (set {res.worst_row + 1}), tolerance 1e-9: {verdict}", err=err)
    if not res.ok:
        sys.exit(1)


if __name__ == "__main__":  # pragma: no cover
    main()
