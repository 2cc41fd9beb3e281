"""The robot model in the paper's notation (section II).

Links 0..n; joint i connects link i-1 to link i. Frame O_i is fixed in link i with z_i along joint i+1.
All vectors are in link coordinates. For joint i:

    A_i(q) = Rz(q + offset) Φ_i      (revolute)     maps O_i coordinates into O_{i-1}
    A_i(q) = Φ_i                      (prismatic)
    p*_i(q) = p_fixed                 (revolute)     origin O_i from O_{i-1}, in O_i
    p*_i(q) = p_fixed + (q + offset) Φ_iᵀ e_z   (prismatic)

Φ_i is a general constant rotation (a standard DH row is the special case Φ_i = Rz(θ)Rx(α) for a
prismatic joint, Rx(α) for a revolute one). The endpoints are the base rotation ω0, ω̇0 (in O_0), the
gravity vector g in O_0 (the base acceleration is p̈_0 = -g) and the tip load f_{n+1}, n_{n+1}: as in
the paper, the force and the moment (about O_n) that link n exerts on the environment, expressed in O_n
(the environment pushes on the tip with their negatives).

Trees (issue 12). Every joint has a parent: `Chain.parents[i-1]` is the joint (1..n) that carries joint
i's parent link, 0 for the base link; a chain is the tree whose parents are i - 1, and `parents` is None
for it. Joints are numbered depth-first from the root (a parent before its children, every subtree a
contiguous range of numbers). Link p's frame O_p has its origin on, and z along, the axis of at most
one child joint (the chain's convention; for a URDF, the child with the largest subtree); another child
d of p has its own joint frame J_d fixed in link p, given by two constants of joint d:

    pre    M_d: J_d's orientation in O_p (identity when None), so A_d(q) = M_d Rz(q + offset) Φ_d
    shift  o_d: J_d's origin from O_p's origin, in O_p (zero when None)

so z_{d-1} referred to O_p is u_d = M_d e_z (`Joint.parent_axis`), p*_d is the origin of O_d from J_d's
origin, and the acceleration a child reads is that of J_d's origin: p̈_p + ω̇_p × o_d + ω_p × (ω_p × o_d).
A floating base (`Chain.floating`) has its own inertia (`base_mass`, `base_com`, `base_inertia`, in O_0)
and takes ω_0, ω̇_0 and the base acceleration per torque set instead of the constants above.
"""
from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from vampc.errors import VampcInternalError

E_Z = np.array([0.0, 0.0, 1.0])


class JointType(enum.Enum):
    """Kind of a one-degree-of-freedom lower pair: σ_i = 1 for revolute, 0 for prismatic."""

    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"

    @property
    def sigma(self) -> int:
        """The paper's σ_i."""
        return 1 if self is JointType.REVOLUTE else 0


@dataclass(frozen=True)
class Limits:
    """Optional joint limits: position interval, speed bound, effort bound (None where not given)."""

    q: tuple[float, float] | None = None
    qd: float | None = None
    tau: float | None = None


def rot_z(theta):
    """Rz(θ), vectorised: θ of shape S gives S + (3, 3)."""
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    out = np.zeros(theta.shape + (3, 3))
    out[..., 0, 0], out[..., 0, 1] = c, -s
    out[..., 1, 0], out[..., 1, 1] = s, c
    out[..., 2, 2] = 1.0
    return out


def matmul(a, b, *more) -> np.ndarray:
    """a @ b (@ more, left to right) for stacks of small matrices, broadcast as `@` broadcasts them,
    each entry summed over k = 0, 1, ... in that order, every product and sum rounded on its own: the
    same bits on every machine. NumPy's `@` hands these to the BLAS, whose kernels differ from one
    CPU to another (a Haswell kernel fuses each multiply-add, a Sandy Bridge one does not), and so
    did the last bits of a robot's constants, the host's A_i(q) and the torques (README, *Same bits
    on every machine*)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.ndim < 2 or b.ndim < 2 or a.shape[-1] != b.shape[-2]:
        raise VampcInternalError(f"matmul of shapes {a.shape} and {b.shape}")
    # two ways to the same bits, for speed: one pair at once (a call per frame of a URDF), a
    # stack entry by entry
    if a.ndim == 2 and b.ndim == 2:
        out = a[:, 0, None] * b[None, 0, :]
        for k in range(1, a.shape[-1]):
            out = out + a[:, k, None] * b[None, k, :]
    else:                                     # each entry a vector over the stack
        out = np.empty(np.broadcast_shapes(a.shape[:-2], b.shape[:-2]) + (a.shape[-2], b.shape[-1]))
        for i in range(a.shape[-2]):          # (4 times faster than broadcasting whole stacks here)
            for j in range(b.shape[-1]):
                entry = a[..., i, 0] * b[..., 0, j]
                for k in range(1, a.shape[-1]):
                    entry = entry + a[..., i, k] * b[..., k, j]
                out[..., i, j] = entry
    return matmul(out, *more) if more else out


def _turned(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Rz(θ) Φ for every θ: matmul(rot_z(θ), Φ), the same bits, without the stack of Rz (Rz's
    zeros and one are written as scalars: a 100 000-set A_i(q) in under half the time)."""
    c, s = np.cos(theta), np.sin(theta)
    minus_s = -s
    out = np.empty(theta.shape + (3, 3))
    for j in range(3):
        p0, p1, p2 = phi[0, j], phi[1, j], phi[2, j]
        out[..., 0, j] = (c * p0 + minus_s * p1) + 0.0 * p2
        out[..., 1, j] = (s * p0 + c * p1) + 0.0 * p2
        out[..., 2, j] = (0.0 * p0 + 0.0 * p1) + 1.0 * p2
    return out


