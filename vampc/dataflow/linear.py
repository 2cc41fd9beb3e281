"""The linear-recursion Newton-Euler dataflow graph (paper section III, Table III.1).

Per joint i the backward (base-to-tip, the paper's naming) node computes ω_i, ω̇_i, p̈_i (12 ops for a
revolute joint: 3 MV, 5 VA, 4 VC) and the non-propagated r̈_i, F_i, N_i (10 ops: 2 MV, 3 VA, 4 VC,
1 SV); the forward node computes f_i, n_i (8 ops: 2 MV, 4 VA, 2 VC). The node ids T1..T24 follow
Table III.1.

Output convention (DESIGN §5). The paper returns the third coordinate of n_i as τ_i, which is right only
when z_{i-1} referred to O_i is e_z. We carry the forward variables referred to O_{i-1} instead:

    f'_i = A_i f_i = A_i (F_i + f'_{i+1})
    n'_i = A_i n_i = A_i (n'_{i+1} + N_i + s*_i × F_i + p*_i × f'_{i+1})

with the same op inventory (2 MV, 4 VA, 2 VC), and τ_i is exactly the third coordinate of n'_i
(revolute) or f'_i (prismatic). The tip load enters as f'_{n+1} = f_{n+1}, n'_{n+1} = n_{n+1} (given in
O_n). The price is one MV more on the path to τ_1 (A_1 is applied at node 1): the achieved latency is
the paper's plus 1 Mult + 2 Addns.

Prismatic joints (σ_i = 0) take the σ̄ terms of Table I.1: ω_i = A_iᵀ ω_{i-1}, ω̇_i = A_iᵀ ω̇_{i-1},
and p̈_i gains A_iᵀ z q̈_i + 2 ω_i × A_iᵀ z q̇_i. Those extra terms are summed into T8 (the centripetal
term), which is ready no later than T9, so they add ops but no latency.
"""
from __future__ import annotations

import numpy as np

from vampc.dataflow.graph import Graph, GraphBuilder
from vampc.dataflow.ops import Op
from vampc.robot.chain import Chain, JointType


def build_linear(chain: Chain, verify: bool = True) -> Graph:
    """The linear Newton-Euler graph of `chain` (see the module docstring); `verify` checks it."""
    b = GraphBuilder(chain.n, "linear")
    w = b.const(chain.base_omega, "omega0")
    wd = b.const(chain.base_omega_dot, "omega_dot0")
    pdd = b.const(chain.base_accel, "pdd0")
    forces = []
    for i in range(1, chain.n + 1):
        w, wd, pdd = _backward_node(b, chain, i, w, wd, pdd)
        forces.append(_nonpropagated(b, chain, i, w, wd, pdd))
    fp = b.const(chain.tip_force, "f_tip")
    np_ = b.const(chain.tip_torque, "n_tip")
    for i in range(chain.n, 0, -1):
        fp, np_ = _forward_node(b, chain, i, forces[i - 1], fp, np_)
        prismatic = chain.joints[i - 1].type is JointType.PRISMATIC
        b.output(i, fp if prismatic else np_)
    return b.build({"recursion": "linear", "convention": "f, n referred to O_{i-1}"}, verify)


def _p_star(b: GraphBuilder, chain: Chain, i: int) -> int:
    j = chain.joints[i - 1]
    if j.type is JointType.PRISMATIC:
        return b.input("p_star", i)
    return b.const(j.p_fixed, f"p_star{i}", i)


def _s_star(b: GraphBuilder, chain: Chain, i: int) -> int:
    j = chain.joints[i - 1]
    if j.type is JointType.PRISMATIC:
        return b.input("s_star", i)
    return b.const(j.p_fixed + j.com, f"s_star{i}", i)


