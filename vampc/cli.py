"""The `vampc` command line: parses options into the option objects of vampc.options, calls the
commands of vampc.commands and prints what they return.

User errors (VampcError) print one line `vampc: error: ...` and exit 1; usage errors (VampcUsageError,
click's own) the same line with the help to read, exit 2; warnings (VampcWarning) one line `vampc:
warning: ...` and the work goes on; anything else is a vampc bug: shown in full with a request to
report it, exit 3.
"""
from __future__ import annotations

import contextlib
import functools
import signal
import sys
import warnings

import click

from vampc import progress
from vampc.cliopts import FilePath, build, options_of
from vampc.errors import (
    Terminated,
    VampcError,
    VampcUsageError,
    VampcWarning,
    begin,
    kept_note,
    raise_if_terminated,
    signalled_while_parsing,
    stopping,
    terminate_like_interrupt,
)
from vampc.options import (
    PRECISION_REFUSES,
    RTL_HELPS,
    RTL_UNRENDERED,
    CompileCommand,
    CompileOptions,
    EmulateOptions,
    FaultsOptions,
    LookaheadOptions,
    PrecisionOptions,
    ReportOptions,
    RobotOptions,
    RtlOptions,
)
from vampc.outputs import (
    WholeText,
    command_begins,
    discard_all,
    need_stdout,
    result_on_stdout,
    silence,
    stderr_apart,
    unencodable,
)


def handle_errors(f):
    """One line per error, the exit status of its kind (see the module docstring)."""
    @functools.wraps(f)
    def wrapper(*args, **kwargs):
        command_begins()
        progress.begin()
        try:
            begin()                            # (a signal while the options were parsed: now)
            with warnings.catch_warnings():
                warnings.simplefilter("always", VampcWarning)
                warnings.showwarning = _show_warning
                done = f(*args, **kwargs)
                raise_if_terminated()          # a Ctrl-C swallowed after the last output
                return done
        except VampcUsageError as exc:
            raise click.UsageError(str(exc)) from None
        except VampcError as exc:
            _status(f"vampc: error: {unbroken(str(exc))}")
            sys.exit(1)
        except Terminated as exc:
            _end_on_signal(exc.signum, _kept(exc))
        except KeyboardInterrupt as exc:
            _end_on_signal(signal.SIGINT, _kept(exc))
        except (click.exceptions.Exit, click.ClickException, SystemExit):
            raise
        except MemoryError:
            discard_all()
            _status("vampc: error: out of memory: this run needs more memory than the process "
                    "may have (fewer states or a smaller robot at a time, or more memory); an "
                    "output not finished is not written")
            sys.exit(1)
        except Exception as exc:
            short = _out_of_resources(exc)
            if short is not None:
                discard_all()
                _status(f"vampc: error: {short}; an output not finished is not written")
                sys.exit(1)
            import traceback
            traceback.print_exc()
            _status("vampc: internal error: this is a bug in vampc, not in your input; please "
                    "report it with the command line and the input file")
            sys.exit(3)
        finally:
            # a check still running beside the command, which ended early (a SIGTERM during
            # report --tradeoff left it running, orphaned: a file-safety audit); the module is
            # loaded only where a check was started
            if "vampc.background" in sys.modules:
                sys.modules["vampc.background"].abandon_all()
            progress.end()
    return wrapper


_WARNING: list[bool] = []        # a warning being said (a warning raised while saying it: once)