def matvec(m, v) -> np.ndarray:
    """m @ v for stacks of matrices and vectors, in matmul's order."""
    return matmul(m, np.asarray(v, dtype=float)[..., None])[..., 0]


def rot_x(alpha: float) -> np.ndarray:
    """Rx(α) as a 3x3 array."""
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


@dataclass(frozen=True)
class Mimic:
    """A coupled mimic joint (URDF `<mimic>` read with --mimic couple, vampc.robot.mimic): joint
    `follower` (1-based) moves as q_f = multiplier · q_leader + offset, its q̇ and q̈ as multiplier times
    the leader's; the host writes its inputs, and its torque is added, times multiplier, to the leader's
    generalized force. `leader` is an independent joint (chains of mimics are composed)."""

    follower: int
    leader: int
    multiplier: float
    offset: float


@dataclass(frozen=True, eq=False)
class Joint:
    """Joint i with the link i it carries (all quantities in O_i unless said otherwise)."""

    name: str
    type: JointType
    phi: np.ndarray          # Φ_i, (3, 3) constant rotation
    p_fixed: np.ndarray      # constant part of p*_i, (3,)
    offset: float            # added to q: θ offset (revolute) or d offset (prismatic)
    mass: float              # m_i
    com: np.ndarray          # r*_i: centre of mass from O_i, (3,)
    inertia: np.ndarray      # J_i about the centre of mass, (3, 3)
    limits: Limits = field(default_factory=Limits)
    pre: np.ndarray | None = None     # M_d: joint frame J_d in the parent's frame (None: identity)
    shift: np.ndarray | None = None   # o_d: J_d's origin from the parent frame's origin (None: zero)

    @property
    def sigma(self) -> int:
        """σ_i: 1 revolute, 0 prismatic."""
        return self.type.sigma

    @property
    def axis(self) -> np.ndarray:
        """z_{i-1} referred to O_i: A_iᵀ e_z = Φ_iᵀ e_z, independent of q."""
        return self.phi[2, :].copy()

    @property
    def parent_axis(self) -> np.ndarray:
        """u_i: z_{i-1} referred to the parent's frame, M_i e_z (e_z when there is no pre-rotation)."""
        return E_Z.copy() if self.pre is None else self.pre[:, 2].copy()

    @property
    def shift_vec(self) -> np.ndarray:
        """o_i as an array (zero when None)."""
        return np.zeros(3) if self.shift is None else np.asarray(self.shift, dtype=float)

    def A(self, q) -> np.ndarray:
        """A_i(q), vectorised over q (shape S gives S + (3, 3))."""
        q = np.asarray(q, dtype=float)
        if self.type is JointType.PRISMATIC:
            a = np.broadcast_to(self.phi, q.shape + (3, 3)).copy()
        else:
            a = _turned(q + self.offset, self.phi)
        return a if self.pre is None else matmul(self.pre, a)

    def p_star(self, q) -> np.ndarray:
        """p*_i(q), vectorised over q (shape S gives S + (3,))."""
        q = np.asarray(q, dtype=float)
        if self.type is JointType.REVOLUTE:
            return np.broadcast_to(self.p_fixed, q.shape + (3,)).copy()
        return self.p_fixed + (q + self.offset)[..., None] * self.axis

    def s_star(self, q) -> np.ndarray:
        """s*_i(q) = p*_i(q) + r*_i."""
        return self.p_star(q) + self.com


