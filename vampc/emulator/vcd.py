"""Value Change Dump output of a tick-engine run (readable by GTKWave).

One scope per VAMP, named after its number and graph node, holding its Result as three `real`
signals x, y, z; one tick of the emulator is 1 ns of VCD time. Only changes are written. The file is
written to a temporary name and renamed when the run completes, so a failed run leaves no partial file.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np


def _ident(k: int) -> str:
    chars = [chr(c) for c in range(33, 127)]
    out = ""
    k += 1
    while k:
        k, r = divmod(k - 1, len(chars))
        out = chars[r] + out
    return out


class VcdWriter:
    """Streams Result changes to a VCD file."""

    def __init__(self, path: str | Path, names: list[str]):
        self.path = Path(path)
        fd, self.tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", dir=self.path.parent or ".")
        self.fh = os.fdopen(fd, "w")
        self.ids = [[_ident(3 * v + c) for c in range(3)] for v in range(len(names))]
        self.last = np.full((len(names), 3), np.nan)
        self._header(names)

    def _header(self, names) -> None:
        w = self.fh.write
        w("$date vampc tick engine $end\n$version vampc $end\n$timescale 1ns $end\n")
        w("$scope module network $end\n")
        for name, ids in zip(names, self.ids):
            w(f"$scope module {name} $end\n")
            for axis, ident in zip("xyz", ids):
                w(f"$var real 64 {ident} {axis} $end\n")
            w("$upscope $end\n")
        w("$upscope $end\n$enddefinitions $end\n")

    def sample(self, tick: int, values: np.ndarray) -> None:
        """Record the Results visible from `tick` on."""
        changed = np.argwhere(~((values == self.last) | (np.isnan(values) & np.isnan(self.last))))
        if changed.size == 0:
            return
        lines = [f"#{tick}"] + [f"r{values[v, c]!r} {self.ids[v][c]}" for v, c in changed]
        self.fh.write("\n".join(lines) + "\n")
        self.last[changed[:, 0], changed[:, 1]] = values[changed[:, 0], changed[:, 1]]

    def close(self, ok: bool = True) -> None:
        """Finish the file (rename into place) or, if the run failed, remove it."""
        self.fh.close()
        if ok:
            os.chmod(self.tmp, 0o644)
            os.replace(self.tmp, self.path)
        else:
            Path(self.tmp).unlink(missing_ok=True)
