"""Clock rates: `--clock F` turns flops into time (one flop per tick, as the paper's timing model and
the emulator have it): latency and interval in µs, torque sets per second, and which control rates
the design serves (one torque set within each control period)."""
from __future__ import annotations

import math
import re
from decimal import Decimal
from fractions import Fraction

UNITS = {"hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9}
# the paper's "about 60Hz or faster" (section I: a manipulator's resonances near 10 Hz), then two
# rates of today's controllers (the paper's was not set beside: a check against the paper)
CONTROL_RATES = (60, 1_000, 10_000)
# The clock rates vampc takes, in Hz (--clock, --rate, a synthesis report's Fmax): a rate of 1e-300 Hz
# made the times of a report infinite, and JSON has no such number
SLOWEST_HZ, FASTEST_HZ = 1e-3, 1e12
RATE_RANGE_TEXT = "at least 0.001 Hz and at most 1000 GHz"      # (said in units parse_clock takes)
_CLOCK = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([a-zA-Z]*)\s*$")


def parse_clock(text: str) -> float:
    """A clock rate in Hz from '20MHz', '20 MHz', '1.5GHz', '500kHz', '4e7Hz'; the unit's case
    does not matter, but it must be there ('20' could be 20 Hz or 20 MHz). ValueError with the
    reason for anything else, below 0.001 Hz or above 1000 GHz (bounds said in units it takes)."""
    m = _CLOCK.match(text)
    unit = m.group(2).lower() if m else None
    if m and not unit:
        x = float(m.group(1))
        if not any(SLOWEST_HZ <= x * scale <= FASTEST_HZ for scale in UNITS.values()):
            raise ValueError(f"{text!r} has no unit, and no unit (Hz, kHz, MHz, GHz) makes it a rate "
                             f"{RATE_RANGE_TEXT}")
        raise ValueError(f"{text!r} has no unit: give Hz, kHz, MHz or GHz (e.g. {m.group(1)}MHz)")
    if m and m.group(2) == "mHz":             # millihertz, or a slip for MHz: say which
        raise ValueError(f"{text!r}: mHz is millihertz; write MHz for megahertz")
    if not m or unit not in UNITS:
        raise ValueError(f"{text!r} is not a clock rate (a number with Hz, kHz, MHz or GHz, "
                         "e.g. 20MHz)")
    hz = float(m.group(1)) * UNITS[unit]
    if not math.isfinite(hz) or hz < SLOWEST_HZ or hz > FASTEST_HZ:
        raise ValueError(f"{text!r}: a clock rate must be {RATE_RANGE_TEXT}")
    return hz


SI = (("G", 1e9), ("M", 1e6), ("k", 1e3), ("", 1.0))


def si_text(x: float, unit: str, rounded_down: bool = False) -> str:
    """x with a G, M or k prefix to `unit` and at most 4 significant digits (rounded down where
    asked: a rate met up to it): si_text(2e7, "Hz") is '20 MHz', si_text(1.26e9, " scalars/s")
    '1.26 G scalars/s', si_text(12, " scalars/s") '12 scalars/s'."""
    for prefix, scale in SI:
        if x >= scale or not prefix:
            shown = down(exact(x) / Fraction(scale), 4) if rounded_down else float(f"{x / scale:.4g}")
            return f"{shown:g} {(prefix + unit).strip()}"


def hz_text(hz: float) -> str:
    """'20 MHz', '1.5 GHz', '500 kHz', '60 Hz', '327.9 kHz', '0.3279 Hz'."""
    return si_text(hz, "Hz")


def hz_text_down(hz: float) -> str:
    """hz_text rounded down: a rate met up to it (476.19 kHz is 'up to 476.1 kHz': 476.2 was said,
    and 'up to 1 kHz' of a clock that does not meet 1 kHz, a new user's find)."""
    return si_text(hz, "Hz", rounded_down=True)


PREFIXES = (("s", 1e6), ("ms", 1e3), ("µs", 1.0), ("ns", 1e-3), ("ps", 1e-6))


def _prefix(us_value: float) -> tuple[str, float]:
    """The engineering unit for a time given in µs: the largest with the value at least 1."""
    for unit, scale in PREFIXES:
        if abs(us_value) >= scale:
            return unit, scale
    return PREFIXES[-1]


def time_text(us_value: float) -> str:
    """A time given in µs with an engineering prefix and at most 4 significant digits:
    '3.05 µs', '200 ms', '2.667 ns', '3.05 s'."""
    if us_value == 0:
        return "0 s"
    unit, scale = _prefix(us_value)
    return f"{float(f'{us_value / scale:.4g}'):g} {unit}"


def times_apart(a_us: float, b_us: float) -> tuple[str, str]:
    """Two times given in µs, each as time_text writes it, with more digits where 4 would make them
    read the same: a refusal said a set "every 1 ms" could not keep up with rows "every 1 ms"
    (1.00025 against 1: a look-ahead audit's find)."""
    from vampc.textio import apart
    a, b = time_text(a_us), time_text(b_us)
    if a != b or a_us == b_us:
        return a, b
    unit, scale = _prefix(max(abs(a_us), abs(b_us)))
    a, b = apart(a_us / scale, b_us / scale, least=5)
    return f"{a} {unit}", f"{b} {unit}"


def time_column(values_us) -> tuple[str, list[str]]:
    """One unit for a column of times given in µs: the unit that puts the largest at 1 to 999, every
    value in it with at most 4 significant digits. (unit, texts); None values come out as '—'. When
    the column spans three orders of magnitude or more, each cell carries its own prefix instead
    (unit '')."""
    present = [abs(v) for v in values_us if v is not None]
    small = min((v for v in present if v), default=0.0)
    if small and max(present) / small >= 1000:     # one unit would print the small ones as 0.000
        return "", [time_text(v) if v is not None else "—" for v in values_us]
    unit, scale = _prefix(max(present, default=0.0) or 1.0)
    return unit, [_four(v / scale) if v is not None else "—" for v in values_us]


def _four(x: float) -> str:
    """At most 4 significant digits, no exponent (the column's unit keeps x below 1000)."""
    return f"{float(f'{x:.4g}'):g}" if x else "0"


def margin_text(margin: float, need: float | None = None) -> str:
    """How far a control rate is met or missed: '×3.4', '×1,639', 'needs a ×3,050 faster clock'.
    A miss is said as the factor `need` (1 / margin unless given exactly) rounded up, so a clock that
    much faster meets the rate (×20.3 had been said where 20.33 was needed, an audit's find)."""
    if margin >= 1:      # rounded down, as a miss is rounded up (×328 was said of 327.87)
        return f"×{down(margin, 0):,.0f}" if margin >= 100 else f"×{down(margin, 3):.3g}"
    need = 1 / exact(margin) if need is None else Fraction(need)
    if need >= 100:
        return f"needs a ×{math.ceil(need):,} faster clock"
    # 3 digits, or as many as tell the factor from 1 (×1.00016, not ×1.01; a clock 10⁻¹⁵ short of
    # one that meets the rate was told it "needs a ×1 faster clock", a new user's find)
    digits = 3 if need >= Fraction(11, 10) else 6
    while True:
        shown = up(need, digits)
        if shown > 1 or digits >= 17:
            return f"needs a ×{shown:.{digits}g} faster clock"
        digits += 1


def up(x: Fraction, digits: int) -> float:
    """x > 0 rounded up to `digits` significant digits, as the float that prints as that decimal."""
    e = _exponent(x)
    step = Fraction(10) ** (e - digits + 1)
    return float(math.ceil(x / step) * step)


def _exponent(q: Fraction) -> int:
    """floor(log10(q)) for q > 0, exactly (near a power of ten the float log may be one off)."""
    e = math.floor(math.log10(q))
    while Fraction(10) ** e > q:
        e -= 1
    while Fraction(10) ** (e + 1) <= q:
        e += 1
    return e


def control_need(fig: dict, hz: float, latency: int, interval: int) -> Fraction:
    """The factor a clock must be multiplied by to meet the control rate `hz`: the rate times the
    flops it waits on (the larger of latency and interval), over the clock (as its float prints),
    exactly."""
    return Fraction(hz) * max(latency, interval) / exact(fig["hz"])


def us(flops: float, hz: float) -> float:
    """Microseconds for `flops` ticks at `hz` (rounded to 6 significant digits)."""
    return float(f"{flops / hz * 1e6:.6g}")


def per_second(flops: float, hz: float) -> float:
    """How many times per second something taking `flops` ticks happens at `hz` (the clock as its
    float prints), exactly, rounded down (to the unit from 100 on, else to 6 significant digits;
    `rate`, the host traffic's, rounds to the nearest): a throughput is never said to be more than
    it is (20 MHz over 27 flops is 740,740.74: 740,741 had been said, a new user's find)."""
    q = exact(hz) / Fraction(flops)
    return down(q, 0) if q >= 100 else down(q, 6)


def rate(count: float) -> float:
    """A host traffic rate as the report gives it (what a link must carry: to the nearest; a
    throughput is `per_second`'s, rounded down): to the nearest whole one from 100 on (text shows
    it with thousands separators, so it must be that number: 6 significant digits printed
    '1,255,560' for 1,255,555.6), else to 6 significant digits."""
    return float(round(count)) if count >= 100 else float(f"{count:.6g}")


def clock_figures(latency: int, interval: int, load_ticks: int, hz: float) -> dict:
    """Latency, interval and load time in µs, torque sets per second, and the control rates the
    design meets: a control loop at rate R needs each set's torques within 1/R of its state, and a
    new set every 1/R, so R ≤ clock / max(latency, interval)."""
    bound = max(latency, interval)
    return {"hz": hz, "text": hz_text(hz), "tick_ns": float(f"{1e9 / hz:.6g}"),
            "latency_us": us(latency, hz), "interval_us": us(interval, hz),
            "sets_per_second": per_second(interval, hz), "load_us": us(load_ticks, hz),
            # (rounded down: "up to 1 kHz" had been said of a clock that does not meet 1 kHz)
            "max_control_rate_hz": down(exact(hz) / bound, 6),
            "limited_by": "latency" if latency >= interval else "interval",
            "control_rates": [{"hz": r, "met": r * bound <= exact(hz),
                               "margin": _margin(exact(hz) / (bound * r))} for r in CONTROL_RATES]}


def _margin(m: Fraction) -> float:
    """A control rate's margin (exact: the clock over the rate's flops) to 6 significant digits, as
    the other rates, rounded down, so a miss stays below 1 (at 609.9 kHz the Puma's 10 kHz is
    missed by 0.016%: rounded to 3 digits it was "not met (×1)", margin 1.0 beside met false) and a
    rate met is never said to be met by more than it is (×328 of 327.87; 312 of 312.5 and 137 of
    136.6, rounded half to even and up: a review's find, 2026-12-06; a float's rounding below a
    boundary, 0.99999999999994 read as 1, a review's too). (3 digits gave 312 000 for 18.75 MHz / 60
    over 1 kHz: a new user's find.)"""
    if m >= 100:                       # (a whole number, as `rate`: 6 digits printed ×1,149,430
        return down(m, 0)              # for 1,149,425: a review's find)
    return down(m, 6)


def exact(x: float) -> Fraction:
    """A float as the decimal it prints as, exactly (32.8, not 32.799999999999997): the numbers the
    user gave (a clock of 609999.99999994 Hz; one of more digits than a float holds,
    419.99999999999999999 kHz, is read as the float 420 kHz, as every figure is) and the report's
    own decimals."""
    return Fraction(Decimal(repr(float(x))))


def down(x: float | Fraction, digits: int) -> float:
    """x > 0 (exact, or a float taken as the decimal it prints as: exact) rounded down to `digits`
    significant digits (0: to a whole number), as the float that prints as that decimal."""
    q = x if isinstance(x, Fraction) else exact(x)
    if digits == 0:
        return float(math.floor(q))
    step = Fraction(10) ** (_exponent(q) - digits + 1)
    return float(math.floor(q / step) * step)


def control_sentence(fig: dict) -> str:
    """What the clock means for control, in one sentence."""
    met = [hz_text(r["hz"]) for r in fig["control_rates"] if r["met"]]
    missed = [hz_text(r["hz"]) for r in fig["control_rates"] if not r["met"]]
    parts = []
    def listed(rates: list[str]) -> str:
        return " and ".join(rates) if len(rates) < 3 else ", ".join(rates[:-1]) + " and " + rates[-1]
    if met:
        parts.append(f"meets {listed(met)} control")
    if missed:
        parts.append(f"does not meet {listed(missed)} control")
    bound = fig["latency_us"] if fig["limited_by"] == "latency" else fig["interval_us"]
    # (a folded layout's interval is at least its latency: its sets do not overlap, and "when sets
    # are pipelined" read as if they could; a new user's find)
    how = ("when sets are pipelined" if fig["interval_us"] < fig["latency_us"] else
           "one after another (the interval is at least the latency: sets do not overlap)")
    return (f"at {fig['text']} the design {', '.join(parts)}: one torque set within each control "
            f"period up to {hz_text_down(fig['max_control_rate_hz'])} (bound by its {fig['limited_by']}, "
            f"{time_text(bound)}), and {sets_text(fig['sets_per_second'])} torque sets per second "
            f"{how}")


def sets_text(per_second: float) -> str:
    """A rate as a count per second, rounded down as `per_second` is: '5,000,000', '7,812',
    '0.6666'."""
    return f"{per_second:,.0f}" if per_second >= 100 else f"{down(per_second, 4):.4g}"


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
        row["interval_us"] = us(row["interval_flops"], hz)