@dataclass(frozen=True, eq=False)
class Chain:
    """A tree of n joints (a serial chain when `parents` is None) with its endpoint conditions (see the
    module docstring). The tip load acts on link n, the last joint's link."""

    name: str
    joints: tuple[Joint, ...]
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    base_omega: np.ndarray = field(default_factory=lambda: np.zeros(3))
    base_omega_dot: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tip_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tip_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))
    source: str = ""
    parents: tuple[int, ...] | None = None   # parent joint of joint i (0: the base); None: a chain
    floating: bool = False                   # base motion per torque set; base wrench as 6 outputs
    base_mass: float = 0.0                   # floating base: the base link's mass, CoM, inertia in O_0
    base_com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    base_inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    mimic: tuple[Mimic, ...] = ()            # coupled joints, by follower (vampc.robot.mimic)
    # the joints --lock took out of the robot file (their names, as given): a program file keeps
    # them, so that a limits file naming one is passed over as it is with the robot file
    locked: tuple[str, ...] = ()
    # the robot file's other joints the chain does not hold (fixed ones, and those the base, the tip
    # or a locked joint leaves out), kept likewise: a limits file for the whole robot names them
    left_out: tuple[str, ...] = ()

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def n_outputs(self) -> int:
        """Values per torque set: n joint forces, then 6 base-wrench components if the base floats."""
        return self.n + (6 if self.floating else 0)

    def parent(self, i: int) -> int:
        """Parent joint of joint i (0: the base link), in O(1)."""
        return i - 1 if self.parents is None else self.parents[i - 1]

    @property
    def parent_of(self) -> tuple[int, ...]:
        """Parent joint of every joint i = 1..n (0: the base link), chain or tree."""
        return tuple(range(self.n)) if self.parents is None else tuple(self.parents)

    @property
    def is_chain(self) -> bool:
        """True when every joint's parent is the joint before it."""
        return self.parents is None or tuple(self.parents) == tuple(range(self.n))

    @property
    def is_fixed_chain(self) -> bool:
        """A serial chain on a fixed base, the paper's kind of robot: the log recursion builds it
        with section IV's prefix networks (anything else as a tree: vampc.dataflow.logtree), and
        the paper's formulas and per-node counts are for it."""
        return self.is_chain and not self.floating

    @property
    def base_rotates(self) -> bool:
        """Whether the base rotates (ω0 or ω̇0 nonzero): the log recursion's base-to-tip pass is
        then grounded in O_{-1}, over n + 1 leaves (vampc.dataflow.logarithmic), and the report
        says what that moves in its latency (vampc.report.counts.path_conditions)."""
        return bool(np.any(self.base_omega) or np.any(self.base_omega_dot))

    @property
    def children(self) -> tuple[tuple[int, ...], ...]:
        """children[p]: the joints whose parent is p (0 = the base), in joint order."""
        out: list[list[int]] = [[] for _ in range(self.n + 1)]
        for i, p in enumerate(self.parent_of, 1):
            out[p].append(i)
        return tuple(map(tuple, out))

    @property
    def leaves(self) -> tuple[int, ...]:
        """Joints with no child joint."""
        return tuple(i for i, c in enumerate(self.children) if i and not c)

    @property
    def depths(self) -> tuple[int, ...]:
        """Depth of joint i (1 for a joint on the base), i = 1..n."""
        d = [0] * (self.n + 1)
        for i, p in enumerate(self.parent_of, 1):
            d[i] = d[p] + 1
        return tuple(d[1:])

    @property
    def height(self) -> int:
        """Joints on the longest root-to-leaf path (n for a chain)."""
        return max(self.depths, default=0)

    @property
    def subtree_end(self) -> tuple[int, ...]:
        """end[i]: one past the last joint of i's subtree (joints i..end-1; depth-first numbering)."""
        end = list(range(1, self.n + 2))
        for i in range(self.n, 0, -1):
            p = self.parent_of[i - 1]
            end[p] = max(end[p], end[i])
        return tuple(end[1:])

    @property
    def base_accel(self) -> np.ndarray:
        """p̈_0 = -g: gravity modelled as an upward acceleration of the base."""
        return -np.asarray(self.gravity, dtype=float)

    @property
    def sigmas(self) -> np.ndarray:
        """σ_i for i = 1..n as an int array."""
        return np.array([j.sigma for j in self.joints], dtype=int)

    def first_non_finite(self) -> tuple[str, str] | None:
        """The first number of the chain that is not finite, as (place, what): place "joint 'name'"
        or "the robot", what "its link's inertia", "the base's centre of mass", ... Or None. These are
        Chain.verify's finite invariants, which a loader's numbers, each finite in its file, can break
        once combined (a fixed link merged at an offset of 1e200, a floating base's centre of mass),
        so the loaders say this to the user instead of verify's internal error."""
        for j in self.joints:
            # (the position first: fixed links merged far away overflow it, and NaN the rotation)
            for label, value in (("position", j.p_fixed), ("rotation", j.phi), ("pre-rotation", j.pre),
                                 ("mass", j.mass), ("centre of mass", j.com), ("inertia", j.inertia),
                                 ("shift", j.shift)):
                if value is not None and not np.all(np.isfinite(value)):
                    return f"joint '{j.name}'", f"its link's {label}"
        for label, value in (("gravity", self.gravity), ("base's angular velocity", self.base_omega),
                             ("base's angular acceleration", self.base_omega_dot),
                             ("tip force", self.tip_force), ("tip torque", self.tip_torque)):
            if not np.all(np.isfinite(value)):
                return "the robot", f"its {label}"
        if self.floating:
            for label, value in (("mass", self.base_mass), ("centre of mass", self.base_com),
                                 ("inertia", self.base_inertia)):
                if not np.all(np.isfinite(value)):
                    return "the base", f"its {label}"
        for m in self.mimic:
            for label, value in (("multiplier", m.multiplier), ("offset", m.offset)):
                if not np.isfinite(value) and 1 <= m.follower <= self.n:
                    return f"joint '{self.joints[m.follower - 1].name}'", f"its mimic {label}"
        return None

    def verify(self) -> None:
        """Check the invariants every later stage relies on; raise VampcInternalError if broken."""
        if self.n == 0:
            raise VampcInternalError(f"{self.name}: chain has no joints")
        found = self.first_non_finite()         # (the numbers' own check, which loaders say)
        if found:
            raise VampcInternalError(f"{self.name}: {found[0]}: {found[1]} is not finite")
        for i, j in enumerate(self.joints, 1):
            _check_rotation(j.phi, f"joint {i} ({j.name}) Φ")
            for label, arr, shape in (("p_fixed", j.p_fixed, (3,)), ("com", j.com, (3,)),
                                      ("inertia", j.inertia, (3, 3))):
                if np.shape(arr) != shape:
                    raise VampcInternalError(f"joint {i} ({j.name}): bad {label}")
            if not j.mass >= 0:
                raise VampcInternalError(f"joint {i} ({j.name}): bad mass {j.mass}")
            if j.pre is not None:
                _check_rotation(j.pre, f"joint {i} ({j.name}) pre-rotation")
            if j.shift is not None and np.shape(j.shift) != (3,):
                raise VampcInternalError(f"joint {i} ({j.name}): bad shift")
        for label in ("gravity", "base_omega", "base_omega_dot", "tip_force", "tip_torque", "base_com"):
            if np.shape(getattr(self, label)) != (3,):
                raise VampcInternalError(f"{self.name}: bad {label}")
        self._verify_tree()
        self._verify_mimic()

    def _verify_mimic(self) -> None:
        """Followers are distinct joints; leaders are joints and none of them a follower."""
        followers = [m.follower for m in self.mimic]
        if len(set(followers)) != len(followers):
            raise VampcInternalError(f"{self.name}: a joint is coupled twice")
        for m in self.mimic:
            if not (1 <= m.follower <= self.n and 1 <= m.leader <= self.n) or m.leader in followers:
                raise VampcInternalError(f"{self.name}: bad mimic coupling {m}")

    def _verify_tree(self) -> None:
        """Parents exist, come first, and number the joints depth-first (subtrees contiguous)."""
        if self.parents is not None and len(self.parents) != self.n:
            raise VampcInternalError(f"{self.name}: {len(self.parents)} parents for {self.n} joints")
        path = [0]                 # the ancestors of the joint before i, and that joint
        for i, p in enumerate(self.parent_of, 1):
            while path and path[-1] != p:
                path.pop()
            if not path:
                raise VampcInternalError(f"{self.name}: joint {i}'s parent {p} is not an ancestor of "
                                         f"joint {i - 1} or joint {i - 1} itself (not depth-first)")
            path.append(i)
        if self.floating and not (self.base_mass >= 0 and np.shape(self.base_inertia) == (3, 3)):
            raise VampcInternalError(f"{self.name}: bad base inertia")


def _check_rotation(m: np.ndarray, label: str) -> None:
    problem = rotation_problem(m)
    if problem:
        raise VampcInternalError(f"{label} is {problem}")


def rotation_problem(m) -> str | None:
    """What keeps `m` from being a proper rotation ("not a finite 3x3 matrix", "not a proper
    rotation"), or None: Chain.verify's test, which a program file's Φ must pass as well."""
    if np.shape(m) != (3, 3) or not np.all(np.isfinite(m)):
        return "not a finite 3x3 matrix"
    if not np.allclose(m @ m.T, np.eye(3), atol=1e-9) or np.linalg.det(m) < 0:
        return "not a proper rotation"
    return None
