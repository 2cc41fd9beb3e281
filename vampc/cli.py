"""The `vampc` command line: a thin layer that parses options, calls the library and formats output.

User errors (VampcError) print one line `vampc: error: ...` and exit 1; usage errors exit 2 (click);
anything else is a vampc bug and is shown in full with a request to report it.
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
    from vampc.compiler import program_document
    from vampc.program.file import write_program
    c = _compile(robot, base, tip, lock, numbering=numbering, **opts)
    out = Path(output) if output else Path(Path(robot).name.split(".")[0] + ".vamp.json")
    write_program(program_document(c), out)
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
        rep["prefix"] = c.options.prefix
    return rep


def _is_program(path: str) -> bool:
    return path.endswith(".vamp.json")


if __name__ == "__main__":  # pragma: no cover
    main()
