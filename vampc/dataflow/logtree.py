"""The logarithmic-recursion Newton-Euler graph of a tree or a floating base (issue 12).

The scheme is vampc.dataflow.treeprefix's, proved numerically in vampc.dynamics.logforms (tree_log_rnea):

Backward: every joint's full prefix X_{0..j} (ω_j, ω̇_j, p̈_j, and W_j, R_j: O_j's orientation and origin
seen from O_0) through the heavy-path plan: the chain's prefix shape (`prefix`, Sklansky the paper's)
over each heavy path, one combining node more per joint below a light edge. Leaves and combining nodes
are logarithmic.py's (Table IV.1 leaves, or Appendix D's with `uniform_leaves`; a shifted joint frame's
leaf takes R = A_dᵀ o_d + p*_d: L7, L8, or o_d as the uniform node's left R). Grounding: in O_0 for a
fixed, still base (each leaf on the base carries gravity); in O_{-1} otherwise, a floating base's
leaf 0 holding its host inputs ω_0, ω̇_0, p̈_0.

Non-propagated: r̈_j, F_j, N_j as in the linear graph (section npv, group j).

Forward, in the base frame (section fwd): per joint (a leaf group, tier 0), the force and moment about
O_0's origin, the tip load folded into joint n:

    G1 = R_j + r*_j,  G3 = N_j + G1 × F_j (G2),  φ_j = W_j F_j (G4),  μ_j = W_j G3 (G5)

then block sums over the depth-first positions (one group per block, tier = its level: Bf, Bn), each
subtree [j, end_j) summed from its canonical blocks earliest first (Rf, Rn), and back to the parent's
frame about J_j's origin (one group per joint):

    f'_j = W_pᵀ Φ_j (K1),  n'_j = W_pᵀ M_j (K2) + f'_j × (R_p + o_j) (K3, K4, K5)   (p = 0: W = I, R = 0)

τ_j is the third coordinate of n'_j (f'_j prismatic), or u_j · it by one VD. A floating base's wrench is
f_0 = F_0 + Σ_all φ, n_0 = N_0 + r*_0 × F_0 + Σ_all μ (outputs n + 1..n + 6). Ops no output reads (the
final prefixes' Q and S, say) are pruned.
"""
from __future__ import annotations

import heapq

from vampc import jsontext
from vampc.dataflow.graph import LOG_GROUNDS, LOG_LEAVES, LOG_TREE_CONVENTION, Graph
from vampc.dataflow.linear import add_tree, link_loads
from vampc.dataflow.logarithmic import (
    BackIds,
    _back_combine,
    _back_leaf,
    _check_ground,
    _collector_paused,
    _Ctx,
    _nonpropagated,
    _tip_load,
    prune_dead,
)
from vampc.dataflow.treeprefix import (
    block_sources,
    path_prefix_plan,
    range_blocks,
    tree_depths,
)
from vampc.machine.ops import Op
from vampc.robot.chain import Chain, JointType


@_collector_paused()
def build_log_tree(chain: Chain, prefix: str = "sklansky", uniform_leaves: bool = False,
                   ground_o0: bool | None = None, verify: bool = True) -> Graph:
    """The logarithmic graph of a tree (or of any robot with a floating base): module docstring."""
    ground0 = False if chain.floating else _check_ground(chain, ground_o0)
    ctx = _Ctx(chain, uniform_leaves)
    prefixes = _backward(ctx, prefix, ground0)
    loads = [_nonpropagated(ctx.b, chain, i, x.omega, x.omega_dot, x.pdd) for i, x in enumerate(prefixes, 1)]
    base = link_loads(ctx.b, 0, chain.base_com, chain.base_mass, chain.base_inertia,
                      *_ground_motion(ctx)) if chain.floating else None
    suffixes, totals = _forward(ctx, prefixes, loads)
    for i, (fp, np_) in enumerate(suffixes, 1):
        _output(ctx, i, fp, np_)
    if base is not None:
        _base_wrench(ctx, base, totals)
    meta = _meta(ctx, prefix, ground0, prefixes, suffixes)
    return prune_dead(ctx.b.build(meta, verify))


