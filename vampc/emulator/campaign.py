"""Fault campaigns (`vampc faults`): many runs of the tick engine, one fault each, classified against
the fault-free run of the same program on the same states (README, Error correction).

Campaigns:

    single        every single permanent fault of each kind on every VAMP (the extraneous checker
                  included when the program has error correction), from Data-Mode tick --at
    transient     every VAMP: one bit of its Result flipped once, at a tick drawn from --seed
    intermittent  every VAMP: a stuck Result bit active in a random fraction (--rate) of cycles
    random        --count faults drawn from --seed: VAMP, kind, register, bit, value, tick, and
                  whether stuck, flipped once or intermittent

The kinds of a permanent fault (--kinds): `result` (bit B of the Result's x scalar stuck at V),
`a` and `b` (bit B of operand register A or B, scalar 0, stuck at V), B by default the word's
highest magnitude bit (62 of binary64, 30 of binary32, the bit below the sign of a fixed-point
word: a stuck 1 there changes any value below half the range) and V by default 1 (--bits and
--values give others: every pair is a fault); `control` (bit 0 of the first slot's delay-R stuck at
the value it does not hold: the register always changes); `dead` (outputs tri-stated); and, on
request, `control2` (the same bit of the second set of control registers, the checking circuitry's
copy of the successor's table).

Each run is classified: `masked` (every torque set as the fault-free run's, nothing flagged),
`detected-corrected` (a checker flagged a mismatch, the faulty VAMP is the one it excised, and no set
entering after it differs), `detected-not-corrected` (flagged, but a healthy VAMP excised or sets
entering after it still differ), `silent-corruption`
(a torque differs and nothing flagged it) or `hang` (the run stopped with an error: what the
emulator cannot run, named). Beside it: the tick and the cycles from the fault's start to the
detection, the sets corrupted before and after it, and the VAMP Maintenance Mode names; without a
detection, `corrupted`, the sets that differ among those run.

A run stops early when its outcome is settled: with checking, `TAIL` periods after sets that
entered after the detection have left the network; without, at the first corrupted set.
"""
from __future__ import annotations

import hashlib
import math
import os
import warnings
from dataclasses import dataclass

import numpy as np

from vampc.emulator.faults import Fault, parse_fault
from vampc.errors import VampcError, VampcUsageError, VampcWarning

CAMPAIGNS = ("single", "transient", "intermittent", "random")
KINDS = ("result", "a", "b", "control", "dead", "control2")
DEFAULT_KINDS = KINDS[:5]       # control2: the checking circuitry's own registers, on request
CLASSES = ("masked", "detected-corrected", "detected-not-corrected", "silent-corruption", "hang")
TAIL = 8          # sets checked after those in flight at a detection, before a run stops
SEED_STATES = 0x5EED


@dataclass(frozen=True)
class Setup:
    """What every run of a campaign shares: the program, the states' ports, the fault-free torques."""

    ld: object
    ports: dict
    reference: np.ndarray
    sets: int
    seed: int


def high_bit(word) -> int:
    """The word's highest magnitude bit (binary64: 62, binary32: 30; qI.F: below the sign)."""
    return word.bits - 2


def physical_vamps(ld) -> int:
    """VAMPs faults can name: the network's, and the extraneous checker with error correction."""
    return len(ld.net.vamps) + (ld.net.checking is not None)


def default_sets(ld) -> int:
    """Sets a campaign runs by default: enough for the first sweep to check the last VAMP, and
    for the sets after it to leave the network."""
    from vampc.emulator.checking import check_periods
    from vampc.network.checking import warmup
    w = warmup(ld.programs, ld.timing, ld.period)
    k = ld.net.checking.compare if ld.net.checking is not None else 1
    latency = ld.net.latency
    return check_periods(len(ld.net.vamps), w, k) + math.ceil(latency / ld.period) + TAIL + 1


DRAWN = ("transient", "random")    # the campaigns that draw each fault's start tick


def reach_sets(ld) -> int:
    """Sets from any start to the end of the compare periods that next check every VAMP (a whole
    sweep, there and back: a fault may start just after its VAMP's check), and for the sets after
    them to leave the network; without error correction, only the latter."""
    from vampc.emulator.checking import sweep_periods
    from vampc.network.checking import warmup
    latency = ld.net.latency
    drain = math.ceil(latency / ld.period) + TAIL + 1
    if ld.net.checking is None:
        return drain
    w = warmup(ld.programs, ld.timing, ld.period)
    return sweep_periods(len(ld.net.vamps), w, ld.net.checking.compare) + drain


def campaign_sets(ld, campaign: str) -> int:
    """Sets a campaign runs by default: default_sets; for one that draws its faults' start ticks
    (DRAWN), default_sets for them to start in and reach_sets after (draw_sets)."""
    return default_sets(ld) + (reach_sets(ld) if campaign in DRAWN else 0)


def draw_sets(ld, sets: int) -> int:
    """The sets a drawn fault may start in: all but the last reach_sets(ld) of the run, so the
    checking reaches every fault before the run ends (one starting later had been counted as
    silent corruption: a new user's random campaign of the default length had a quarter of its
    faults so); the whole run when it is shorter."""
    reach = reach_sets(ld)
    return sets - reach if sets > reach else sets


