"""The `vampc` command line: a thin layer that parses options, calls the library and formats output.

User errors (VampcError) print one line `vampc: error: ...` and exit 1; usage errors exit 2 (click);
anything else is a vampc bug: it is shown in full with a request to report it, and exits 3.
"""
from __future__ import annotations

import functools
import json
import sys
from pathlib import Path

import click

from vampc.errors import VampcError


def _robot_options(f):
    """Options shared by every command that reads a robot file."""
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
        click.option("--verify/--no-verify", default=True, show_default=True,
                     help="Check every IR's invariants at each stage boundary."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def _parse_lock(items) -> dict[str, float]:
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep or not name.strip():
            raise click.BadParameter(f"{item!r} is not JOINT=VALUE", param_hint="--lock")
    return out


def _handle_errors(f):
    @functools.wraps(f)
    def wrapper(*args, **kwargs):
        try:
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


def _compile(robot, base, tip, lock, **opts):
    from vampc.compiler import CompileOptions, compile_chain
    from vampc.robot import load_robot
    chain = load_robot(robot, base=base, tip=tip, lock=_parse_lock(lock))
    return compile_chain(chain, CompileOptions(**opts))


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="vampc")
def main():
    """Compile a robot description into a program for a network of VAMPs (Lathrop, Parallelism in
    Manipulator Dynamics), emulate it bit-exactly, and report what it costs.

    ROBOT files: a Denavit-Hartenberg table (.yaml, .yml, .json) or a URDF (.urdf, .xml).
    """


@main.command()
@click.argument("robot", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Program file to write (default: ROBOT's name with .vamp.json, in the current folder).")
@click.option("--numbering", type=click.Path(dir_okay=False),
              help="Burned-in VAMP numbers, one per line, in logical VAMP order.")
@_compile_options
@_robot_options
@_handle_errors
def compile(robot, output, numbering, base, tip, lock, **opts):
    """Compile ROBOT into a program file: dataflow graph, schedule, netlist, VAMP program words,
    Program-Mode stream and host I/O schedule."""
    from vampc.compiler import program_text
    from vampc.program.file import write_program
    c = _compile(robot, base, tip, lock, numbering=numbering, **opts)
    out = Path(output) if output else Path(Path(robot).stem + ".vamp.json")
    write_program(program_text(c), out)
    s = c.schedule
    click.echo(f"{out}: {c.chain.n} joints, {c.graph.recursion} recursion, {len(c.network.vamps)} "
               f"VAMPs, latency {s.latency} flops ({s.mults} M + {s.adds} A), interval {s.interval} flops")


@main.command()
@click.argument("source", type=click.Path(dir_okay=False))
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True)
@_compile_options
@_robot_options
@_handle_errors
def report(source, fmt, base, tip, lock, **opts):
    """Report flop counts, latency, VAMP, buffer and package counts for SOURCE: a robot file (compiled
    on the fly with the options given) or a program file written by `vampc compile`."""
    rep = _report(source, base, tip, lock, **opts)
    if fmt == "json":
        click.echo(json.dumps(rep, indent=1, sort_keys=True))
    else:
        from vampc.report.text import render
        click.echo(render(rep), nl=False)


def _report(source, base, tip, lock, **opts) -> dict:
    if _is_program(source):
        from vampc.program.file import read_program
        return read_program(source)["summary"]
    from vampc.report.counts import summary
    c = _compile(source, base, tip, lock, **opts)
    rep = summary(c)
    if c.graph.recursion == "log":
        from vampc.report.compare import compare_prefixes
        rep["prefix_comparison"] = compare_prefixes(c.chain, c.options)
    return rep


@main.command()
@click.argument("source", type=click.Path(dir_okay=False))
@click.option("--trajectory", type=click.Path(dir_okay=False),
              help="States to run: CSV with header q1..qn,qd1..qdn,qdd1..qddn (optional leading t), "
              ".npy or .npz.")
@click.option("--random", "random_count", type=int, metavar="N",
              help="Run N random states (within the joint limits, else ±π, ±1 rad/s, ±1 rad/s²).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed for --random and for "
              "the tick engine's random initial register contents.")
@click.option("--engine", type=click.Choice(["stream", "tick"]), default="stream", show_default=True,
              help="stream: vectorised over the trajectory; tick: one flop at a time from Program Mode "
              "(the hardware specification; slower). They agree bit for bit.")
@click.option("--check", is_flag=True, help="Compare every torque set with the reference Newton-Euler; "
              "exit 1 if any relative error exceeds 1e-9.")
@click.option("--vcd", type=click.Path(dir_okay=False), help="Tick engine: write every VAMP's Result "
              "as a VCD waveform (GTKWave).")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Write torques as CSV "
              "(header tau1..taun).")
