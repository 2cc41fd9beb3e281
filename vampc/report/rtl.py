"""The figures of `vampc rtl --synth ecp5 [--pnr] --format json` in the report (`report --rtl
FILE.json`): the synthesized cells of each kind of VAMP and of the network, and the clock the
slowest VAMP reaches (README, RTL)."""
from __future__ import annotations

from vampc import jsontext
from vampc.errors import VampcError
from vampc.report.clock import FASTEST_HZ, RATE_RANGE_TEXT, SLOWEST_HZ
from vampc.textio import shown


def kind_name(kind) -> str:
    """A kind of VAMP (slots, operand-A inputs, operand-B inputs: Vamp.kind) as `vampc rtl`'s
    figures name it."""
    slots, a, b = kind
    return f"{slots} slot(s), {a}+{b} inputs"


def unrendered(net) -> tuple[str, str] | None:
    """What of the network `vampc rtl` does not render yet (README, RTL: Limits), and how to compile
    without it; None if it renders it all."""
    if net.bus is not None:
        return "the Mostly-Local Bus (--bus mlb)", "compile with the point-to-point wiring (--bus p2p)"
    if net.checking is not None:
        return "error correction's checking (--error-correction)", "compile without it"
    return None


def rtl_figures(path: str, c) -> dict:
    """The report's `rtl` section from the JSON at `path`, checked to be this program's design."""
    missing = unrendered(c.network) if c.network is not None else None
    if missing:
        what, _ = missing
        raise VampcError(f"{path}: the figures are of another design: this program has {what}, "
                         "which `vampc rtl` does not render, so its hardware is not in them "
                         "(README, RTL: Limits)")
    text = ""
    try:     # (read as every input is: a character device refused, a pipe's NUL byte; a review's)
        from vampc.textio import decode_utf8, read_whole
        text = decode_utf8(read_whole(path, text=True), path, "figures file")
        doc = jsontext.loads(text)
    except OSError as exc:
        raise VampcError(f"{path}: cannot read: {exc.strerror}") from None
    except jsontext.DecodeError as exc:      # (said with its line and column: a new user's find)
        raise VampcError(f"{path}: not JSON: {jsontext.decode_problem(exc, text)}") from None
    except ValueError as exc:
        raise VampcError(f"{path}: not JSON: {exc}") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("synth"), dict) or \
            not isinstance(doc["synth"].get("kinds"), dict) or not doc["synth"]["kinds"] or \
            "network" not in doc["synth"]:
        raise VampcError(f"{path}: not the output of `vampc rtl --synth ecp5 --format json` (no "
                         "synth.kinds and synth.network)")
    word = c.options.word
    if not word.startswith("q"):   # (a float program's report took them: an audit's)
        raise VampcError(f"{path}: the figures are of another design: this program's words are "
                         f"{word}, and `vampc rtl` renders fixed-point words only (README, RTL)")
    net = c.network
    vamps = len(net.vamps) if net is not None else None
    same = [("robot", "robot", c.chain.name), ("word", "word", word), ("vamps", "VAMPs", vamps)]
    same += [(key, key.replace("_", " "), getattr(c.options, key))      # (files since 2026-12-03)
             for key in ("rounding", "overflow", "mult_latency", "add_latency") if key in doc]
    if net is not None:     # (files since 2026-12-06: a one-joint arm's folded figures, its kinds
        #                     and count those of the systolic network, were taken for it)
        same += [(key, what, ours) for key, what, ours in (
            ("period", "period in ticks", net.period),
            ("latency_ticks", "latency in ticks", net.latency)) if key in doc]

    def another(what, theirs, ours) -> None:
        if theirs != ours:
            raise VampcError(f"{path}: the figures are of another design ({what} {theirs!r}, this "
                             f"program's {ours!r})")
    def not_its_output(what: str) -> VampcError:
        return VampcError(f"{path}: {what} (the file is not `vampc rtl --synth ecp5 --format "
                          "json`'s, or was edited)")
    for key, what, ours in same:
        theirs = doc.get(key)
        # (of the type `vampc rtl` writes: true for 1 and 60.0 for 60 passed Python's ==, and a
        # missing key was said as "VAMPs None": an audit's and a new user's finds)
        if ours is not None and type(theirs) is not type(ours):
            kind = "a count" if type(ours) is int else "a name"
            raise not_its_output(f"no {key}" if theirs is None else f"{key} is {theirs!r}, not {kind}")
        another(what, theirs, ours)
    def field(table, key: str, where: str):
        """A count of the file: a whole number, at least 0 (VampcError naming it otherwise: a
        missing or edited one was a KeyError, a ValueError or a ZeroDivisionError)."""
        x = table.get(key) if isinstance(table, dict) else None
        if type(x) is not int or x < 0:
            raise not_its_output(f"synth.{where}.{key} is {x!r}, not a count")
        return x

    def mhz(x, where: str) -> float:
        """An Fmax: a number of MHz in the --clock range (clock.SLOWEST_HZ to FASTEST_HZ): a
        negative one had been used as the clock."""
        if type(x) not in (int, float) or not SLOWEST_HZ / 1e6 <= x <= FASTEST_HZ / 1e6:
            raise VampcError(f"{path}: {where} is {x!r}, not a clock rate in MHz (one "
                             f"{RATE_RANGE_TEXT})")
        return float(x)
    kinds, fmax = [], []
    for name, k in doc["synth"]["kinds"].items():
        at = f"kinds.{name}"
        row = {"kind": name, "vamps": field(k, "vamps", at), "LUT4": field(k, "LUT4", at),
               "MULT18X18D": field(k, "MULT18X18D", at), "flip_flops": field(k, "flip_flops", at)}
        if "pnr" in k:          # (`vampc rtl --pnr`'s: every kind's, each with its clocks)
            clocks = k["pnr"].get("fmax_mhz") if isinstance(k["pnr"], dict) else None
            if not isinstance(clocks, dict) or not clocks:
                # (a pnr of "x" or clocks {} were taken as no place and route, and the report
                # gave no times, unsaid: a new user's find)
                raise VampcError(f"{path}: synth.{at}.pnr.fmax_mhz is not a table of clocks")
            row["fmax_mhz"] = min(mhz(v, f"synth.{at}.pnr.fmax_mhz.{c}") for c, v in clocks.items())
            fmax.append(row["fmax_mhz"])
        kinds.append(row)
    if 0 < len(fmax) < len(kinds):
        bare = next(r["kind"] for r in kinds if "fmax_mhz" not in r)
        raise VampcError(f"{path}: synth.kinds.{bare} has no pnr where other kinds have one (the "
                         "file was edited)")
    if c.network is not None:
        # the VAMPs of each kind (slots, multiplexer inputs) the figures are of, against this
        # network's: a file of another network with the robot, word and VAMP count was taken
        from collections import Counter
        ours = Counter(kind_name(v.kind) for v in c.network.vamps)
        theirs = {r["kind"]: r["vamps"] for r in kinds}
        odd = [n for n in sorted(set(theirs) | set(ours)) if theirs.get(n) != ours.get(n)]
        if odd:      # (every kind that differs: one a run had a new user find four in four runs)
            raise VampcError(f"{path}: the figures are of another design (" + "; ".join(
                f"VAMPs of kind {shown(n)} {theirs.get(n, 0)}, this program's {ours.get(n, 0)}"
                for n in odd) + ")")
    target = doc["synth"].get("target", "ecp5")
    if target != "ecp5":     # (the one `vampc rtl --synth` has; a number here was exit 3)
        raise VampcError(f"{path}: synth.target is {target!r}, not 'ecp5', the one target of "
                         "`vampc rtl --synth` (the file was edited, or is not its output)")
    net = doc["synth"]["network"]          # (null: its synthesis left out by --max-minutes)
    out = {"file": str(path), "target": target, "kinds": kinds,
           "network": None if net is None else {
               "LUT4": field(net, "LUT4", "network"),
               "MULT18X18D": field(net, "MULT18X18D", "network"),
               "flip_flops": field(net, "flip_flops", "network"),
               "cells": field(net, "total", "network")},
           "vamps_sum": {key: sum(r[key] * r["vamps"] for r in kinds)
                         for key in ("LUT4", "MULT18X18D", "flip_flops")},
           "fmax_mhz": min(fmax) if fmax else None}
    if net is not None and "period" not in doc:    # (an older file: taken, not in silence)
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(
            f"{path}: written before `vampc rtl` gave the period and latency, so they are not "
            "compared: the figures are taken as this network's by its robot, word and kinds of "
            "VAMP alone"), stacklevel=2)
    return out


