"""Random chains and trees for property tests and benchmarks: general Φ_i (not DH), mixed joint types."""
from __future__ import annotations

from dataclasses import replace

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


TREE_SHAPES = ("random", "chain", "binary", "star")


def tree_parents(n: int, shape: str = "random", rng: np.random.Generator | int = 0) -> tuple[int, ...]:
    """Parents of joints 1..n, numbered depth-first. random: each joint hangs on a random joint of the
    path to the previous one (or the base); chain: i - 1; binary: a balanced binary tree (heap order
    renumbered depth-first); star: ⌈√n⌉ chains of about equal length on the base."""
    rng = np.random.default_rng(rng)
    if shape == "chain":
        return tuple(range(n))
    if shape == "binary":
        return _depth_first([0] + [(k - 1) // 2 + 1 if k else 0 for k in range(1, n)])
    if shape == "star":
        arms = max(1, int(np.ceil(np.sqrt(n))))
        return tuple(0 if (i - 1) % -(-n // arms) == 0 else i - 1 for i in range(1, n + 1))
    path, parents = [0], []
    for i in range(1, n + 1):
        del path[int(rng.integers(1, len(path) + 1)):]
        parents.append(path[-1])
        path.append(i)
    return tuple(parents)


def _depth_first(heap_parents: list[int]) -> tuple[int, ...]:
    """Renumber a tree given by parents in any topological order (1-based, 0 the base) depth-first."""
    children: dict[int, list[int]] = {}
    for i, p in enumerate(heap_parents, 1):
        children.setdefault(p, []).append(i)
    new, stack, order = {0: 0}, list(reversed(children.get(0, []))), []
    while stack:
        i = stack.pop()
        new[i] = len(order) + 1
        order.append(i)
        stack.extend(reversed(children.get(i, [])))
    return tuple(new[heap_parents[i - 1]] for i in order)


def random_tree(n: int, rng: np.random.Generator | int = 0, shape: str = "random",
                prismatic_fraction: float = 0.3, floating: bool = False, endpoints: bool = False) -> Chain:
    """A random n-joint tree: general frames, and for every child after a link's first a random joint
    frame (pre-rotation and shift, as a URDF gives); `floating` gives the base an inertia of its own."""
    rng = np.random.default_rng(rng)
    parents = tree_parents(n, shape, rng)
    base = random_chain(n, rng, prismatic_fraction, endpoints=endpoints)
    seen: set[int] = set()
    joints = []
    for j, p in zip(base.joints, parents):
        if p in seen:
            j = replace(j, pre=random_rotation(rng), shift=rng.uniform(-0.3, 0.3, 3))
        seen.add(p)
        joints.append(j)
    extra = {}
    if floating:
        extra = dict(floating=True, base_mass=float(rng.uniform(1, 10)), base_com=rng.uniform(-0.2, 0.2, 3),
                     base_inertia=random_inertia(rng, 0.5), base_omega=np.zeros(3),
                     base_omega_dot=np.zeros(3))
    return replace(base, joints=tuple(joints), parents=parents, name=f"tree{n}", **extra)


def random_base(count: int, rng: np.random.Generator | int = 0) -> np.ndarray:
    """(count, 9) floating-base motions [ω_0, ω̇_0, a_0]: ±1 rad/s, ±1 rad/s², ±1 m/s² per component."""
    return np.random.default_rng(rng).uniform(-1.0, 1.0, (count, 9))


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
        q[:, i] = _uniform(rng, lo, hi, count)
        vmax = j.limits.qd if j.limits.qd else 1.0
        qd[:, i] = _uniform(rng, -vmax, vmax, count)
    qdd = rng.uniform(-1.0, 1.0, (count, n))
    return q, qd, qdd


def _uniform(rng: np.random.Generator, lo: float, hi: float, count: int) -> np.ndarray:
    """rng.uniform(lo, hi, count), the same numbers, also for a range wider than float64 holds
    (limits of ±1e308: NumPy raised OverflowError)."""
    if np.isfinite(float(hi) - float(lo)):
        return rng.uniform(lo, hi, count)
    u = rng.random(count)
    return lo * (1.0 - u) + hi * u
