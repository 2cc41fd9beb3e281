"""Logarithmic combining forms of section IV (Table IV.1, Appendix B, Appendix D) in plain numpy.

A relational parameter X_{a,b} abstracts links a..b; adjacent ones combine as X_{a,b} = X_{a,k} ⊗ X_{k+1,b}
(a ≤ k < b), and ⊗ is associative, so any bracketing of the leaves X_{a,a} gives the same X_{a,b}. The
prefixes X_{0,i} of the backward (base→tip, the paper's naming) pass are the linear ω_i, ω̇_i, p̈_i of
Table I.1; the suffixes X_{i,n+1} of the forward (tip→base) pass are f_i, n_i. Notation: z = e_z (z_{j-1}
in O_{j-1}); A_jᵀz = joint.axis; W_{a,b} = A_a⋯A_b maps O_b to O_{a-1}; W_{a,a-1} = I; σ̄ = 1 - σ.

Backward closed forms (Appendix B), all referred to O_b, derivatives taken in O_{a-1}:

    ω_{a,b} = Σ_{j=a..b} W_{j,b}ᵀ σ_j z q̇_j          Q_{a,b} = Σ W_{j,b}ᵀ σ̄_j z q̇_j
    ω̇_{a,b} = Σ W_{j,b}ᵀ σ_j (z q̈_j + ω_{a,j-1} × z q̇_j)
    R_{a,b} = Σ W_{j+1,b}ᵀ p*_j (O_b from O_{a-1})    S_{a,b} = Σ W_{j+1,b}ᵀ (ω_{a,j} × p*_j)
    p̈_{a,b} = Σ W_{j+1,b}ᵀ (p̈ᵍ_j + ω̇_{a,j} × p*_j + ω_{a,j} × (ω_{a,j} × p*_j)
                            + σ̄_j (A_jᵀz q̈_j + 2 ω_{a,j} × A_jᵀz q̇_j))

Backward leaves (`back_leaf`), a = 1..n, from the closed forms at b = a:

    W = A_a   ω = σ_a A_aᵀz q̇_a   ω̇ = σ_a A_aᵀz q̈_a   Q = σ̄_a A_aᵀz q̇_a   R = p*_a   S = ω_{a,a} × p*_a
    p̈ = ω̇_{a,a} × p*_a + ω_{a,a} × (ω_{a,a} × p*_a) + σ̄_a A_aᵀz q̈_a

The closed form also gives + 2 ω_{a,a} × Q_{a,a}, which is identically zero (σ_a σ̄_a = 0), so it is left
out. The grounding leaf a = 0 (not printed in the paper; derived here with O_{-1} placed at the origin of
O_0 and aligned with it at the instant, so A_0 = I and p*_0 = 0, and σ_0 = 1): W = I, ω = ω_0, ω̇ = ω̇_0,
Q = 0, R = 0, S = 0, p̈ = p̈ᵍ_0 = p̈_0 = chain.base_accel = -g (gravity as base acceleration, including any
centripetal term of the site).

Backward combine (`back_combine`), with T1 = W_{k+1,b}ᵀ ω_{a,k} and T2 = W_{k+1,b}ᵀ ω̇_{a,k}:

    W_{a,b} = W_{a,k} W_{k+1,b}
    ω_{a,b} = T1 + ω_{k+1,b}                Q_{a,b} = W_{k+1,b}ᵀ Q_{a,k} + Q_{k+1,b}
    ω̇_{a,b} = T2 + T1 × ω_{k+1,b} + ω̇_{k+1,b}    R_{a,b} = W_{k+1,b}ᵀ R_{a,k} + R_{k+1,b}
    S_{a,b} = W_{k+1,b}ᵀ S_{a,k} + T1 × R_{k+1,b} + S_{k+1,b}
    p̈_{a,b} = W_{k+1,b}ᵀ p̈_{a,k} + p̈_{k+1,b} + T2 × R_{k+1,b}
              + T1 × (T1 × R_{k+1,b} + 2 (S_{k+1,b} + Q_{k+1,b}))

The only matrix the backward combine needs is W_{k+1,b} of the right operand (and W_{a,k} for W itself).

Forward closed forms: f_{a,b} = Σ_{j=a..b} W_{a+1,j} F_j and n_{a,b} = Σ W_{a+1,j}(N_j + s*_j × F_j +
p*_j × A_{j+1} f_{j+1,b}), referred to O_a, n about the origin of O_{a-1}. Both need the *shifted* products
W'_{a,b} = W_{a+1,b+1} (O_{b+1} to O_a) and R'_{a,b} = A_{b+1}ᵀ R_{a,b} = Σ_{j=a..b} W'_{j,b}ᵀ p*_j (the
origin of O_b from O_{a-1}, referred to O_{b+1}). `Fwd.W` is W' and `Fwd.R` is R'. Forward combine
(`fwd_combine`), X_{a,b} = X_{a,k} ⊗ X_{k+1,b}:

    W'_{a,b} = W'_{a,k} W'_{k+1,b}           R'_{a,b} = W'_{k+1,b}ᵀ R'_{a,k} + R'_{k+1,b}
    f_{a,b} = f_{a,k} + W'_{a,k} f_{k+1,b}   n_{a,b} = n_{a,k} + W'_{a,k} (n_{k+1,b} + R'_{a,k} × f_{k+1,b})

so f and n need W' and R' of the *left* operand only; W' and R' themselves combine exactly like the
backward W and R. Forward leaves (`fwd_leaf`), a = 1..n+1:

    W' = A_{a+1}   R' = A_{a+1}ᵀ p*_a   f = F_a   n = N_a + s*_a × F_a      (A_{n+1} = A_{n+2} = I)

and the tip load is the leaf a = n+1: f = f_{n+1}, n = n_{n+1}, W' = I, R' = 0 (F_{n+1} = f_{n+1},
N_{n+1} = n_{n+1}, s*_{n+1} = p*_{n+1} = 0 in the closed forms). Then X_{i,n+1} = (f_i, n_i) for i = 1..n.
Folding the tip into leaf n instead (f = F_n + f_{n+1}, n = N_n + s*_n × F_n + n_{n+1} + p*_n × f_{n+1})
is equivalent and saves a leaf. With a zero tip load X_{i,n} = X_{i,n+1}.

Where these differ from the printed Table IV.1 (and Appendix D), and why:

1. ω_{a,a} and Q_{a,a}: the printed q̄_a is q̇_a (the closed forms carry q̇_j).
2. ω̇_{a,a}: printed σ_a A_aᵀz q̇_a; the closed form at b = a gives q̈_a (ω_{a,a-1} = 0).
3. p̈_{a,a}: the printed p̈*_a is p̈ᵍ_a (base acceleration, zero unless a = 0); the printed
   ∂_a A_aᵀ x_{a-1} q̈_a is σ̄_a A_aᵀ z_{a-1} q̈_a; the printed 2 ω_{a,a} × Q_{a,a} is identically zero.
4. The grounding leaf a = 0 is derived above (the paper only describes it in words).
5. Forward pass: the paper carries W_{a+1,b+1} and recomputes the unshifted R_{a,b}, forming
   T20 = A_{k+1}ᵀ R_{a,k} at each combine (Table V.1). But combining the unshifted R_{a,b} needs the
   unshifted W_{k+1,b}, and the paper counts one MM per forward node (for W_{a+1,b+1}), so as printed the
   forward node cannot recompute R. Carrying R' = A_{b+1}ᵀ R instead makes T20 = R'_{a,k} a stored value.
   Forward combine here: 1 MM + 4 MV (f 1; n 2, split as the paper's W'n + W'(R' × f); R' 1) + 4 VA +
   1 VC = 10 ops, 12 VAMPs, against the paper's 11 ops, 13 VAMPs (W'(n + R' × f) would save one more MV
   at the cost of latency). The forward leaf's R' = A_{a+1}ᵀ p*_a is one MV per leaf. The backward combine
   is op-for-op the paper's (1 MM, 6 MV, 12 VA, 4 VC, 1 SV = 24 ops, 26 VAMPs).
6. Appendix D (`*_leaf_unified`): R_{k+1,b} = \\dot p*_a is p*_a; p̈_{a,k} = σ̄_a a_{a-1} q̈_a is
   σ̄_a z q̈_a; n_{k+1,b} = \\dot s*_a × F_a is s*_a × F_a; with R', the right operand's R' is
   A_{a+1}ᵀ p*_a.
7. Table V.1's W'_{k+1,b} p̈_{a,k} (step T16) is W_{k+1,b}ᵀ p̈_{a,k}.
8. The joint force is τ_i = (A_iᵀz)·n_i (or ·f_i), not the third coordinate of n_i
   (README, *Exactness convention*).

Trees (issue 12; vampc.dataflow.treeprefix). A joint d whose joint frame J_d is shifted by o_d from its
parent's frame origin (vampc.robot.chain) is the leaf X_{d,d} after a motionless virtual leaf
V_d = (I, 0, 0, 0, o_d, 0, 0) (a rigid offset inside the parent link): V_d ⊗ X_{d,d} has T1 = T2 = 0, so it
is X_{d,d} with R = A_dᵀ o_d + p*_d, the origin of O_d from the parent frame's origin, and nothing else
changed; z q̇ of the leaf is u_d q̇_d in the parent's frame. Backward: `tree_prefix_backward` evaluates
treeprefix's plan (heavy paths, the chain shape on each, one ⊗ per joint below a light edge) with these
leaves and `back_combine`. Forward, in the base frame: with W_j, R_j of joint j's full prefix (O_j's
orientation and origin seen from O_0), link j's force and moment about O_0's origin, in O_0, are

    φ_j = W_j F_j,   μ_j = W_j (N_j + (R_j + r*_j) × F_j)          (the tip load folded into joint n)

and the forward recursion is their plain sum over each subtree: Φ_c = Σ_{k ∈ sub(c)} φ_k, M_c likewise
(`tree_forward`: sums of treeprefix.range_blocks). Back in the parent p's frame, about J_c's origin:

    f'_c = W_pᵀ Φ_c = A_c f_c,   n'_c = W_pᵀ M_c + f'_c × (R_p + o_c) = A_c n_c      (W_0 = I, R_0 = 0)

and τ_c = u_c · n'_c (u_c · f'_c prismatic). A floating base's wrench is F_0 + Σ_all φ, N_0 + r*_0 × F_0
+ Σ_all μ. `tree_log_rnea` runs both passes; the tests hold it to `rnea` on random trees.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from vampc.dynamics.reference import (
    check_state,
    cross,
    joint_forces,
    link_loads,
    mtv,
    mv,
)
from vampc.errors import VampcInternalError
from vampc.robot.chain import Chain


class State(NamedTuple):
    """Joint positions, velocities and accelerations, each of shape (n,) or (N, n)."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray


