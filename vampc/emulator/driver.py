"""The host side of a whole emulation run, fed in chunks so memory does not grow with the run.

`vampc emulate --random 1000000000` must not build a billion states first: the stream engine takes
torque sets in chunks (a few tens of megabytes of port values each), the caller writes each chunk's
torques (and states) as they come and the check against the reference accumulates over chunks. The
tick engine runs a whole trajectory at once (its sets pass through one pipeline), so a run that would
not fit in memory is refused before it starts.

Random states are drawn in blocks of RANDOM_BLOCK sets, block b from the seed sequence (seed, b): the
states of a run depend on the seed and their position only, not on the chunk size or the engine.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable, Iterator

import numpy as np

# imported before any output is open: a signal landing in numpy's lazy import of it loses its
# exception (raise_if_terminated asks again at every chunk anyway)
import numpy.random  # noqa: F401

from vampc.emulator.host import (
    CheckResult,
    Trajectory,
    WordCheck,
    check_torques,
    word_check,
)
from vampc.emulator.load import Loaded
from vampc.errors import VampcError, raise_if_terminated
from vampc.kinds import Engine, unhandled

RANDOM_BLOCK = 1024
CHUNK_BYTES = 64 << 20      # port values per chunk of the stream engine
MAX_CHUNK = 1 << 16
MAX_STATES = 1 << 53        # beyond this a set index is not exact in a float64 (and no run ends)


def random_states(chain, start: int, count: int, seed: int) -> Trajectory:
    """States start .. start + count - 1 of the random run with this seed (see the module
    docstring): within the joint limits, else ±π rad (±0.5 m prismatic), ±1 rad/s, ±1 rad/s²."""
    from vampc.robot.random import random_base, random_state
    parts, first = [], start // RANDOM_BLOCK
    for block in range(first, (start + count - 1) // RANDOM_BLOCK + 1):
        rng = np.random.default_rng([seed, block])
        state = random_state(chain, RANDOM_BLOCK, rng)
        parts.append(state + (random_base(RANDOM_BLOCK, rng),) if chain.floating else state)
    lo = start - first * RANDOM_BLOCK
    arrays = [np.concatenate([p[k] for p in parts])[lo:lo + count] for k in range(len(parts[0]))]
    if chain.mimic:   # followers move with their leaders (vampc.robot.mimic), their own limits aside
        from vampc.robot.mimic import couple
        arrays[:3] = couple(chain, *arrays[:3])
    return Trajectory(*arrays[:3], None, arrays[3] if chain.floating else None)


@dataclass(frozen=True)
class States:
    """Where a run's states come from: a trajectory in memory, or `count` random states."""

    count: int
    trajectory: Trajectory | None = None
    seed: int = 0
    source: str | None = None     # the trajectory's file, for messages naming a state's place

    @staticmethod
    def random(count: int, seed: int) -> "States":
        """`count` random states (refused beyond what a run can index)."""
        if not 1 <= count <= MAX_STATES:
            raise VampcError(f"--random {count}: the number of states must be between 1 and "
                             f"{MAX_STATES}")
        return States(count, None, seed)

    def chunk(self, chain, start: int, count: int) -> Trajectory:
        """States start .. start + count - 1."""
        if self.trajectory is None:
            return random_states(chain, start, count, self.seed)
        tr = self.trajectory
        part = slice(start, start + count)
        return Trajectory(tr.q[part], tr.qd[part], tr.qdd[part], None if tr.t is None else tr.t[part],
                          None if tr.base is None else tr.base[part])