@click.option("--allow-out-of-limits", is_flag=True, help="Run states outside the joint limits.")
@_compile_options
@_robot_options
@_handle_errors
def emulate(source, trajectory, random_count, seed, engine, check, vcd, output, allow_out_of_limits,
            base, tip, lock, **opts):
    """Run a program file (or a robot file, compiled on the fly) in the VAMP network emulator and
    return the joint torques it computes."""
    from vampc.emulator import emulate as run
    from vampc.emulator.host import check_limits, check_torques, random_trajectory, read_trajectory
    if (trajectory is None) == (random_count is None):
        raise click.UsageError("give exactly one of --trajectory FILE or --random N")
    if vcd and engine != "tick":
        raise click.UsageError("--vcd needs --engine tick")
    ld = _loaded(source, base, tip, lock, **opts)
    if trajectory:
        traj = read_trajectory(trajectory, ld.chain)
        if not allow_out_of_limits:
            check_limits(ld.chain, traj, trajectory)
    else:
        traj = random_trajectory(ld.chain, random_count, seed)
    writer = _vcd_writer(vcd, ld)
    ok = False
    try:
        with _Progress(f"{engine} engine") as progress:
            result = run(ld, traj, engine=engine, seed=seed, vcd=writer, progress=progress)
        ok = True
    finally:
        if writer is not None:
            writer.close(ok)
    _print_emulation(result, traj.count)
    if output:
        from vampc.emulator.trajectory import write_torques
        write_torques(output, result.tau)
    if check:
        _report_check(check_torques(ld.chain, traj, result.tau))


def _loaded(source, base, tip, lock, **opts):
    from vampc.emulator import load_program, loaded_from_doc
    if _is_program(source):
        return load_program(source)
    from vampc.compiler import program_document
    return loaded_from_doc(program_document(_compile(source, base, tip, lock, **opts)), source)


def _vcd_writer(path, ld):
    if not path:
        return None
    from vampc.emulator.vcd import VcdWriter
    nodes = ld.doc["graph"]["nodes"]
    names = [f"vamp{ld.numbers[v.index]}_{nodes[v.node]['section']}{nodes[v.node]['group']}_"
             f"{nodes[v.node]['name']}" for v in ld.net.vamps]
    try:
        return VcdWriter(path, names)
    except OSError as exc:
        raise VampcError(f"{path}: cannot write waveform: {exc.strerror}") from None


def _print_emulation(r, count: int) -> None:
    rate = count / r.wall_seconds if r.wall_seconds > 0 else float("inf")
    click.echo(f"{r.engine} engine: {count} torque sets; program load {r.load_ticks} ticks; first "
               f"set after {r.first_tick} flops, then one every {r.interval} flops; emulated time "
               f"{r.emulated_flops} flops; wall time {r.wall_seconds:.3f} s ({rate:,.0f} sets/s)")


def _report_check(res) -> None:
    verdict = "OK" if res.ok else "FAILED"
    click.echo(f"check against reference RNEA: max abs error {res.max_abs:.3e}, max relative error "
               f"{res.max_rel:.3e} (set {res.worst_row + 1}), tolerance 1e-9: {verdict}")
    if not res.ok:
        sys.exit(1)


class _Progress:
    """A progress line on stderr, shown only for runs longer than two seconds and only on a terminal
    (or when VAMPC_PROGRESS=1)."""

    def __init__(self, label: str):
        import os
        import time
        self.label, self.clock = label, time.monotonic
        self.enabled = sys.stderr.isatty() or os.environ.get("VAMPC_PROGRESS") == "1"
        self.t0 = self.last = self.clock()
        self.shown = False

    def __enter__(self):
        return self

    def __call__(self, done: int, total: int) -> None:
        now = self.clock()
        if not self.enabled or now - self.t0 < 2.0 or now - self.last < 0.2:
            return
        self.last, self.shown = now, True
        pct = 100.0 * done / max(total, 1)
        sys.stderr.write(f"\r{self.label}: {pct:5.1f}% ({done}/{total}), {now - self.t0:.0f} s")
        sys.stderr.flush()

    def __exit__(self, *exc):
        if self.shown:
            sys.stderr.write("\n")


def _is_program(path: str) -> bool:
    return path.endswith(".vamp.json")


if __name__ == "__main__":  # pragma: no cover
    main()
