"""Clock rates: `--clock F` turns flops into time (one flop per tick, as the paper's timing model and
the emulator have it): latency and interval in µs, torque sets per second, and which control rates
the design serves (one torque set within each control period)."""
from __future__ import annotations

import math
import re

UNITS = {"": 1.0, "hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9}
CONTROL_RATES = (1_000, 10_000)
_CLOCK = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([a-zA-Z]*)\s*$")


def parse_clock(text: str) -> float:
    """A clock rate in Hz from '20MHz', '20 MHz', '1.5GHz', '500kHz', '4e7' (Hz); the unit's case
    does not matter. ValueError with the reason for anything else, zero or more than 1 THz."""
    m = _CLOCK.match(text)
    unit = m.group(2).lower() if m else None
    if not m or unit not in UNITS:
        raise ValueError(f"{text!r} is not a clock rate (a number with Hz, kHz, MHz or GHz, "
                         "e.g. 20MHz)")
    hz = float(m.group(1)) * UNITS[unit]
    if not math.isfinite(hz) or hz <= 0 or hz > 1e12:
        raise ValueError(f"{text!r}: a clock rate must be above 0 and at most 1 THz")
    return hz


def hz_text(hz: float) -> str:
    """'20 MHz', '1.5 GHz', '500 kHz', '60 Hz'."""
    for unit, scale in (("GHz", 1e9), ("MHz", 1e6), ("kHz", 1e3)):
        if hz >= scale:
            return f"{hz / scale:.4g} {unit}"
    return f"{hz:.4g} Hz"


def us_text(x: float) -> str:
    """Microseconds for a table: '3.05', '0.2', '118,691'."""
    return f"{x:,.0f}" if x >= 1000 else f"{x:g}"


def us(flops: float, hz: float) -> float:
    """Microseconds for `flops` ticks at `hz` (rounded to 6 significant digits)."""
    return float(f"{flops / hz * 1e6:.6g}")


def per_second(flops: float, hz: float) -> float:
    """How many times per second something taking `flops` ticks happens at `hz`."""
    return float(f"{hz / flops:.6g}")


def clock_figures(latency: int, interval: int, load_ticks: int, hz: float) -> dict:
    """Latency, interval and load time in µs, torque sets per second, and the control rates the
    design meets: a control loop at rate R needs each set's torques within 1/R of its state, and a
    new set every 1/R, so R ≤ clock / max(latency, interval)."""
    bound = max(latency, interval)
    fastest = hz / bound
    return {"hz": hz, "text": hz_text(hz), "tick_ns": float(f"{1e9 / hz:.6g}"),
            "latency_us": us(latency, hz), "interval_us": us(interval, hz),
            "sets_per_second": per_second(interval, hz), "load_us": us(load_ticks, hz),
            "max_control_rate_hz": float(f"{fastest:.6g}"),
            "limited_by": "latency" if latency >= interval else "interval",
            "control_rates": [{"hz": r, "met": r <= fastest,
                               "margin": float(f"{fastest / r:.3g}")} for r in CONTROL_RATES]}


def control_sentence(fig: dict) -> str:
    """What the clock means for control, in one sentence."""
    met = [hz_text(r["hz"]) for r in fig["control_rates"] if r["met"]]
    missed = [hz_text(r["hz"]) for r in fig["control_rates"] if not r["met"]]
    parts = []
    if met:
        parts.append(f"meets {' and '.join(met)} control")
    if missed:
        parts.append(f"does not meet {' and '.join(missed)} control")
    return (f"at {fig['text']} the design {', '.join(parts)}: one torque set within each control "
            f"period up to {hz_text(fig['max_control_rate_hz'])} (bound by its {fig['limited_by']}, "
            f"{fig['latency_us'] if fig['limited_by'] == 'latency' else fig['interval_us']:g} µs), "
            f"and {fig['sets_per_second']:,.0f} torque sets per second when sets are pipelined")


def add_clock(rep: dict, hz: float) -> None:
    """Add times at `hz` to every figure of a report that is counted in flops."""
    own = rep["latency"]["flops"], rep["interval_flops"], rep["hardware"]["load_ticks"]
    rep["clock"] = clock_figures(*own, hz)
    for row in rep["table_o1"]["formulas"]:
        row["time_us"] = us(row["flops"], hz)
        if row["measure"] == "interval":
            row["sets_per_second"] = per_second(row["flops"], hz)
    for row in rep["table_o1"]["measured"]:
        row["time_us"] = us(row["flops"], hz)
        if "interval_flops" in row:
            row["interval_us"] = us(row["interval_flops"], hz)
            row["sets_per_second"] = per_second(row["interval_flops"], hz)
    for row in rep.get("layout_comparison", []):
        row["latency_us"] = us(row["latency_flops"], hz)
        row["interval_us"] = us(row["interval_flops"], hz)
        row["sets_per_second"] = per_second(row["interval_flops"], hz)
        if "load_ticks" in row:
            row["load_us"] = us(row["load_ticks"], hz)
    for row in rep.get("prefix_comparison", []):
        row["latency_us"] = us(row["latency_flops"], hz)
