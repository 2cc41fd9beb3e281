"""Helpers shared by the emulator tests: compile a chain into a loaded program, run both engines."""
from __future__ import annotations

import re

import msgspec
import numpy as np

from vampc.compiler import CompileOptions, compile_chain, program_document
from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.host import random_trajectory
from vampc.errors import VampcError


def document(chain, **opts) -> dict:
    """The program document of a chain (not written to disk)."""
    return program_document(compile_chain(chain, CompileOptions(**opts)))


def loaded(chain, **opts):
    """A Loaded program for a chain."""
    return loaded_from_doc(document(chain, **opts))


def run_both(ld, count: int, seed: int = 1, tick_count: int | None = None):
    """(trajectory, stream result, tick result) on `count` random states (tick on the first
    `tick_count`)."""
    traj = random_trajectory(ld.chain, count, seed)
    stream = emulate(ld, traj, "stream")
    short = traj if tick_count is None else _head(traj, tick_count)
    tick = emulate(ld, short, "tick", seed=seed)
    return traj, stream, tick


def _head(traj, k):
    from vampc.emulator.host import Trajectory
    return Trajectory(traj.q[:k], traj.qd[:k], traj.qdd[:k])


_ENCODE, _DECODE = msgspec.json.Encoder().encode, msgspec.json.Decoder().decode


def mutated(doc: dict, change) -> dict:
    """A deep copy of a document with `change(copy)` applied (a document is JSON data: copied
    through its JSON text, six times faster than copy.deepcopy, which the fault sweeps spent most
    of their time in)."""
    new = _DECODE(_ENCODE(doc))
    change(new)
    return new


def torques(doc: dict, traj, engine="stream", **kw) -> np.ndarray:
    """Torques of a document on a trajectory."""
    return emulate(loaded_from_doc(doc), traj, engine, **kw).tau


# What the loader's checks of a program say when they refuse one (vampc/emulator/load.py, timing.py,
# the bus's), and the tick engine's own as it runs one unchecked ("(a timing error)", at a tick): a
# damaged word must be refused by one of them, at a place (a VAMP, a slot, a constant buffer, a
# delay line, a word of the program stream), or change the torques. Any other error (a schema's, a
# decoder's, an internal one, a loader refusing everything) is not a report of the damage.
CHECKS = re.compile("|".join((
    r"never matches the Cycle-Counter", r"selects no input", r"is selected by no slot",
    r"is re-latched at (tick|counter) \d+, before the micro-step",
    r"latches operand [AB] at (tick|counter) \d+, the schedule has tick",
    r"drives its result at (tick|counter) \d+, the schedule has", r"run micro-steps in the same tick",
    r"ROM pointer \d+ selects .*, the graph node is", r"the wiring has a loop: VAMP",
    r"is read from VAMP .*, but it (appears at tick|shows set)", r"holds .*, not graph node",
    r"matches no VAMP on that input's Operand-[AB] paths", r"but the stream lists VAMP",
    r"but no tap reads past stage", r"is read by no tap", r"loops back through VAMP",
    r"latches tier \d+'s bus", r"^<program>: tick \d+: .*\(a timing error\)$",
)))
PLACE = re.compile(r"VAMP \d+|network\.(consts|buffers)\[\d+\]|program stream of \w+ \d+, word \d+")


def outcome(doc: dict, traj, good: np.ndarray, engine="stream", **kw) -> str:
    """"reported" (a check named above refused the program at a place), "changed" (it ran and its
    torques differ from `good`), "silent" (it ran to `good`'s torques) or "unexplained: ..." (some
    other error)."""
    try:
        tau = torques(doc, traj, engine, **kw)
    except VampcError as e:
        said = str(e)
        return "reported" if CHECKS.search(said) and PLACE.search(said) else f"unexplained: {said}"
    return "silent" if np.array_equal(tau, good) else "changed"
