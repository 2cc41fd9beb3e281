"""Clock rates (vampc.report.clock): parsing --clock, and the times and control rates it gives."""
from __future__ import annotations

import pytest

from vampc.report.clock import clock_figures, control_sentence, hz_text, parse_clock


@pytest.mark.parametrize("text,hz", [("20MHz", 20e6), ("20 MHz", 20e6), ("20mhz", 20e6),
                                     ("1.5GHz", 1.5e9), ("500kHz", 5e5), ("60Hz", 60.0),
                                     ("4e7", 4e7), (" 2.5e1 kHz ", 25e3)])
def test_parse_clock(text, hz):
    assert parse_clock(text) == pytest.approx(hz)


@pytest.mark.parametrize("text", ["", "fast", "20 MHzz", "MHz", "-5MHz", "0Hz", "1e13", "nan",
                                  "inf", "20 THz", "1,000Hz"])
def test_bad_clock_values_say_why(text):
    with pytest.raises(ValueError) as err:
        parse_clock(text)
    assert repr(text) in str(err.value) and "\n" not in str(err.value)


def test_figures_at_20_mhz_for_the_linear_systolic_puma():
    # 61 flops at 50 ns = 3.05 µs; a set every 4 flops = 0.2 µs -> 5 000 000 sets/s; control is
    # latency-bound: 20 MHz / 61 = 327 869 Hz.
    fig = clock_figures(61, 4, 15, 20e6)
    assert (fig["latency_us"], fig["interval_us"], fig["load_us"]) == (3.05, 0.2, 0.75)
    assert fig["sets_per_second"] == 5e6 and fig["tick_ns"] == 50
    assert fig["max_control_rate_hz"] == pytest.approx(327869, rel=1e-5)
    assert fig["limited_by"] == "latency"
    assert [(r["hz"], r["met"]) for r in fig["control_rates"]] == [(1000, True), (10000, True)]
    assert control_sentence(fig).startswith("at 20 MHz the design meets 1 kHz and 10 kHz control")


def test_a_slow_clock_misses_10_khz():
    # Folded: 61 flops latency, 64 interval; at 500 kHz one set per 128 µs -> 7.8 kHz at most.
    fig = clock_figures(61, 64, 527, 5e5)
    assert fig["limited_by"] == "interval"
    assert [r["met"] for r in fig["control_rates"]] == [True, False]
    assert "does not meet 10 kHz control" in control_sentence(fig)


def test_hz_text():
    assert [hz_text(x) for x in (60, 1e3, 2.5e4, 2e7, 1.5e9)] == ["60 Hz", "1 kHz", "25 kHz",
                                                                   "20 MHz", "1.5 GHz"]