def _stderr_apart(group, argv: list[str]) -> None:
    """vampc.outputs.stderr_apart on the files the command line gives, found before it is parsed
    (a usage error is said too): the command's source and the values of its file options only
    (every word had been compared, and `--recursion log 2> log` was refused: a review's find)."""
    at = next((k for k, t in enumerate(argv) if t in group.commands), None)
    if at is None:
        return
    cmd = group.commands[argv[at]]
    files = {o for p in cmd.params if isinstance(p, click.Option) and isinstance(p.type, FilePath)
             for o in p.opts}
    valued = {o for p in cmd.params if isinstance(p, click.Option) and not p.is_flag
              and not p.count for o in p.opts}
    given: list[tuple[str, str]] = []          # (how the command line gives it, the file name)
    rest = iter(argv[at + 1:])
    for token in rest:
        if token == "--":
            given += [("", t) for t in rest]
            break
        option, eq, value = token.partition("=")
        if token.startswith("--") and eq:
            if option in files:
                given.append((option, value))
        elif token in valued:
            value = next(rest, "")
            if token in files:
                given.append((token, value))
        elif token.startswith("-") and not token.startswith("--") and len(token) > 2 and \
                token[:2] in files:                                  # (-oFILE)
            given.append((token[:2], token[2:]))
        elif not token.startswith("-") or token == "-":
            given.append(("", token))
    stderr_apart(given)


def _status(text: str) -> None:
    """A run's last line on standard error (its error, or that it was stopped): one that standard
    error cannot take is dropped, and the exit status says how the run ended (a full standard
    error turned a usage error's 2, or a signal's 143, into 1: a review's find)."""
    with contextlib.suppress(OSError, ValueError):
        click.echo(text, err=True)


def _out_of_resources(exc: BaseException) -> str | None:
    """What the system would not give the run, said in a line, where an exception (or one it was
    raised from) is the system saying so: no thread could be started (under `ulimit -v` a thread
    pool's submit raised RuntimeError), no more files could be opened (`ulimit -n`: the pipes of a
    worker pool), no process could be made; each was a traceback and "internal error", exit 3 (a
    CI engineer's finds). None for anything else."""
    import errno
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:      # (raised from: not a bug met while
        seen.add(id(exc))                               # handling one, which is shown in full)
        if isinstance(exc, RuntimeError) and "can't start new thread" in str(exc):
            return ("cannot start a thread: the system refused one (out of memory under "
                    "`ulimit -v`, or the limit on processes and threads, `ulimit -u`)")
        if isinstance(exc, OSError) and exc.errno in (errno.EMFILE, errno.ENFILE):
            return "too many open files: the process may open no more (`ulimit -n`)"
        if isinstance(exc, OSError) and exc.filename is None and (
                exc.errno == errno.ENOMEM or exc.errno == errno.EAGAIN and _making_a_process(exc)):
            return (f"the system refused the run a resource ({exc.strerror or exc}): out of "
                    "memory, or a limit on processes (`ulimit -v`, `ulimit -u`)")
        exc = exc.__cause__
    return None


def _making_a_process(exc: BaseException) -> bool:
    """Whether `exc` was raised making a process (a worker pool's fork, a tool's spawn): there
    EAGAIN is the system's limit on processes; elsewhere it is non-blocking I/O's 'try again'."""
    tb = exc.__traceback__
    while tb is not None:
        code = tb.tb_frame.f_code
        if code.co_name in ("_launch", "_execute_child", "fork", "_fork_exec", "posix_spawn"):
            return True
        tb = tb.tb_next
    return False


def _end_on_signal(signum: int, kept: str = "") -> None:
    """End the run as a SIGTERM, SIGHUP or Ctrl-C ends it: further signals ignored, every output
    being written removed, its one line (and what it kept), exit status 128 + the signal's number."""
    stopping()
    discard_all()
    _status(("vampc: interrupted" if signum == signal.SIGINT
             else f"vampc: terminated ({signal.Signals(signum).name})") + kept)
    sys.exit(128 + signum)


def _end_if_signalled() -> None:
    """A SIGTERM, SIGHUP or Ctrl-C that came while the command line was parsed, and no command
    began to raise it (help was printed, or the line was a usage error): the run ends as that
    signal ends a command."""
    signum = signalled_while_parsing()
    if signum is not None:
        _end_on_signal(signum)


def _kept(exc: BaseException) -> str:
    """What an interrupted command kept, where it says so (`exc.note`: a fault campaign's runs)."""
    note = getattr(exc, "note", "") or kept_note()
    return f"; {note}" if note else ""


