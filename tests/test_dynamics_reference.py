"""The serial RNEA oracle against checks that do not share its code: energy balance, textbook closed forms,
potential gradients, the statics Jacobian, an equivalent robot for base rotation, and Pinocchio."""
from dataclasses import replace

import numpy as np
import pytest

from vampc.dynamics.reference import (
    kinetic_energy,
    mass_matrix,
    potential_energy,
    rnea,
    rnea_variables,
)
from vampc.errors import VampcError
from vampc.robot.chain import Chain, Joint, JointType, rot_z
from vampc.robot.random import (
    random_base,
    random_chain,
    random_rotation,
    random_state,
    random_tree,
)

RTOL = 1e-9
FD_RTOL = 1e-9      # fourth-order central differences (h = 1e-3): truncation ~h^4, round-off ~eps/h


def assert_close(actual, expected, rtol=RTOL, floor=1e-6):
    """|actual - expected| ≤ rtol · max(max|expected|, floor), elementwise."""
    scale = max(np.max(np.abs(expected)), floor)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * scale)


def derivative(fun, x, h=1e-3):
    """Fourth-order central difference of a scalar function of a scalar."""
    return (fun(x - 2 * h) - 8 * fun(x - h) + 8 * fun(x + h) - fun(x + 2 * h)) / (12 * h)


def quiet(chain: Chain) -> Chain:
    """The same robot on a non-rotating base with no tip load (gravity kept)."""
    zero = np.zeros(3)
    return replace(chain, base_omega=zero, base_omega_dot=zero, tip_force=zero, tip_torque=zero)


def tip_pose(chain: Chain, q):
    """Own forward kinematics by 4x4 transforms: (rotation ⁰W_n, origin of O_n) in base coordinates."""
    t = np.eye(4)
    for joint, qi in zip(chain.joints, q):
        step = np.eye(4)
        step[:3, :3] = joint.A(qi)
        step[:3, 3] = joint.A(qi) @ joint.p_star(qi)
        t = t @ step
    return t[:3, :3], t[:3, 3]


def sine_path(n, rng):
    """q(t) as a sum of two sines per joint, with its exact first and second derivatives."""
    amp, freq, phase = rng.uniform(0.2, 1, (3, 2, n)) * np.array([1, 3, 6])[:, None, None]

    def path(t):
        arg = freq * t + phase
        return ((amp * np.sin(arg)).sum(0), (amp * freq * np.cos(arg)).sum(0),
                (-amp * freq ** 2 * np.sin(arg)).sum(0))
    return path


def planar_joint(length, mass, com, inertia_z):
    """A revolute DH link of the planar arm: α = 0, a = length, centre of mass at com (in O_i)."""
    return Joint(name="j", type=JointType.REVOLUTE, phi=np.eye(3), p_fixed=np.array([length, 0, 0.]),
                 offset=0.0, mass=mass, com=np.asarray(com, dtype=float),
                 inertia=np.diag([0.0, inertia_z, inertia_z]))


# --- (a) energy balance -------------------------------------------------------------------------------------

@pytest.mark.parametrize("shape, seed",
                         [("chain", s) for s in range(6)] + [("tree", s) for s in range(4)])
def test_power_equals_energy_rate(shape, seed):
    """d(T + V)/dt = τ·q̇ on random chains and random trees (no external wrench)."""
    rng = np.random.default_rng(seed)
    chain = quiet(random_chain(int(rng.integers(1, 8)), seed, prismatic_fraction=0.4)
                  if shape == "chain" else
                  random_tree(int(rng.integers(2, 12)), seed, "random", prismatic_fraction=0.4))
    path = sine_path(chain.n, rng)

    def energy(t):
        q, qd, _ = path(t)
        return kinetic_energy(chain, q, qd) + potential_energy(chain, q)
    for t in rng.uniform(0, 3, 3):
        q, qd, qdd = path(t)
        tau = rnea(chain, q, qd, qdd)
        assert abs(derivative(energy, t) - tau @ qd) <= FD_RTOL * max(np.abs(tau * qd).sum(), 1.0)


# --- (b), (c) closed forms ----------------------------------------------------------------------------------

