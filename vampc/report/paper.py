"""The paper's own figures, as it prints them and as its formulas give them (Lathrop, *Parallelism in
Manipulator Dynamics*): Table O.1 (a: formulas in n; b: the printed column for n = 6), the section VI
tables (requirements per node, VAMPs), its buffering and wiring statements and section VII's pin budget.

Nothing here is measured: these are the numbers vampc's measured ones are set beside. The printed
tables carry errors, so every printed value is kept next to what its formula gives, and
`o1_checks` says where the two disagree and why.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction as F
from typing import Callable

from vampc.kinds import Section


def ceil_log2(x: int) -> int:
    """⌈log2 x⌉ for a positive integer, exactly (no floating point)."""
    return (x - 1).bit_length()


@dataclass(frozen=True)
class Formulation:
    """One row of Table O.1: a method, its Mults and Addns as formulas in n (O.1a) and the values the
    paper prints for n = 6 (O.1b). `measure` says what the row counts: the time of one torque set
    done serially ("serial"), one set's latency on parallel hardware ("latency"), or the interval
    between successive sets ("interval")."""

    key: str
    method: str
    mults: Callable[[int], F]
    adds: Callable[[int], F]
    mults_text: str
    adds_text: str
    printed_n6: tuple[int, int]
    measure: str
    qualifier: str = ""       # the paper's "(estimated)", "(successive)"


def _log_tiers(n: int) -> int:
    return ceil_log2(n + 1)


TABLE_O1 = (
    Formulation("uicker_kahn", "Uicker/Kahn (original Lagrangian)",
                lambda n: F(65, 2) * n**4 + F(1037, 12) * n**3 + F(685, 4) * n**2 + F(160, 3) * n - 128,
                lambda n: 25 * n**4 + F(199, 3) * n**3 + F(259, 2) * n**2 + F(127, 3) * n - 96,
                "32½n⁴ + 86⁵⁄₁₂n³ + 171¼n² + 53⅓n − 128",
                "25n⁴ + 66⅓n³ + 129½n² + 42⅓n − 96",
                (66271, 51548), "serial"),
    Formulation("waters", "Waters (partially recursive)",
                lambda n: F(213, 2) * n**2 + F(1241, 2) * n - 512, lambda n: F(82 * n**2 + 514 * n - 384),
                "106½n² + 620½n − 512", "82n² + 514n − 384", (7051, 5652), "serial"),
    Formulation("hollerbach_4x4", "Hollerbach (4×4 Lagrangian)", lambda n: F(830 * n - 592),
                lambda n: F(675 * n - 464), "830n − 592", "675n − 464", (4388, 3586), "serial"),
    Formulation("hollerbach_3x3", "Hollerbach (3×3 Lagrangian)", lambda n: F(412 * n - 277),
                lambda n: F(320 * n - 201), "412n − 277", "320n − 201", (2195, 1719), "serial"),
    Formulation("luh_walker_paul", "Luh, Walker, Paul (Newton-Euler)", lambda n: F(150 * n - 48),
                lambda n: F(131 * n - 48), "150n − 48", "131n − 48", (852, 738), "serial"),
    Formulation("horn_raibert", "Horn, Raibert (table look-up)", lambda n: F(2 * n**3 + n**2),
                lambda n: F(n**3 + n**2 + 2 * n), "2n³ + n²", "n³ + n² + 2n", (468, 264), "serial"),
    Formulation("luh_lin", "Luh, Lin (scheduled parallel N.E.)", lambda n: F(57 * n - 18),
                lambda n: F(50 * n - 18), "57n − 18", "50n − 18", (323, 280), "latency",
                "estimated"),
    Formulation("lathrop_linear", "Lathrop (linear parallel N.E.)", lambda n: F(2 * n + 3),
                lambda n: F(6 * n + 7), "2n + 3", "6n + 7", (15, 43), "latency"),
    Formulation("lathrop_log", "Lathrop (logarithmic parallel N.E.)",
                lambda n: F(2 * _log_tiers(n) + 5), lambda n: F(6 * _log_tiers(n) + 10),
                "2⌈log₂(n+1)⌉ + 5", "6⌈log₂(n+1)⌉ + 10", (11, 28), "latency"),
    Formulation("lathrop_systolic", "Lathrop (systolic pipeline)", lambda n: F(1), lambda n: F(3),
                "1", "3", (1, 3), "interval", "successive"),
)

# Luh and Lin's "concurrency factor of 2.64 on the Stanford arm", which Table O.1 applies to
# Luh-Walker-Paul (section I).
LUH_LIN_FACTOR = F(264, 100)


def formulation(key: str) -> Formulation:
    """The Table O.1 row with this key."""
    return next(f for f in TABLE_O1 if f.key == key)


def number(value: F) -> int | float:
    """A formula's value as JSON takes it: an int when whole, else a float."""
    return int(value) if value.denominator == 1 else float(value)


