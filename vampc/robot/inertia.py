"""Whether an inertia is one a rigid body can have: symmetric positive semi-definite up to rounding.

Its own module, without the robot files' parsers (PyYAML, lxml), since a program file's robot section
is checked with it too and running a program imports no robot loader (README, Emulator speed)."""
from __future__ import annotations

import numpy as np

# An inertia whose smallest eigenvalue is negative by at most this much of its largest entry, or by
# at most NEARLY_PSD_ABS kg m² (a 10 g bead 3 mm from its axis: below any link's inertia), is a
# rounding error of the file (exported models print a few digits): taken as it is, with a warning
# (vampc.robot.urdf; a program's robot section, vampc.program.document).
NEARLY_PSD = 1e-4
NEARLY_PSD_ABS = 1e-7


def inertia_problem(inertia: np.ndarray, tolerance: float = 1e-9, floor: float = 0.0) -> str | None:
    """Why a 3x3 inertia is not symmetric positive semi-definite, or None if it is (up to rounding:
    `tolerance` of its largest entry, or `floor` in its own units, whichever is larger)."""
    scale = max(float(np.max(np.abs(inertia))), 1e-300)
    limit = max(tolerance * scale, floor)
    if np.max(np.abs(inertia - inertia.T)) > limit:
        return "inertia is not symmetric"
    eig = np.linalg.eigvalsh(inertia)
    if eig[0] < -limit:
        shown = ", ".join(f"{e:.6g}" for e in eig)
        return f"inertia is not positive semi-definite (eigenvalues {shown})"
    return None


def improper_inertias(inertias: np.ndarray) -> np.ndarray:
    """For a stack of 3x3 inertias (m, 3, 3): True where `inertia_problem` finds a problem (the same tests,
    one LAPACK call for the whole stack instead of one each)."""
    scale = np.maximum(np.abs(inertias).max(axis=(1, 2), initial=0.0), 1e-300)
    asymmetric = np.abs(inertias - np.swapaxes(inertias, 1, 2)).max(axis=(1, 2), initial=0.0) > 1e-9 * scale
    if len(inertias) == 0:
        return asymmetric
    return asymmetric | (np.linalg.eigvalsh(inertias)[:, 0] < -1e-9 * scale)
