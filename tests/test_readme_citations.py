"""Every README section vampc's text cites (messages, help, docstrings: "README, Word formats",
README "Output files") is a heading of the README: the HTML page cited "Scheduling on a VAMP
budget", which had become "VAMP budgets and the trade-off" (a new user's find)."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_every_cited_readme_section_exists():
    heads = [re.sub(r"^#+\s*", "", line).strip() for line in
             (ROOT / "README.md").read_text().splitlines() if line.startswith("#")]
    cited = []
    for path in sorted((ROOT / "vampc").rglob("*.py")):
        text = " ".join(path.read_text().split())          # (a citation may be cut by a line end)
        text = re.sub(r'"\s*"', "", text)                    # (or by implicit concatenation)
        for match in re.finditer(r'README(?:,| \(?section)? "?([A-Z`][^")\.;:]*)', text):
            cited.append((path.relative_to(ROOT), match[1].strip()))
    assert len(cited) > 20
    missing = [(str(p), c) for p, c in cited
               if not any(c.startswith(h) or (len(c) >= 3 and h.startswith(c)) for h in heads)]
    assert not missing, missing
