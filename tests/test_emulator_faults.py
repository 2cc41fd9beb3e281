"""Deliberately corrupted programs: every flipped field of every slot (delays, ROM pointer,
multiplexer selects), VAMP number and wire is either reported or changes the torques — never a
silently plausible answer. Systolic and folded (time-multiplexed) programs alike."""
from __future__ import annotations

import itertools

import msgspec
import numpy as np
import pytest
from emulator_util import CHECKS, PLACE, document, mutated, outcome, torques

from vampc.emulator import emulate, loaded_from_doc
from vampc.emulator.host import random_trajectory
from vampc.errors import VampcError
from vampc.program.words import FIELD, FIELDS, ROM, Program, decode, encode, vamp_words
from vampc.robot.random import random_chain

CHAIN = random_chain(2, 11, prismatic_fraction=0.5, endpoints=True)
LAYOUTS = {"systolic": {}, "folded": {"layout": "folded"},
           "shared": {"layout": "folded", "share_passes": True}}
DOCS = {name: document(CHAIN, **opts) for name, opts in LAYOUTS.items()}
TRAJ = random_trajectory(loaded_from_doc(DOCS["systolic"]).chain, 16, 2)   # a steady state too
GOOD = torques(DOCS["systolic"], TRAJ)


def _slots(doc, v) -> list[Program]:
    return [Program(*(s[f] for f in FIELDS)) for s in doc["programs"][v]["slots"]]


def _set_field(v: int, k: int, field: str, value: int):
    """Change one field of one slot consistently (the VAMP's stream words and the readable listing),
    so the damage must be caught by the timing, schedule and graph checks, not the listing check."""
    def change(doc):
        number = doc["network"]["vamps"][v]["number"]
        slots = _slots(doc, v)
        slots[k] = msgspec.structs.replace(slots[k], **{field: value})
        for entry in doc["program_stream"]:
            where = [i for i, t in enumerate(entry["targets"]) if t == v]
            if where:
                first, last = where[0], where[-1] + 1
                words = [list(w) for w in vamp_words(number, tuple(slots))]
                entry["words"][first:last] = words
                entry["targets"][first:last] = [v] * len(words)
                entry["depth"][first:last] = [entry["depth"][first]] * len(words)
        doc["programs"][v]["slots"][k][field] = value
        if field == "rom" and value < len(ROM):     # (the listing names the op its pointer runs)
            doc["programs"][v]["slots"][k]["op"] = ROM[value][0].value
        doc["io"]["load_ticks"] = max(i + d + 1 for e in doc["program_stream"]
                                      for i, d in enumerate(e["depth"]))
    return change


def _outcome(doc, engine="stream", **kw) -> str:
    return outcome(doc, TRAJ, GOOD, engine, **kw)


def _flips(doc):
    """Every other value of every field of every slot: all counters of the period for a delay (a
    sample for long periods), every ROM entry, every multiplexer input, and one value out of range."""
    P = doc["network"]["period"]
    rng = np.random.default_rng(0)
    for p in doc["programs"]:
        v, mux = p["vamp"], doc["network"]["vamps"][p["vamp"]]
        for k, slot in enumerate(p["slots"]):
            for field in ("delay_a", "delay_b", "delay_r"):
                values = range(P) if P <= 8 else sorted(set(rng.integers(0, P, 3).tolist()) | {
                    (slot[field] + 1) % P, (slot[field] - 1) % P})
                for value in [*values, P + 1]:
                    if value != slot[field]:
                        yield v, k, field, value
            for value in range(len(ROM)):
                if value != slot["rom"]:
                    yield v, k, "rom", value
            for field, inputs in (("sel_a", mux["a"]), ("sel_b", mux["b"])):
                for value in range(len(inputs) + 1):
                    if value != slot[field]:
                        yield v, k, field, value


FLIPS = {name: list(_flips(doc)) for name, doc in DOCS.items()}


def test_the_sweep_is_large():
    # per slot: 3 delays x 4 wrong values, 8 ROM entries, and 1 select out of range per operand
    assert len(FLIPS["systolic"]) == 22 * len(DOCS["systolic"]["programs"])
    assert len(FLIPS["folded"]) > 1000 and len(FLIPS["shared"]) > 1000