def o1_row(f: Formulation, n: int, mult: int = 1, add: int = 1) -> dict:
    """One Table O.1 row evaluated at n, with the printed n = 6 value and its check when n = 6. Its
    flops are at a Mult of `mult` flops and an Addn of `add` (the paper's 1 and 1 by default), as
    the report counts its own latency."""
    m, a = f.mults(n), f.adds(n)
    flops = m * mult + a * add
    # (the exact values beside the JSON numbers: a float cannot hold a third past n of about
    # 1487, and the text, guessing the fraction from it, showed 400,531,184,751,237 3/10 of a
    # 2000-joint robot for ...237⅓: a new user's find)
    row = {"key": f.key, "method": f.method, "measure": f.measure, "source": "formula",
           "mults": number(m), "adds": number(a), "flops": number(flops),
           "mults_exact": str(m), "adds_exact": str(a), "flops_exact": str(flops),
           "mults_formula": f.mults_text, "adds_formula": f.adds_text, "qualifier": f.qualifier}
    if n == 6:
        pm, pa = f.printed_n6
        row["printed_n6"] = {"mults": pm, "adds": pa, "matches": (m, a) == (pm, pa),
                             "note": o1_check_note(f)}
    return row


def o1_check_note(f: Formulation) -> str:
    """Where the printed n = 6 column (Table O.1b) disagrees with the row's formula (O.1a), and why;
    'formula and printed value agree' otherwise."""
    m, a = f.mults(6), f.adds(6)
    pm, pa = f.printed_n6
    if (m, a) == (pm, pa):
        return "formula and printed value agree"
    if f.key == "luh_lin":
        return (f"printed {pm} + {pa} is Luh-Walker-Paul's 852 + 738 divided by the concurrency factor "
                f"2.64 ({float(852 / LUH_LIN_FACTOR):.1f}, {float(738 / LUH_LIN_FACTOR):.1f}); the "
                "formula rounds the coefficients first (150/2.64 ≈ 57, 48/2.64 ≈ 18, "
                f"131/2.64 ≈ 50) and gives {number(m)} + {number(a)}: both are estimates")
    parts = []
    for what, got, printed in (("Mults", m, pm), ("Addns", a, pa)):
        if got != printed:
            parts.append(f"{what}: the formula gives {number(got):,}, the paper prints {printed:,} "
                         f"({number(printed - got):+,})")
    return "; ".join(parts) + (" — the printed column (adapted from Hollerbach [16]) does not follow "
                               "from the printed formula; vampc shows both")


def o1_checks() -> list[dict]:
    """Every Table O.1 row at n = 6: formula value, printed value, agreement and note."""
    return [o1_row(f, 6) for f in TABLE_O1]


# --- section VI: requirements per node and VAMPs -------------------------------------------------

# "Requirements Per Node" tables (ops; MV covers MV and MTV, MM is one op of 3 VAMPs).
OPS_PER_NODE = {
    ("linear", "bwd"): {"MV": 3, "VA": 5, "VC": 4},
    ("linear", "npv"): {"MV": 2, "VA": 3, "VC": 4, "SV": 1},
    ("linear", "fwd"): {"MV": 2, "VA": 4, "VC": 2},
    ("log", "bwd"): {"MV": 6, "VA": 12, "VC": 4, "SV": 1, "MM": 1},
    ("log", "npv"): {"MV": 2, "VA": 3, "VC": 4, "SV": 1},
    ("log", "fwd"): {"MV": 5, "VA": 4, "VC": 1, "MM": 1},
}

# The paper's printed totals per node (its tables print 12, 10, 22, 8; 24, 34, 11).
OPS_PER_NODE_PRINTED_TOTAL = {("linear", "bwd"): 12, ("linear", "npv"): 10, ("linear", "fwd"): 8,
                              ("log", "bwd"): 24, ("log", "npv"): 10, ("log", "fwd"): 11}

# "VAMPs, n = 6" (propagated / non-propagated / totals): per node, tier, single device, systolic.
VAMPS_N6 = {
    ("linear", "bwd"): {"per_node": 12, "tier": None, "single_device": 12, "systolic": 72},
    ("linear", "npv"): {"per_node": 10, "tier": None, "single_device": 10, "systolic": 60},
    ("linear", "fwd"): {"per_node": 8, "tier": None, "single_device": 8, "systolic": 48},
    ("log", "bwd"): {"per_node": 26, "tier": 78, "single_device": 78, "systolic": 338},
    ("log", "npv"): {"per_node": 10, "tier": 20, "single_device": 20, "systolic": 60},
    ("log", "fwd"): {"per_node": 13, "tier": 39, "single_device": 39, "systolic": 169},
}
VAMPS_N6_TOTALS = {
    ("linear", "bwd"): {"per_node": 22, "tier": None, "single_device": 22, "systolic": 132},
    ("linear", "fwd"): {"per_node": 8, "tier": None, "single_device": 8, "systolic": 48},
    ("log", "bwd"): {"per_node": 36, "tier": 98, "single_device": 98, "systolic": 398},
    ("log", "fwd"): {"per_node": 13, "tier": 39, "single_device": 39, "systolic": 169},
}
# Section VI: "seven nodes total on each of the forward and backward recursions ... plus six more if
# the a = b case is handled as in Appendix D", and a tier of 3 nodes for n = 6.
LOG_NODES_N6, LOG_TIER_NODES_N6, LOG_NPV_PER_TIER_N6 = 13, 3, 2