@dataclass(frozen=True)
class Back:
    """Backward relational parameter X_{a,b}: W (…, 3, 3); ω, ω̇, Q, R, S, p̈ (…, 3), all in O_b."""

    W: np.ndarray
    omega: np.ndarray
    omega_dot: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    S: np.ndarray
    pdd: np.ndarray


@dataclass(frozen=True)
class Fwd:
    """Forward relational parameter X_{a,b}: W = W_{a+1,b+1}, R = A_{b+1}ᵀ R_{a,b}, f and n in O_a."""

    W: np.ndarray
    R: np.ndarray
    f: np.ndarray
    n: np.ndarray


Split = Callable[[int, int], int]


def split_middle(a: int, b: int) -> int:
    """Balanced bracketing: k = ⌊(a + b) / 2⌋."""
    return (a + b) // 2


def split_last(a: int, b: int) -> int:
    """k = b - 1: X_{a,b} = X_{a,b-1} ⊗ X_{b,b}, the linear backward recursion."""
    return b - 1


def split_first(a: int, b: int) -> int:
    """k = a: X_{a,b} = X_{a,a} ⊗ X_{a+1,b}, the linear forward recursion."""
    return a


# --- leaves ------------------------------------------------------------------------------------------------

def _check_index(chain: Chain, a: int, lo: int, hi: int) -> None:
    if not lo <= a <= hi:
        raise VampcInternalError(f"{chain.name}: leaf {a} outside {lo}..{hi}")


