"""Coupled mimic joints (`--mimic couple`): the host's side of the coupling.

The network computes every joint, followers included, as for any tree; the coupling lives at the
host's boundary, where Pinocchio's mimic model puts it. With q the independent joints' positions and
q_full = G q + b (a follower f of leader l: q_f = m_f q_l + o_f; the rest: q_i = q_i), the host

- expands each state: q_f = m_f q_l + o_f, q̇_f = m_f q̇_l, q̈_f = m_f q̈_l (`expand`), and
- reduces each torque set: the generalized forces of the independent joints are Gᵀ τ_full, that is
  τ_l + Σ_f m_f τ_f for a leader, τ_i for a joint nobody mimics (`reduce_torques`); a floating base's
  six wrench components pass unchanged.

This is d'Alembert's principle for the constrained system, and Pinocchio's rnea on a model built with
`mimic=True` gives the same (tests/test_robot_mimic.py). A trajectory file and the torque output carry
the independent joints only, in joint order (`free_joints`). A check in a word narrower than
float64, and `vampc precision`, measure the torque file's columns against the reference's reduced
alike, relative to the file's largest |τ| (`delivered_bounds`); the float64 check compares every
joint of the network too (followers included), each group against its own largest |τ|.
"""
from __future__ import annotations

import numpy as np

from vampc.robot.chain import Chain


def free_joints(chain: Chain) -> np.ndarray:
    """0-based indices of the joints the host is given (every joint but the followers), in order."""
    followers = {m.follower for m in chain.mimic}
    return np.array([i for i in range(chain.n) if i + 1 not in followers], dtype=np.intp)


def n_free(chain: Chain) -> int:
    """How many joints a state gives (and torque sets return, besides a floating base's wrench)."""
    return chain.n - len(chain.mimic)


def free_names(chain: Chain) -> list[str]:
    """The independent joints' names, in order."""
    return [chain.joints[i].name for i in free_joints(chain)]


def expand(chain: Chain, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray):
    """Full (count, n) states from the independent joints' (count, n_free)."""
    if not chain.mimic:
        return q, qd, qdd
    free = free_joints(chain)
    out = []
    for part, shifted in ((q, True), (qd, False), (qdd, False)):
        full = np.empty((part.shape[0], chain.n))
        full[:, free] = part
        for m in chain.mimic:
            full[:, m.follower - 1] = m.multiplier * full[:, m.leader - 1] + (m.offset if shifted else 0.0)
        out.append(full)
    return tuple(out)


def couple(chain: Chain, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray):
    """Full states whose followers are recomputed from their leaders (random states drawn for all)."""
    if not chain.mimic:
        return q, qd, qdd
    free = free_joints(chain)
    return expand(chain, q[:, free], qd[:, free], qdd[:, free])


def reduce_states(chain: Chain, *parts: np.ndarray):
    """The independent joints' columns of full (count, n) states."""
    if not chain.mimic:
        return parts
    free = free_joints(chain)
    return tuple(p[:, free] for p in parts)


def reduce_torques(chain: Chain, tau: np.ndarray) -> np.ndarray:
    """Gᵀ τ: (count, n [+ 6]) network outputs to (count, n_free [+ 6]) generalized forces."""
    if not chain.mimic:
        return tau
    tau = np.array(tau, dtype=float)
    for m in chain.mimic:
        tau[:, m.leader - 1] += m.multiplier * tau[:, m.follower - 1]
    return tau[:, _file_columns(chain, tau.shape[1])]


def _file_columns(chain: Chain, width: int) -> np.ndarray:
    """Which of `width` network outputs are the torque file's columns: the independent joints'
    (their generalized forces), then a floating base's wrench."""
    return np.r_[free_joints(chain), np.arange(chain.n, width)]


def column_names(chain: Chain, prefix: str) -> list[str]:
    """The trajectory file's name for each joint's `prefix` (q, qd, qdd) column, joint by joint: a
    follower has none, so it is named with the leader it is derived from."""
    free = {int(i): k for k, i in enumerate(free_joints(chain), 1)}
    leader = {m.follower - 1: m.leader - 1 for m in chain.mimic}
    return [f"{prefix}{free[i]}" if i in free else
            f"{prefix} of joint '{chain.joints[i].name}' (derived from {prefix}{free[leader[i]]})"
            for i in range(chain.n)]


def leaders(chain: Chain) -> list[int]:
    """0-based indices of the joints some follower mimics, in joint order."""
    return sorted({m.leader - 1 for m in chain.mimic})


def checked_columns(chain: Chain, tau: np.ndarray) -> np.ndarray:
    """The network's outputs (count, n [+ 6]), then the torque file's columns (`reduce_torques`: a
    leader's τ_l + Σ_f m_f τ_f, the others the network's own again): what a float64 check's
    edited-file diagnosis compares."""
    if not chain.mimic:
        return tau
    return np.hstack([tau, reduce_torques(chain, tau)])


def delivered_bounds(chain: Chain, error: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Bounds on the errors of the torque file's columns (`reduce_torques`) from the network's
    outputs' (`error`, absolute) and their magnitudes' bounds (`size`): a leader's column errs by
    at most e_l + Σ_f |m_f| e_f, plus float64's rounding of the sum, both the host's and the
    reference's it is measured against (a product and an addition per follower in each: half an
    ulp of the sum's reach each, 2⁻⁵³ of it); every other column by its own output's."""
    if not chain.mimic:
        return error
    error, size = np.asarray(error, dtype=float), np.asarray(size, dtype=float)
    out = np.array(error, dtype=float)
    for i in leaders(chain):
        followers = [m for m in chain.mimic if m.leader - 1 == i]
        reach = size[i] + error[i] + sum(abs(m.multiplier) * (size[m.follower - 1]
                                                              + error[m.follower - 1])
                                         for m in followers)
        out[i] = (error[i] + sum(abs(m.multiplier) * error[m.follower - 1] for m in followers)
                  + 4 * len(followers) * 2.0 ** -53 * reach)
    return out[_file_columns(chain, len(error))]
