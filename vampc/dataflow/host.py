"""What the host computes for every torque set: the INPUT quantities of a dataflow graph.

VAMPs cannot do trigonometry, so the host writes, per joint i and per state (DESIGN §3):

    A       A_i(q_i)                      (3x3, row-major when flattened)
    zqd     z_{i-1} q̇_i = [0, 0, q̇_i]    (two pre-stored zeroes, q̇ in the third scalar)
    zqdd    z_{i-1} q̈_i = [0, 0, q̈_i]
    p_star  p*_i(q_i)                     (prismatic joints only: it moves with q)
    s_star  s*_i(q_i) = p*_i + r*_i       (prismatic joints only)

This module is the single definition of those values; the graph evaluator and the emulator's host
driver both call it.
"""
from __future__ import annotations

import numpy as np

from vampc.dataflow.graph import InputKey
from vampc.robot.chain import Chain


def input_value(chain: Chain, key: InputKey, q, qd, qdd) -> np.ndarray:
    """The value of one INPUT for states (q, qd, qdd) each of shape (N, n): (N, 3) or (N, 3, 3)."""
    j = chain.joints[key.joint - 1]
    col = key.joint - 1
    if key.quantity == "A":
        return j.A(q[:, col])
    if key.quantity in ("zqd", "zqdd"):
        src = qd if key.quantity == "zqd" else qdd
        out = np.zeros((src.shape[0], 3))
        out[:, 2] = src[:, col]
        return out
    if key.quantity == "p_star":
        return j.p_star(q[:, col])
    if key.quantity == "s_star":
        return j.s_star(q[:, col])
    raise KeyError(f"unknown host quantity {key.quantity!r}")


def input_values(chain: Chain, keys, q, qd, qdd) -> dict[InputKey, np.ndarray]:
    """input_value for every key, states given as (N, n) arrays."""
    q, qd, qdd = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd))
    return {k: input_value(chain, k, q, qd, qdd) for k in keys}