def unbroken(text: str) -> str:
    """An error or warning on one line: a line break in it (a file name holding one, as the user
    gave it) written as \\n or \\r (`-o $'nodir\\nx/a.csv'` gave an error of three lines: a
    file-safety audit)."""
    return text.replace("\r", "\\r").replace("\n", "\\n")


_WHERE = {"client": "here", "scheduler": "on the scheduler", "workers": "on the workers"}


def _library_text(category, message) -> str:
    """A library's warning on one line: its line breaks are layout, not a file name's (Dask's
    version table came out as one line of literal \\n, a new user's find), so they are spaces,
    and Dask's table of packages whose versions differ is said in words."""
    text = str(message)
    if category.__name__ == "VersionMismatchWarning":
        table, _, notes = text.partition("Notes:")
        rows = [[c.strip() for c in line.strip().strip("|").split("|")]
                for line in table.splitlines() if line.strip().startswith("|")]
        if len(rows) > 1 and rows[0][:1] == ["Package"]:
            heads = [h.lower() for h in rows[0][1:]]
            said, workers_differ = [], False
            for pkg, *values in rows[1:]:
                got = dict(zip(heads, values))
                workers_differ |= got.get("workers") not in (got.get("client"), "None")
                said.append(f"{pkg} " + ", ".join(_version(v, h) for h, v in got.items()))
            return ("the cluster's Python packages are not this Python's (" + "; ".join(said) + ")"
                    + (": vampc's tasks run on the workers, which need vampc and what it needs, as "
                       "installed here" if workers_differ else "")
                    + (f"; Dask's notes: {' '.join(notes.split())}" if notes.strip() else ""))
    return " ".join(text.split())


def _version(value: str, where: str) -> str:
    """One cell of Dask's version table in words, with where it is: workers of several versions
    ({'1.25', '1.26'}), a package missing, no worker at all (None in the workers' column)."""
    if value == "None" and where == "workers":
        return "no worker to ask"
    if value.startswith("{") and value.endswith("}"):
        value = " or ".join(v.strip().strip("'\"") for v in value[1:-1].split(","))
    return f"{'missing' if value == 'MISSING' else value} {_WHERE.get(where, 'for ' + where)}"


def _show_warning(message, category, *rest):
    """One line on stderr (through say: a reader gone drops it, the run goes on). A warning raised
    while one is said is dropped: click 8.5 warned of get_text_stream inside say(), whose warning
    was said through say() again, without end (every command an internal error in a fresh
    install)."""
    if _WARNING:
        return
    _WARNING.append(True)
    try:
        if issubclass(category, VampcWarning):
            say(f"vampc: warning: {unbroken(str(message))}", err=True)
        else:   # a library's own warning (numpy's, say): not ours to silence, but one line
            say(f"vampc: warning: {category.__name__}: {_library_text(category, message)}", err=True)
    finally:
        _WARNING.clear()


