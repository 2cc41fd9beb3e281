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
    # --- fast paths: native code on the raw bytes, else np.loadtxt on the text; whatever neither
    # takes goes through the cell-by-cell parser below, which names the bad line and column ---
    fast = _read_csv_native(path.read_bytes(), n)
    text = None
    if fast is None:
        text = path.read_text()
        fast = _read_csv_loadtxt(text, n)
    if fast is not None:
        return fast
    # --- end of fast paths ---
    rows = list(csv.reader(io.StringIO(text)))
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


# The fast paths return (data, t), or None whenever the file is anything but a plain well-formed
# table: the slow parser then reads it the same way or reports the precise error. Both give each cell
# the value float() gives it.

def _plain_header(head: str, n: int):
    """Whether the header line has a t column (True/False), or None if it is not the expected one."""
    names = [c.strip() for c in head.split(",")]
    has_t = bool(names) and names[0] == "t"
    return has_t if names == (["t"] if has_t else []) + header(n) else None


def _read_csv_native(raw: bytes, n: int):
    """vampc.emulator.native.parse_csv (strict decimal cells, strtod) on the bytes after the header."""
    head, _, body = raw.partition(b"\n")
    try:
        has_t = _plain_header(head.decode("ascii"), n)
    except UnicodeDecodeError:
        return None
    if has_t is None:
        return None
    from vampc.emulator.native import parse_csv
    data = parse_csv(body, 3 * n + has_t)
    if data is None:
        return None
    return (data[:, 1:], data[:, 0]) if has_t else (data, None)


def _read_csv_loadtxt(text: str, n: int):
    """np.loadtxt on the text after the header."""
    head, _, body = text.partition("\n")
    has_t = _plain_header(head, n)
    data = None if has_t is None else _loadtxt(body, 3 * n + has_t)
    if data is None:
        return None
    return (data[:, 1:], data[:, 0]) if has_t else (data, None)


def _loadtxt(body: str, cols: int):
    """np.loadtxt converts as float() does (PyOS_string_to_double) but, unlike the csv module, skips
    blank lines and takes no quotes: refuse what csv would read differently."""
    lines = body.split("\n")
    if lines[-1] == "":
        lines.pop()     # the final newline ends the last row; it does not start an empty one
    if not lines:
        return None
    try:
        data = np.loadtxt(lines, delimiter=",", comments=None, quotechar=None, ndmin=2, dtype=float)
    except ValueError:
        return None
    return data if data.shape == (len(lines), cols) else None   # no skipped blank line, not ragged


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
    """CSV `tau1..taun`, full precision (%.17g round-trips), written atomically."""
    from vampc.program.file import write_text_atomic
    # --- fast path: one %-format over all rows at C speed; %.17g round-trips like repr, faster ---
    count, n = tau.shape
    head = ",".join(f"tau{i}" for i in range(1, n + 1)) + "\n"
    row = ",".join(["%.17g"] * n) + "\n"
    text = head + (row * count) % tuple(np.asarray(tau, dtype=float).ravel().tolist())
    # --- end of fast path ---
    try:
        write_text_atomic(path, text)
    except OSError as exc:
        raise VampcError(f"{path}: cannot write torques: {exc.strerror}") from None