def faults_of(ld, campaign: str, kinds=KINDS, at: int = 0, count: int = 100, rate: float = 0.2,
              seed: int = 0, sets: int = 100, bits=None, values=(1,)) -> list[Fault]:
    """The campaign's faults, in a fixed order (the results file's keys). `bits`, `values`: of
    the single campaign's stuck data bits (default: the word's highest magnitude bit, stuck at
    1). A drawn start tick is in the first draw_sets(ld, sets) sets."""
    V, hi, P = physical_vamps(ld), high_bit(ld.arith), ld.period
    last = draw_sets(ld, sets) * P - 1
    rng = np.random.default_rng([seed, 0xCA])
    specs: list[str] = []
    if campaign == "single":
        for v in range(V):
            for kind in kinds:
                for bit in (bits or [hi]) if kind in ("result", "a", "b") else [None]:
                    for value in values if kind in ("result", "a", "b") else [None]:
                        spec = _permanent(ld, v, kind, bit, at, value)
                        if spec is not None:
                            specs.append(spec)
    elif campaign == "transient":
        for v in range(V):
            specs.append(f"vamp={v},flip=result.x:{hi},at={int(rng.integers(0, last))}")
    elif campaign == "intermittent":
        for v in range(V):
            specs.append(f"vamp={v},stuck=result.x:{hi},value=1,rate={rate},at={at}")
    elif campaign == "random":
        from vampc import progress
        with progress.counter("drawing faults", count, unit="fault") as drawn:
            _draw_random(ld, specs, rng, V, kinds, last, rate, count, drawn)
    else:
        raise VampcError(f"--campaign {campaign}: choose from {', '.join(CAMPAIGNS)}")
    return [parse_fault(s) for s in specs]


def _draw_random(ld, specs: list, rng, V: int, kinds, last: int, rate: float, count: int,
                 drawn) -> None:
    """The random campaign's `count` faults, drawn in turn into `specs` (about 0.1 ms each: a
    million took minutes, said by `drawn(done, total)`, a progress bar). control2 without error
    correction (no second set) is left out of the kinds, with a warning, or refused alone (its
    draws had become result faults, unsaid)."""
    if "control2" in kinds and ld.net.checking is None:
        kinds = [k for k in kinds if k != "control2"]
        if not kinds:
            raise VampcUsageError("--kinds control2: a program without error correction has no "
                                  "second set of control registers (compile --error-correction)")
        warnings.warn(VampcWarning("--kinds control2: left out, a program without error correction "
                                   "has no second set of control registers"), stacklevel=2)
    lacking = {k: set(_lacking(ld, k)) for k in ("control", "control2") if k in kinds}
    # the VAMPs that have each: control2's in the check order (each holds its successor's copy)
    homes = {k: [w for w in (ld.net.checking.order if k == "control2" else range(V))
                 if w not in lacking[k]] for k in lacking}
    for done in range(count):
        if done % 4096 == 0:
            drawn(done, count)
        v = int(rng.integers(0, V))
        kind = str(rng.choice(kinds))
        t = int(rng.integers(0, last))
        if kind == "dead":
            specs.append(f"vamp={v},dead,at={t}")
            continue
        # a kind a VAMP has no register of is drawn on another VAMP that has it (it had become a
        # result fault, unsaid: a --kinds control campaign ran result faults too, a review found)
        if v in lacking.get(kind, ()):
            v = int(homes[kind][int(rng.integers(0, len(homes[kind])))])
        ck = ld.net.checking
        how = str(rng.choice(["stuck", "flip", "intermittent"]))
        if kind in ("control", "control2"):
            # one of the slot's control bits, each as likely (a field's bits as the hardware holds
            # them: bits 0..11 of any field were drawn, most in no register, a new user's find)
            from vampc.emulator.faults import control_widths
            from vampc.program.words import FIELDS
            owner = v if kind == "control" else ck.order[ck.order.index(v) + 1]
            slot = int(rng.integers(0, len(ld.programs[owner])))
            widths = control_widths(ld, owner)
            bit = int(rng.integers(0, sum(widths)))
            field = 0
            while bit >= widths[field]:
                bit -= widths[field]
                field += 1
            reg = f"{kind}.{FIELDS[field]}.{slot}"
        else:
            reg = {"result": f"result.{'xyz'[int(rng.integers(0, 3))]}",
                   "a": f"a.{int(rng.integers(0, 9))}", "b": f"b.{int(rng.integers(0, 9))}"}[kind]
            bit = int(rng.integers(0, ld.arith.bits))
        extra = "" if how == "flip" else f",value={int(rng.integers(0, 2))}"
        if how == "intermittent":
            if kind in ("control", "control2"):   # written once: no intermittent fault
                how, extra = "stuck", extra
            else:
                how, extra = "stuck", extra + f",rate={float(rng.choice([0.05, 0.2, 0.5]))}"
        specs.append(f"vamp={v},{how}={reg}:{bit}{extra},at={t}")


def not_run(ld, kinds) -> list[str]:
    """The single campaign's (VAMP, kind) pairs that have no such fault (`_permanent` gives None),
    by kind, each said with why: they are left out of the count, and the summary says so (a new
    user found 305 faults on 153 VAMPs for two kinds and nothing saying which was missing; a
    review, control2 on every VAMP of a program without error correction)."""
    V, out = physical_vamps(ld), []
    for kind in kinds:
        none = _lacking(ld, kind)
        if not none:
            continue
        where = "every VAMP" if len(none) == V else \
            f"VAMP{'s' * (len(none) > 1)} {', '.join(map(str, none))}"
        why = ("the extraneous VAMP has no control registers of its own" if kind == "control" else
               "no error correction: no VAMP has a second set" if ld.net.checking is None else
               "the last in the check order: no second set")
        out.append(f"{kind} on {where} ({why})")
    return out


