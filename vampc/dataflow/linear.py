"""The linear-recursion Newton-Euler dataflow graph (paper section III, Table III.1).

Per joint i the backward (base-to-tip, the paper's naming) node computes ω_i, ω̇_i, p̈_i (12 ops for a
revolute joint: 3 MV, 5 VA, 4 VC) and the non-propagated r̈_i, F_i, N_i (10 ops: 2 MV, 3 VA, 4 VC,
1 SV); the forward node computes f_i, n_i (8 ops: 2 MV, 4 VA, 2 VC). The node ids T1..T24 follow
Table III.1.

Output convention (README, *Exactness convention*). The paper returns the third coordinate of n_i as
τ_i, which is right only when z_{i-1} referred to O_i is e_z. We carry the forward variables
referred to O_{i-1} instead:

    f'_i = A_i f_i = A_i (F_i + f'_{i+1})
    n'_i = A_i n_i = A_i (n'_{i+1} + N_i + s*_i × F_i + p*_i × f'_{i+1})

with the same op inventory (2 MV, 4 VA, 2 VC), and τ_i is exactly the third coordinate of n'_i
(revolute) or f'_i (prismatic). The tip load enters as f'_{n+1} = f_{n+1}, n'_{n+1} = n_{n+1} (given in
O_n). The price is one MV more on the path to τ_1 (A_1 is applied at node 1): the achieved latency is
the paper's plus 1 Mult + 2 Addns.

Prismatic joints (σ_i = 0) take the σ̄ terms of Table I.1: ω_i = A_iᵀ ω_{i-1}, ω̇_i = A_iᵀ ω̇_{i-1},
and p̈_i gains A_iᵀ z q̈_i + 2 ω_i × A_iᵀ z q̇_i. Those extra terms are summed into T8 (the centripetal
term), which is ready no later than T9, so they add ops but no latency.

Trees (issue 12). Joint i's backward node reads its parent's ω, ω̇, p̈ (the base's for a joint on the
base); a joint with a shifted joint frame (vampc.robot.chain: o_i ≠ 0) first forms the acceleration of
its joint frame's origin, H5 = p̈_p + ω̇_p × o_i + ω_p × (ω_p × o_i) (3 VC, 2 VA: H1..H5). Its forward
node sums its children's f' and n' (VA trees named Sf, Sn; a shifted child adds o_d × f'_d first: Y1,
Y2); a leaf other than joint n has no child terms (T19, T22, T24 drop out), joint n takes the tip load
as in the chain. τ_i is the third coordinate of n'_i when z_{i-1} is e_z in the parent's frame, else
one VD with u_i = M_i e_z ("tau"). A floating base (host inputs omega0, omega_dot0, pdd0 of joint 0)
forms the base link's F_0, N_0 (section npv, group 0) and its wrench f_0 = F_0 + Σ f'_r, n_0 = N_0 +
r*_0 × F_0 + Σ (n'_r + o_r × f'_r) (section fwd, group 0: B1, B2, f0, n0): outputs n + 1..n + 6. The
latency is set by the deepest branch: each level costs what a chain's joint costs, plus the VA
levels of its children's sums. A chain builds exactly the graph above.
"""
from __future__ import annotations

import numpy as np

from vampc.dataflow.graph import LINEAR_META, Graph, GraphBuilder
from vampc.machine.ops import Op
from vampc.robot.chain import Chain, JointType


def build_linear(chain: Chain, verify: bool = True) -> Graph:
    """The linear Newton-Euler graph of `chain` (see the module docstring); `verify` checks it."""
    b = GraphBuilder(chain.n, "linear")
    motion = {0: base_motion(b, chain)}
    forces = []
    for i, parent in enumerate(chain.parent_of, 1):
        w, wd, pdd = motion[parent]
        pdd = shifted_accel(b, chain, i, w, wd, pdd)
        motion[i] = _backward_node(b, chain, i, w, wd, pdd)
        forces.append(_nonpropagated(b, chain, i, *motion[i]))
    base_loads = _base_loads(b, chain, *motion[0]) if chain.floating else None
    tip = (b.const(chain.tip_force, "f_tip"), b.const(chain.tip_torque, "n_tip"))
    incoming: dict[int, list[tuple[int, int]]] = {}
    for i in range(chain.n, 0, -1):
        f_next, n_next = tip if i == chain.n else _children_sum(b, i, incoming.get(i, []))
        fp, np_ = _forward_node(b, chain, i, forces[i - 1], f_next, n_next)
        b.output(i, *joint_output(b, chain, i, fp, np_))
        incoming.setdefault(chain.parent(i), []).insert(0, _passed_up(b, chain, i, fp, np_))
    if chain.floating:
        _base_wrench(b, chain, base_loads, incoming.get(0, []))
    return b.build(dict(LINEAR_META), verify)


def base_motion(b: GraphBuilder, chain: Chain) -> tuple[int, int, int]:
    """ω_0, ω̇_0, p̈_0: constants for a fixed base, host inputs of joint 0 for a floating one."""
    if chain.floating:
        return b.input("omega0", 0), b.input("omega_dot0", 0), b.input("pdd0", 0)
    return (b.const(chain.base_omega, "omega0"), b.const(chain.base_omega_dot, "omega_dot0"),
            b.const(chain.base_accel, "pdd0"))


