"""The logarithmic-recursion Newton-Euler dataflow graph (sections IV–VI, Tables IV.1, V.1, App. B–D).

The backward (base-to-tip: the paper's naming) pass builds the relational parameters X_{a,b} =
(W, ω, ω̇, Q, R, S, p̈) of Table IV.1 through a parallel-prefix network (vampc.dataflow.prefix;
Sklansky is the paper's Figure IV.2), so that X_{0,i} holds ω_i, ω̇_i, p̈_i. Each joint then forms its
non-propagated r̈_i, F_i, N_i exactly as the linear graph does (linear.py's helper; section "npv",
group i). The forward (tip-to-base) pass builds X_{i,n} = (W, R, f', n') through the same shape
mirrored, and τ_i is the third coordinate of n'_{i,n} (revolute) or f'_{i,n} (prismatic). Every
recursion node is one `group` of its section ("bwd" or "fwd"): leaves first, then the combining
nodes tier by tier. graph.meta records each group's (a, k, b, tier) and where X_{0,i} and X_{i,n} are
(`relational_nodes`).

Combining nodes (Table V.1; the forms are vampc.dynamics.logforms', checked there against the closed
forms of Appendix B). Backward, with T1 = W_{k+1,b}ᵀ ω_{a,k} and T2 = W_{k+1,b}ᵀ ω̇_{a,k}:

    W = W_{a,k} W_{k+1,b}                    ω = T1 + ω_{k+1,b}
    ω̇ = T2 + (T1 × ω_{k+1,b} + ω̇_{k+1,b})     R = W_{k+1,b}ᵀ R_{a,k} + R_{k+1,b}     (Q likewise)
    S = W_{k+1,b}ᵀ S_{a,k} + (T1 × R_{k+1,b} + S_{k+1,b})
    p̈ = W_{k+1,b}ᵀ p̈_{a,k}
        + (p̈_{k+1,b} + (T2 × R_{k+1,b} + T1 × (T1 × R_{k+1,b} + 2 (S_{k+1,b} + Q_{k+1,b}))))

24 ops = 26 VAMPs (6 MV, spelled MTV here, 12 VA, 4 VC, 1 SV, 1 MM), named after Table V.1 (W, T1..T17,
omega, omega_dot, R, S, Q, pdd; T16 is W_{k+1,b}ᵀ p̈_{a,k}, which the table prints as W'). Forward,
referred to O_{a-1} (see "Output convention"), with W and R recomputed as on the backward pass
(section V): 10 ops = 12 VAMPs (4 MV, 4 VA, 1 VC, 1 MM):

    f'_{a,b} = f'_{a,k} + W_{a,k} f'_{k+1,b}                                        (T19, f)
    n'_{a,b} = (n'_{a,k} + W_{a,k} (R_{a,k} × f'_{k+1,b})) + W_{a,k} n'_{k+1,b}    (T21..T24, n)

Leaves (a = b). By default Table IV.1's, with the corrections of README's *Exactness convention*
(q̇_a in ω and Q, q̈_a in ω̇, no p̈*_a term for a ≥ 1, the ∂ term is σ̄_a A_aᵀ z q̈_a; 2 ω_{a,a} ×
Q_{a,a} is identically zero since σ_a σ̄_a = 0): a revolute leaf is W = A_a, ω = A_aᵀ z q̇_a, ω̇ =
A_aᵀ z q̈_a, Q = 0, R = p*_a, S = ω × p*_a, p̈ = ω̇ × p*_a + ω × S (2 MV, 3 VC, 1 VA); a prismatic
one ω = ω̇ = S = 0, Q = A_aᵀ z q̇_a, p̈ = A_aᵀ z q̈_a (2 MV). Forward: W = A_a, R = p*_a, f' = A_a
F_a, n' = A_a (N_a + s*_a × F_a) (2 MV, 1 VC, 1 VA); partial terms are named L1..L6. With
uniform_leaves the combining node itself builds X_{a,a} from Appendix D's artificial operands
(corrected as in logforms: ṗ*_a is p*_a, a_{a-1} is z_{a-1}):

    backward  X_{a,k} = (I, σ_a z q̇_a, σ_a z q̈_a, σ̄_a z q̇_a, 0, 0, σ̄_a z q̈_a)
              X_{k+1,b} = (A_a, 0, 0, 0, p*_a, 0, 0)
    forward   X_{a,k} = (A_a, s*_a, 0, 0),  X_{k+1,b} = (I, -r*_a, F_a, N_a)

all host inputs or constants, so a leaf is one combining node and nothing more. The forward operands
are not the printed ones (f_{a,k} = F_a, n_{k+1,b} = s*_a × F_a, which needs a VC outside the node):
here the node's own T21 = R_{a,k} × f'_{k+1,b} forms s*_a × F_a, and -r*_a = p*_a - s*_a restores
R_{a,a} = p*_a.

Grounding. In O_{-1} (the general case) leaf 0 is X_{0,0} = (I, ω0, ω̇0, 0, 0, 0, p̈0 = -g): constants
in both leaf styles (a uniform node would only turn constants into constants), and the network spans
n + 1 leaves. In O_0 (section VI; whenever ω0 = ω̇0 = 0, or ground_o0=True) leaf 0 goes and leaf 1
carries the base acceleration: p̈_{1,1} gains A_1ᵀ p̈0 (1 MV + 1 VA, added to ω̇ × p*_1 before the later
ω × S, so no latency), or with uniform leaves p̈_{a,k} = σ̄_1 z q̈_1 + p̈0 (a constant for a revolute
joint 1: no op). The paper asks for n even because its argument is the width of one single-device tier
(⌈n/2⌉ against ⌈(n+1)/2⌉ nodes); in the unrolled graph grounding in O_0 saves combining nodes for
every n (Sklansky, n = 7: 9 instead of 12 each way) and a whole tier each way when n is a power of 2.
The tip load is folded into leaf n as F_n + f_{n+1} and N_n + (n_{n+1} - r*_n × f_{n+1}) (a constant):
at most 2 VA, none for a free tip (the paper's case).

Output convention (README, *Exactness convention*). τ_i = z_{i-1}·n_i is the third coordinate of A_i
n_i, not of n_i. As in the linear graph the forward parameters are carried referred to O_{a-1}:
f'_{a,b} = A_a f_{a,b}, n'_{a,b} = A_a n_{a,b}. Multiplying logforms' combine by A_a (A_a
W_{a+1,k+1} = W_{a,k} A_{k+1}, A (u × v) = A u × A v, A_{k+1} A_{k+1}ᵀ R_{a,k} = R_{a,k}) gives the
forms above: they use the unshifted W_{a,k}, R_{a,k} of the backward pass (R_{a,k} and f'_{k+1,b}
are both in O_k), so the paper's T20 = A_{k+1}ᵀ R_{a,k} is not needed, and τ_i is read off directly.
The output correction is the A_a of the forward leaf: 2 MV per joint with Table IV.1 leaves (f =
F_a, n = N_a + s*_a × F_a in the paper) and no op at all with uniform leaves (W_{a,k} = A_a instead
of I). On the critical path it is one MV, 1 Mult + 2 Addns.

VAMPs, n = 6, general rotary arm, Sklansky, uniform leaves (the paper's section VI case: grounded in O_0,
7 combining + 6 leaf nodes each way): backward 13 × 26 + npv 6 × 10 = 398, as the paper; forward
13 × 12 = 156 against the paper's 13 × 13 = 169, one T20 less per node. Per node 26 + 10 and 12 (paper
36 and 13). Table IV.1 leaves instead: backward 7 × 26 + 38 (leaves; leaf 1 with gravity 8, the others
6) + 60, forward 7 × 12 + 6 × 4. prune=True drops what no torque reads (W, Q, R, S and their T5, T7,
T8, T9 of every X_{0,b}; W and R of every final suffix): 338 → 278 backward, 156 → 116 forward.

Latency (ASAP, 1 Mult = 1 Addn = 1 flop, general rotary arm, Sklansky, grounded in O_0), against the
paper's (2L + 5) M + (6L + 10) A, L = ⌈log2(n+1)⌉:

    n        paper            Table IV.1 leaves     uniform leaves
    1        23 (7M+16A)      16 (6M+10A)           20 (6M+14A)
    2        31 (9M+22A)      26 (8M+18A)           28 (8M+20A)
    3        31 (9M+22A)      34 (10M+24A)          36 (10M+26A)
    4        39 (11M+28A)     34 (10M+24A)          36 (10M+26A)
    5..7     39 (11M+28A)     42 (12M+30A)          44 (12M+32A)
    8        47 (13M+34A)     42 (12M+30A)          44 (12M+32A)
    9..15    47 (13M+34A)     50 (14M+36A)          52 (14M+38A)
    16       55 (15M+40A)     50 (14M+36A)          52 (14M+38A)
    17..31   55 (15M+40A)     58 (16M+42A)          60 (16M+44A)
    32       63 (17M+46A)     58 (16M+42A)          60 (16M+44A)
    33..63   63 (17M+46A)     66 (18M+48A)          68 (18M+50A)
    64       71 (19M+52A)     66 (18M+48A)          68 (18M+50A)

For n ≥ 2 that is (2t + 6) M + (6t + 12) A with t = ⌈log2 n⌉: the paper's plus the output correction
(1 M + 2 A) when t = L, and 1 M + 4 A below it when n is a power of 2 (grounding in O_0 saves one
MV + VA tier each way). The rest matches the paper's Appendix C: 1 MV + 1 VA per tier, and a leaf p̈
ready at MV + 2 VC + 1 VA, within Appendix C's padded MV + 2 VC + 3 VA. Uniform leaves cost 2 Addns
more (a VA more in each pass's leaf). Grounded in O_{-1}: 8L + 18 flops, less for n = 1, 2 (21, 29)
and n a power of 2 (8L + 14), where leaf 0's constant operands shorten the first tier. The other shapes
trade depth for VAMPs (prefix.py); "serial" grows by 8 flops per joint, like the linear graph.
"""
from __future__ import annotations

