"""Frame poses composed from a Chain alone, shared by the robot-loader tests."""
from __future__ import annotations

import numpy as np


def chain_frames(chain, q) -> list[np.ndarray]:
    """Base-frame poses of O_1..O_n composed from the Chain: O_i in O_{i-1} is [A_i, A_i p*_i]."""
    out, pose = [], np.eye(4)
    for joint, qi in zip(chain.joints, q):
        step = np.eye(4)
        step[:3, :3] = joint.A(qi)
        step[:3, 3] = joint.A(qi) @ joint.p_star(qi)
        pose = pose @ step
        out.append(pose)
    return out