def _ground_motion(ctx: _Ctx) -> tuple[int, int, int]:
    from vampc.dataflow.linear import base_motion
    return base_motion(ctx.b, ctx.chain)


# --- backward: path prefixes ------------------------------------------------------------------------------

def _backward(ctx: _Ctx, shape: str, ground0: bool) -> list[BackIds]:
    """Every joint's full prefix through treeprefix's plan."""
    chain = ctx.chain
    tiers, keys = path_prefix_plan(chain.parent_of, shape, ground=not ground0)
    x = {(j, j): _back_leaf(ctx, j, ground0) for j in range(0 if not ground0 else 1, chain.n + 1)}
    for t, tier in enumerate(tiers, 1):
        for a, k, b in tier:
            ctx.node("bwd", a, k, b, t)
            x[a, b] = _back_combine(ctx, x[a, k], x[_path_child(chain, k, b), b])
    return [x[key] for key in keys]


def _path_child(chain: Chain, k: int, b: int) -> int:
    """The child of k on the path down to b."""
    c = b
    while chain.parent(c) != k:
        c = chain.parent(c)
    return c


# --- forward: subtree sums in the base frame --------------------------------------------------------------

class _Sums:
    """Block sums of (φ, μ) over depth-first positions, built once and shared by every range."""

    def __init__(self, ctx: _Ctx, leaves: list[tuple[int, int]]):
        self.ctx, self.leaves, self.blocks = ctx, leaves, {}

    def block(self, level: int, index: int) -> tuple[tuple[int, int], int]:
        """((Σφ, Σμ) node ids, level ready) of block (level, index)."""
        if level == 0:
            return self.leaves[index], 0
        key = (level, index)
        if key not in self.blocks:
            parts = [self.block(*h) for h in block_sources(level, index, len(self.leaves))]
            if len(parts) == 1:
                self.blocks[key] = parts[0]
            else:
                lo = index << level
                self.ctx.node("fwd", lo + 1, level, min(lo + (1 << level), len(self.leaves)), level)
                (f1, n1), t1 = parts[0]
                (f2, n2), t2 = parts[1]
                b = self.ctx.b
                self.blocks[key] = ((b.op(Op.VA, f1, f2, "Bf"), b.op(Op.VA, n1, n2, "Bn")), max(t1, t2) + 1)
        return self.blocks[key]

    def range(self, lo: int, hi: int) -> tuple[tuple[int, int], int]:
        """Σ over positions [lo, hi), its blocks added earliest first (ops in the current group)."""
        heap = [(t, k, ids) for k, (ids, t) in enumerate(self.block(*blk) for blk in range_blocks(lo, hi))]
        heapq.heapify(heap)
        count = len(heap)
        while len(heap) > 1:
            t1, _, (f1, n1) = heapq.heappop(heap)
            t2, _, (f2, n2) = heapq.heappop(heap)
            b = self.ctx.b
            heapq.heappush(heap, (max(t1, t2) + 1, count, (b.op(Op.VA, f1, f2, "Rf"), b.op(Op.VA, n1, n2, "Rn"))))
            count += 1
        t, _, ids = heap[0]
        return ids, t


def _forward(ctx: _Ctx, prefixes: list[BackIds], loads) -> tuple[list[tuple[int, int]], tuple[int, int]]:
    """(f'_j, n'_j) per joint and (Σ_all φ, Σ_all μ)."""
    chain = ctx.chain
    sums = _Sums(ctx, [_local(ctx, j, prefixes[j - 1], *loads[j - 1]) for j in range(1, chain.n + 1)])
    out = []
    for j, end in enumerate(chain.subtree_end, 1):
        ctx.node("fwd", j, j, end - 1, 1 + max(chain.n - 1, 0).bit_length())
        (f_sum, n_sum), _ = sums.range(j - 1, end - 1)
        out.append(_to_parent(ctx, j, prefixes, f_sum, n_sum))
    ctx.node("fwd", 1, 0, chain.n, 1 + max(chain.n - 1, 0).bit_length())
    return out, sums.range(0, chain.n)[0]