import gc
from contextlib import contextmanager
from typing import NamedTuple

import numpy as np

from vampc import jsontext
from vampc.dataflow.graph import (
    LOG_CONVENTION,
    LOG_GROUNDS,
    LOG_LEAVES,
    Graph,
    GraphBuilder,
    Node,
    Output,
)
from vampc.dataflow.linear import _nonpropagated, _p_star, _s_star
from vampc.dataflow.prefix import chain_table, prefix_tiers, suffix_tiers
from vampc.errors import VampcError, VampcInternalError
from vampc.machine.ops import Op
from vampc.robot.chain import Chain, JointType


class BackIds(NamedTuple):
    """Node ids of a backward relational parameter X_{a,b} (Table IV.1), all referred to O_b."""

    W: int
    omega: int
    omega_dot: int
    Q: int
    R: int
    S: int
    pdd: int


class FwdIds(NamedTuple):
    """Node ids of a forward X_{a,b}: W_{a,b} and R_{a,b} (as backward), f'_{a,b}, n'_{a,b} in O_{a-1}."""

    W: int
    R: int
    f: int
    n: int


class _Ctx:
    """One build: the builder, the chain, the shared constants and the table of recursion nodes."""

    def __init__(self, chain: Chain, uniform: bool):
        self.b = GraphBuilder(chain.n, "log")
        self.chain, self.uniform = chain, uniform
        self.zero = self.b.const(np.zeros(3), "zero")
        self.eye = self.b.const(np.eye(3), "I")
        self.two = self.b.const([2.0, 0.0, 0.0], "two")
        self.table: dict[str, list] = {"bwd": [], "fwd": []}

    def node(self, section: str, a: int, k: int, b: int, tier: int) -> None:
        """Open recursion node X_{a,k} ⊗ X_{k+1,b} (a leaf when a = b): the group of the ops added next."""
        rows = self.table[section]
        rows.append((len(rows) + 1, a, k, b, tier))
        self.b.at(section, len(rows))

    def joint(self, i: int):
        """Joint i (1-based)."""
        return self.chain.joints[i - 1]