def say(text: str, err: bool = False, nl: bool = True) -> None:
    """Print a command's text (to stderr when stdout carries data). A stream that cannot take the
    command's result (a reader gone, a full disk) is the command's one-line error. Lines printed
    beside the files a command writes (a summary) whose reader went away (`vampc emulate ... -o
    tau.csv | head -1`) are dropped, as with standard output closed: the files are still written
    and the exit status is the run's. Every byte is written or that is the error: a write the
    stream took only part of (a file-size limit reached, Python unbuffered) is not a result cut
    short with exit status 0. A Ctrl-C or signal whose exception was swallowed on the way (in a
    finaliser) is raised again first."""
    raise_if_terminated()
    name = "stderr" if err else "stdout"
    if getattr(sys, name) is None:      # (closed: dropped, as click.echo drops it; need_stdout has
        return                          # refused a result before any work)
    try:
        with progress.aside():
            # (the standard stream itself, as click.echo takes it on a sound locale: click 8.5
            # deprecates get_text_stream, and its warning, said through say(), recursed)
            stream = getattr(sys, name)
            try:
                click.echo(text, file=WholeText(stream), nl=nl)
            except UnicodeEncodeError as exc:
                # an encoding that cannot hold τ or µ (PYTHONIOENCODING=latin-1): the report was an
                # internal error. A message is said with escapes; a result is refused, whole
                if not err and result_on_stdout():
                    raise unencodable(exc) from None
                escaped = text.encode(exc.encoding, "backslashreplace").decode(exc.encoding)
                click.echo(escaped, file=WholeText(stream), nl=nl)
    except OSError as exc:
        if err:
            # standard error that cannot be written (its reader gone, read-only, full): its lines
            # are dropped and the run goes on, its exit status saying how it ended (a warning had
            # failed the run with exit 1, no output and nothing said: a CI user's find); one full
            # for now (non-blocking) drops this line alone
            if not isinstance(exc, (BlockingIOError, InterruptedError)):
                silence(sys.stderr)
            return
        if isinstance(exc, BrokenPipeError):       # nothing more reaches it, at exit either
            silence(sys.stdout)
            if not result_on_stdout():
                return
        elif not result_on_stdout():
            # a summary line standard output cannot take (> /dev/full): dropped, said once on
            # standard error; the files are written (the summary comes once they are) and the
            # exit status is the run's (it was exit 1 beside files already replaced: a new user's)
            silence(sys.stdout)
            say(f"vampc: warning: standard output cannot take the summary lines "
                f"({exc.strerror or exc}): they are dropped; files are written as without them",
                err=True)
            return
        raise VampcError(f"cannot write to standard output: {exc.strerror or exc}") from None


def _encodable(text: str) -> str:
    """`text` as standard output's encoding can hold it: a character it cannot (⌈, τ under a
    Latin-1 or ASCII locale) as its backslash escape. Every command's --help had been a traceback
    there (a CI user's find); a result is refused whole instead (say)."""
    encoding = getattr(sys.stdout, "encoding", None) or "utf-8"
    try:
        text.encode(encoding)
    except UnicodeEncodeError:
        return text.encode(encoding, "backslashreplace").decode(encoding)
    except LookupError:
        pass
    return text


class _Command(click.Command):
    """A vampc command: an option that takes one value given twice is a usage error (click keeps
    the last, and `--limits a.csv --limits b.csv` dropped a.csv without a word; options that take
    several, such as --fault and --lock, say so in their help). Its help is written as standard
    output can hold it (_encodable)."""

    def get_help(self, ctx) -> str:
        return _encodable(super().get_help(ctx))

    def make_parser(self, ctx):
        parser = super().make_parser(ctx)
        parse = parser.parse_args

        def once(args):
            opts, rest, order = parse(args)
            seen = set()
            for param in order:
                if isinstance(param, click.Option) and not param.multiple and not param.count:
                    if param.name in seen:
                        names = " / ".join(param.opts + param.secondary_opts)
                        raise click.UsageError(f"{names} given more than once: give it once",
                                               ctx)
                    seen.add(param.name)
            return opts, rest, order
        parser.parse_args = once
        return parser