def two_link_torques(l1, m1, m2, lc1, lc2, i1, i2, g, q, qd, qdd):
    """Textbook Lagrangian torques of the planar 2R arm (gravity along -y of the base)."""
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    m11 = m1 * lc1 ** 2 + m2 * (l1 ** 2 + lc2 ** 2 + 2 * l1 * lc2 * c2) + i1 + i2
    m12 = m2 * (lc2 ** 2 + l1 * lc2 * c2) + i2
    m22 = m2 * lc2 ** 2 + i2
    h = m2 * l1 * lc2 * s2
    g1 = (m1 * lc1 + m2 * l1) * g * np.cos(q[0]) + m2 * lc2 * g * np.cos(q[0] + q[1])
    g2 = m2 * lc2 * g * np.cos(q[0] + q[1])
    tau1 = m11 * qdd[0] + m12 * qdd[1] - h * (2 * qd[0] * qd[1] + qd[1] ** 2) + g1
    tau2 = m12 * qdd[0] + m22 * qdd[1] + h * qd[0] ** 2 + g2
    return np.array([tau1, tau2])


@pytest.mark.parametrize("rod", [False, True])
def test_two_link_planar_arm(rod):
    rng = np.random.default_rng(7)
    l1, l2, m1, m2, g = 0.7, 0.5, 2.0, 1.3, 9.81
    # point masses at the link ends, or uniform rods (centre at mid-length, I = m l²/12)
    lc1, lc2 = (l1 / 2, l2 / 2) if rod else (l1, l2)
    i1, i2 = (m1 * l1 ** 2 / 12, m2 * l2 ** 2 / 12) if rod else (0.0, 0.0)
    chain = Chain(name="planar2", joints=(planar_joint(l1, m1, [lc1 - l1, 0, 0], i1),
                                         planar_joint(l2, m2, [lc2 - l2, 0, 0], i2)),
                  gravity=np.array([0.0, -g, 0.0]))
    for q, qd, qdd in zip(*random_state(chain, 5, rng)):
        expected = two_link_torques(l1, m1, m2, lc1, lc2, i1, i2, g, q, qd, qdd)
        assert_close(rnea(chain, q, qd, qdd), expected)


def test_pendulum():
    length, mass, g = 0.8, 1.7, 9.81
    chain = Chain(name="pendulum", joints=(planar_joint(length, mass, [0, 0, 0], 0.0),),
                  gravity=np.array([0.0, -g, 0.0]))
    for q, qd, qdd in [(0.3, 1.2, -0.4), (-2.0, 0.0, 2.5), (1.1, -3.0, 0.0)]:
        expected = mass * length ** 2 * qdd + mass * g * length * np.cos(q)
        assert_close(rnea(chain, [q], [qd], [qdd]), [expected])


def test_vertical_slider():
    joint = Joint(name="slide", type=JointType.PRISMATIC, phi=np.eye(3), p_fixed=np.zeros(3),
                  offset=0.2, mass=3.0, com=np.array([0.1, -0.2, 0.3]), inertia=np.eye(3) * 0.1)
    chain = Chain(name="slider", joints=(joint,))
    for q, qd, qdd in [(0.3, 1.2, -0.4), (-0.1, 5.0, 2.5)]:
        assert_close(rnea(chain, [q], [qd], [qdd]), [3.0 * (qdd + 9.81)])


# --- (d) gravity, (e) tip load: statics ---------------------------------------------------------------------

@pytest.mark.parametrize("seed", range(4))
def test_static_torque_is_potential_gradient(seed):
    chain = quiet(random_chain(6, seed, prismatic_fraction=0.4))
    q = random_state(chain, 1, seed)[0][0]
    zero = np.zeros(chain.n)
    for i in range(chain.n):
        grad = derivative(lambda x: potential_energy(chain, q + x * np.eye(chain.n)[i]), 0.0)
        assert abs(rnea(chain, q, zero, zero)[i] - grad) <= FD_RTOL * max(abs(grad), 1.0)


