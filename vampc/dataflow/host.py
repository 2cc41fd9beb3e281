"""What the host computes for every torque set: the INPUT quantities of a dataflow graph.

VAMPs cannot do trigonometry, so the host writes, per joint i and per state (the paper's
section II):

    A       A_i(q_i)                      (3x3, row-major when flattened)
    zqd     z_{i-1} q̇_i = [0, 0, q̇_i]    (two pre-stored zeroes, q̇ in the third scalar; u_i q̇_i
                                          for a joint whose axis u_i is not z of its parent's frame)
    zqdd    z_{i-1} q̈_i = [0, 0, q̈_i]    (u_i q̈_i likewise)
    p_star  p*_i(q_i)                     (prismatic joints only: it moves with q)
    s_star  s*_i(q_i) = p*_i + r*_i       (prismatic joints only)

and for a floating base (joint 0), from the trajectory's base columns [ω_0, ω̇_0, a_0]:

    omega0      ω_0                       omega_dot0  ω̇_0
    pdd0        p̈_0 = a_0 - g             (the classical acceleration of O_0's origin, minus gravity)

This module is the single definition of those values; the graph evaluator and the emulator's host
driver both call it.
"""
from __future__ import annotations

import numpy as np

from vampc.dataflow.graph import InputKey
from vampc.kinds import Quantity
from vampc.robot.chain import Chain

BASE_QUANTITIES = {"omega0": 0, "omega_dot0": 3, "pdd0": 6}   # their columns in a base (N, 9) array


def input_value(chain: Chain, key: InputKey, q, qd, qdd, base=None) -> np.ndarray:
    """The value of one INPUT for states (q, qd, qdd) each of shape (N, n), and a floating base's
    motions `base` (N, 9): (N, 3) or (N, 3, 3)."""
    if key.quantity in BASE_QUANTITIES:
        return _base_value(chain, key.quantity, base, q.shape[0])
    j = chain.joints[key.joint - 1]
    col = key.joint - 1
    if key.quantity is Quantity.A:
        return j.A(q[:, col])
    if key.quantity in (Quantity.ZQD, Quantity.ZQDD):
        src = qd if key.quantity is Quantity.ZQD else qdd
        if j.pre is not None:
            return src[:, col, None] * j.parent_axis
        out = np.zeros((src.shape[0], 3))
        out[:, 2] = src[:, col]
        return out
    if key.quantity is Quantity.P_STAR:
        return j.p_star(q[:, col])
    if key.quantity is Quantity.S_STAR:
        return j.s_star(q[:, col])
    raise KeyError(f"unknown host quantity {key.quantity!r}")


def _base_value(chain: Chain, quantity: str, base, count: int) -> np.ndarray:
    base = np.zeros((count, 9)) if base is None else np.atleast_2d(np.asarray(base, dtype=float))
    col = BASE_QUANTITIES[quantity]
    value = base[:, col:col + 3]
    return value - np.asarray(chain.gravity, dtype=float) if quantity is Quantity.PDD0 else value.copy()


def input_values(chain: Chain, keys, q, qd, qdd, base=None) -> dict[InputKey, np.ndarray]:
    """input_value for every key, states given as (N, n) arrays (and base motions (N, 9))."""
    q, qd, qdd = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd))
    return {k: input_value(chain, k, q, qd, qdd, base) for k in keys}
