"""Deliberately corrupted programs: every flipped delay, ROM pointer, VAMP number and wire is either
reported or changes the torques — never a silently plausible answer."""
from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from emulator_util import document, mutated, torques
from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.host import random_trajectory
from vampc.errors import VampcError
from vampc.program.words import FIELD, ROM, decode, encode
from vampc.robot.random import random_chain

CHAIN = random_chain(2, 11, prismatic_fraction=0.5, endpoints=True)
DOC = document(CHAIN)
TRAJ = random_trajectory(loaded_from_doc(DOC).chain, 16, 2)   # long enough for a steady state
GOOD = torques(DOC, TRAJ)


def _word_at(doc, vamp):
    for e, entry in enumerate(doc["program_stream"]):
        if vamp in entry["targets"]:
            return e, entry["targets"].index(vamp)
    raise AssertionError(vamp)


def _set_field(vamp: int, field: str, value: int):
    """Change one field of a VAMP's program consistently (stream word and readable listing), so
    the damage must be caught by the timing, schedule and graph checks, not by the listing check."""
    def change(doc):
        e, k = _word_at(doc, vamp)
        number, prog = decode(doc["program_stream"][e]["words"][k])
        doc["program_stream"][e]["words"][k] = list(encode(number, dataclasses.replace(prog, **{field: value})))
        doc["programs"][vamp][field] = value
    return change


def _outcome(doc, engine="stream", **kw) -> str:
    try:
        tau = torques(doc, TRAJ, engine, **kw)
    except VampcError:
        return "reported"
    return "silent" if np.array_equal(tau, GOOD) else "changed"


def _program_flips():
    C = DOC["network"]["cycle"]
    for p in DOC["programs"]:
        for field in ("delay_a", "delay_b", "delay_r"):
            for value in [*range(C), C + 1]:
                if value != p[field]:
                    yield p["vamp"], field, value
        for value in range(len(ROM)):
            if value != p["rom"]:
                yield p["vamp"], "rom", value


FLIPS = list(_program_flips())


def test_the_sweep_is_large():
    assert len(FLIPS) == 20 * len(DOC["programs"])   # 3 delays x 4 wrong values + 8 ROM entries


def test_every_program_flip_is_reported_or_changes_torques():
    silent = [(v, f, x) for v, f, x in FLIPS if _outcome(mutated(DOC, _set_field(v, f, x))) == "silent"]
    assert silent == []


def test_tick_engine_alone_sees_timing_flips():
    # Without the static checks, the tick engine's own behaviour must still expose a delay that
    # breaks the timing: a mixed-set latch, a wrong-set torque, or different torques.
    breaking = []
    for vamp, field, value in FLIPS:
        if field == "rom":
            continue
        doc = mutated(DOC, _set_field(vamp, field, value))
        try:
            from vampc.emulator import timing
            timing.derive(loaded_from_doc(doc))
        except VampcError:
            breaking.append(doc)
    assert len(breaking) > 10
    outcomes = {_outcome(doc, "tick", static_check=False) for doc in breaking[:40]}
    assert "silent" not in outcomes


def test_renumbered_word_is_reported():
    def change(doc):
        e, k = _word_at(doc, 0)
        doc["program_stream"][e]["words"][k][0] = 99999
    with pytest.raises(VampcError, match="never programmed|matches no VAMP"):
        torques(mutated(DOC, change), TRAJ)


def test_non_integer_number_is_reported():
    def change(doc):
        e, k = _word_at(doc, 3)
        doc["program_stream"][e]["words"][k][0] += 0.5
    with pytest.raises(VampcError):
        torques(mutated(DOC, change), TRAJ)


def _taps(doc):
    V, P = len(doc["network"]["vamps"]), len(doc["network"]["ports"])
    K = len(doc["network"]["consts"])
    return ([["vamp", i, 0] for i in range(V)] + [["port", i, 0] for i in range(P)]
            + [["const", i, 0] for i in range(K)])


def _wire_flips(count=300, seed=0):
    rng = np.random.default_rng(seed)
    vamps, taps = DOC["network"]["vamps"], _taps(DOC)
    for _ in range(count):
        v = int(rng.integers(len(vamps)))
        operand = "ab"[int(rng.integers(2))]
        new = taps[int(rng.integers(len(taps)))]
        if [new] != vamps[v][operand]:
            yield v, operand, new


@pytest.mark.parametrize("v,operand,new", list(_wire_flips()))
def test_rewired_operand_is_reported_or_changes_torques(v, operand, new):
    def change(doc):
        doc["network"]["vamps"][v][operand] = [new]
    assert _outcome(mutated(DOC, change)) != "silent"


def test_field_packing_limits():
    with pytest.raises(VampcError, match="does not fit"):
        encode(1, decode([1, 0, 0])[1].__class__(FIELD, 0, 0, 0))


def test_every_vamp_has_a_distinct_program_word():
    words = [tuple(w) for e in DOC["program_stream"] for w in e["words"]]
    assert len(words) == len(set(words)) == len(DOC["programs"])
    assert sorted(itertools.chain.from_iterable(e["targets"] for e in DOC["program_stream"])) == \
        list(range(len(DOC["programs"])))


def test_good_program_runs_both_engines():
    ld = loaded_from_doc(DOC)
    assert np.array_equal(emulate(ld, TRAJ, "tick").tau, GOOD)


def test_operand_a_loop_is_reported():
    # VAMP 0's Operand-A rewired to a VAMP downstream of it: the programming path becomes a loop.
    downstream = next(v["index"] for v in DOC["network"]["vamps"] if v["a"] == [["vamp", 0, 0]])
    def change(doc):
        doc["network"]["vamps"][0]["a"] = [["vamp", downstream, 0]]
    with pytest.raises(VampcError, match=r"VAMP \d+: its Operand-A path loops back through VAMP \d+"):
        torques(mutated(DOC, change), TRAJ)
