"""The paper's figures (vampc.report.paper): Table O.1's formulas against its printed n = 6 column,
the section VI tables against each other, and section VII's pin budget.

Expected values are worked by hand from the formulas as printed (Table O.1a) and the column as
printed (Table O.1b); the three rows where they disagree are the paper's, not vampc's.
"""
from __future__ import annotations

from fractions import Fraction

import pytest

from vampc.report import paper

# Table O.1b as printed, and the formulas of O.1a evaluated at n = 6 by hand:
# Uicker/Kahn Mults 32½·1296 + 86 5/12·216 + 171¼·36 + 53⅓·6 − 128
#                 = 42120 + 18666 + 6165 + 320 − 128.
BY_HAND = {
    "uicker_kahn": ((67143, 51548), (66271, 51548)),
    "waters": ((7045, 5652), (7051, 5652)),
    "hollerbach_4x4": ((4388, 3586), (4388, 3586)),
    "hollerbach_3x3": ((2195, 1719), (2195, 1719)),
    "luh_walker_paul": ((852, 738), (852, 738)),
    "horn_raibert": ((468, 264), (468, 264)),
    "luh_lin": ((324, 282), (323, 280)),
    "lathrop_linear": ((15, 43), (15, 43)),
    "lathrop_log": ((11, 28), (11, 28)),
    "lathrop_systolic": ((1, 3), (1, 3)),
}


@pytest.mark.parametrize("key", sorted(BY_HAND))
def test_every_o1_row_at_n6_formula_and_printed(key):
    (fm, fa), (pm, pa) = BY_HAND[key]
    row = paper.o1_row(paper.formulation(key), 6)
    assert (row["mults"], row["adds"], row["flops"]) == (fm, fa, fm + fa)
    printed = row["printed_n6"]
    assert (printed["mults"], printed["adds"]) == (pm, pa)
    assert printed["matches"] == ((fm, fa) == (pm, pa))
    assert (printed["note"] == "formula and printed value agree") == printed["matches"]


def test_the_three_disagreements_are_explained():
    notes = {r["key"]: r["printed_n6"]["note"] for r in paper.o1_checks()}
    assert notes["uicker_kahn"].startswith("Mults: the formula gives 67,143, the paper prints 66,271 "
                                           "(-872)")
    assert notes["waters"].startswith("Mults: the formula gives 7,045, the paper prints 7,051 (+6)")
    # Luh-Lin: the printed column is LWP / 2.64, the formula rounds the coefficients first.
    assert "divided by the concurrency factor 2.64 (322.7, 279.5)" in notes["luh_lin"]
    assert "gives 324 + 282" in notes["luh_lin"]


def test_luh_lin_printed_values_are_lwp_over_the_concurrency_factor():
    assert round(Fraction(852) / paper.LUH_LIN_FACTOR) == 323
    assert round(Fraction(738) / paper.LUH_LIN_FACTOR) == 280


@pytest.mark.parametrize("n,tiers", [(1, 1), (2, 2), (3, 2), (6, 3), (7, 3), (8, 4), (64, 7)])
def test_log_formula_uses_exact_ceil_log2(n, tiers):
    row = paper.o1_row(paper.formulation("lathrop_log"), n)
    assert (row["mults"], row["adds"]) == (2 * tiers + 5, 6 * tiers + 10)
    assert ("printed_n6" in row) == (n == 6)


def test_a_fractional_formula_value_stays_exact():
    # Uicker/Kahn Addns at n = 2: 25·16 + 66⅓·8 + 129½·4 + 42⅓·2 − 96 = 1437⅓.
    row = paper.o1_row(paper.formulation("uicker_kahn"), 2)
    assert row["adds"] == pytest.approx(1437 + 1 / 3)


def test_section_vi_tables_are_consistent():
    assert paper.vamp_table_checks() == []


def test_pin_budget_gives_the_papers_packages():
    # Section VII: 8 pins per VAMP wired separately -> 5 per 40-pin package; 4 shared pins and 3 per
    # VAMP -> 12; an 8-pin package holds one VAMP either way.
    assert paper.vamps_per_package(40) == {"separate": 5, "shared": 12}
    assert paper.vamps_per_package(8) == {"separate": 1, "shared": 1}
    assert paper.vamps_per_package(64) == {"separate": 8, "shared": 20}
    assert paper.paper_packages(180) == {"separate": 36, "shared": 15}


def test_input_buffer_estimate_and_its_items():
    assert paper.input_buffer_estimate(6) == 237
    assert sum(paper.INPUT_BUFFER_ITEMS.values()) == 37 and paper.INPUT_BUFFER_ENDPOINTS == 15