def _eye(batch: tuple[int, ...]) -> np.ndarray:
    return np.broadcast_to(np.eye(3), batch + (3, 3))


def _vec(v, batch: tuple[int, ...]) -> np.ndarray:
    return np.broadcast_to(np.asarray(v, dtype=float), batch + (3,))


def _ground_leaf(chain: Chain, batch: tuple[int, ...]) -> Back:
    zero = _vec(np.zeros(3), batch)
    return Back(W=_eye(batch), omega=_vec(chain.base_omega, batch),
                omega_dot=_vec(chain.base_omega_dot, batch), Q=zero, R=zero, S=zero,
                pdd=_vec(chain.base_accel, batch))


def back_leaf(chain: Chain, a: int, state: State) -> Back:
    """X_{a,a} of the backward pass, a = 0 (grounding node) .. n; see the module docstring."""
    _check_index(chain, a, 0, chain.n)
    q, qd, qdd = check_state(chain, *state)
    if a == 0:
        return _ground_leaf(chain, q.shape[:-1])
    joint = chain.joints[a - 1]
    axis, p_star = joint.axis, joint.p_star(q[..., a - 1])
    vel, acc = axis * qd[..., a - 1, None], axis * qdd[..., a - 1, None]
    w, wd = joint.sigma * vel, joint.sigma * acc
    pdd = cross(wd, p_star) + cross(w, cross(w, p_star)) + (1 - joint.sigma) * acc
    big_a = joint.A(q[..., a - 1])
    r = p_star if joint.shift is None else p_star + mtv(big_a, joint.shift)   # V_d ⊗ X_{d,d}
    return Back(W=big_a, omega=w, omega_dot=wd, Q=(1 - joint.sigma) * vel,
                R=r, S=cross(w, p_star), pdd=pdd)