def _cells(t: dict) -> str:
    return f"{t['LUT4']:,} LUT4, {t['MULT18X18D']:,} MULT18X18D, {t['flip_flops']:,} flip-flops"


def rtl_pairs(r: dict | None) -> list[tuple[str, str]]:
    """The section as (label, text) rows for the text and markdown reports."""
    if not r:
        return []
    n = r["network"]
    # (labels within the summary's column, numbers with separators as every other count of the
    # report: "synthesized (ecp5) the network 135472 LUT4" ran label into figures, a new user's find)
    out = [("RTL synthesis",
            f"{r['target']}: " + (f"the network {_cells(n)} ({r['file']})" if n is not None else
                                  "each kind of VAMP; the network's synthesis is not in the file "
                                  f"(`vampc rtl` leaves it out beyond --max-minutes) ({r['file']})"))]
    for k in r["kinds"]:
        fmax = f", Fmax {k['fmax_mhz']:g} MHz" if "fmax_mhz" in k else ""
        out.append(("  a VAMP kind", f"{k['kind']}: {_cells(k)}{fmax} ({k['vamps']:,} such)"))
    # (in the JSON only: the text left out the one whole-design figure a network's synthesis
    # left out by --max-minutes leaves: a new user's find)
    out.append(("  every VAMP", f"{_cells(r['vamps_sum'])} (each kind's cells × its number of VAMPs)"))
    if r["fmax_mhz"] is not None:
        out.append(("  clock", f"{r['fmax_mhz']:g} MHz, the slowest VAMP's Fmax (one VAMP placed "
                               "and routed on its own: the network's wiring may lower it)"))
    return out
