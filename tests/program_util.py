"""The program-file edit the damaged-file tests share."""
from __future__ import annotations

import json
from pathlib import Path

from vampc.program.file import checksum


def edited_program(program, tmp_path: Path, change, fix_checksum: bool = True) -> Path:
    """A copy of the program file `program` in tmp_path with `change(doc)` applied to its JSON, its
    checksum recomputed (unless fix_checksum is False: then the edit is a damaged file)."""
    doc = json.loads(Path(program).read_text())
    change(doc)
    if fix_checksum:
        doc["checksum"] = checksum(doc)
    path = tmp_path / "edited.vamp.json"
    path.write_text(json.dumps(doc))
    return path


def reported_with_summary(doc: dict, tmp_path: Path):
    """`vampc report` of the program document `doc` (its summary edited by the caller), its
    checksum made again: the click Result, asserted to exit 0."""
    from click.testing import CliRunner

    from vampc.cli import main
    doc["checksum"] = checksum(doc)
    old = tmp_path / "old.vamp.json"
    old.write_text(json.dumps(doc))
    r = CliRunner().invoke(main, ["report", str(old)])
    assert r.exit_code == 0, r.output
    return r