def _loads_at(chain: Chain, a: int, big_f, big_n, batch) -> tuple[np.ndarray, np.ndarray]:
    """(F_a, N_a); the tip leaf a = n+1 carries (f_{n+1}, n_{n+1})."""
    if a == chain.n + 1:
        return _vec(chain.tip_force, batch), _vec(chain.tip_torque, batch)
    return np.asarray(big_f)[..., a - 1, :], np.asarray(big_n)[..., a - 1, :]


def _shifted(chain: Chain, a: int, q) -> tuple[np.ndarray, np.ndarray]:
    """(W'_{a,a}, R'_{a,a}) = (A_{a+1}, A_{a+1}ᵀ p*_a), with A_{n+1} = A_{n+2} = I and p*_{n+1} = 0."""
    batch = q.shape[:-1]
    p_star = chain.joints[a - 1].p_star(q[..., a - 1]) if a <= chain.n else _vec(np.zeros(3), batch)
    if a >= chain.n:
        return _eye(batch), p_star
    a_next = chain.joints[a].A(q[..., a])
    return a_next, mtv(a_next, p_star)


def fwd_leaf(chain: Chain, a: int, q, big_f, big_n) -> Fwd:
    """X_{a,a} of the forward pass, a = 1..n+1 (n+1 is the tip load); F, N are (…, n, 3) link loads."""
    _check_index(chain, a, 1, chain.n + 1)
    (q,) = check_state(chain, q)
    f, torque = _loads_at(chain, a, big_f, big_n, q.shape[:-1])
    w, r = _shifted(chain, a, q)
    if a <= chain.n:
        torque = torque + cross(chain.joints[a - 1].s_star(q[..., a - 1]), f)
    return Fwd(W=w, R=r, f=f, n=torque)


