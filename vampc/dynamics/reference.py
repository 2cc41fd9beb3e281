"""Serial recursive Newton-Euler (Table I.1, after Luh, Walker and Paul): the oracle for every later stage.

Conventions (the paper's section II). All vectors are in link coordinates: ω_i, ω̇_i, p̈_i, r̈_i,
F_i, N_i, f_i, n_i are referred to O_i. The paper calls the base→tip pass the *backward* recursion
and the tip→base pass the *forward* recursion; this module keeps that naming.

Backward (base→tip), for i = 1..n, with z = e_z in O_{i-1} and A_iᵀ z = joint.axis:

    ω_i  = A_iᵀ(ω_{i-1} + σ_i z q̇_i)
    ω̇_i  = A_iᵀ(ω̇_{i-1} + σ_i (z q̈_i + ω_{i-1} × z q̇_i))
    p̈_i  = A_iᵀ p̈_{i-1} + ω̇_i × p*_i + ω_i × (ω_i × p*_i) + σ̄_i (A_iᵀz q̈_i + 2 ω_i × A_iᵀz q̇_i)
    r̈_i  = ω_i × (ω_i × r*_i) + ω̇_i × r*_i + p̈_i,   F_i = m_i r̈_i,   N_i = J_i ω̇_i + ω_i × (J_i ω_i)

starting from ω_0 = chain.base_omega, ω̇_0 = chain.base_omega_dot and p̈_0 = chain.base_accel = -g (gravity as
an upward acceleration of the base), all in O_0. Forward (tip→base), for i = n..1:

    f_i = F_i + A_{i+1} f_{i+1}
    n_i = A_{i+1} n_{i+1} + N_i + s*_i × F_i + p*_i × (A_{i+1} f_{i+1})

with f_{n+1} = chain.tip_force, n_{n+1} = chain.tip_torque and A_{n+1} = I (they are given in O_n). As in the
paper (f_j is exerted *on* link j *by* link j-1), f_{n+1}, n_{n+1} are the force and the moment about the
origin of O_n that link n exerts on the environment (the fictitious link n+1); the environment pushes on the
robot with -f_{n+1}, -n_{n+1}. n_i is the moment about the origin of O_{i-1}, which lies on joint i's axis,
so the joint force is

    τ_i = z_{i-1}·n_i (revolute) or z_{i-1}·f_i (prismatic),  z_{i-1} referred to O_i = joint.axis = Φ_iᵀ e_z,

not the third coordinate of n_i (README, *Exactness convention*: the two agree only when Φ_i = I).

Every function accepts a single state (q of shape (n,)) or a batch (q of shape (N, n), or any leading
shape): the same code runs on both because every product broadcasts over leading axes.

`kinetic_energy`, `potential_energy` and `mass_matrix` are deliberately computed another way (base-frame
forward kinematics and geometric Jacobians), so the tests can check `rnea` against them.
"""
from __future__ import annotations

import numpy as np

from vampc.errors import VampcError
from vampc.robot.chain import Chain

# --- small batched vector algebra (leading axes broadcast) ---------------------------------------------