def _local(ctx: _Ctx, j: int, x: BackIds, big_f: int, big_n: int) -> tuple[int, int]:
    """φ_j = W_j F_j, μ_j = W_j (N_j + (R_j + r*_j) × F_j): link j's load about O_0's origin, in O_0."""
    ctx.node("fwd", j, j, j, 0)
    b = ctx.b
    big_f, big_n = _tip_load(ctx, j, big_f, big_n)
    c = b.op(Op.VA, x.R, b.const(ctx.joint(j).com, f"r_star{j}", j), "G1")
    m = b.op(Op.VA, big_n, b.op(Op.VC, c, big_f, "G2"), "G3")
    return b.op(Op.MV, x.W, big_f, "G4"), b.op(Op.MV, x.W, m, "G5")


def _to_parent(ctx: _Ctx, j: int, prefixes: list[BackIds], f_sum: int, n_sum: int) -> tuple[int, int]:
    """f'_j = W_pᵀ Φ_j, n'_j = W_pᵀ M_j + f'_j × (R_p + o_j): the subtree's load in the parent's frame,
    about joint j's frame origin."""
    b, p, shift = ctx.b, ctx.chain.parent(j), ctx.joint(j).shift
    if p == 0:
        if shift is None:
            return f_sum, n_sum
        return f_sum, b.op(Op.VA, n_sum, b.op(Op.VC, f_sum, b.const(shift, f"shift{j}", j), "K4"), "K5")
    w, r = prefixes[p - 1].W, prefixes[p - 1].R
    fp = b.op(Op.MTV, w, f_sum, "K1")
    if shift is not None:
        r = b.op(Op.VA, r, b.const(shift, f"shift{j}", j), "K3")
    return fp, b.op(Op.VA, b.op(Op.MTV, w, n_sum, "K2"), b.op(Op.VC, fp, r, "K4"), "K5")


def _output(ctx: _Ctx, j: int, fp: int, np_: int) -> None:
    """τ_j: the third coordinate of n'_j (f'_j prismatic), or u_j · it (VD) when u_j is not e_z."""
    joint, b = ctx.joint(j), ctx.b
    src = fp if joint.type is JointType.PRISMATIC else np_
    if joint.pre is None:
        b.output(j, src, 2)
        return
    ctx.node("fwd", j, j, j, 2 + max(ctx.chain.n - 1, 0).bit_length())
    b.output(j, b.op(Op.VD, b.const(joint.parent_axis, f"u{j}", j), src, "tau"), 0)


def _base_wrench(ctx: _Ctx, loads: tuple[int, int], totals: tuple[int, int]) -> None:
    """f_0 = F_0 + Σ φ, n_0 = N_0 + r*_0 × F_0 + Σ μ: outputs n + 1..n + 6."""
    chain, b = ctx.chain, ctx.b
    ctx.node("fwd", 0, 0, 0, 2 + max(chain.n - 1, 0).bit_length())
    big_f, big_n = loads
    b2 = b.op(Op.VA, big_n, b.op(Op.VC, b.const(chain.base_com, "r_star0"), big_f, "B1"), "B2")
    f0 = add_tree(b, [big_f, totals[0]], "f0")
    n0 = add_tree(b, [b2, totals[1]], "n0")
    for k in range(3):
        b.output(chain.n + 1 + k, f0, k)
        b.output(chain.n + 4 + k, n0, k)


def _meta(ctx: _Ctx, prefix: str, ground0: bool, prefixes, suffixes) -> dict:
    """logarithmic.py's metadata, for a tree: its depth figures too."""
    depths = tree_depths(ctx.chain.parent_of, prefix, not ground0, ctx.chain.floating)
    return {
        "recursion": "log", "prefix": prefix, "tree": jsontext.dumps(depths),
        "leaves": LOG_LEAVES[ctx.uniform], "ground": LOG_GROUNDS[ground0],
        "convention": LOG_TREE_CONVENTION,
        "bwd_nodes": jsontext.dumps(ctx.table["bwd"]), "fwd_nodes": jsontext.dumps(ctx.table["fwd"]),
        "prefixes": jsontext.dumps([[x.omega, x.omega_dot, x.pdd] for x in prefixes]),
        "suffixes": jsontext.dumps([[f, n] for f, n in suffixes]),
    }


__all__ = ["build_log_tree"]