class _Vampc(click.Group):
    """The command group: a usage error is one line on stderr, `vampc: error: ...` with the help to
    read, exit 2, like every other error."""

    command_class = _Command

    def get_help(self, ctx) -> str:
        return _encodable(super().get_help(ctx))

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, False, **extra)
        _stderr_apart(self, sys.argv[1:] if args is None else list(args))
        restore = terminate_like_interrupt()
        try:
            try:
                code = super().main(args, prog_name, complete_var, False, **extra)
            finally:
                _end_if_signalled()      # (however parsing ended: help, a usage error, an abort)
        except click.UsageError as exc:
            if type(exc).__name__ == "NoArgsIsHelpError":      # `vampc` alone: the help
                click.echo(exc.ctx.get_help(), err=True)
                sys.exit(2)
            where = exc.ctx.command_path if exc.ctx is not None else "vampc"
            message = " ".join(exc.format_message().split())
            if isinstance(exc, click.NoSuchOption) and exc.ctx is not None:
                message = self._taken_elsewhere(exc, where) or message
            _status(f"vampc: error: {message} (see '{where} --help')")
            sys.exit(2)
        except click.ClickException as exc:
            exc.show()
            sys.exit(exc.exit_code)
        except click.Abort as exc:
            stopped = exc.__cause__ or exc.__context__
            if isinstance(stopped, KeyboardInterrupt):
                _end_on_signal(getattr(stopped, "signum", signal.SIGINT))
            _status("vampc: interrupted")
            sys.exit(1)
        finally:
            restore()
        sys.exit(code if isinstance(code, int) else 0)

    def _taken_elsewhere(self, exc, where: str) -> str | None:
        """An unknown option that another command takes, said so instead of click's guesses
        (`vampc compile --clock` was asked "Did you mean '--lock'?", `vampc precision --check`
        offered --check-cycles, which precision refuses: a new user's find)."""
        takers = [name for name, cmd in sorted(self.commands.items())
                  if cmd is not exc.ctx.command and any(exc.option_name in p.opts + p.secondary_opts
                                                        for p in cmd.params)]
        if not takers:
            return None
        names = takers[0] if len(takers) == 1 else f"{', '.join(takers[:-1])} and {takers[-1]}"
        root = exc.ctx.find_root().command_path      # (vampc, or python -m vampc as run)
        return (f"No such option '{exc.option_name}' for {where}: it is an option of {root} "
                f"{names}")


@click.group(cls=_Vampc, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="vampc")
def main():
    """Compile a robot description into a program for a network of VAMPs (Lathrop, Parallelism in
    Manipulator Dynamics), emulate it bit-exactly, and report what it costs.

    ROBOT files: a Denavit-Hartenberg table (.yaml, .yml, .json), a URDF (.urdf, .xml) or a MuJoCo
    MJCF model (.xml with a <mujoco> root; pip install "vampc[mjcf]"). Outputs
    never replace an input, a folder or a device, and a failed run leaves existing files as they
    were (README "Output files").
    """


@main.command(short_help="Compile a robot file into a program file for a network of VAMPs.")
@click.argument("robot", type=FilePath())
@options_of(CompileCommand, CompileOptions, RobotOptions)
@click.pass_context
@handle_errors
def compile(ctx, robot, **params):
    """Compile ROBOT into a program file: dataflow graph, schedule, netlist, VAMP program words,
    Program-Mode stream and host I/O schedule."""
    from vampc.commands import compile_command
    if params.get("dump_after"):                # (the IR's text is the result)
        need_stdout("vampc compile --dump-after")
    dump = compile_command(robot, build(CompileCommand, ctx, params),
                           build(CompileOptions, ctx, params), build(RobotOptions, ctx, params), say)
    if dump is not None:
        say(dump, nl=False)


@main.command(short_help="Run a program (or a robot file) in the emulator: joint torques.")
@click.argument("source", type=FilePath())
@options_of(EmulateOptions, CompileOptions, RobotOptions)
@click.pass_context
@handle_errors
def emulate(ctx, source, **params):
    """Run a program file (or a robot file, compiled on the fly) in the VAMP network emulator and
    return the joint torques it computes (-o FILE, or -o - for standard output)."""
    from vampc.commands import emulate_command
    if not emulate_command(source, build(EmulateOptions, ctx, params),
                           build(CompileOptions, ctx, params), build(RobotOptions, ctx, params),
                           params, say):
        sys.exit(1)


@main.command(short_help="Flop, latency, VAMP, buffer, package and clock figures; pictures.")
@click.argument("source", type=FilePath())
@options_of(ReportOptions, CompileOptions, RobotOptions)
@click.pass_context
@handle_errors
def report(ctx, source, **params):
    """Report flop counts, latency, VAMP, buffer and package counts for SOURCE beside the paper's
    (Table O.1, sections VI and VII): a robot file (compiled on the fly with the options given) or a
    program file written by `vampc compile` (its figures are recomputed from the file's graph,
    schedule and network). Pictures and pages go to the files named. With --tradeoff: the
    trade-off sweep instead."""
    from vampc.commands import report_command
    need_stdout("vampc report")
    # (the text written before the pictures are put in place: see report_command)
    report_command(source, build(ReportOptions, ctx, params), build(CompileOptions, ctx, params),
                   build(RobotOptions, ctx, params), params, emit=lambda text: say(text, nl=False))


