"""Random chains for property tests and benchmarks: general Φ_i (not DH), mixed joint types."""
from __future__ import annotations

import numpy as np

from vampc.robot.chain import Chain, Joint, JointType, Limits


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random proper rotation (QR of a Gaussian matrix, sign-fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def random_inertia(rng: np.random.Generator, scale: float = 0.1) -> np.ndarray:
    """A random symmetric positive-definite inertia obeying the triangle inequalities."""
    principal = rng.uniform(0.2, 1.0, size=3) * scale
    principal[2] = rng.uniform(abs(principal[0] - principal[1]) + 1e-3 * scale,
                               principal[0] + principal[1])
    rot = random_rotation(rng)
    return rot @ np.diag(principal) @ rot.T


def random_chain(n: int, rng: np.random.Generator | int = 0, prismatic_fraction: float = 0.3,
                 general: bool = True, gravity: bool = True, endpoints: bool = False) -> Chain:
    """A random n-joint chain.

    general: Φ_i a random rotation (else a DH Rx(α)); endpoints: nonzero ω0, ω̇0 and tip force/torque.
    """
    rng = np.random.default_rng(rng)
    joints = []
    for i in range(n):
        kind = JointType.PRISMATIC if rng.random() < prismatic_fraction else JointType.REVOLUTE
        phi = random_rotation(rng) if general else _rx(rng.uniform(-np.pi, np.pi))
        joints.append(Joint(
            name=f"j{i + 1}", type=kind, phi=phi, p_fixed=rng.uniform(-0.5, 0.5, 3),
            offset=float(rng.uniform(-1, 1)), mass=float(rng.uniform(0.1, 5.0)),
            com=rng.uniform(-0.3, 0.3, 3), inertia=random_inertia(rng),
            limits=Limits(q=(-np.pi, np.pi) if kind is JointType.REVOLUTE else (-0.5, 0.5))))
    extra = {}
    if endpoints:
        extra = dict(base_omega=rng.normal(size=3), base_omega_dot=rng.normal(size=3),
                     tip_force=rng.normal(size=3), tip_torque=rng.normal(size=3))
    g = rng.normal(size=3) * 5 if gravity else np.zeros(3)
    return Chain(name=f"random{n}", joints=tuple(joints), gravity=g, source="<random>", **extra)


def _rx(alpha: float) -> np.ndarray:
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def random_state(chain: Chain, count: int, rng: np.random.Generator | int = 0):
    """(q, qd, qdd), each (count, n): within the joint limits, else ±π (±0.5 prismatic), ±1, ±1."""
    rng = np.random.default_rng(rng)
    n = chain.n
    q = np.empty((count, n))
    qd = np.empty((count, n))
    for i, j in enumerate(chain.joints):
        lo, hi = j.limits.q if j.limits.q else (-np.pi, np.pi)
        q[:, i] = rng.uniform(lo, hi, count)
        vmax = j.limits.qd if j.limits.qd else 1.0
        qd[:, i] = rng.uniform(-vmax, vmax, count)
    qdd = rng.uniform(-1.0, 1.0, (count, n))
    return q, qd, qdd