def chunk_size(ld: Loaded) -> int:
    """Sets per chunk: CHUNK_BYTES of port values, at most MAX_CHUNK, at least 1."""
    per_set = 8 * (sum(p.size for p in ld.net.ports) + 4 * ld.chain.n_outputs)
    return int(max(1, min(MAX_CHUNK, CHUNK_BYTES // max(per_set, 1))))


STREAM_ADVICE = "run fewer sets or use --engine stream, which takes them in chunks"


# The tick engine's own tables per delay-buffer stage (a row of nine registers and its indexes):
# 345-370 bytes measured on 250-, 500- and 1000-joint chains (0.12, 0.5 and 2 million stages: 117,
# 255 and 773 MB peak for one set); a 5000-joint chain's 50 million stages took 16.3 GB, which the
# check, counting only the sets' values, had let start.
TICK_BYTES_PER_STAGE = 400


def tick_memory_check(ld: Loaded, count: int, advice: str = STREAM_ADVICE, copies: int = 1,
                      whole: str = "use --engine stream, which holds no register per stage") -> None:
    """The tick engine holds every set's port values and torques, and a row of registers per
    delay-buffer stage: refuse a run that cannot fit, `copies` engines at once (a fault campaign's
    local workers). `advice`: what the command can do instead (a fault campaign has only the tick
    engine); `whole`: what it can do when the network alone does not fit, whatever the sets."""
    stages = sum(b.stages for b in ld.net.buffers)
    sets = 8 * count * (sum(p.size for p in ld.net.ports) + 2 * ld.chain.n_outputs)
    need = copies * (sets + TICK_BYTES_PER_STAGE * stages)
    avail = short_of_memory(need)
    if avail is None:
        return
    engines = f" in the tick engines of {copies} workers" if copies > 1 else " in the tick engine"
    if copies * TICK_BYTES_PER_STAGE * stages > avail // 2:
        raise VampcError(f"{ld.path}: the network's {stages:,} delay-buffer stages need about "
                         f"{copies * TICK_BYTES_PER_STAGE * stages / 2**30:.1f} GiB{engines}, "
                         f"whatever the sets ({avail / 2**30:.1f} GiB available); {whole}")
    raise VampcError(f"{ld.path}: {count} torque set{'s' if count != 1 else ''} need about "
                     f"{need / 2**30:.1f} GiB{engines} ({avail / 2**30:.1f} GiB available); "
                     f"{advice}")


def short_of_memory(need: int) -> int | None:
    """The memory available when a run needing `need` bytes does not fit in half of it (the memory
    checks' rule, leaving the rest to the system and the run's own overheads); None when it fits, or
    when the memory available cannot be read."""
    avail = _available_memory()
    return None if avail is None or need <= avail // 2 else avail


def _available_memory() -> int | None:
    """The memory a run can take: Linux's MemAvailable (free memory and the page cache it can
    reclaim), or where there is none the free pages; and within a cgroup's memory limit (v2 or v1:
    a container's, a systemd slice's), what the limit leaves. The free pages alone can read little
    on a machine with gigabytes of reclaimable cache, refusing runs that fit, and a container's
    limit was not seen (a review's finds)."""
    avail = mem_available()
    if avail is None:
        try:
            avail = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES")
        except (ValueError, OSError, AttributeError):
            return None
    room = cgroup_room()
    return avail if room is None else min(avail, room)


def mem_available(meminfo: str = "/proc/meminfo") -> int | None:
    """MemAvailable in bytes, None where the file or the line is not there."""
    try:
        with open(meminfo, encoding="ascii", errors="replace") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


# (the limit, the usage, and in memory.stat the reclaimable page cache the usage counts)
V2 = ("memory.max", "memory.current", "inactive_file")
V1 = ("memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file")


def cgroup_room(root: str = "/sys/fs/cgroup", own: str = "/proc/self/cgroup") -> int | None:
    """What this process's cgroup memory limits leave, None where none is found: at every level
    from its own cgroup up to the hierarchy's root (a limit applies to everything below it), the
    limit less the usage, the usage without the inactive page cache the system can reclaim; the
    least of them. cgroup v2's memory.max and memory.current, else v1's memory.limit_in_bytes and
    memory.usage_in_bytes (2^62 or more: no limit). The own cgroup comes from `own` (the line
    "0::/path", or v1's "N:memory:/path"); a folder that is not there (a container's own cgroup
    is mounted at the root) is passed over."""
    paths = {"v2": "", "v1": ""}
    try:
        with open(own, encoding="ascii", errors="replace") as f:
            for line in f:
                number, controllers, path = (line.rstrip("\n").split(":", 2) + ["", ""])[:3]
                if number == "0" and not controllers:
                    paths["v2"] = path.rstrip("/")
                elif "memory" in controllers.split(","):
                    paths["v1"] = path.rstrip("/")
    except (OSError, ValueError):
        pass
    for base, files, path in ((root, V2, paths["v2"]), (os.path.join(root, "memory"), V1, paths["v1"])):
        parts = [p for p in path.split("/") if p]
        rooms = [room for k in range(len(parts), -1, -1)
                 if (room := _room(os.path.join(base, *parts[:k]), files)) is not None]
        if rooms:
            return min(rooms)
    return None


def _room(folder: str, files: tuple[str, str, str]) -> int | None:
    """One cgroup's limit less its usage (the reclaimable cache left out), None without a limit."""
    limit_file, usage_file, cache_key = files
    try:
        with open(os.path.join(folder, limit_file), encoding="ascii", errors="replace") as f:
            limit = f.read().strip()
        if limit == "max" or int(limit) >= 1 << 62:
            return None
        with open(os.path.join(folder, usage_file), encoding="ascii", errors="replace") as f:
            usage = int(f.read().strip())
    except (OSError, ValueError):
        return None
    cache = 0
    try:
        with open(os.path.join(folder, "memory.stat"), encoding="ascii", errors="replace") as f:
            for line in f:
                key, _, value = line.partition(" ")
                if key == cache_key:
                    cache = int(value)
                    break
    except (OSError, ValueError):
        pass
    return max(0, int(limit) - max(0, usage - cache))


@dataclass(frozen=True)
class Outcome:
    """What a run did: timing (as vampc.emulator.Emulation), the merged check, engine wall time."""

    engine: str
    count: int
    load_ticks: int
    first_tick: int
    interval: int
    data_ticks: int
    engine_seconds: float
    check: CheckResult | WordCheck | None     # WordCheck: a word format other than float64
    overflows: int = 0                        # results and host words beyond the word (counted)
    overflow_sites: tuple[str, ...] = ()      # where the first few happened (stream.overflow_sites)
    checking: dict | None = None              # error correction: what the checking did (tick)

    @property
    def emulated_flops(self) -> int:
        """Program load plus data ticks (1 tick = 1 flop)."""
        return self.load_ticks + self.data_ticks


def run(ld: Loaded, states: States, engine: str = "stream", seed: int = 0, vcd=None,
        check: bool = False, sink: Callable[[Trajectory, np.ndarray], None] | None = None,
        progress=None, faults=(), stream=None) -> Outcome:
    """Run every state through the engine. Each chunk's states and torques go to `sink(traj, tau)`
    in order. A non-finite torque is a VampcError naming the set and the joint. `faults`: injected
    into the tick engine (vampc.emulator.faults). `stream`: the stream engine's preparation for
    these states (prepare_stream), made here when not given."""
    engine = Engine(engine)
    match engine:
        case Engine.TICK:           # one chunk: the tick engine runs the sets back to back
            tick_memory_check(ld, states.count)
            size = states.count
        case Engine.STREAM:
            size = chunk_size(ld)
        case _:
            unhandled(engine)
    from vampc.emulator.stream import count_overflows_from_here
    count_overflows_from_here(ld)
    with np.errstate(over="ignore", invalid="ignore"):   # non-finite torques are refused below
        return _run(ld, states, engine, seed, vcd, check, sink, progress, size, faults, stream)


def _run(ld, states, engine: Engine, seed, vcd, check, sink, progress, size, faults=(),
         stream=None) -> Outcome:
    from vampc.emulator import emulate, prepare_stream
    merged, seconds, first = None, 0.0, None
    if engine is Engine.STREAM and stream is None:
        stream = prepare_stream(ld, states.count)
    if progress is not None:      # the sets start now: the bar's clock too (the static check of a
        progress(0, states.count)  # 1024-joint log program had counted as 13 s of 20 sets' time)
    sites: list[str] = []
    for start, traj in _chunks(ld, states, size):
        raise_if_terminated()
        def chunk_progress(done, total, start=start):
            if progress is not None:
                progress(start + done, states.count)
        em = emulate(ld, traj, engine=engine, seed=seed, vcd=vcd, static_check=stream is None,
                     progress=chunk_progress, stream=stream, faults=faults)
        first = first or em
        seconds += em.wall_seconds
        if ld.arith.overflows and len(sites) < SITES:     # where, for the first few
            sites += _sites(ld, stream, traj, SITES - len(sites), start)
        try:
            _check_finite(ld, em.tau, start, faults, states.source, sites)
        except VampcError as exc:
            # what the error-correction checking had done by then goes with the refusal (emulate
            # says it): a NaN torque had stopped the run with no word of it, though a campaign
            # found the fault corrected at tick 81 (a hardware audit)
            exc.checking = em.checking
            raise
        if check and ld.word is None:
            merged = _merge(merged, check_torques(ld.chain, traj, em.tau), start)
        elif check:      # another word: its error against float64, joint by joint
            merged = word_check(ld.chain, traj, em.tau).merged(merged)
        if sink is not None:
            sink(traj, em.tau)
        raise_if_terminated()
    match engine:
        case Engine.TICK:
            data_ticks = first.data_ticks
        case Engine.STREAM:     # its timing is the schedule's: set j completes j·C after set 0
            data_ticks = (states.count - 1) * first.interval + first.first_tick + 1
        case _:
            unhandled(engine)
    return Outcome(engine, states.count, first.load_ticks, first.first_tick, first.interval,
                   data_ticks, seconds, merged, ld.arith.overflows, tuple(sites), first.checking)


SITES = 5       # overflows located and reported by a run


def _sites(ld, stream, traj, limit: int, start: int) -> list[str]:
    """The first overflows of a chunk, located (vampc.emulator.stream.overflow_sites)."""
    from vampc.emulator.stream import flow, overflow_sites
    from vampc.emulator.timing import derive
    fl = stream.flow if stream is not None else flow(ld, derive(ld))
    return overflow_sites(ld, fl, traj, limit, start)


def _chunks(ld: Loaded, states: States, size: int) -> Iterator[tuple[int, Trajectory]]:
    for start in range(0, states.count, size):
        yield start, states.chunk(ld.chain, start, min(size, states.count - start))


def _check_finite(ld: Loaded, tau: np.ndarray, start: int, faults=(), source=None,
                  sites=()) -> None:
    """VampcError naming the first torque that is not finite, and the cause (non_finite); with the
    state's place in its trajectory file `source`, where given (the numbers too large may be the
    state's), and the overflows counted by then with the first of `sites` (a float32 run that
    overflowed stopped naming neither, where a fixed-point word's lists them: a new user's find)."""
    found = non_finite(ld, tau, faults, sites[0] if sites else None)
    if found is not None:
        k, where = start + found[0] + 1, ""
        if source is not None:         # (a CSV's states start on its line 2)
            from vampc.emulator.trajectory import numpy_file
            npy = numpy_file(source)
            where = f" ({'state' if npy else 'line'} {k if npy else k + 1} of {source})"
        raise VampcError(f"{ld.path}: set {k}{where}, {found[1]}")


def non_finite(ld: Loaded, tau: np.ndarray, faults=(), first: str | None = None) \
        -> tuple[int, str] | None:
    """The row of the first torque that is not finite and what to say of it (the joint or wrench
    component, the value and the cause: the injected faults where there are any, else an overflow
    of the robot's or the state's numbers, with the run's count and the `first` place where given;
    nothing was written); None if every torque is finite."""
    bad = ~np.isfinite(tau)
    if not bad.any():
        return None
    r, j = (int(x) for x in np.argwhere(bad)[0])
    from vampc.emulator.trajectory import WRENCH_COLUMNS
    where = (f"joint {j + 1} ({ld.chain.joints[j].name}): the torque" if j < ld.chain.n
             else f"{WRENCH_COLUMNS[j - ld.chain.n]}: the base wrench")
    cause = (f"{ld.arith.name} overflow under the injected fault{'s' if len(faults) > 1 else ''}"
             if faults else
             f"{ld.arith.name} overflow: the robot's or the state's numbers are too large")
    if first is not None and not faults:
        n = ld.arith.overflows
        cause += f"; {n} overflow{'s' if n != 1 else ''} by then, the first in {first.strip()}"
    return r, f"{where} is {tau[r, j]} ({cause}); {STOPPED}"


STOPPED = "the run stopped and wrote no output file"     # (emulate says more when it streamed)


def _merge(acc: CheckResult | None, new: CheckResult, start: int) -> CheckResult:
    new = CheckResult(new.max_abs, new.max_rel, new.worst_row + start, new.ok, new.floored)
    if acc is None:
        return new
    worst = new if new.max_rel > acc.max_rel else acc
    return CheckResult(max(acc.max_abs, new.max_abs), worst.max_rel, worst.worst_row,
                       acc.ok and new.ok, acc.floored + new.floored)


__all__ = ["Outcome", "States", "run", "random_states", "chunk_size"]