def test_layouts_compute_the_same_torques():
    for doc in DOCS.values():
        assert np.array_equal(torques(doc, TRAJ), GOOD)


# the shared-pass layout is the folded one with a second pass in each slot's span: its 1850 flips
# (5.5 s) run under -m slow, the systolic and folded ones by default (the suite's 4 minutes)
@pytest.mark.parametrize("layout", [pytest.param(name, marks=pytest.mark.slow) if name == "shared" else name
                                    for name in LAYOUTS])
def test_every_slot_field_flip_is_reported_or_changes_torques(layout):
    doc = DOCS[layout]
    wrong = [(f, said) for f in FLIPS[layout]
             if (said := _outcome(mutated(doc, _set_field(*f)))) not in ("reported", "changed")]
    assert wrong == []


def test_an_error_that_is_no_check_of_the_program_is_not_a_report():
    # the sweeps' outcome would call a schema's or any other error a report of the damage otherwise
    def unreadable(doc):
        doc["programs"][0]["slots"][0]["delay_a"] = "seven"
    assert _outcome(mutated(DOCS["systolic"], unreadable)).startswith("unexplained: ")
    assert _outcome(DOCS["systolic"]) == "silent"


@pytest.mark.parametrize("layout", list(LAYOUTS))
def test_tick_engine_alone_sees_timing_flips(layout):
    """Without the static checks, the tick engine's own checks must report a delay that breaks the
    timing (a mixed-set latch, an operand another slot latched, a re-latch, a wrong-set torque)
    where it first happens. A program's delays are the same every period, so the first two torque
    sets are the first a wrong delay can mix (the sets before the first hold none): a run of those
    two sets must report each such error, and the very report (tick, VAMP, sets) the 16-set run
    makes. (Different torques were accepted too: an engine whose mixed-set check skipped set 0, or
    whose operand-owner check started a period late, passed; both reported a period later in the
    long run, and the short one then said another error, at the torques, or none.)"""
    from vampc.emulator import timing
    breaking = []
    for v, k, field, value in FLIPS[layout]:
        if field not in ("delay_a", "delay_b", "delay_r"):
            continue
        doc = mutated(DOCS[layout], _set_field(v, k, field, value))
        try:
            timing.derive(loaded_from_doc(doc))
        except VampcError:
            breaking.append(doc)
        if len(breaking) >= 40:
            break
    assert len(breaking) > 10
    first_two = random_trajectory(loaded_from_doc(DOCS["systolic"]).chain, 2, 2)
    for doc in breaking:
        said = []
        for traj in (TRAJ, first_two):
            with pytest.raises(VampcError) as err:
                torques(doc, traj, "tick", static_check=False)
            said.append(str(err.value))
        assert CHECKS.search(said[0]) and PLACE.search(said[0]), said[0]
        assert said[1] == said[0]


def _word_at(doc, vamp):
    for e, entry in enumerate(doc["program_stream"]):
        if vamp in entry["targets"]:
            return e, entry["targets"].index(vamp)
    raise AssertionError(vamp)


def test_renumbered_word_is_reported():
    def change(doc):
        e, k = _word_at(doc, 0)
        doc["program_stream"][e]["words"][k][0] = 99999
    with pytest.raises(VampcError, match="never programmed|matches no VAMP"):
        torques(mutated(DOCS["systolic"], change), TRAJ)


def test_non_integer_number_is_reported():
    def change(doc):
        e, k = _word_at(doc, 3)
        doc["program_stream"][e]["words"][k][0] += 0.5
    with pytest.raises(VampcError):
        torques(mutated(DOCS["systolic"], change), TRAJ)


@pytest.mark.parametrize("layout", ["folded", "shared"])
def test_a_lost_extended_word_is_reported(layout):
    doc = DOCS[layout]
    entry = next(e for e in doc["program_stream"] if any(w[0] < 0 for w in e["words"]))
    lost = next(i for i, w in enumerate(entry["words"]) if w[0] < 0)
    def change(d):
        e = next(x for x in d["program_stream"] if x["root"] == entry["root"])
        for key in ("words", "targets", "depth"):
            del e[key][lost]
        d["io"]["load_ticks"] = max(i + dd + 1 for x in d["program_stream"]
                                    for i, dd in enumerate(x["depth"]))
    with pytest.raises(VampcError, match="never programmed|lists .* but the program stream"):
        torques(mutated(doc, change), TRAJ)