@main.command(short_help="The narrowest fixed-point word for a robot or program.")
@click.argument("source", type=FilePath())
@options_of(PrecisionOptions, CompileOptions, RobotOptions, hidden=PRECISION_REFUSES)
@click.pass_context
@handle_errors
def precision(ctx, source, **params):
    """The narrowest fixed-point word for SOURCE: per width, the torque error bound analysed from the
    joint limits and the error observed on random states (README, Word formats)."""
    from vampc.commands import precision_command
    need_stdout("vampc precision")
    say(precision_command(source, build(PrecisionOptions, ctx, params), build(
        CompileOptions, ctx, params), build(RobotOptions, ctx, params), params), nl=False)


@main.command(short_help="Torque shift register over a path: limits ahead, retiming.")
@click.argument("source", type=FilePath())
@options_of(LookaheadOptions, CompileOptions, RobotOptions)
@click.pass_context
@handle_errors
def lookahead(ctx, source, **params):
    """The torque shift register of section VIII over a path: every row's torques, limits seen before
    the arm gets there, and time scaling: uniform, window by window, or chosen among candidate
    futures side by side (README, vampc lookahead)."""
    from vampc.commands import lookahead_command
    if all(params.get(name) is None for name in ("output", "torques", "plot")):
        need_stdout("vampc lookahead")          # (its summary, the violations, is the result)
    if not lookahead_command(source, build(LookaheadOptions, ctx, params), build(
            CompileOptions, ctx, params), build(RobotOptions, ctx, params), params, say):
        sys.exit(1)


@main.command(short_help="Fault campaigns on the tick engine: what each fault does.")
@click.argument("source", type=FilePath())
@options_of(FaultsOptions, CompileOptions, RobotOptions)
@click.pass_context
@handle_errors
def faults(ctx, source, **params):
    """A fault campaign on the tick engine: every single permanent fault of a kind on every VAMP,
    transient or intermittent faults, or random ones; each run classified (masked, detected and
    corrected, detected not corrected, silent corruption, hang) against the fault-free run. With a
    program compiled with --error-correction the checking of section VII runs (README, Error
    correction)."""
    from vampc.commands import faults_command
    if params.get("output") in (None, "-"):
        need_stdout("vampc faults")
    faults_command(source, build(FaultsOptions, ctx, params), build(CompileOptions, ctx, params),
                   build(RobotOptions, ctx, params), params, say)


@main.command(short_help="The network as Verilog: co-simulation, synthesis figures.")
@click.argument("source", type=FilePath())
@options_of(RtlOptions, CompileOptions, RobotOptions, hidden=RTL_UNRENDERED, helps=RTL_HELPS)
@click.pass_context
@handle_errors
def rtl(ctx, source, **params):
    """The compiled network as synthesizable Verilog (-o FILE.v), co-simulated against the emulator
    bit for bit (--cosim N --check) and synthesized for cell counts and Fmax (--synth ecp5 --pnr).
    SOURCE: a program compiled with a fixed-point word (--word qI.F), a program in another word
    given --word qI.F here, or a robot file compiled here with --word qI.F. The Mostly-Local Bus
    (--bus mlb) and error correction (--error-correction) are not rendered in RTL yet: such a
    program or option is refused (README, RTL)."""
    from vampc.commands import rtl_command
    if (params.get("cosim") is not None or params.get("synth") is not None) and \
            params.get("output") != "-":        # their verdict and figures are its result
        need_stdout("vampc rtl")
    if not rtl_command(source, build(RtlOptions, ctx, params), build(CompileOptions, ctx, params),
                       build(RobotOptions, ctx, params), params, say):
        sys.exit(1)


if __name__ == "__main__":  # pragma: no cover
    main()
