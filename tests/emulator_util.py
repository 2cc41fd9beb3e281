"""Helpers shared by the emulator tests: compile a chain into a loaded program, run both engines."""
from __future__ import annotations

import msgspec
import numpy as np

from vampc.compiler import CompileOptions, compile_chain, program_document
from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.host import random_trajectory


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
