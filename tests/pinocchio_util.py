"""Pinocchio as the independent reference: vampc's states in Pinocchio's layout, and its torques back
in vampc's joint order. Used by the tests and by benchmarks/example_robot_data.py."""
from __future__ import annotations

from pathlib import Path

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


# --- every URDF of example-robot-data (tests/test_example_robot_data.py, benchmarks/) -----------------

# A robot whose file has an inertia that is not positive semi-definite beyond rounding (vampc refuses
# it unless --accept-improper-inertia; Pinocchio does not check): romeo_laas_small's hip links.
IMPROPER_INERTIA = {"romeo_laas_small.urdf"}


def erd_urdfs() -> dict:
    """File name -> path of every URDF of the installed example-robot-data ({} when absent). A name
    two robots share (anymal.urdf: ANYmal B's and C's) is given with its robot's folder,
    `anymal_b_simple_description/anymal.urdf` (keyed by name alone, C's had replaced B's, which no
    test ran: an audit's)."""
    from collections import Counter
    try:
        from importlib.metadata import PackageNotFoundError, files
        listed = [f for f in files("example-robot-data") or () if f.suffix == ".urdf"]
    except PackageNotFoundError:
        return {}
    shared = Counter(f.name for f in listed)

    def named(f) -> str:
        if shared[f.name] == 1:
            return f.name
        robot = next((part for part in f.parts if part.endswith("_description")), f.parent.name)
        return f"{robot}/{f.name}"
    return dict(sorted((named(f), f.locate()) for f in listed))


def coupled_matrix(chain) -> np.ndarray:
    """G with q_full = G q_free + b, from the chain's couplings (n × n_free)."""
    followers = {m.follower - 1: m for m in chain.mimic}
    free = [i for i in range(chain.n) if i not in followers]
    g = np.zeros((chain.n, len(free)))
    g[free, range(len(free))] = 1.0
    for f, m in followers.items():
        g[f, free.index(m.leader - 1)] = m.multiplier
    return g


def check_against_pinocchio(path, floating: bool, count: int = 4, seed: int = 1,
                            recursions=("linear", "log")) -> dict:
    """Load, compile, emulate (stream engine) `count` random states and compare with Pinocchio, each
    recursion and each mimic mode the robot has. Returns what happened: `skip` (why the robot is not
    a case: Pinocchio refuses it, or it has no movable joint), else `n`, `accepted` (whether it needed
    --accept-improper-inertia), `coupled` (how many joints --mimic couple couples, when any; `couple
    refused`: why it refused them, where Pinocchio's mimic model refuses them too), `check` (the largest error of vampc's own --check against its
    reference RNEA, relative to each set's largest |τ|), and `errors`: (mimic mode, recursion) ->
    the largest error against Pinocchio relative to the largest |τ|. Ordinary mimics are compared
    with Pinocchio's default model; coupled ones with its mimic=True model where it builds one, and
    always with Gᵀ τ of its default model at the expanded states."""
    import warnings

    from vampc.compiler import CompileOptions, compile_chain
    from vampc.emulator import emulate, loaded_from_compiled
    from vampc.emulator.host import check_torques, random_trajectory
    from vampc.errors import VampcError
    from vampc.robot import load_urdf
    from vampc.robot.mimic import free_joints, free_names, reduce_torques
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = load_pin_urdf(path, floating)
    except Exception as exc:  # noqa: BLE001 - Pinocchio raises ValueError, RuntimeError...
        why = " ".join(str(exc).replace(str(path), Path(path).name).split())
        return {"skip": f"Pinocchio refuses it ({why[:100]})"}
    if model.nv == (6 if floating else 0):
        return {"skip": "no movable joint"}
    out = {"errors": {}, "accepted": False, "check": 0.0}
    for mimic in ("ordinary", "couple"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                chain = load_urdf(path, floating=floating, mimic=mimic,
                                  accept_improper_inertia=out["accepted"])
            except VampcError as exc:
                if mimic == "couple" and _pin_refuses_mimic(path, floating):
                    out["couple refused"] = str(exc).split(": ", 1)[1]   # as Pinocchio refuses it
                    break
                if "--accept-improper-inertia" not in str(exc):
                    raise
                out["accepted"] = True
                chain = load_urdf(path, floating=floating, mimic=mimic, accept_improper_inertia=True)
        if mimic == "couple" and not chain.mimic:
            break
        if chain.mimic:
            out["coupled"] = len(chain.mimic)
        out["n"] = out.get("n", chain.n)
        traj = random_trajectory(chain, count, seed)
        names = [j.name for j in chain.joints]
        full = pin_torques(model, names, traj.q, traj.qd, traj.qdd, traj.base)
        wants = [full]
        if chain.mimic:
            g = coupled_matrix(chain)
            g6 = np.block([[g, np.zeros((chain.n, full.shape[1] - chain.n))],
                           [np.zeros((full.shape[1] - chain.n, g.shape[1])), np.eye(full.shape[1] - chain.n)]])
            wants = [full @ g6]
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    coupled = load_pin_urdf(path, floating, mimic=True)
            except Exception:  # noqa: BLE001 - e.g. a leader after its follower
                coupled = None
            if coupled is not None:
                free = free_joints(chain)
                wants.append(pin_torques(coupled, free_names(chain), traj.q[:, free], traj.qd[:, free],
                                         traj.qdd[:, free], traj.base))
        for recursion in recursions:
            ld = loaded_from_compiled(compile_chain(chain, CompileOptions(recursion=recursion)))
            tau = emulate(ld, traj, "stream").tau
            res = check_torques(chain, traj, tau)
            out["check"] = max(out["check"], res.max_rel if res.ok else np.inf)
            got = reduce_torques(chain, tau)
            out["errors"][(mimic, recursion)] = max(
                float(np.max(np.abs(got - want)) / np.max(np.abs(want))) for want in wants)
    return out


def _pin_refuses_mimic(path, floating: bool) -> bool:
    import warnings
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            load_pin_urdf(path, floating, mimic=True)
    except Exception:  # noqa: BLE001
        return True
    return False