def vamps_per_op(op: str) -> int:
    """VAMPs an op of the paper's tables takes (MM: three)."""
    return 3 if op == "MM" else 1


def vamp_table_checks() -> list[str]:
    """The section VI tables checked against each other: per-node ops times VAMPs per op, tiers,
    systolic counts and totals. Returns one line per check that fails (none do: the printed VAMP
    tables are consistent)."""
    bad = []
    for key, ops in OPS_PER_NODE.items():
        if sum(ops.values()) != OPS_PER_NODE_PRINTED_TOTAL[key]:
            bad.append(f"{key}: ops per node add up to {sum(ops.values())}")
        vamps = sum(k * vamps_per_op(op) for op, k in ops.items())
        if vamps != VAMPS_N6[key]["per_node"]:
            bad.append(f"{key}: {vamps} VAMPs per node from the ops, printed {VAMPS_N6[key]['per_node']}")
    nodes = {"linear": 6, "log": LOG_NODES_N6}
    for (rec, sec), row in VAMPS_N6.items():
        count = 6 if sec == Section.NPV else nodes[rec]
        if row["per_node"] * count != row["systolic"]:
            bad.append(f"{rec} {sec}: systolic {row['systolic']} is not {count} × {row['per_node']}")
    for (rec, sec), row in VAMPS_N6_TOTALS.items():
        parts = [VAMPS_N6[(rec, sec)]] + ([VAMPS_N6[(rec, "npv")]] if sec == Section.BWD else [])
        for col in ("per_node", "single_device", "systolic"):
            if sum(p[col] for p in parts) != row[col]:
                bad.append(f"{rec} {sec} total {col}: {row[col]} is not the sum of its parts")
    return bad


# --- section VI: buffering and communication ------------------------------------------------------

def input_buffer_estimate(n: int) -> int:
    """The paper's ≈ 37n + 15 scalars of input buffering."""
    return 37 * n + 15


# What the 37 per joint and the 15 are: z q̇ (3), z q̈ (3), A (9); p*, ṗ*, r*, s*, z (3 each);
# m (1); J (symmetric: 6); endpoints ω0, ω̇0, p̈0, f_{n+1}, n_{n+1} (3 each).
INPUT_BUFFER_ITEMS = {"zqd": 3, "zqdd": 3, "A": 9, "p_star": 3, "p_star_dot": 3, "r_star": 3,
                      "s_star": 3, "z": 3, "m": 1, "J": 6}
INPUT_BUFFER_ENDPOINTS = 15

# Communication (section VI): vector buses between successive nodes, per pass, and the bounds on
# point-to-point buses inside one module.
LINEAR_INTER_NODE_BUSES = {"bwd": 4, "fwd": 2}
LOG_INTER_NODE_BUSES = 18
INTERNAL_BUS_BOUNDS = {"module": 50, "shared_passes": 70, "npv": 20}


# --- section VII: pins and packages ---------------------------------------------------------------

# Each VAMP needs Power, Ground, Clock-1, Clock-2, Global-Reset, Operand-A, Operand-B and Result
# when wired separately; sharing one Clock (split on chip), Power, Ground and Global-Reset per
# package leaves Operand-A, Operand-B and Result per VAMP.
PINS_SEPARATE = ("Power", "Ground", "Clock-1", "Clock-2", "Global-Reset", "Operand-A", "Operand-B",
                 "Result")
PINS_SHARED_PER_PACKAGE = ("Clock", "Power", "Ground", "Global-Reset")
PINS_SHARED_PER_VAMP = ("Operand-A", "Operand-B", "Result")
PAPER_PACKAGES_LINEAR_N6 = 11   # "11 such 40-pin packages would implement the full systolic pipeline"


def vamps_per_package(pins: int) -> dict[str, int]:
    """VAMPs a package of `pins` pins holds by the paper's pin budget (40 pins: 5 and 12)."""
    shared = (pins - len(PINS_SHARED_PER_PACKAGE)) // len(PINS_SHARED_PER_VAMP)
    return {"separate": pins // len(PINS_SEPARATE), "shared": max(shared, 0)}


def paper_packages(vamps: int, pins: int = 40) -> dict[str, int]:
    """Packages for `vamps` VAMPs of one operand wire each, by the paper's pin budget."""
    per = vamps_per_package(pins)
    return {style: math.ceil(vamps / k) if k else 0 for style, k in per.items()}