def _lacking(ld, kind: str) -> list[int]:
    """The VAMPs that have no fault of `kind` (`_permanent` gives None): the extraneous VAMP no
    control, the last of the check order no control2 (every VAMP without error correction)."""
    if kind not in ("control", "control2"):       # (the others have one on every VAMP)
        return []
    return [v for v in range(physical_vamps(ld)) if _permanent(ld, v, kind, None, 0, None) is None]


def _permanent(ld, v: int, kind: str, bit, at: int, value) -> str | None:
    if kind == "result":
        return f"vamp={v},stuck=result.x:{bit},value={value},at={at}"
    if kind in ("a", "b"):
        return f"vamp={v},stuck={kind}.0:{bit},value={value},at={at}"
    if kind == "control":
        if v >= len(ld.net.vamps):
            return None                     # E's only control registers are its successor's
        held = ld.programs[v][0].delay_r & 1
        return f"vamp={v},stuck=control.delay_r:0,value={1 - held},at={at}"
    if kind == "control2":                  # the checking's own copy of the successor's table
        ck = ld.net.checking
        if ck is None or v == ck.order[-1]:
            return None
        held = ld.programs[ck.order[ck.order.index(v) + 1]][0].delay_r & 1
        return f"vamp={v},stuck=control2.delay_r:0,value={1 - held},at={at}"
    if kind == "dead":
        return f"vamp={v},dead,at={at}"
    raise VampcError(f"--kinds: {kind!r} is no fault kind ({', '.join(KINDS)})")


# --- one run ----------------------------------------------------------------------------------

def engine_class(ld):
    if ld.net.checking is not None:
        from vampc.emulator.checking import CheckingTickEngine
        return CheckingTickEngine
    from vampc.emulator.tick import TickEngine
    return TickEngine


def reference_run(ld, ports, sets: int, seed: int) -> np.ndarray:
    """The fault-free torques; VampcError if the checking flags a mismatch without a fault."""
    engine = engine_class(ld)(ld, seed=seed)
    engine.program()
    with np.errstate(all="ignore"):
        tau = engine.run(ports, sets)
    if getattr(engine, "detections", None):
        d = engine.detections[0]
        raise VampcError(f"{ld.path}: the checking flagged VAMP {d['excised']} at tick "
                         f"{d['tick']} without any fault (a false alarm: an emulator error)")
    from vampc.emulator.driver import non_finite
    found = non_finite(ld, tau)
    if found is not None:    # (every run would be measured against it: a campaign on a robot whose
        #                      torques overflow said 100% coverage, exit 0: a new user's find)
        raise VampcError(f"{ld.path}: set {found[0] + 1} of the fault-free run, {found[1]}")
    return tau


def first_set_after(tick: int, period: int) -> int:
    """The first torque set entering after a detection at Data-Mode tick `tick`: the sets before it
    entered by the end of that cycle (run_fault's split of corrupted sets, and a results line's
    check of it)."""
    return tick // period + 1


def latency_cycles(tick: int, at: int, period: int) -> int:
    """Whole cycles from a fault's start (tick `at`) to its detection at `tick`."""
    return (tick - at) // period


def run_fault(setup: Setup, fault: Fault) -> dict:
    """One run with `fault`, classified (see the module docstring)."""
    ld, P = setup.ld, setup.ld.period
    ec = ld.net.checking is not None
    latency = ld.net.latency
    ref_bits = setup.reference.view(np.int64)
    out = {"fault": fault.text, "vamp": fault.vamp, "kind": _kind(fault)}
    engine = engine_class(ld)(ld, seed=setup.seed, faults=[fault])

    def settled(t, tau, seen) -> bool:
        if ec:
            if not engine.detections:
                return False
            first_after = first_set_after(engine.detections[0]["tick"], P)
            return t >= (first_after + TAIL) * P + latency
        done = (seen >= 0).all(axis=1)
        return bool((done & _differs(tau, ref_bits)).any())

    before = ld.arith.overflows
    try:
        engine.program()
        with np.errstate(all="ignore"):
            tau = engine.run(setup.ports, setup.sets, until=settled)
    except VampcError as exc:
        out.update({"class": "hang", "reason": str(exc).split(": ", 1)[-1]})
        return out
    finally:
        if ld.word is not None:
            # a fixed-point word's overflows in the run, which the network counts (a run whose
            # fault saturated 23 values was silent and said nothing of them: a faults audit's)
            out["overflows"] = ld.arith.overflows - before
            ld.arith.overflows = before
    done = engine.last_seen
    run_sets = int(done.sum())
    bad = done & _differs(tau, ref_bits)
    out["sets_run"] = run_sets
    detections = getattr(engine, "detections", [])
    if detections:
        d = detections[0]
        after = first_set_after(d["tick"], P)
        entered = np.arange(len(bad))
        out.update({"detected_tick": d["tick"],
                    "latency_cycles": latency_cycles(d["tick"], fault.at, P),
                    "finder": d["finder"], "excised": d["excised"],
                    "corrupted_before": int((bad & (entered < after)).sum()),
                    "corrupted_after": int((bad & (entered >= after)).sum()),
                    # (the sets run after it: a run stops TAIL sets after the detection, so
                    # corrupted_after counts among those, not over a whole run; a new user read
                    # its 0 or 9 as all a longer run spoils, where 194 of 197 sets were)
                    "sets_after": int((done & (entered >= after)).sum())})
        m = engine.maintenance()
        out["named"] = m["named"]
        out["maintenance_ticks"] = m["ticks"]
        out["named_right"] = m["named"] == [fault.vamp]
        out["class"] = run_class(out, fault.vamp)
        if out["class"] == "detected-not-corrected" or not out["named_right"]:
            out["reason"] = _escape_reason(ld, fault, d, out, m)
    else:
        out["corrupted"] = int(bad.sum())
        if bad.any():
            # (a run whose one torque set was inf was silent corruption and nothing more, though
            # vampc emulate refuses a non-finite torque: a hardware audit) still silent, for no
            # checking flagged it, but a host that checks its torques would see it: said. Written
            # for every corrupted run, so a run kept from an older results file is told apart
            out["first_wrong_non_finite"] = not bool(np.isfinite(tau[int(np.argmax(bad))]).all())
        out["class"] = run_class(out, fault.vamp)
        if bad.any() and ec:
            out["reason"] = _silent_reason(ld, fault, run_sets, engine)
        elif ec and engine.stalled is not None:     # no torque spoiled, but the checking is lost
            out["reason"] = _stall_reason(engine.stalled)
    # the checking stalled, whatever the torques: the summary counts these runs (only the runs with
    # no torque spoiled had been: 2 of the 33 a late dead-VAMP campaign stalled, an audit's)
    if ec and getattr(engine, "stalled", None) is not None:
        out["stalled"] = engine.stalled
    return out