def back_leaf_unified(chain: Chain, a: int, state: State) -> tuple[Back, Back]:
    """Appendix D: operands (L, R) with back_combine(L, R) == back_leaf(chain, a, state)."""
    leaf = back_leaf(chain, a, state)
    zero = np.zeros_like(leaf.R)
    if a == 0:
        left = Back(_eye(zero.shape[:-1]), leaf.omega, leaf.omega_dot, zero, zero, zero, zero)
        return left, Back(leaf.W, zero, zero, zero, zero, zero, leaf.pdd)
    joint = chain.joints[a - 1]
    q, qd, qdd = check_state(chain, *state)
    u = joint.parent_axis
    vel, acc = qd[..., a - 1, None] * u, qdd[..., a - 1, None] * u
    sig, bar = joint.sigma, 1 - joint.sigma
    shift = zero + joint.shift_vec
    left = Back(_eye(zero.shape[:-1]), sig * vel, sig * acc, bar * vel, shift, zero, bar * acc)
    return left, Back(leaf.W, zero, zero, zero, joint.p_star(q[..., a - 1]), zero, zero)


def fwd_leaf_unified(chain: Chain, a: int, q, big_f, big_n) -> tuple[Fwd, Fwd]:
    """Appendix D: operands (L, R) with fwd_combine(L, R) == fwd_leaf(chain, a, q, F, N)."""
    leaf = fwd_leaf(chain, a, q, big_f, big_n)
    f, torque = _loads_at(chain, a, big_f, big_n, leaf.f.shape[:-1])
    zero = np.zeros_like(leaf.f)
    left = Fwd(_eye(zero.shape[:-1]), zero, f, torque)
    return left, Fwd(leaf.W, leaf.R, zero, leaf.n - torque)


# --- combining forms ---------------------------------------------------------------------------------------

def back_combine(left: Back, right: Back) -> Back:
    """X_{a,b} = X_{a,k} ⊗ X_{k+1,b} for the backward pass (module docstring; Table V.1 step names)."""
    wt = right.W
    t1, t2 = mtv(wt, left.omega), mtv(wt, left.omega_dot)
    twice = 2.0 * (right.S + right.Q)
    pdd = (mtv(wt, left.pdd) + right.pdd + cross(t2, right.R)
           + cross(t1, cross(t1, right.R) + twice))
    return Back(W=left.W @ right.W, omega=t1 + right.omega,
                omega_dot=t2 + cross(t1, right.omega) + right.omega_dot,
                Q=mtv(wt, left.Q) + right.Q, R=mtv(wt, left.R) + right.R,
                S=mtv(wt, left.S) + cross(t1, right.R) + right.S, pdd=pdd)


def fwd_combine(left: Fwd, right: Fwd) -> Fwd:
    """X_{a,b} = X_{a,k} ⊗ X_{k+1,b} for the forward pass; f, n use only the left W' = W_{a+1,k+1}, R'."""
    w = left.W
    torque = left.n + mv(w, right.n) + mv(w, cross(left.R, right.f))
    return Fwd(W=left.W @ right.W, R=mtv(right.W, left.R) + right.R,
               f=left.f + mv(w, right.f), n=torque)


# --- evaluation under an arbitrary bracketing ------------------------------------------------------------

def reduce_range(a: int, b: int, leaf: Callable, combine: Callable, split: Split, memo: dict):
    """X_{a,b}, bracketed by split(a', b') -> k for every range met; memo shares equal sub-ranges."""
    if (a, b) not in memo:
        if a == b:
            memo[a, b] = leaf(a)
        else:
            k = split(a, b)
            if not a <= k < b:
                raise VampcInternalError(f"split({a}, {b}) = {k} is not in {a}..{b - 1}")
            memo[a, b] = combine(reduce_range(a, k, leaf, combine, split, memo),
                                 reduce_range(k + 1, b, leaf, combine, split, memo))
    return memo[a, b]


