"""The robot model in the paper's notation (section II, DESIGN §3).

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


def rot_x(alpha: float) -> np.ndarray:
    """Rx(α) as a 3x3 array."""
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


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

    @property
    def sigma(self) -> int:
        """σ_i: 1 revolute, 0 prismatic."""
        return self.type.sigma

    @property
    def axis(self) -> np.ndarray:
        """z_{i-1} referred to O_i: A_iᵀ e_z = Φ_iᵀ e_z, independent of q."""
        return self.phi[2, :].copy()

    def A(self, q) -> np.ndarray:
        """A_i(q), vectorised over q (shape S gives S + (3, 3))."""
        q = np.asarray(q, dtype=float)
        if self.type is JointType.PRISMATIC:
            return np.broadcast_to(self.phi, q.shape + (3, 3)).copy()
        return rot_z(q + self.offset) @ self.phi

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
    """A serial chain of n joints with its endpoint conditions (see the module docstring)."""

    name: str
    joints: tuple[Joint, ...]
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    base_omega: np.ndarray = field(default_factory=lambda: np.zeros(3))
    base_omega_dot: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tip_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tip_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))
    source: str = ""

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def base_accel(self) -> np.ndarray:
        """p̈_0 = -g: gravity modelled as an upward acceleration of the base."""
        return -np.asarray(self.gravity, dtype=float)

    @property
    def sigmas(self) -> np.ndarray:
        """σ_i for i = 1..n as an int array."""
        return np.array([j.sigma for j in self.joints], dtype=int)

    def verify(self) -> None:
        """Check the invariants every later stage relies on; raise VampcInternalError if broken."""
        if self.n == 0:
            raise VampcInternalError(f"{self.name}: chain has no joints")
        for i, j in enumerate(self.joints, 1):
            _check_rotation(j.phi, f"joint {i} ({j.name}) Φ")
            for label, arr, shape in (("p_fixed", j.p_fixed, (3,)), ("com", j.com, (3,)),
                                      ("inertia", j.inertia, (3, 3))):
                if np.shape(arr) != shape or not np.all(np.isfinite(arr)):
                    raise VampcInternalError(f"joint {i} ({j.name}): bad {label}")
            if not (np.isfinite(j.mass) and j.mass >= 0):
                raise VampcInternalError(f"joint {i} ({j.name}): bad mass {j.mass}")
        for label in ("gravity", "base_omega", "base_omega_dot", "tip_force", "tip_torque"):
            arr = getattr(self, label)
            if np.shape(arr) != (3,) or not np.all(np.isfinite(arr)):
                raise VampcInternalError(f"{self.name}: bad {label}")


def _check_rotation(m: np.ndarray, label: str) -> None:
    if np.shape(m) != (3, 3) or not np.all(np.isfinite(m)):
        raise VampcInternalError(f"{label} is not a finite 3x3 matrix")
    if not np.allclose(m @ m.T, np.eye(3), atol=1e-9) or np.linalg.det(m) < 0:
        raise VampcInternalError(f"{label} is not a proper rotation")
