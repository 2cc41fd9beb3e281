"""Trajectory files in and torque files out.

CSV: a header `q1..qn,qd1..qdn,qdd1..qddn`, optionally with a leading `t` column, then one state per row.
.npy: an array (count, 3n) or (count, 3n + 1) with t first. .npz: arrays `q`, `qd`, `qdd` (count, n) and
optionally `t`. Torques are written as CSV with the header `tau1..taun`, atomically.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from vampc.errors import VampcError


def header(n: int) -> list[str]:
    """The expected CSV column names (without t)."""
    return ([f"q{i}" for i in range(1, n + 1)] + [f"qd{i}" for i in range(1, n + 1)]
            + [f"qdd{i}" for i in range(1, n + 1)])


def read(path, n: int):
    """A Trajectory from a .csv, .npy or .npz file; VampcError naming the row and column on bad data."""
    from vampc.emulator.host import Trajectory
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix == ".npz":
            data, t = _read_npz(path, n)
        elif suffix == ".npy":
            data, t = _read_npy(path, n)
        else:
            data, t = _read_csv(path, n)
    except OSError as exc:
        raise VampcError(f"{path}: cannot read trajectory: {exc.strerror or exc}") from None
    _check_finite(path, data)
    return Trajectory(data[:, :n].copy(), data[:, n:2 * n].copy(), data[:, 2 * n:].copy(), t)


def _read_csv(path: Path, n: int):
    rows = list(csv.reader(io.StringIO(path.read_text())))
    if not rows:
        raise VampcError(f"{path}: empty trajectory file")
    names = [c.strip() for c in rows[0]]
    has_t = bool(names) and names[0] == "t"
    want = (["t"] if has_t else []) + header(n)
    if names != want:
        raise VampcError(f"{path}: header has {len(names)} columns {','.join(names[:4])}...; "
                         f"expected {len(want)}: {','.join(want[:2])}...{want[-1]} "
                         f"(the program is for {n} joints)")
    data = np.empty((len(rows) - 1, len(want)))
    for r, row in enumerate(rows[1:], 2):
        if len(row) != len(want):
            raise VampcError(f"{path}: line {r}: {len(row)} columns, expected {len(want)}")
        for c, cell in enumerate(row):
            try:
                data[r - 2, c] = float(cell)
            except ValueError:
                raise VampcError(f"{path}: line {r}, column {want[c]}: {cell!r} is not a number") from None
    if data.shape[0] == 0:
        raise VampcError(f"{path}: the trajectory has no states")
    return (data[:, 1:], data[:, 0]) if has_t else (data, None)


def _read_npy(path: Path, n: int):
    try:
        arr = np.load(path, allow_pickle=False)
    except ValueError as exc:
        raise VampcError(f"{path}: not a numpy array file ({exc})") from None
    if arr.ndim != 2 or arr.shape[1] not in (3 * n, 3 * n + 1) or arr.shape[0] == 0:
        raise VampcError(f"{path}: array of shape {arr.shape}; expected (states, {3 * n}) or "
                         f"(states, {3 * n + 1}) with t first")
    arr = _as_float(path, arr)
    return (arr[:, 1:], arr[:, 0]) if arr.shape[1] == 3 * n + 1 else (arr, None)


def _read_npz(path: Path, n: int):
    try:
        z = np.load(path, allow_pickle=False)
    except ValueError as exc:
        raise VampcError(f"{path}: not a numpy .npz file ({exc})") from None
    missing = [k for k in ("q", "qd", "qdd") if k not in z.files]
    if missing:
        raise VampcError(f"{path}: missing arrays {missing} (need q, qd, qdd; optional t)")
    parts = [_as_float(path, z[k]) for k in ("q", "qd", "qdd")]
    for k, p in zip(("q", "qd", "qdd"), parts):
        if p.ndim != 2 or p.shape != (parts[0].shape[0], n) or p.shape[0] == 0:
            raise VampcError(f"{path}: array {k} has shape {p.shape}; expected (states, {n})")
    return np.concatenate(parts, axis=1), (z["t"] if "t" in z.files else None)


def _as_float(path, arr) -> np.ndarray:
    if not np.issubdtype(arr.dtype, np.number):
        raise VampcError(f"{path}: array of {arr.dtype} is not numeric")
    return np.asarray(arr, dtype=float)


def _check_finite(path, data: np.ndarray) -> None:
    bad = ~np.isfinite(data)
    if bad.any():
        r, c = (int(x) for x in np.argwhere(bad)[0])
        raise VampcError(f"{path}: state {r + 1}, column {c + 1}: {data[r, c]} is not finite")


def write_torques(path, tau: np.ndarray) -> None:
    """CSV `tau1..taun`, full precision (repr round-trips), written atomically."""
    from vampc.program.file import write_json_atomic
    buf = io.StringIO()
    buf.write(",".join(f"tau{i}" for i in range(1, tau.shape[1] + 1)) + "\n")
    for row in tau:
        buf.write(",".join(repr(float(x)) for x in row) + "\n")
    try:
        write_json_atomic(path, buf.getvalue())
    except OSError as exc:
        raise VampcError(f"{path}: cannot write torques: {exc.strerror}") from None