def prefix_backward(chain: Chain, state: State, split: Split = split_middle) -> list[Back]:
    """[X_{0,0}, …, X_{0,n}]: X_{0,i} holds ω_i, ω̇_i, p̈_i of Table I.1 and W_{0,i} = A_1⋯A_i."""
    memo: dict = {}
    leaf = lambda a: back_leaf(chain, a, state)   # noqa: E731 - a closure keeps reduce_range generic
    return [reduce_range(0, i, leaf, back_combine, split, memo) for i in range(chain.n + 1)]


def suffix_forward(chain: Chain, q, big_f, big_n, split: Split = split_middle) -> list[Fwd]:
    """[X_{1,n+1}, …, X_{n+1,n+1}]: element i-1 holds f_i, n_i of Table I.1 (in O_i) for i = 1..n."""
    memo: dict = {}
    leaf = lambda a: fwd_leaf(chain, a, q, big_f, big_n)   # noqa: E731
    last = chain.n + 1
    return [reduce_range(i, last, leaf, fwd_combine, split, memo) for i in range(1, last + 1)]


def log_rnea(chain: Chain, q, qd, qdd, split: Split = split_middle) -> np.ndarray:
    """Joint forces through the combining forms: prefixes, then link loads, then suffixes."""
    q, qd, qdd = check_state(chain, q, qd, qdd)
    back = prefix_backward(chain, State(q, qd, qdd), split)[1:]
    omega, omega_dot, pdd = (np.stack([getattr(x, k) for x in back], axis=-2)
                             for k in ("omega", "omega_dot", "pdd"))
    _, big_f, big_n = link_loads(chain, omega, omega_dot, pdd)
    fwd = suffix_forward(chain, q, big_f, big_n, split)[:-1]
    return joint_forces(chain, np.stack([x.f for x in fwd], -2), np.stack([x.n for x in fwd], -2))


# --- trees (issue 12) --------------------------------------------------------------------------------------

def tree_prefix_backward(chain: Chain, state: State, shape: str = "sklansky", base=None) -> list[Back]:
    """Every joint's full prefix X_{0..j} (j = 1..n) by treeprefix's plan, grounded in O_{-1}; a floating
    base's grounding leaf takes `base` (…, 9) = [ω_0, ω̇_0, a_0] (vampc.dynamics.reference.base_motion)."""
    from vampc.dataflow.treeprefix import path_prefix_plan
    from vampc.dynamics.reference import base_motion
    tiers, keys = path_prefix_plan(chain.parent_of, shape, ground=True)
    q, _, _ = check_state(chain, *state)
    x = {(j, j): back_leaf(chain, j, state) for j in range(1, chain.n + 1)}
    w, wd, pdd = base_motion(chain, base, q.shape[:-1])
    zero = np.zeros_like(w)
    x[0, 0] = Back(_eye(q.shape[:-1]), w, wd, zero, zero, zero, pdd)
    path = {j: p for j, p in enumerate(chain.parent_of, 1)}
    for tier in tiers:
        for a, k, b in tier:
            c = b
            while path[c] != k:
                c = path[c]
            x[a, b] = back_combine(x[a, k], x[c, b])
    return [x[key] for key in keys]