@contextmanager
def _collector_paused():
    """Pause the cyclic garbage collector. A build allocates about 20 n log2 n nodes and no cycles; the
    collector's repeated scans of the growing node list would double the build time for large n."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


@_collector_paused()
def build_log(chain: Chain, prefix: str = "sklansky", uniform_leaves: bool = False,
              ground_o0: bool | None = None, prune: bool = False, verify: bool = True) -> Graph:
    """The logarithmic Newton-Euler graph of `chain` (see the module docstring).

    prefix: the prefix-network shape (vampc.dataflow.prefix.SHAPES), mirrored for the forward pass.
    uniform_leaves: build X_{a,a} with Appendix D's uniform combining node instead of Table IV.1's leaf.
    ground_o0: ground the recursion in O_0 (section VI); None = whenever ω0 = ω̇0 = 0.
    prune: drop the ops no torque depends on (the uniform nodes' unused W, Q, R, S).
    verify: check the graph's invariants (Graph.verify) before returning it.
    """
    if not chain.is_fixed_chain:
        from vampc.dataflow.logtree import build_log_tree
        return build_log_tree(chain, prefix, uniform_leaves, ground_o0, verify)
    ground0 = _check_ground(chain, ground_o0)
    ctx = _Ctx(chain, uniform_leaves)
    prefixes = _backward(ctx, prefix, ground0)
    loads = [_nonpropagated(ctx.b, chain, i, x.omega, x.omega_dot, x.pdd)
             for i, x in enumerate(prefixes, 1)]
    suffixes = _forward(ctx, prefix, loads)
    for i, x in enumerate(suffixes, 1):
        ctx.b.output(i, x.f if ctx.joint(i).type is JointType.PRISMATIC else x.n)
    if verify and ctx.table != chain_table(prefix, chain.n, ground0):
        raise VampcInternalError(f"{chain.name}: the recursion nodes are not chain_table's")
    graph = ctx.b.build(_meta(ctx, prefix, ground0, prefixes, suffixes), verify)
    return prune_dead(graph) if prune else graph


def _check_ground(chain: Chain, ground_o0: bool | None) -> bool:
    still = not chain.base_rotates
    if ground_o0 and not still:
        raise VampcError(f"{chain.name}: cannot ground the log recursion in O_0: the base rotates "
                         f"(ω0 or ω̇0 nonzero)")
    return still if ground_o0 is None else ground_o0


# --- backward (base-to-tip) pass --------------------------------------------------------------------------

def _backward(ctx: _Ctx, shape: str, ground0: bool) -> list[BackIds]:
    """X_{0,i} for i = 1..n through the prefix network; leaf position p holds joint p + first."""
    first = 1 if ground0 else 0
    x = {(p, p): _back_leaf(ctx, a, ground0) for p, a in enumerate(range(first, ctx.chain.n + 1))}
    for t, tier in enumerate(prefix_tiers(shape, len(x)), 1):
        for a, k, b in tier:
            ctx.node("bwd", a + first, k + first, b + first, t)
            x[a, b] = _back_combine(ctx, x[a, k], x[k + 1, b])
    return [x[0, i - first] for i in range(1, ctx.chain.n + 1)]


def _back_leaf(ctx: _Ctx, a: int, ground0: bool) -> BackIds:
    """X_{a,a}: constants for a = 0; Table IV.1 (corrected) or Appendix D's uniform node otherwise."""
    if a == 0:
        return _ground_leaf(ctx)
    ctx.node("bwd", a, a, a, 0)
    gravity = ground0 and ctx.chain.parent(a) == 0   # grounded in O_0: a leaf on the base carries p̈_0
    if ctx.uniform:
        return _back_combine(ctx, *_unified_back_operands(ctx, a, gravity))
    if ctx.joint(a).type is JointType.PRISMATIC:
        return _prismatic_leaf(ctx, a, gravity)
    return _revolute_leaf(ctx, a, gravity)


def _ground_leaf(ctx: _Ctx) -> BackIds:
    """X_{0,0} in O_{-1} = O_0 at the instant: ω0, ω̇0 and gravity as p̈ᵍ_0 (constants, or a floating
    base's host inputs; no ops)."""
    from vampc.dataflow.linear import base_motion
    w, wd, pdd = base_motion(ctx.b, ctx.chain)
    return BackIds(ctx.eye, w, wd, ctx.zero, ctx.zero, ctx.zero, pdd)


def _revolute_leaf(ctx: _Ctx, a: int, gravity: bool) -> BackIds:
    """ω = A_aᵀ z q̇_a, ω̇ = A_aᵀ z q̈_a, S = ω × p*_a, p̈ = ω̇ × p*_a + ω × S (Q = 0, R = p*_a)."""
    b = ctx.b
    A, p = b.input("A", a), _p_star(b, ctx.chain, a)
    w = b.op(Op.MTV, A, b.input("zqd", a), "omega")
    wd = b.op(Op.MTV, A, b.input("zqdd", a), "omega_dot")
    s = b.op(Op.VC, w, p, "S")
    l1 = b.op(Op.VC, wd, p, "L1")
    if gravity:   # added to the earlier term, so the later ω × S still ends the leaf
        l1 = b.op(Op.VA, l1, b.op(Op.MTV, A, b.const(ctx.chain.base_accel, "pdd0"), "L3"), "L4")
    pdd = b.op(Op.VA, l1, b.op(Op.VC, w, s, "L2"), "pdd")
    return BackIds(A, w, wd, ctx.zero, _leaf_r(ctx, a, A, p), s, pdd)


def _leaf_r(ctx: _Ctx, a: int, A: int, p: int) -> int:
    """R of leaf a: p*_a, or A_aᵀ o_a + p*_a for a shifted joint frame (logforms: a virtual leaf)."""
    shift = ctx.joint(a).shift
    if shift is None:
        return p
    b = ctx.b
    return b.op(Op.VA, b.op(Op.MTV, A, b.const(shift, f"shift{a}", a), "L7"), p, "L8")


def _prismatic_leaf(ctx: _Ctx, a: int, gravity: bool) -> BackIds:
    """Q = A_aᵀ z q̇_a, p̈ = A_aᵀ z q̈_a (ω = ω̇ = S = 0, R = p*_a)."""
    b = ctx.b
    A, zqdd = b.input("A", a), b.input("zqdd", a)
    if gravity:
        zqdd = b.op(Op.VA, zqdd, b.const(ctx.chain.base_accel, "pdd0"), "L3")
    q = b.op(Op.MTV, A, b.input("zqd", a), "Q")
    pdd = b.op(Op.MTV, A, zqdd, "pdd")
    return BackIds(A, ctx.zero, ctx.zero, q, _leaf_r(ctx, a, A, _p_star(b, ctx.chain, a)), ctx.zero, pdd)


def _unified_back_operands(ctx: _Ctx, a: int, gravity: bool) -> tuple[BackIds, BackIds]:
    """Appendix D's operands X_{a,k}, X_{k+1,b} of leaf a (module docstring), ready for _back_combine."""
    b, z = ctx.b, ctx.zero
    zqd, zqdd = b.input("zqd", a), b.input("zqdd", a)
    if ctx.joint(a).type is JointType.PRISMATIC:
        w, wd, q, pdd = z, z, zqd, zqdd
    else:
        w, wd, q, pdd = zqd, zqdd, z, z
    if gravity:
        g = b.const(ctx.chain.base_accel, "pdd0")
        pdd = g if pdd == z else b.op(Op.VA, pdd, g, "L3")
    shift = ctx.joint(a).shift
    left = BackIds(ctx.eye, w, wd, q, z if shift is None else b.const(shift, f"shift{a}", a), z, pdd)
    return left, BackIds(b.input("A", a), z, z, z, _p_star(b, ctx.chain, a), z, z)


def _back_combine(ctx: _Ctx, x: BackIds, y: BackIds) -> BackIds:
    """X_{a,b} = X_{a,k} ⊗ X_{k+1,b} (x, y): Table V.1's 24 ops (6 MV, 12 VA, 4 VC, 1 SV, 1 MM)."""
    w = ctx.b.op(Op.MM, x.W, y.W, "W")
    t1, t2, omega, omega_dot = _back_angular(ctx, x, y)
    q, r, s, t6 = _back_auxiliary(ctx, x, y, t1)
    return BackIds(w, omega, omega_dot, q, r, s, _back_pdd(ctx, x, y, t1, t2, t6))


def _back_angular(ctx: _Ctx, x: BackIds, y: BackIds):
    """T1, T2, ω_{a,b} = T1 + ω_{k+1,b}, ω̇_{a,b} = T2 + T1 × ω_{k+1,b} + ω̇_{k+1,b}."""
    b = ctx.b
    t1 = b.op(Op.MTV, y.W, x.omega, "T1")
    omega = b.op(Op.VA, t1, y.omega, "omega")
    t2 = b.op(Op.MTV, y.W, x.omega_dot, "T2")
    t4 = b.op(Op.VA, b.op(Op.VC, t1, y.omega, "T3"), y.omega_dot, "T4")
    return t1, t2, omega, b.op(Op.VA, t2, t4, "omega_dot")


def _back_auxiliary(ctx: _Ctx, x: BackIds, y: BackIds, t1: int):
    """Q, R, S of X_{a,b} (and T6 = T1 × R_{k+1,b}, which p̈ reuses)."""
    b = ctx.b
    r = b.op(Op.VA, b.op(Op.MTV, y.W, x.R, "T5"), y.R, "R")
    t6 = b.op(Op.VC, t1, y.R, "T6")
    t8 = b.op(Op.VA, t6, y.S, "T8")
    s = b.op(Op.VA, b.op(Op.MTV, y.W, x.S, "T7"), t8, "S")
    q = b.op(Op.VA, b.op(Op.MTV, y.W, x.Q, "T9"), y.Q, "Q")
    return q, r, s, t6


def _back_pdd(ctx: _Ctx, x: BackIds, y: BackIds, t1: int, t2: int, t6: int) -> int:
    """p̈_{a,b} = T16 + p̈_{k+1,b} + T2 × R_{k+1,b} + T1 × (T6 + 2 (S_{k+1,b} + Q_{k+1,b}))."""
    b = ctx.b
    t10 = b.op(Op.VC, t2, y.R, "T10")
    t12 = b.op(Op.SV, ctx.two, b.op(Op.VA, y.S, y.Q, "T11"), "T12")
    t14 = b.op(Op.VC, t1, b.op(Op.VA, t6, t12, "T13"), "T14")
    t15 = b.op(Op.VA, t10, t14, "T15")
    t16 = b.op(Op.MTV, y.W, x.pdd, "T16")
    return b.op(Op.VA, t16, b.op(Op.VA, y.pdd, t15, "T17"), "pdd")


# --- forward (tip-to-base) pass ---------------------------------------------------------------------------

def _forward(ctx: _Ctx, shape: str, loads: list[tuple[int, int]]) -> list[FwdIds]:
    """X_{i,n} for i = 1..n through the mirrored network; leaf position p holds joint p + 1."""
    n = ctx.chain.n
    x = {(p, p): _fwd_leaf(ctx, p + 1, *loads[p]) for p in range(n)}
    for t, tier in enumerate(suffix_tiers(shape, n), 1):
        for a, k, b in tier:
            ctx.node("fwd", a + 1, k + 1, b + 1, t)
            x[a, b] = _fwd_combine(ctx, x[a, k], x[k + 1, b])
    return [x[p, n - 1] for p in range(n)]


def _fwd_leaf(ctx: _Ctx, i: int, big_f: int, big_n: int) -> FwdIds:
    """X_{i,i}: W = A_i, R = p*_i, f' = A_i F_i, n' = A_i (N_i + s*_i × F_i) (tip load folded into i = n)."""
    ctx.node("fwd", i, i, i, 0)
    b = ctx.b
    f_src, n_src = _tip_load(ctx, i, big_f, big_n)
    A, s = b.input("A", i), _s_star(b, ctx.chain, i)
    if ctx.uniform:   # X_{a,k} = (A_i, s*_i, 0, 0), X_{k+1,b} = (I, -r*_i, F_i, N_i)
        minus_r = b.const(-np.asarray(ctx.joint(i).com), f"minus_r_star{i}", i)
        return _fwd_combine(ctx, FwdIds(A, s, ctx.zero, ctx.zero), FwdIds(ctx.eye, minus_r, f_src, n_src))
    f = b.op(Op.MV, A, f_src, "f")
    t = b.op(Op.VA, n_src, b.op(Op.VC, s, f_src, "L5"), "L6")
    return FwdIds(A, _p_star(b, ctx.chain, i), f, b.op(Op.MV, A, t, "n"))


def _tip_load(ctx: _Ctx, i: int, big_f: int, big_n: int) -> tuple[int, int]:
    """(F, N) of leaf i; leaf n adds the tip load: F_n + f_{n+1} and N_n + n_{n+1} - r*_n × f_{n+1}.

    With s*_n × (F_n + f_{n+1}) formed by the leaf anyway, the rest of p*_n × f_{n+1} + n_{n+1} is a
    constant, so a load at the tip costs at most 2 VA and a zero one nothing.
    """
    chain, b = ctx.chain, ctx.b
    if i != chain.n:
        return big_f, big_n
    f_tip = np.asarray(chain.tip_force, dtype=float)
    c = np.asarray(chain.tip_torque, dtype=float) - np.cross(ctx.joint(i).com, f_tip)
    if np.any(f_tip):
        big_f = b.op(Op.VA, big_f, b.const(f_tip, "f_tip"), "Ftip")
    if np.any(c):
        big_n = b.op(Op.VA, big_n, b.const(c, "n_tip_c"), "Ntip")
    return big_f, big_n


def _fwd_combine(ctx: _Ctx, x: FwdIds, y: FwdIds) -> FwdIds:
    """X_{a,b} = X_{a,k} ⊗ X_{k+1,b} (x, y), referred to O_{a-1}: 10 ops (4 MV, 4 VA, 1 VC, 1 MM).

    f'_{a,b} = f'_{a,k} + W_{a,k} f'_{k+1,b};  n'_{a,b} = n'_{a,k} + W_{a,k} (R_{a,k} × f'_{k+1,b})
    + W_{a,k} n'_{k+1,b}; W and R recomputed as on the backward pass (section V).
    """
    b = ctx.b
    w = b.op(Op.MM, x.W, y.W, "W")
    r = b.op(Op.VA, b.op(Op.MTV, y.W, x.R, "T5"), y.R, "R")
    f = b.op(Op.VA, x.f, b.op(Op.MV, x.W, y.f, "T19"), "f")
    t21 = b.op(Op.VC, x.R, y.f, "T21")
    t23 = b.op(Op.VA, x.n, b.op(Op.MV, x.W, t21, "T22"), "T23")
    n = b.op(Op.VA, t23, b.op(Op.MV, x.W, y.n, "T24"), "n")
    return FwdIds(w, r, f, n)


# --- graph metadata and pruning ---------------------------------------------------------------------------

def _meta(ctx: _Ctx, prefix: str, ground0: bool, prefixes, suffixes) -> dict:
    """What later stages and tests may want to know: the recursion nodes and where X_{0,i}, X_{i,n} are."""
    return {
        "recursion": "log", "prefix": prefix, "leaves": LOG_LEAVES[ctx.uniform],
        "ground": LOG_GROUNDS[ground0], "convention": LOG_CONVENTION,
        "bwd_nodes": jsontext.dumps(ctx.table["bwd"]), "fwd_nodes": jsontext.dumps(ctx.table["fwd"]),
        "prefixes": jsontext.dumps([[x.omega, x.omega_dot, x.pdd] for x in prefixes]),
        "suffixes": jsontext.dumps([[x.f, x.n] for x in suffixes]),
    }


def relational_nodes(graph: Graph) -> dict[str, list[list[int | None]]]:
    """Node ids of X_{0,i} (ω, ω̇, p̈) and X_{i,n} (f', n') per joint i, from a log graph's metadata.

    Returns {"prefixes": [[ω, ω̇, p̈], ...], "suffixes": [[f', n'], ...]}; None marks a pruned node.
    """
    meta = dict(graph.meta)
    return {key: jsontext.loads(meta[key]) for key in ("prefixes", "suffixes")}


@_collector_paused()
def prune_dead(graph: Graph) -> Graph:
    """`graph` without the nodes no torque output depends on (ids renumbered, order kept)."""
    live = graph.live_nodes()
    new = {old: i for i, old in enumerate(sorted(live))}
    # Node(...) rather than dataclasses.replace: the latter is ~10x slower on a million nodes.
    nodes = tuple(Node(new[nd.id], nd.op, tuple(new[a] for a in nd.args), nd.name, nd.section, nd.group,
                       nd.key, nd.value) for nd in graph.nodes if nd.id in live)
    outputs = tuple(Output(o.joint, new[o.node], o.component) for o in graph.outputs)
    meta = dict(graph.meta)
    for key in ("prefixes", "suffixes"):
        ids = jsontext.loads(meta[key])
        meta[key] = jsontext.dumps([[new.get(v) for v in row] for row in ids])
    meta["pruned"] = "yes"
    pruned = Graph(nodes, outputs, graph.n, graph.recursion, tuple(sorted(meta.items())))
    pruned.verify()
    return pruned