def _backward_node(b: GraphBuilder, chain: Chain, i: int, w_prev: int, wd_prev: int, pdd_prev: int):
    """ω_i, ω̇_i, p̈_i from ω_{i-1}, ω̇_{i-1}, p̈_{i-1} (Table III.1, propagated variables)."""
    b.at("bwd", i)
    A, zqd, zqdd = b.input("A", i), b.input("zqd", i), b.input("zqdd", i)
    p = _p_star(b, chain, i)
    if chain.joints[i - 1].type is JointType.REVOLUTE:
        t2 = b.op(Op.VA, w_prev, zqd, "T2")
        w = b.op(Op.MTV, A, t2, "omega")
        t4 = b.op(Op.VC, w_prev, zqd, "T4")
        t5 = b.op(Op.VA, zqdd, t4, "T5")
        t6 = b.op(Op.VA, t5, wd_prev, "T6")
        wd = b.op(Op.MTV, A, t6, "omega_dot")
        t8 = b.op(Op.VC, w, b.op(Op.VC, w, p, "T7"), "T8")
    else:
        w = b.op(Op.MTV, A, w_prev, "omega")
        wd = b.op(Op.MTV, A, wd_prev, "omega_dot")
        t8 = b.op(Op.VC, w, b.op(Op.VC, w, p, "T7"), "T8")
        t8 = b.op(Op.VA, t8, _prismatic_terms(b, A, w, zqd, zqdd), "T8p")
    t9 = b.op(Op.VC, wd, p, "T9")
    t10 = b.op(Op.VA, t8, t9, "T10")
    t11 = b.op(Op.MTV, A, pdd_prev, "T11")
    pdd = b.op(Op.VA, t10, t11, "pdd")
    return w, wd, pdd


def _prismatic_terms(b: GraphBuilder, A: int, w: int, zqd: int, zqdd: int) -> int:
    """A_iᵀ z q̈_i + 2 ω_i × A_iᵀ z q̇_i (Table I.1, translational case)."""
    pa = b.op(Op.MTV, A, zqdd, "Pa")
    pb = b.op(Op.MTV, A, zqd, "Pb")
    pc = b.op(Op.VC, w, pb, "Pc")
    pd = b.op(Op.SV, b.const([2.0, 0.0, 0.0], "two"), pc, "Pd")
    return b.op(Op.VA, pa, pd, "Pe")


def _nonpropagated(b: GraphBuilder, chain: Chain, i: int, w: int, wd: int, pdd: int):
    """r̈_i, F_i, N_i (Table III.1, non-propagated variables); returns (F_i, N_i)."""
    b.at("npv", i)
    j = chain.joints[i - 1]
    r = b.const(j.com, f"r_star{i}", i)
    t13 = b.op(Op.VC, w, b.op(Op.VC, w, r, "T12"), "T13")
    t14 = b.op(Op.VC, wd, r, "T14")
    t15 = b.op(Op.VA, t13, t14, "T15")
    rdd = b.op(Op.VA, t15, pdd, "rdd")
    F = b.op(Op.SV, b.const([j.mass, 0.0, 0.0], f"m{i}", i), rdd, "F")
    J = b.const(np.asarray(j.inertia), f"J{i}", i)
    t16 = b.op(Op.MV, J, w, "T16")
    t17 = b.op(Op.VC, w, t16, "T17")
    t18 = b.op(Op.MV, J, wd, "T18")
    N = b.op(Op.VA, t17, t18, "N")
    return F, N


def _forward_node(b: GraphBuilder, chain: Chain, i: int, FN, f_next: int, n_next: int):
    """f'_i, n'_i from f'_{i+1}, n'_{i+1} (Table III.1 forward, referred to O_{i-1})."""
    F, N = FN
    b.at("fwd", i)
    A = b.input("A", i)
    t20 = b.op(Op.VC, _s_star(b, chain, i), F, "T20")
    t21 = b.op(Op.VA, t20, N, "T21")
    t19 = b.op(Op.VA, F, f_next, "T19")
    f = b.op(Op.MV, A, t19, "f")
    t22 = b.op(Op.VC, _p_star(b, chain, i), f_next, "T22")
    t23 = b.op(Op.VA, t21, t22, "T23")
    t24 = b.op(Op.VA, t23, n_next, "T24")
    n = b.op(Op.MV, A, t24, "n")
    return f, n