def run_class(run: dict, vamp: int) -> str:
    """The class of a run with a fault on VAMP `vamp`, from its other fields (a run that stopped
    with an error has no `sets_run`; a detected one its `detected_tick`). A results line's class
    is checked against it."""
    if "sets_run" not in run:
        return "hang"
    if "detected_tick" in run:
        return "detected-corrected" if run["corrupted_after"] == 0 and \
            run["excised"] == vamp else "detected-not-corrected"
    return "silent-corruption" if run["corrupted"] else "masked"


def _differs(tau: np.ndarray, ref_bits: np.ndarray) -> np.ndarray:
    return (tau.view(np.int64) != ref_bits[:len(tau)]).any(axis=1)


def _kind(f: Fault) -> str:
    if f.kind == "dead":
        return "dead"
    cls = "permanent" if f.kind == "stuck" and f.rate is None else \
        "intermittent" if f.kind == "stuck" else "transient"
    return f"{cls} {f.register}"


def _escape_reason(ld, fault: Fault, d: dict, out: dict, m: dict) -> str:
    V = len(ld.net.vamps)
    if fault.vamp == V:
        return ("a fault in the extraneous checker, which nothing checks: it flagged VAMP "
                f"{d['excised']} and plays its role with the fault")
    if d["finder"] == fault.vamp:
        return ("a fault in the checker itself (its copy of its successor's result differs): it "
                f"flagged the healthy VAMP {d['excised']} and plays its role with the fault")
    if d["excised"] in m["unreachable"]:
        node = ld.graph.nodes[ld.net.vamps[d["excised"]].slots[0].node].label
        return (f"excised and replaced, but Maintenance Mode cannot name it: no torque depends on "
                f"VAMP {d['excised']}'s result ({node}), so the finder's number on its line "
                "reaches no output")
    if not out["named_right"]:
        return f"Maintenance Mode named {out['named']}, not VAMP {fault.vamp}"
    return (f"{out['corrupted_after']} of the {out['sets_after']} set(s) run after the correction "
            f"still differ (a run stops {TAIL} sets after the detection's; later sets are not run)")