def shifted_accel(b: GraphBuilder, chain: Chain, i: int, w: int, wd: int, pdd: int) -> int:
    """p̈ of joint i's frame origin: p̈_p + ω̇_p × o_i + ω_p × (ω_p × o_i) (p̈_p itself when o_i = 0)."""
    shift = chain.joints[i - 1].shift
    if shift is None:
        return pdd
    b.at("bwd", i)
    o = b.const(shift, f"shift{i}", i)
    h2 = b.op(Op.VC, w, b.op(Op.VC, w, o, "H1"), "H2")
    h4 = b.op(Op.VA, h2, b.op(Op.VC, wd, o, "H3"), "H4")
    return b.op(Op.VA, pdd, h4, "H5")


def _children_sum(b: GraphBuilder, i: int, terms: list[tuple[int, int]]) -> tuple[int | None, int | None]:
    """Σ f', Σ n' of joint i's children as balanced VA trees (None, None for a leaf)."""
    if not terms:
        return None, None
    b.at("fwd", i)
    return (add_tree(b, [f for f, _ in terms], "Sf"), add_tree(b, [n for _, n in terms], "Sn"))


def add_tree(b: GraphBuilder, ids: list[int], name: str) -> int:
    """The sum of `ids` by a balanced tree of VA ops (⌈log2 k⌉ levels)."""
    while len(ids) > 1:
        ids = [b.op(Op.VA, ids[k], ids[k + 1], name) if k + 1 < len(ids) else ids[k]
               for k in range(0, len(ids), 2)]
    return ids[0]


def _passed_up(b: GraphBuilder, chain: Chain, i: int, fp: int, np_: int) -> tuple[int, int]:
    """What joint i passes to its parent: f'_i and n'_i, moved to the parent frame's origin if shifted."""
    shift = chain.joints[i - 1].shift
    if shift is None:
        return fp, np_
    b.at("fwd", i)
    y1 = b.op(Op.VC, b.const(shift, f"shift{i}", i), fp, "Y1")
    return fp, b.op(Op.VA, np_, y1, "Y2")


def joint_output(b: GraphBuilder, chain: Chain, i: int, fp: int, np_: int) -> tuple[int, int]:
    """(node, component) holding τ_i: the third coordinate of n'_i (f'_i prismatic), or u_i · it by one VD
    when joint i's axis is not z of its parent's frame."""
    joint = chain.joints[i - 1]
    src = fp if joint.type is JointType.PRISMATIC else np_
    if joint.pre is None:
        return src, 2
    b.at("fwd", i)
    return b.op(Op.VD, b.const(joint.parent_axis, f"u{i}", i), src, "tau"), 0


def _base_loads(b: GraphBuilder, chain: Chain, w: int, wd: int, pdd: int) -> tuple[int, int]:
    """F_0, N_0 of a floating base link (section npv, group 0)."""
    return link_loads(b, 0, chain.base_com, chain.base_mass, chain.base_inertia, w, wd, pdd)


def _base_wrench(b: GraphBuilder, chain: Chain, loads: tuple[int, int], terms) -> None:
    """f_0 = F_0 + Σ f'_r, n_0 = N_0 + r*_0 × F_0 + Σ n'_r: outputs n + 1..n + 6 (force, then moment)."""
    big_f, big_n = loads
    b.at("fwd", 0)
    b2 = b.op(Op.VA, big_n, b.op(Op.VC, b.const(chain.base_com, "r_star0"), big_f, "B1"), "B2")
    f0 = add_tree(b, [big_f] + [f for f, _ in terms], "f0")
    n0 = add_tree(b, [b2] + [n for _, n in terms], "n0")
    for k in range(3):
        b.output(chain.n + 1 + k, f0, k)
        b.output(chain.n + 4 + k, n0, k)


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
    j = chain.joints[i - 1]
    return link_loads(b, i, j.com, j.mass, j.inertia, w, wd, pdd)


def link_loads(b: GraphBuilder, i: int, com, mass: float, inertia, w: int, wd: int, pdd: int):
    """F, N of link i (section npv, group i) from its ω, ω̇, p̈ and its mass, CoM and inertia."""
    b.at("npv", i)
    r = b.const(com, f"r_star{i}", i)
    t13 = b.op(Op.VC, w, b.op(Op.VC, w, r, "T12"), "T13")
    t14 = b.op(Op.VC, wd, r, "T14")
    t15 = b.op(Op.VA, t13, t14, "T15")
    rdd = b.op(Op.VA, t15, pdd, "rdd")
    F = b.op(Op.SV, b.const([mass, 0.0, 0.0], f"m{i}", i), rdd, "F")
    J = b.const(np.asarray(inertia), f"J{i}", i)
    t16 = b.op(Op.MV, J, w, "T16")
    t17 = b.op(Op.VC, w, t16, "T17")
    t18 = b.op(Op.MV, J, wd, "T18")
    N = b.op(Op.VA, t17, t18, "N")
    return F, N


def _forward_node(b: GraphBuilder, chain: Chain, i: int, FN, f_next: int | None, n_next: int | None):
    """f'_i, n'_i from the children's Σ f', Σ n' (Table III.1 forward, referred to O_{i-1}); a leaf
    without a tip load (f_next None) drops T19, T22 and T24."""
    F, N = FN
    b.at("fwd", i)
    A = b.input("A", i)
    t20 = b.op(Op.VC, _s_star(b, chain, i), F, "T20")
    t21 = b.op(Op.VA, t20, N, "T21")
    if f_next is None:
        return b.op(Op.MV, A, F, "f"), b.op(Op.MV, A, t21, "n")
    t19 = b.op(Op.VA, F, f_next, "T19")
    f = b.op(Op.MV, A, t19, "f")
    t22 = b.op(Op.VC, _p_star(b, chain, i), f_next, "T22")
    t23 = b.op(Op.VA, t21, t22, "T23")
    t24 = b.op(Op.VA, t23, n_next, "T24")
    n = b.op(Op.MV, A, t24, "n")
    return f, n
