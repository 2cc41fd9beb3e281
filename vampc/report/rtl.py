"""The figures of `vampc rtl --synth ecp5 [--pnr] --format json` in the report (`report --rtl
FILE.json`): the synthesized cells of each kind of VAMP and of the network, and the clock the
slowest VAMP reaches (README, RTL)."""
from __future__ import annotations

from vampc import jsontext
from vampc.errors import VampcError


def rtl_figures(path: str, c) -> dict:
    """The report's `rtl` section from the JSON at `path`, checked to be this program's design."""
    try:
        with open(path, encoding="utf-8") as f:
            doc = jsontext.loads(f.read())
    except OSError as exc:
        raise VampcError(f"{path}: cannot read: {exc.strerror}") from None
    except ValueError as exc:
        raise VampcError(f"{path}: not JSON ({exc})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("synth"), dict) or \
            not isinstance(doc["synth"].get("kinds"), dict) or "network" not in doc["synth"]:
        raise VampcError(f"{path}: not the output of `vampc rtl --synth ecp5 --format json` (no "
                         "synth.kinds and synth.network)")
    word = c.options.word
    vamps = len(c.network.vamps) if c.network is not None else None
    for what, theirs, ours in (("robot", doc.get("robot"), c.chain.name),
                               ("word", doc.get("word"), word), ("VAMPs", doc.get("vamps"), vamps)):
        if theirs != ours:
            raise VampcError(f"{path}: the figures are of another design ({what} {theirs!r}, this "
                             f"program's {ours!r})")
    kinds, fmax = [], []
    for name, k in doc["synth"]["kinds"].items():
        row = {"kind": name, "vamps": int(k["vamps"]), "LUT4": int(k["LUT4"]),
               "MULT18X18D": int(k["MULT18X18D"]), "flip_flops": int(k["flip_flops"])}
        clocks = (k.get("pnr") or {}).get("fmax_mhz") or {}
        if clocks:
            row["fmax_mhz"] = float(min(clocks.values()))
            fmax.append(row["fmax_mhz"])
        kinds.append(row)
    net = doc["synth"]["network"]
    out = {"file": str(path), "target": doc["synth"].get("target", "ecp5"), "kinds": kinds,
           "network": {"LUT4": int(net["LUT4"]), "MULT18X18D": int(net["MULT18X18D"]),
                       "flip_flops": int(net["flip_flops"]), "cells": int(net["total"])},
           "vamps_sum": {key: sum(r[key] * r["vamps"] for r in kinds)
                         for key in ("LUT4", "MULT18X18D", "flip_flops")},
           "fmax_mhz": min(fmax) if len(fmax) == len(kinds) and fmax else None}
    return out


def rtl_pairs(r: dict | None) -> list[tuple[str, str]]:
    """The section as (label, text) rows for the text and markdown reports."""
    if not r:
        return []
    n = r["network"]
    out = [("synthesized (" + r["target"] + ")",
            f"the network {n['LUT4']} LUT4, {n['MULT18X18D']} MULT18X18D, {n['flip_flops']} "
            f"flip-flops ({r['file']})")]
    for k in r["kinds"]:
        fmax = f", Fmax {k['fmax_mhz']:g} MHz" if "fmax_mhz" in k else ""
        out.append((f"  a VAMP, {k['kind']}", f"{k['LUT4']} LUT4, {k['MULT18X18D']} MULT18X18D, "
                                               f"{k['flip_flops']} flip-flops{fmax} "
                                               f"({k['vamps']} such)"))
    if r["fmax_mhz"] is not None:
        out.append(("  clock", f"{r['fmax_mhz']:g} MHz, the slowest VAMP's Fmax (one VAMP placed "
                               "and routed on its own: the network's wiring may lower it)"))
    return out