def next_check(ld, vamp: int, start: int) -> int:
    """The period ending the first compare window that checks `vamp` after period `start` (with
    no detection or stall before it)."""
    from vampc.emulator.checking import check_periods, sweep_periods
    ck = ld.net.checking
    w, k, V = ck.warmup, ck.compare, len(ld.net.vamps)
    end = check_periods(ck.order.index(vamp), w, k)
    sweep = sweep_periods(V, w, k)
    return end + sweep * max(0, -(-(start + 1 - end) // sweep))


def _silent_reason(ld, fault: Fault, run_sets: int, engine) -> str:
    if fault.vamp == len(ld.net.vamps):
        return "a fault in the extraneous checker, which nothing checks"
    if engine.stalled is not None:
        return _stall_reason(engine.stalled)
    if next_check(ld, fault.vamp, fault.at // ld.period) > run_sets:
        return f"the check did not reach the VAMP after the fault within the run's {run_sets} sets"
    if fault.kind == "flip" or fault.rate is not None:
        return "not active in the compare periods that checked the VAMP"
    if fault.register == "control2":     # (not the data: a new user's find)
        return ("a fault in the checking circuitry's copy of the successor's control: the compare "
                "periods saw equal results, yet the torques were spoiled")
    return "the fault left the checked results equal in the compare periods (the data masked it)"


def _stall_reason(stalled: dict) -> str:
    doing = "checking" if stalled["phase"] == "fwd" else "the sweep came back to it"
    return (f"VAMP {stalled['vamp']} died while {doing} and its Test signal stays false: the "
            f"checking stalled at tick {stalled['tick']}, nothing is checked or named after it")


# --- a whole campaign -------------------------------------------------------------------------

def program_digest(path) -> str:
    """A program file's identity for the results file (its bytes' SHA-256, first 16 digits)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def summarise(ld, runs: list[dict], sets: int, reference_overflows: int = 0) -> dict:
    """Coverage, latency and corruption figures over a campaign's runs. `reference_overflows`: the
    fault-free run's overflow count, against which a silent run's count shows the fault."""
    by = {c: sum(1 for r in runs if r.get("class") == c) for c in CLASSES}
    effective = len(runs) - by["masked"]
    lat = sorted(r["latency_cycles"] for r in runs if "latency_cycles" in r)
    before = [r["corrupted_before"] for r in runs if "corrupted_before" in r]
    out = {"runs": len(runs), "classes": by,
           "error_correction": ld.net.checking is not None, "sets": sets,
           "coverage": (by["detected-corrected"] / effective) if effective else None,
           "silent_corruption_rate": by["silent-corruption"] / len(runs) if runs else None,
           "silent_non_finite": sum(1 for r in runs if r.get("class") == "silent-corruption"
                                    and r.get("first_wrong_non_finite")),
           # (runs kept from a results file of an older vampc, which did not look: said, not
           # counted as finite, a review's find)
           "silent_not_examined": sum(1 for r in runs if r.get("class") == "silent-corruption"
                                      and "first_wrong_non_finite" not in r)}
    if ld.word is not None:      # the silent runs whose word overflowed: the network's count shows them
        # (where the fault-free run overflows too, the count does not single the fault out: "which
        # the count shows" had been said of them, a new user's find)
        out["reference_overflows"] = reference_overflows
        out["silent_overflowed"] = sum(1 for r in runs if r.get("class") == "silent-corruption"
                                       and r.get("overflows"))
        # (runs kept from an older vampc's results file, which did not count them: said apart, as
        # silent_not_examined is, not counted as without overflow: a review's find)
        out["silent_overflows_not_examined"] = sum(1 for r in runs if r.get("class") ==
                                                   "silent-corruption" and "overflows" not in r)
    if ld.net.checking is not None:
        out["named_right"] = sum(1 for r in runs if r.get("named_right"))
        out["detected"] = len(lat)
        # (a dead checker stalls the checking for the rest of the run with no torque spoiled: a
        # masked run, and coverage said 100%, a new user's find: counted and said beside it)
        out["stalled"] = sum(1 for r in runs if r.get("stalled"))
        if lat:
            out["latency_cycles"] = {"min": lat[0], "median": lat[len(lat) // 2],
                                     "p90": lat[min(len(lat) - 1, int(0.9 * len(lat)))],
                                     "max": lat[-1], "mean": sum(lat) / len(lat),
                                     "histogram": _histogram(lat)}
            out["corrupted_before_correction"] = {"max": max(before),
                                                  "mean": sum(before) / len(before)}
        out["escapes"] = [{"fault": r["fault"], "class": r["class"],
                           "reason": r.get("reason", "")} for r in runs
                          if r.get("class") not in ("masked", "detected-corrected")
                          or (r["class"] == "detected-corrected" and not r["named_right"])
                          or r.get("stalled")]
    kinds: dict[str, dict] = {}
    for r in runs:
        k = kinds.setdefault(r["kind"], {c: 0 for c in CLASSES})
        k[r["class"]] += 1
    out["by_kind"] = kinds
    return out


def _histogram(values: list[int], bins: int = 8) -> list[dict]:
    lo, hi = values[0], values[-1]
    width = max(1, math.ceil((hi - lo + 1) / bins))
    out = []
    for b in range(lo, hi + 1, width):
        out.append({"from": b, "to": b + width - 1,
                    "runs": sum(1 for v in values if b <= v < b + width)})
    return out



# --- the results file -------------------------------------------------------------------------

SET_COUNTS = ("sets_run", "corrupted", "corrupted_before", "corrupted_after", "sets_after")
TICK_COUNTS = ("detected_tick", "maintenance_ticks")


def _a_run_of(run, faults, sets: int | None = None, period: int | None = None) -> bool:
    """Whether a results line is a run of this campaign's list `faults`, with the fields the
    summary reads of the types it reads (an edited line was a KeyError, or filed under another
    fault: `"index": true` counted as fault 1's), and its counts possible: a count of torque sets
    within the campaign's `sets`, a tick at least 0 (an edited "sets_run": -4 and "corrupted":
    1000000 of 197 sets were taken and reported), and the counts of one run consistent with each
    other and, given the program's `period`, with its detection tick (an edited
    "corrupted_before": 83 of a run of 12 sets, or "latency_cycles" 7 for 2, were taken and moved
    the summary's means: a new user's find)."""
    def whole(x) -> bool:
        return type(x) is int
    if not isinstance(run, dict) or not whole(run.get("index")) or \
            not 0 <= run["index"] < len(faults) or run.get("fault") != faults[run["index"]]:
        return False
    if any(k in run and not (whole(run[k]) and run[k] >= 0) for k in SET_COUNTS + TICK_COUNTS) or \
            sets is not None and any(run.get(k, 0) > sets for k in SET_COUNTS):
        return False
    fault = parse_fault(run["fault"])
    if run.get("class") not in CLASSES or run.get("kind") != _kind(fault) or \
            not whole(run.get("vamp")) or run["vamp"] != fault.vamp:
        return False          # (the kind and VAMP follow from the fault: edited ones were taken)
    if run["class"] == "detected-corrected" and "named_right" not in run:
        return False          # (the summary reads it of every corrected run: a KeyError)
    if run["class"] != run_class(run, fault.vamp):
        return False          # (an edited "class": "masked" of a corrupted run was counted masked)
    if "sets_run" in run and (run.get("corrupted", 0) > run["sets_run"] or
                              run.get("corrupted_before", 0) + run.get("corrupted_after", 0) > run["sets_run"]
                              or run.get("sets_after", 0) > run["sets_run"]):
        return False
    if "sets_after" in run and run.get("corrupted_after", 0) > run["sets_after"]:
        return False
    if period is not None and "detected_tick" in run:
        # run_fault's own rules: the sets entering before the detection's cycle ends, and the
        # whole cycles from the fault's start to it
        if run.get("corrupted_before", 0) > first_set_after(run["detected_tick"], period) or \
                run.get("latency_cycles") != latency_cycles(run["detected_tick"], fault.at, period):
            return False
    return all(whole(run[k]) for k in ("latency_cycles", "corrupted_before") if k in run) and \
        all(isinstance(run[k], bool) for k in ("named_right", "first_wrong_non_finite") if k in run)


class ResultsFile:
    """A campaign's results as JSON Lines: a header naming the campaign, then one line per run as it
    finishes (`index` into the campaign's faults). A re-run with the same header resumes: the runs
    on file are kept and not run again; a last line cut short (a run interrupted mid-write) is
    dropped. A file holding another campaign is refused, never overwritten."""

    def __init__(self, path: str, header: dict, default: bool = False, period: int | None = None):
        self.path, self.header = path, header
        self.period = period            # the program's: a run's counts checked against its ticks
        self.default = default          # the path is the default one, not the user's --results
        self.done: dict[int, dict] = {}
        self.added = 0                  # runs added by this run (a Ctrl-C before open() asks too)
        self._fh = None

    @property
    def called(self) -> str:
        """The file as messages name it: the option the user gave, or that it is the default."""
        return f"{self.path} (the default results file)" if self.default else f"--results {self.path}"

    def load(self) -> None:
        """Read what an earlier run of this campaign left (VampcError for another campaign's file)."""
        from vampc import jsontext
        if os.path.islink(self.path) or os.path.exists(self.path) and not os.path.isfile(self.path):
            # (a dangling link too: it had been written through, a link to a file refused)
            raise VampcError(f"{self.called}: not a regular file (a link or a device is "
                             "never written)")
        if not os.path.exists(self.path):
            return
        with open(self.path, "rb") as fh:
            data = fh.read()
        self._read = len(data)            # (open checks that nobody wrote to it since)
        not_ours = VampcError(f"{self.called} is not a results file of vampc faults (never "
                              "overwritten; give " + ("--results FILE" if self.default else
                                                      "another --results file") + ")")
        if b"\n" not in data:
            if not (jsontext.dumps(self.header).encode() + b"\n").startswith(data):
                raise not_ours
            self._truncate = 0                # made, but stopped in its header: a new file
            self._fresh = True
            return
        lines = data.split(b"\n")
        good = len(data) if data.endswith(b"\n") else len(data) - len(lines[-1])
        lines = data[:good].split(b"\n")      # a last line with no newline was cut: run again
        try:
            head = jsontext.loads(lines[0]) if lines and lines[0] else None
        except ValueError:
            head = None
        if not isinstance(head, dict) or "vampc_faults" not in head:
            # (binary or UTF-16 text in the default file was "the results of another campaign
            # (another program ...)": a file-safety audit)
            raise not_ours
        if head != self.header:
            what = _differing(head, self.header)
            if self.default:      # (the user gave no --results: "--results X" named an option
                #                    they never wrote, after a default run with other --kinds)
                raise VampcError(f"{self.path}, the default results file, holds the results of "
                                 "another campaign (" + (what or "another program or robot file "
                                 "by that name, or other --kinds, --sets, --seed, faults or "
                                 "compile options") + "): give --results FILE for this one, or "
                                 "remove it to start over")
            raise VampcError(f"--results {self.path}: it holds the results of another campaign or "
                             "program (" + (f"{what}; " if what else "") + "give another --results "
                             "file, or remove it to start over)")
        line_of: dict[int, int] = {}
        for k, line in enumerate(lines[1:], 2):
            if not line.strip():
                continue
            try:
                run = jsontext.loads(line)
                if not _a_run_of(run, self.header["faults"], self.header.get("sets"), self.period):
                    raise ValueError(line)
            except (ValueError, KeyError, TypeError):
                if sum(len(x) + 1 for x in lines[:k]) <= good:      # not just a cut-short last line
                    raise VampcError(f"{self.called}: line {k} is not a run's result "
                                     "(the file was edited; remove it to start over)") from None
                continue
            if run["index"] in line_of:       # (the later line silently replaced the earlier one)
                raise VampcError(f"{self.called}: lines {line_of[run['index']]} and {k} are "
                                 f"both run {run['index']}'s result (the file was edited; remove it "
                                 "to start over)")
            line_of[run["index"]] = k
            self.done[run["index"]] = run
        self._truncate = good

    def open(self) -> None:
        """Ready to append (the header written if the file is new)."""
        from vampc import jsontext
        self.created = not os.path.exists(self.path)
        fresh = self.created or getattr(self, "_fresh", False)
        self.added = 0
        try:
            self._fh = open(self.path, "ab")
            self._lock()
            if getattr(self, "_truncate", None) is not None:
                self._fh.truncate(self._truncate)
            if fresh:
                self._fh.write(jsontext.dumps(self.header).encode() + b"\n")
            self._fh.flush()
        except OSError as exc:
            raise self._cannot(exc) from None

    def _lock(self) -> None:
        """Hold the file for this run alone: two campaigns given one results file wrote 244 lines
        for 122 runs, and the next run called the file edited (a file-safety audit). The second
        is refused, and so is a run whose file another wrote to after it was read."""
        try:
            import fcntl
        except ImportError:                  # (no fcntl, as on Windows: unguarded)
            return
        held = False
        try:
            fcntl.flock(self._fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            held = True                      # another run holds it
        except OSError:                      # (no locks on this file system, NFS without lockd or
            pass                             # some FUSE mounts: not another run's, unguarded)
        if not held and os.fstat(self._fh.fileno()).st_size == getattr(self, "_read", 0):
            return
        fh, self._fh = self._fh, None
        fh.close()
        self.created = False                 # (the other run's file, whoever made it: kept)
        raise VampcError(f"{self.called} " + (
            "is being written by another vampc faults run now: wait for it to end (a re-run then "
            "resumes from its results), or give another --results file" if held else
            "was written by another vampc faults run after this one read it: run the command again "
            "to resume from what it holds now"))

    def add(self, index: int, run: dict) -> None:
        from vampc import jsontext
        run = {"index": index, **run}
        try:
            self._fh.write(jsontext.dumps(run).encode() + b"\n")
            self._fh.flush()
        except OSError as exc:       # (a full disk: a traceback and "internal error", exit 3)
            raise self._cannot(exc) from None
        self.done[index] = run       # (kept once written: what _cannot says is kept)
        self.added += 1

    def _cannot(self, exc: OSError) -> VampcError:
        # (before any run's result there is nothing to resume from: a full disk under a new
        # results file had been said to keep "the results written before": a new user's find)
        kept = ("the results written before are kept: the same command resumes from them"
                if self.done else "no run's result had been written")
        return VampcError(f"{self.called}: cannot write: {exc.strerror or exc} ({kept})")

    def close(self, failed: bool = False) -> None:
        """Close; a file this run made and added no result to is removed if it failed."""
        if self._fh is not None:
            fh, self._fh = self._fh, None
            try:
                fh.close()
            except OSError as exc:       # (what a full disk kept in the buffer)
                if not failed:
                    raise self._cannot(exc) from None
            if failed and self.created and not self.added:
                os.unlink(self.path)


# --- rendering --------------------------------------------------------------------------------

CSV_COLUMNS = ("index", "fault", "vamp", "kind", "class", "sets_run", "detected_tick",
               "latency_cycles", "finder", "excised", "named", "named_right", "corrupted_before",
               "corrupted_after", "sets_after", "corrupted", "maintenance_ticks", "reason",
               "first_wrong_non_finite",
               "overflows")     # (a narrower word's, as the JSON's runs have them; empty in float64)
LABELS = {"masked": "masked", "detected-corrected": "detected and corrected",
          "detected-not-corrected": "detected, not corrected",
          "silent-corruption": "silent corruption", "hang": "hang"}


def _differing(head, header: dict) -> str | None:
    """What a results file's header and this campaign's differ in, said ("565 sets a run, not
    1488, other faults"): a default random campaign's file of an earlier vampc, whose
    default length was shorter, was refused as if --sets had been given. None if it is no header."""
    if not isinstance(head, dict) or head.get("vampc_faults") != header.get("vampc_faults"):
        return None
    said = {"program": _other_program(head.get("program"), header["program"]),
            "campaign": f"the {head.get('campaign')} campaign, not "
            f"{header['campaign']}", "sets": f"{head.get('sets')} sets a run, not {header['sets']}",
            "seed": f"seed {head.get('seed')}, not {header['seed']}", "faults": _other_faults(head, header)}
    differ = [key for key in said if head.get(key) != header.get(key)]
    text = ", ".join(said[key] for key in differ) or None
    if differ and set(differ) <= {"sets", "faults"}:
        # the same program, campaign and seed: another --sets or --kinds, or an earlier vampc, which
        # drew other faults and ran other lengths for them (a user's file from before an upgrade
        # was said to be "another campaign or program" alone: an audit of old files)
        text += ("; the same program, campaign and seed: other options, or a file an earlier "
                 "vampc wrote, which drew other faults or ran other lengths")
    return text


def _other_program(theirs, ours: str) -> str:
    """How the file's program differs from this campaign's (their identities: the file's digest,
    then for a robot file its compile options, then for a what-if --word the word run): a what-if
    word run after the program's own campaign was said to be "another program" (a new user's)."""
    if not isinstance(theirs, str):
        return "another program"
    (base_t, _, rest_t), (base_o, _, rest_o) = theirs.partition(":"), ours.partition(":")
    if base_t != base_o:
        return "another program or robot file"
    if not rest_t.startswith("{") and not rest_o.startswith("{"):     # a program file's words
        own = "the program's own"
        return f"another word: {rest_t or own} in the file, {rest_o or own} here"
    return "the same robot file compiled with other options or --word"


def _other_faults(head: dict, header: dict) -> str:
    """How the file's faults differ from this campaign's: their counts and the first that differs
    ("other faults" alone left a new user to guess: another --kinds, a subset of them)."""
    theirs = head.get("faults") if isinstance(head.get("faults"), list) else []
    ours = header["faults"]
    n = min(len(theirs), len(ours))
    k = next((i for i in range(n) if theirs[i] != ours[i]), n)
    said = f"other faults, {len(theirs)} in the file and {len(ours)} here"
    if k < n:
        return f"{said}; the first that differs is fault {k + 1}: {theirs[k]!r} in the file, {ours[k]!r} here"
    if len(theirs) != len(ours):
        longer, where = (theirs, "in the file") if len(theirs) > n else (ours, "here")
        return f"{said}; fault {k + 1} on, {longer[k]!r} first, only {where}"
    return said


def render_csv(runs: list[dict]) -> str:
    import csv
    import io
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for r in runs:
        w.writerow(["" if r.get(c) is None else " ".join(map(str, r[c])) if isinstance(r.get(c), list)
                    else r[c] for c in CSV_COLUMNS])
    return buf.getvalue()


def render_text(head: str, summary: dict) -> str:
    n = summary["runs"]
    pct = lambda k: f"{100 * k / n:.1f}%" if n else "-"           # noqa: E731
    lines = [head]
    for c in CLASSES:
        k = summary["classes"][c]
        lines.append(f"  {LABELS[c]:<26}{k:>6}  ({pct(k)})")
    if summary["coverage"] is not None:
        lines.append(f"coverage (detected and corrected, of the faults not masked): "
                     f"{100 * summary['coverage']:.1f}%" + (
                         "" if summary["error_correction"] else
                         " (error correction off: nothing checks; a program compiled with "
                         "--error-correction does, README Error correction)"))
    seen, unseen = summary.get("silent_non_finite", 0), summary.get("silent_not_examined", 0)
    if summary.get("stalled"):
        lines.append(f"checking stalled: in {summary['stalled']} of {n} runs nothing was checked after "
                     "a point (a dead VAMP's Test signal; escapes below), which coverage does not show")
    lines.append(f"silent corruption: {summary['classes']['silent-corruption']} of {n} runs "
                 f"({pct(summary['classes']['silent-corruption'])})"
                 + (f"; in {seen} of them the first wrong torque set holds an inf or NaN, which a "
                    "host that checks its torques sees (vampc emulate refuses it)" if seen else "")
                 + ((f"; in {summary['silent_overflowed']} of them the word overflowed, which the "
                     "network's overflow count shows (vampc emulate says it)"
                     if not summary.get("reference_overflows") else
                     f"; in {summary['silent_overflowed']} of them the word overflowed, but so did "
                     "the fault-free run, so the network's overflow count does not single them out")
                    if summary.get("silent_overflowed") else "")
                 + (f"; {summary['silent_overflows_not_examined']} read from a results file of an "
                    "older vampc were not examined for overflows"
                    if summary.get("silent_overflows_not_examined") else "")
                 + (f"; {unseen} read from a results file of an older vampc were not examined for "
                    "an inf or NaN" if unseen else ""))
    if summary["error_correction"]:
        lines.append(f"faulty VAMP named in Maintenance Mode: {summary['named_right']} of "
                     f"{summary['detected']} detected")
        lat = summary.get("latency_cycles")
        if lat:
            lines.append(f"detection latency, cycles from the fault: min {lat['min']}, median "
                         f"{lat['median']}, 90% {lat['p90']}, max {lat['max']} (mean "
                         f"{lat['mean']:.1f})")
            bars = "  ".join(f"{b['from']}-{b['to']}: {b['runs']}" for b in lat["histogram"])
            lines.append(f"  runs by latency: {bars}")
            cb = summary["corrupted_before_correction"]
            # (over every detected run, corrected or not: it read as the corrected runs' alone,
            # a new user's find)
            lines.append(f"torque sets corrupted before the detection, over the "
                         f"{summary['detected']} detected runs: max {cb['max']}, mean {cb['mean']:.1f}")
    lines.append("by kind:")
    width = max((len(k) for k in summary["by_kind"]), default=4) + 2
    lines.append("  " + "kind".ljust(width) + "".join(f"{LABELS[c]:>26}" for c in CLASSES))
    for kind, counts in summary["by_kind"].items():
        lines.append("  " + kind.ljust(width) + "".join(f"{counts[c]:>26}" for c in CLASSES))
    esc = summary.get("escapes")
    if esc:
        # (what an escape is, said: a new user read "detected and corrected" and "masked" runs
        # listed as escapes as a mistake)
        lines.append(f"escapes ({len(esc)}): runs the checking did not handle in full (a torque "
                     "spoiled unflagged, a fault not corrected, the faulty VAMP not named, the "
                     "checking stalled, or the run hung)")
        for e in esc:
            lines.append(f"  {e['fault']}: {LABELS[e['class']]}: {e['reason']}")
    elif summary["error_correction"]:
        lines.append("escapes: none")
    return "\n".join(lines)