def tree_forward(chain: Chain, prefixes: list[Back], big_f, big_n):
    """(f', n') per joint, in the parent's frame about the joint frame's origin (A_c f_c, A_c n_c), and
    Σ φ, Σ μ over all joints, from the full prefixes and the link loads (…, n, 3), by subtree sums in
    O_0 (module docstring)."""
    phi, mu = _base_frame_loads(chain, prefixes, big_f, big_n)
    end, n = chain.subtree_end, chain.n
    blocks: dict = {}
    sums = [(_range_sum(phi, i - 1, end[i - 1] - 1, blocks, "f"),
             _range_sum(mu, i - 1, end[i - 1] - 1, blocks, "n")) for i in range(1, n + 1)]
    out = []
    for i, (joint, p) in enumerate(zip(chain.joints, chain.parent_of), 1):
        f_sum, n_sum = sums[i - 1]
        if p == 0:
            fp, np_ = f_sum, n_sum + cross(f_sum, joint.shift_vec)
        else:
            wp, rp = prefixes[p - 1].W, prefixes[p - 1].R
            fp = mtv(wp, f_sum)
            np_ = mtv(wp, n_sum) + cross(fp, rp + joint.shift_vec)
        out.append((fp, np_))
    return out, (_range_sum(phi, 0, n, blocks, "f"), _range_sum(mu, 0, n, blocks, "n"))


def _base_frame_loads(chain: Chain, prefixes: list[Back], big_f, big_n):
    """φ_j = W_j F_j and μ_j = W_j (N_j + (R_j + r*_j) × F_j), the tip load folded into joint n."""
    phi, mu = [], []
    for j, (joint, x) in enumerate(zip(chain.joints, prefixes), 1):
        f, torque = np.asarray(big_f)[..., j - 1, :], np.asarray(big_n)[..., j - 1, :]
        if j == chain.n:
            f = f + chain.tip_force
            torque = torque + chain.tip_torque - np.cross(joint.com, chain.tip_force)
        phi.append(mv(x.W, f))
        mu.append(mv(x.W, torque + cross(x.R + joint.com, f)))
    return phi, mu


def _range_sum(values: list, lo: int, hi: int, blocks: dict, tag: str):
    """Σ values[lo:hi] as the sum of its canonical blocks (treeprefix.range_blocks)."""
    from vampc.dataflow.treeprefix import range_blocks
    total = None
    for level, index in range_blocks(lo, hi):
        part = _block(values, level, index, blocks, tag)
        total = part if total is None else total + part
    return total


def _block(values: list, level: int, index: int, blocks: dict, tag: str):
    """Σ of block (level, index) of `values`, memoised in `blocks`."""
    from vampc.dataflow.treeprefix import block_sources
    key = (tag, level, index)
    if key not in blocks:
        if level == 0:
            blocks[key] = values[index]
        else:
            halves = block_sources(level, index, len(values))
            blocks[key] = sum((_block(values, lv, ix, blocks, tag) for lv, ix in halves[1:]),
                              _block(values, *halves[0], blocks, tag))
    return blocks[key]


def tree_log_rnea(chain: Chain, q, qd, qdd, shape: str = "sklansky", base=None) -> np.ndarray:
    """Joint forces (and a floating base's wrench) of a tree through tree prefixes and subtree sums."""
    from vampc.dynamics.reference import _loads, base_motion
    q, qd, qdd = check_state(chain, q, qd, qdd)
    pre = tree_prefix_backward(chain, State(q, qd, qdd), shape, base)
    omega, omega_dot, pdd = (np.stack([getattr(x, k) for x in pre], axis=-2)
                             for k in ("omega", "omega_dot", "pdd"))
    _, big_f, big_n = link_loads(chain, omega, omega_dot, pdd)
    fwd, (f_all, n_all) = tree_forward(chain, pre, big_f, big_n)
    u = np.array([j.parent_axis for j in chain.joints])
    sigma = chain.sigmas.astype(bool)
    f = np.stack([x[0] for x in fwd], -2)
    n = np.stack([x[1] for x in fwd], -2)
    tau = np.where(sigma, np.sum(u * n, axis=-1), np.sum(u * f, axis=-1))
    if not chain.floating:
        return tau
    w, wd, p0 = base_motion(chain, base, q.shape[:-1])
    _, f0, n0 = _loads(chain.base_com, chain.base_mass, chain.base_inertia, w, wd, p0)
    return np.concatenate([tau, f0 + f_all, n0 + cross(chain.base_com, f0) + n_all], axis=-1)