@pytest.mark.parametrize("seed", range(4))
def test_tip_load_is_jacobian_transpose(seed):
    rng = np.random.default_rng(seed)
    chain = replace(random_chain(6, seed, prismatic_fraction=0.4, gravity=False),
                    tip_force=rng.normal(size=3), tip_torque=rng.normal(size=3))
    q = random_state(chain, 1, seed)[0][0]
    rot, _ = tip_pose(chain, q)
    force, torque = rot @ chain.tip_force, rot @ chain.tip_torque     # the wrench in base coordinates
    zero = np.zeros(chain.n)
    for i in range(chain.n):
        e = np.eye(chain.n)[i]
        jv = np.array([derivative(lambda x: tip_pose(chain, q + x * e)[1][k], 0.0) for k in range(3)])
        drot = np.array([[derivative(lambda x: tip_pose(chain, q + x * e)[0][r, c], 0.0)
                          for c in range(3)] for r in range(3)])
        spin = drot @ rot.T                                               # [jω]×
        jw = np.array([spin[2, 1], spin[0, 2], spin[1, 0]])
        expected = jv @ force + jw @ torque
        assert abs(rnea(chain, q, zero, zero)[i] - expected) <= FD_RTOL * max(abs(expected), 1.0)


# --- (f) base rotation: the same robot carried by two extra massless joints ---------------------------------

def rotation_with_axis(axis, rng):
    """A rotation Φ with Φᵀ e_z = axis (a joint whose axis, seen from its link, is `axis`)."""
    x = np.cross(axis, rng.normal(size=3))
    x /= np.linalg.norm(x)
    return np.array([x, np.cross(axis, x), axis])


def massless_joint(phi):
    return Joint(name="base", type=JointType.REVOLUTE, phi=phi, p_fixed=np.zeros(3), offset=0.0,
                 mass=0.0, com=np.zeros(3), inertia=np.zeros((3, 3)))


@pytest.mark.parametrize("seed", range(4))
def test_base_rotation_equals_driven_base_joints(seed):
    """ω_0, ω̇_0 arise from joints a, b below O_0 with q̇_a = |ω_0|, q̇_b = 0: then ω_0 = A_bᵀ axis_a q̇_a
    and ω̇_0 = A_bᵀ axis_a q̈_a + axis_b q̈_b, which spans any ω̇_0 when axis_b ⟂ ω_0."""
    rng = np.random.default_rng(seed)
    chain = random_chain(5, seed, prismatic_fraction=0.4, endpoints=True)
    w0, wd0 = chain.base_omega, chain.base_omega_dot
    w_hat = w0 / np.linalg.norm(w0)
    v = wd0 - (wd0 @ w_hat) * w_hat
    v /= np.linalg.norm(v)
    qa, qb = rng.uniform(-np.pi, np.pi, 2)
    joint_b = massless_joint(rotation_with_axis(v, rng))
    a_b = joint_b.A(qb)
    joint_a = massless_joint(rotation_with_axis(a_b @ w_hat, rng))
    carried = replace(quiet(chain), joints=(joint_a, joint_b) + chain.joints,
                      gravity=joint_a.A(qa) @ a_b @ chain.gravity,
                      tip_force=chain.tip_force, tip_torque=chain.tip_torque)
    for q, qd, qdd in zip(*random_state(chain, 3, seed)):
        tau = rnea(carried, np.r_[qa, qb, q], np.r_[np.linalg.norm(w0), 0.0, qd],
                   np.r_[wd0 @ w_hat, wd0 @ v, qdd])
        assert_close(rnea(chain, q, qd, qdd), tau[2:], rtol=1e-12)


# --- (g) Pinocchio ------------------------------------------------------------------------------------------

def pinocchio_model(chain: Chain):
    """Pinocchio joint i sits at O_{i-1} with z on the joint axis; O_i = (joint frame) · C_i, constant C_i."""
    pin = pytest.importorskip("pinocchio")
    model, parent, placement = pin.Model(), 0, pin.SE3.Identity()
    for j in chain.joints:
        revolute = j.type is JointType.REVOLUTE
        rot = rot_z(j.offset) @ j.phi if revolute else j.phi
        origin = rot @ j.p_fixed + (0 if revolute else j.offset * np.array([0, 0, 1.0]))
        c = pin.SE3(rot, origin)
        kind = pin.JointModelRZ() if revolute else pin.JointModelPZ()
        parent = model.addJoint(parent, kind, placement, j.name)
        body = pin.Inertia(j.mass, rot @ j.com + origin, rot @ j.inertia @ rot.T)
        model.appendBodyToJoint(parent, body, pin.SE3.Identity())
        placement = c
    model.gravity.linear = np.asarray(chain.gravity, dtype=float)
    return pin, model, placement