def _taps(doc):
    V, P = len(doc["network"]["vamps"]), len(doc["network"]["ports"])
    K = len(doc["network"]["consts"])
    return ([["vamp", i, 0] for i in range(V)] + [["port", i, 0] for i in range(P)]
            + [["const", i, 0] for i in range(K)])


def _wire_flips(doc, count, seed=0):
    rng = np.random.default_rng(seed)
    vamps, taps = doc["network"]["vamps"], _taps(doc)
    for _ in range(count):
        v = int(rng.integers(len(vamps)))
        operand = "ab"[int(rng.integers(2))]
        k = int(rng.integers(len(vamps[v][operand])))
        new = taps[int(rng.integers(len(taps)))]
        if [new] != vamps[v][operand][k]:
            yield v, operand, k, new


WIRES = [("systolic", *f) for f in _wire_flips(DOCS["systolic"], 200)] + \
        [("folded", *f) for f in _wire_flips(DOCS["folded"], 100, 1)]


@pytest.mark.parametrize("layout,v,operand,k,new", WIRES)
def test_rewired_operand_is_reported_or_changes_torques(layout, v, operand, k, new):
    def change(doc):
        doc["network"]["vamps"][v][operand][k] = [new]
    assert _outcome(mutated(DOCS[layout], change)) in ("reported", "changed")


def test_field_packing_limits():
    with pytest.raises(VampcError, match="does not fit"):
        encode(1, decode([1, 0, 0])[1].__class__(FIELD, 0, 0, 0))
    with pytest.raises(VampcError, match="does not fit"):
        vamp_words(1, (Program(0, 0, 0, 0), Program(1 << 24, 0, 0, 0)))


def test_every_systolic_vamp_has_one_distinct_word():
    doc = DOCS["systolic"]
    words = [tuple(w) for e in doc["program_stream"] for w in e["words"]]
    assert len(words) == len(set(words)) == len(doc["programs"])
    assert sorted(itertools.chain.from_iterable(e["targets"] for e in doc["program_stream"])) == \
        list(range(len(doc["programs"])))


@pytest.mark.parametrize("layout", list(LAYOUTS))
def test_good_program_runs_both_engines(layout):
    ld = loaded_from_doc(DOCS[layout])
    assert np.array_equal(emulate(ld, TRAJ, "tick").tau, GOOD)


def test_operand_a_loop_is_reported():
    # VAMP 0's Operand-A rewired to a VAMP downstream of it: the programming path becomes a loop.
    doc = DOCS["systolic"]
    downstream = next(v["index"] for v in doc["network"]["vamps"] if v["a"] == [[["vamp", 0, 0]]])
    def change(d):
        d["network"]["vamps"][0]["a"] = [[["vamp", downstream, 0]]]
    with pytest.raises(VampcError, match=r"VAMP \d+: its Operand-A path loops back through VAMP \d+"):
        torques(mutated(doc, change), TRAJ)


@pytest.mark.parametrize("layout", ["systolic", "folded"])
def test_a_refused_flip_is_blamed_on_the_vamp_flipped(layout):
    """A delay or ROM pointer edited in both the stream and the listing was refused naming another
    VAMP: the one the damaged slot's result then reached at the wrong tick (VAMP 5's delay-R said
    as VAMP 26's operand re-latched; a ROM pointer edited from VA to VC as VAMP 1's timing: a new
    user's find). Each slot's own words are now checked first: every refusal names the VAMP whose
    field was flipped. (Every fifth flip of the sweep: of all 1408 systolic and 1781 folded ones,
    370 and 101 had been blamed elsewhere; all of them take 11 s.)"""
    from vampc.emulator.check import check_program
    blamed = []
    for v, k, field, value in FLIPS[layout][::5]:
        try:
            check_program(loaded_from_doc(mutated(DOCS[layout], _set_field(v, k, field, value))))
        except VampcError as exc:
            said = str(exc)
            if not (f"VAMP {v} (" in said or f"VAMP {v} slot {k} (" in said):
                blamed.append((v, k, field, value, said))
    assert blamed == [], (len(blamed), blamed[:3])
