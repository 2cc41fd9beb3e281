"""Pinocchio as the independent reference: vampc's states in Pinocchio's layout, and its torques back
in vampc's joint order. Used by the tests and by benchmarks/example_robot_data.py."""
from __future__ import annotations

import numpy as np


def pin_arrays(model, names, q, v, head_v):
    """Pinocchio's configuration and velocity (or acceleration) vectors for joint values q, v given by
    joint name; `head_v` fills a free-flyer's first velocity entries. A continuous joint takes
    (cos q, sin q); a mimic follower of a mimic model has no entries of its own and is not named."""
    import pinocchio as pin
    qq, vv = pin.neutral(model), np.zeros(model.nv)
    vv[:len(head_v)] = head_v
    for k, name in enumerate(names):
        j = model.joints[model.getJointId(name)]
        if j.nq == 2:                       # a continuous joint: (cos q, sin q)
            qq[j.idx_q:j.idx_q + 2] = np.cos(q[k]), np.sin(q[k])
        else:
            qq[j.idx_q] = q[k]
        vv[j.idx_v] = v[k]
    return qq, vv


def pin_torques(model, names, q, qd, qdd, base=None) -> np.ndarray:
    """Pinocchio's rnea for each state (rows of q, qd, qdd given for the joints `names`, in that
    order; `base`: a floating base's (count, 9) ω_0, ω̇_0, a_0 in O_0, as vampc takes it), as
    (count, len(names)) torques, then the base wrench's six components for a floating base."""
    import pinocchio as pin
    data, out = model.createData(), []
    for s in range(len(q)):
        b = base[s] if base is not None else None
        head_v = np.r_[np.zeros(3), b[:3]] if b is not None else []
        head_a = np.r_[b[6:], b[3:6]] if b is not None else []
        pq, pv = pin_arrays(model, names, q[s], qd[s], head_v)
        _, pa = pin_arrays(model, names, q[s], qdd[s], head_a)
        if b is not None:
            pq[:7] = [0, 0, 0, 0, 0, 0, 1]
        tau = pin.rnea(model, data, pq, pv, pa)
        joints = [tau[model.joints[model.getJointId(n)].idx_v] for n in names]
        out.append(np.r_[joints, tau[:6]] if b is not None else np.array(joints))
    return np.array(out)


def load_pin_urdf(path, floating: bool, mimic: bool = False):
    """pin.buildModelFromUrdf, with a free-flyer root when `floating`, mimic joints coupled when
    `mimic`."""
    import pinocchio as pin
    args = (str(path), pin.JointModelFreeFlyer()) if floating else (str(path),)
    return pin.buildModelFromUrdf(*args, mimic=mimic)