@pytest.mark.parametrize("seed", range(6))
def test_matches_pinocchio(seed):
    chain = random_chain(2 + seed, seed, prismatic_fraction=0.5, endpoints=True)
    chain = replace(chain, base_omega=np.zeros(3), base_omega_dot=np.zeros(3))
    pin, model, tip_frame = pinocchio_model(chain)
    data = model.createData()
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    # the environment pushes on link n with -f_{n+1}, -n_{n+1} (about O_n), moved to the joint frame
    fext[-1] = tip_frame.act(pin.Force(-chain.tip_force, -chain.tip_torque))
    for q, qd, qdd in zip(*random_state(chain, 4, seed)):
        assert_close(rnea(chain, q, qd, qdd), pin.rnea(model, data, q, qd, qdd, fext))


# --- the API ------------------------------------------------------------------------------------------------

def test_batch_equals_single_states():
    chain = random_chain(7, 3, endpoints=True)
    q, qd, qdd = random_state(chain, 20, 3)
    batch = rnea(chain, q, qd, qdd)
    assert batch.shape == (20, 7)
    single = np.array([rnea(chain, *s) for s in zip(q, qd, qdd)])
    np.testing.assert_array_equal(batch, single)


def test_mass_matrix_is_the_acceleration_map():
    chain = replace(quiet(random_chain(6, 5, prismatic_fraction=0.4)), gravity=np.zeros(3))
    q, _, qdd = random_state(chain, 1, 5)
    m = mass_matrix(chain, q[0])
    np.testing.assert_allclose(m, m.T, atol=1e-14)
    assert_close(rnea(chain, q[0], np.zeros(6), qdd[0]), m @ qdd[0])


def test_variables_shapes_and_torque_convention():
    chain = random_chain(4, 2, endpoints=True)
    out = rnea_variables(chain, *(s[0] for s in random_state(chain, 1, 2)))
    for key in ("omega", "omega_dot", "pdd", "rdd", "F", "N", "f", "n"):
        assert out[key].shape == (4, 3)
    axes = np.array([j.axis for j in chain.joints])
    pick = np.where(chain.sigmas[:, None] == 1, out["n"], out["f"])
    np.testing.assert_allclose(out["tau"], np.sum(axes * pick, axis=1), atol=0)
    assert not np.allclose(out["tau"], pick[:, 2])     # the third coordinate would be wrong for Φ ≠ I


def test_bad_shapes_are_user_errors():
    chain = random_chain(3, 0)
    with pytest.raises(VampcError, match=r"expected equal shapes \(n,\) or \(N, n\) with n = 3"):
        rnea(chain, np.zeros(3), np.zeros(2), np.zeros(3))


# --- (h) trees and floating bases -------------------------------------------------------------------------

def pinocchio_tree(chain: Chain):
    """A Pinocchio model of a tree: joint d sits at its joint frame J_d = (M_d, o_d) in O_parent, O_d is
    (joint frame) · C_d; a floating base is a free-flyer joint at O_0 carrying the base link's inertia.
    Returns (pin, model, C_n, first) with `first` the Pinocchio index of joint 1."""
    pin = pytest.importorskip("pinocchio")
    model = pin.Model()
    index, frames, first = {0: 0}, {0: pin.SE3.Identity()}, 1
    if chain.floating:
        index[0] = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
        model.appendBodyToJoint(index[0], pin.Inertia(chain.base_mass, chain.base_com, chain.base_inertia),
                                pin.SE3.Identity())
        first = 2
    for i, (j, p) in enumerate(zip(chain.joints, chain.parent_of), 1):
        revolute = j.type is JointType.REVOLUTE
        rot = rot_z(j.offset) @ j.phi if revolute else j.phi
        origin = rot @ j.p_fixed + (0 if revolute else j.offset * np.array([0, 0, 1.0]))
        pre = np.eye(3) if j.pre is None else j.pre
        placement = frames[p] * pin.SE3(pre, j.shift_vec)
        kind = pin.JointModelRZ() if revolute else pin.JointModelPZ()
        index[i] = model.addJoint(index[p], kind, placement, j.name)
        model.appendBodyToJoint(index[i], pin.Inertia(j.mass, rot @ j.com + origin, rot @ j.inertia @ rot.T),
                                pin.SE3.Identity())
        frames[i] = pin.SE3(rot, origin)
    model.gravity.linear = np.asarray(chain.gravity, dtype=float)
    return pin, model, frames[chain.n], first