def mv(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """M v for stacks of 3x3 matrices and 3-vectors."""
    return np.einsum("...ij,...j->...i", m, v)


def mtv(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Mᵀ v for stacks of 3x3 matrices and 3-vectors."""
    return np.einsum("...ji,...j->...i", m, v)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b over the last axis (np.cross is several times slower on batches of 3-vectors)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(np.shape(a), np.shape(b)))
    np.subtract(a1 * b2, a2 * b1, out=out[..., 0])
    np.subtract(a2 * b0, a0 * b2, out=out[..., 1])
    np.subtract(a0 * b1, a1 * b0, out=out[..., 2])
    return out


# --- inputs --------------------------------------------------------------------------------------------

def check_state(chain: Chain, *arrays) -> tuple[np.ndarray, ...]:
    """Convert q, q̇, q̈ (...) to float arrays of one common shape (..., n); raise VampcError otherwise."""
    out = tuple(np.asarray(x, dtype=float) for x in arrays)
    shape = out[0].shape
    for x in out:
        if x.shape != shape or x.ndim == 0 or x.shape[-1] != chain.n:
            raise VampcError(f"{chain.name}: joint arrays have shapes {[y.shape for y in out]}, "
                             f"expected equal shapes (n,) or (N, n) with n = {chain.n}")
    return out


def _endpoint(vec: np.ndarray, batch: tuple[int, ...]) -> np.ndarray:
    return np.broadcast_to(np.asarray(vec, dtype=float), batch + (3,))


# --- the two recursions ----------------------------------------------------------------------------------

def base_motion(chain: Chain, base, batch: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ω_0, ω̇_0 and p̈_0 = a_0 - g in O_0. A fixed base: the chain's constants. A floating base: `base`
    (..., 9) = [ω_0, ω̇_0, a_0] per state, a_0 the classical acceleration of O_0's origin (zero if None)."""
    if not chain.floating:
        if base is not None:
            raise VampcError(f"{chain.name}: base motion given for a fixed-base robot")
        return tuple(_endpoint(v, batch) for v in (chain.base_omega, chain.base_omega_dot, chain.base_accel))
    if base is None:
        base = np.zeros(batch + (9,))
    base = np.broadcast_to(np.asarray(base, dtype=float), batch + (9,))
    return base[..., 0:3], base[..., 3:6], base[..., 6:9] - np.asarray(chain.gravity, dtype=float)


def shifted_accel(w, wd, pdd, shift):
    """Acceleration of a point fixed in a link at `shift` from its frame's origin (same coordinates)."""
    if shift is None:
        return pdd
    return pdd + cross(wd, shift) + cross(w, cross(w, shift))


def _backward(chain: Chain, q, qd, qdd, base=None) -> dict[str, list[np.ndarray]]:
    """Base→tip pass of Table I.1 (the paper's "backward" recursion): ω, ω̇, p̈ and the A_i, p*_i used.
    Each joint reads its parent's ω, ω̇ and the acceleration of its own joint frame's origin."""
    batch = q.shape[:-1]
    motion = {0: base_motion(chain, base, batch)}
    out = {key: [] for key in ("A", "p_star", "omega", "omega_dot", "pdd")}
    for i, (joint, parent) in enumerate(zip(chain.joints, chain.parent_of)):
        w, wd, pdd = motion[parent]
        pdd = shifted_accel(w, wd, pdd, joint.shift)
        a, ps = joint.A(q[..., i]), joint.p_star(q[..., i])
        axis, vel, acc = joint.axis, qd[..., i, None], qdd[..., i, None]
        if joint.sigma:
            w_new = mtv(a, w) + axis * vel
            wd = mtv(a, wd) + axis * acc + cross(mtv(a, w), axis * vel)
            w = w_new
            pdd = mtv(a, pdd) + cross(wd, ps) + cross(w, cross(w, ps))
        else:
            w, wd = mtv(a, w), mtv(a, wd)
            pdd = (mtv(a, pdd) + cross(wd, ps) + cross(w, cross(w, ps))
                   + axis * acc + 2.0 * cross(w, axis * vel))
        motion[i + 1] = (w, wd, pdd)
        for key, val in zip(out, (a, ps, w, wd, pdd)):
            out[key].append(val)
    out["base"] = motion[0]
    return out


def link_loads(chain: Chain, omega, omega_dot, pdd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The non-propagated variables r̈_i, F_i, N_i from ω_i, ω̇_i, p̈_i (arrays (..., n, 3))."""
    com = np.array([j.com for j in chain.joints])
    mass = np.array([j.mass for j in chain.joints])[:, None]
    inertia = np.array([j.inertia for j in chain.joints])
    return _loads(com, mass, inertia, omega, omega_dot, pdd)


def _loads(com, mass, inertia, omega, omega_dot, pdd):
    rdd = cross(omega, cross(omega, com)) + cross(omega_dot, com) + pdd
    big_n = mv(inertia, omega_dot) + cross(omega, mv(inertia, omega))
    return rdd, mass * rdd, big_n


def _forward(chain: Chain, q, fwd_a, p_star, big_f, big_n) -> tuple[list, list, tuple]:
    """Tip→base pass of Table I.1 (the paper's "forward" recursion): f_i, n_i in O_i, i = 1..n, and what
    the base's children pass to it (Σ A_c f_c, Σ (A_c n_c + o_c × A_c f_c) in O_0). A joint sums its
    children's forces and moments, moved from their joint frames' origins to its own."""
    batch = q.shape[:-1]
    zero = np.zeros(batch + (3,))
    f_in = [zero] * (chain.n + 1)      # per link: Σ over children of A_d f_d, in its frame
    n_in = [zero] * (chain.n + 1)      # Σ A_d n_d + o_d × A_d f_d (about its frame's origin)
    f_in[chain.n] = _endpoint(chain.tip_force, batch)       # the tip load is given in O_n
    n_in[chain.n] = _endpoint(chain.tip_torque, batch)
    fs, ns = [None] * chain.n, [None] * chain.n
    for i in reversed(range(chain.n)):
        joint, parent = chain.joints[i], chain.parent_of[i]
        s_star = p_star[i] + joint.com
        f = big_f[..., i, :] + f_in[i + 1]
        n = n_in[i + 1] + big_n[..., i, :] + cross(s_star, big_f[..., i, :]) + cross(p_star[i], f_in[i + 1])
        fs[i], ns[i] = f, n
        af, an = mv(fwd_a[i], f), mv(fwd_a[i], n)
        if joint.shift is not None:
            an = an + cross(joint.shift, af)
        f_in[parent] = f_in[parent] + af
        n_in[parent] = n_in[parent] + an
    return fs, ns, (f_in[0], n_in[0])


def joint_forces(chain: Chain, f: np.ndarray, n: np.ndarray) -> np.ndarray:
    """τ_i = z_{i-1}·n_i (revolute) or z_{i-1}·f_i (prismatic), z_{i-1} = joint.axis; f, n (..., n, 3)."""
    axes = np.array([j.axis for j in chain.joints])
    sigma = chain.sigmas.astype(bool)
    return np.where(sigma, np.sum(axes * n, axis=-1), np.sum(axes * f, axis=-1))


def base_wrench(chain: Chain, motion, children) -> tuple[np.ndarray, np.ndarray]:
    """Floating base: the force and moment (about O_0's origin, in O_0) the base joint must supply: the
    base link's own F_0, N_0 + r*_0 × F_0 and what its children pass to it."""
    w, wd, pdd = motion
    _, big_f, big_n = _loads(chain.base_com, chain.base_mass, chain.base_inertia, w, wd, pdd)
    return big_f + children[0], big_n + cross(chain.base_com, big_f) + children[1]


def _run(chain: Chain, q, qd, qdd, base=None) -> dict[str, np.ndarray]:
    q, qd, qdd = check_state(chain, q, qd, qdd)
    back = _backward(chain, q, qd, qdd, base)
    out = {key: np.stack(back[key], axis=-2) for key in ("omega", "omega_dot", "pdd")}
    out["rdd"], out["F"], out["N"] = link_loads(chain, out["omega"], out["omega_dot"], out["pdd"])
    fs, ns, children = _forward(chain, q, back["A"], back["p_star"], out["F"], out["N"])
    out["f"], out["n"] = np.stack(fs, axis=-2), np.stack(ns, axis=-2)
    out["tau"] = joint_forces(chain, out["f"], out["n"])
    if chain.floating:
        f0, n0 = base_wrench(chain, back["base"], children)
        out["base_wrench"] = np.concatenate([f0, n0], axis=-1)
        out["tau"] = np.concatenate([out["tau"], out["base_wrench"]], axis=-1)
    return out


def rnea(chain: Chain, q, qd, qdd, base=None) -> np.ndarray:
    """Joint forces τ for states q, q̇, q̈ of shape (n,) or (N, n); returns the same shape. A floating
    base takes `base` (..., 9) = [ω_0, ω̇_0, a_0] (see `base_motion`) and returns (..., n + 6): the joint
    forces, then the base wrench [f_0, n_0] in O_0 (n_0 about O_0's origin)."""
    return _run(chain, q, qd, qdd, base)["tau"]


def rnea_variables(chain: Chain, q, qd, qdd, base=None) -> dict[str, np.ndarray]:
    """Every Table I.1 variable for one state: 'omega', 'omega_dot', 'pdd', 'rdd', 'F', 'N', 'f', 'n'.

    Each has shape (n, 3), row i-1 holding the value for link i referred to O_i; 'tau' has shape (n,)
    (n + 6 with a floating base, whose wrench is also 'base_wrench'). A batch (N, n) of states gives
    (N, n, 3) and (N, n).
    """
    return _run(chain, q, qd, qdd, base)


# --- independent energy / mass-matrix code (base-frame kinematics, geometric Jacobians) -------------------

def _base_frames(chain: Chain, q) -> tuple[list[np.ndarray], list[np.ndarray], list, list]:
    """Orientation ⁰W_i and origin of O_i in base coordinates, i = 0..n (by composing transforms), and
    per joint its axis and a point on it (J_i's origin), in base coordinates."""
    batch = q.shape[:-1]
    rots = [np.broadcast_to(np.eye(3), batch + (3, 3))]
    origins = [np.zeros(batch + (3,))]
    axes, points = [], []
    for i, (joint, p) in enumerate(zip(chain.joints, chain.parent_of)):
        points.append(origins[p] + mv(rots[p], joint.shift_vec))
        axes.append(mv(rots[p], np.broadcast_to(joint.parent_axis, origins[p].shape)))
        rots.append(rots[p] @ joint.A(q[..., i]))
        origins.append(points[-1] + mv(rots[-1], joint.p_star(q[..., i])))
    return rots, origins, axes, points


def _ancestors(chain: Chain) -> np.ndarray:
    """mask[i-1, j-1] = 1 when joint j moves link i (j is i or an ancestor of i)."""
    mask = np.zeros((chain.n, chain.n))
    for i, p in enumerate(chain.parent_of):
        if p:
            mask[i] = mask[p - 1]
        mask[i, i] = 1.0
    return mask


def _com_jacobians(chain: Chain, q):
    """Per link: centre of mass c_i, ⁰W_i, and the geometric Jacobians Jv_i, Jω_i (..., 3, n), base coords."""
    rots, origins, axes, points = _base_frames(chain, q)
    axes = np.stack(axes, -1)
    sigma = chain.sigmas.astype(float)
    moves = _ancestors(chain)
    for i, joint in enumerate(chain.joints, 1):
        com = origins[i] + mv(rots[i], joint.com)
        lever = np.stack([com - points[j] for j in range(chain.n)], axis=-1)
        jv = sigma * np.swapaxes(cross(np.swapaxes(axes, -1, -2), np.swapaxes(lever, -1, -2)), -1, -2)
        jv = jv + (1.0 - sigma) * axes
        mask = moves[i - 1]                  # only joint i and its ancestors move link i
        yield joint, com, rots[i], jv * mask, sigma * axes * mask


def mass_matrix(chain: Chain, q) -> np.ndarray:
    """M(q) = Σ m_i Jv_iᵀ Jv_i + Jω_iᵀ (⁰W_i J_i ⁰W_iᵀ) Jω_i; q (..., n) gives (..., n, n)."""
    (q,) = check_state(chain, q)
    total = np.zeros(q.shape + (chain.n,))
    for joint, _, rot, jv, jw in _com_jacobians(chain, q):
        inertia = rot @ joint.inertia @ np.swapaxes(rot, -1, -2)
        total = total + joint.mass * np.swapaxes(jv, -1, -2) @ jv + np.swapaxes(jw, -1, -2) @ inertia @ jw
    return total


def kinetic_energy(chain: Chain, q, qd) -> np.ndarray:
    """T = ½ q̇ᵀ M(q) q̇ relative to the base frame (assumes ω_0 = 0 and a non-rotating base)."""
    q, qd = check_state(chain, q, qd)
    return 0.5 * np.einsum("...i,...ij,...j->...", qd, mass_matrix(chain, q), qd)


def potential_energy(chain: Chain, q) -> np.ndarray:
    """V = -Σ m_i g·c_i, with g = chain.gravity in O_0 and c_i the centre of mass in base coordinates."""
    (q,) = check_state(chain, q)
    total = np.zeros(q.shape[:-1])
    for joint, com, *_ in _com_jacobians(chain, q):
        total = total - joint.mass * com @ np.asarray(chain.gravity, dtype=float)
    return total