def pinocchio_rnea(chain: Chain, q, qd, qdd, base=None, velocity=None, orientation=None):
    """Pinocchio's RNEA of `chain` (tip load as an external force) in vampc's column order; for a
    floating base, `base` = [ω_0, ω̇_0, a_0] is turned into the free flyer's spatial state with the base
    origin's linear `velocity` and the base `orientation` (a rotation: gravity seen in O_0 changes)."""
    pin, model, tip_frame, first = pinocchio_tree(chain)
    data = model.createData()
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    fext[model.njoints - 1 if chain.n else 0] = tip_frame.act(pin.Force(-chain.tip_force, -chain.tip_torque))
    if not chain.floating:
        return pin.rnea(model, data, q, qd, qdd, fext)
    w, wd, acc = base[:3], base[3:6], base[6:]
    v = np.zeros(3) if velocity is None else velocity
    rot = np.eye(3) if orientation is None else orientation
    quat = pin.Quaternion(rot).coeffs()
    # vampc's a_0 is classical, with the robot's own gravity g in O_0: the physical acceleration a with
    # a - rotᵀ g = a_0 - g (Pinocchio's gravity seen in O_0 is rotᵀ g), and Pinocchio's is spatial, a - ω × v
    spatial = acc - chain.gravity + rot.T @ chain.gravity - np.cross(w, v)
    tau = pin.rnea(model, data, np.r_[np.zeros(3), quat, q], np.r_[v, w, qd], np.r_[spatial, wd, qdd], fext)
    return np.r_[tau[6:], tau[:6]]


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("shape", ["random", "binary", "star"])
def test_tree_matches_pinocchio(seed, shape):
    chain = random_tree(1 + 3 * seed, seed, shape, prismatic_fraction=0.4, endpoints=True)
    chain = replace(chain, base_omega=np.zeros(3), base_omega_dot=np.zeros(3))
    for q, qd, qdd in zip(*random_state(chain, 3, seed)):
        assert_close(rnea(chain, q, qd, qdd), pinocchio_rnea(chain, q, qd, qdd))


@pytest.mark.parametrize("seed", range(8))
def test_floating_base_matches_pinocchio(seed):
    rng = np.random.default_rng(seed)
    chain = random_tree(1 + 4 * seed, seed, "random", prismatic_fraction=0.4, floating=True, endpoints=True)
    chain = replace(chain, base_omega=np.zeros(3), base_omega_dot=np.zeros(3))
    for (q, qd, qdd), base in zip(zip(*random_state(chain, 3, seed)), random_base(3, seed)):
        velocity, orientation = rng.normal(size=3), random_rotation(rng)
        want = pinocchio_rnea(chain, q, qd, qdd, base, velocity, orientation)
        got = rnea(chain, q, qd, qdd, base)
        assert got.shape == (chain.n + 6,)
        assert_close(got, want)


def test_tree_mass_matrix_is_the_acceleration_map():
    chain = random_tree(9, 5, "random", prismatic_fraction=0.4)
    q, qd, qdd = (x[0] for x in random_state(chain, 1, 2))
    bias = rnea(chain, q, qd, np.zeros(chain.n))
    assert_close(rnea(chain, q, qd, qdd) - bias, mass_matrix(chain, q) @ qdd)


def test_floating_base_at_rest_carries_the_weight():
    chain = random_tree(6, 3, "star", floating=True)
    zero = np.zeros(chain.n)
    wrench = rnea(chain, zero, zero, zero, np.zeros(9))[chain.n:]
    total = chain.base_mass + sum(j.mass for j in chain.joints)
    assert_close(wrench[:3], -total * chain.gravity)
