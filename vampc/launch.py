"""The `vampc` console script: the command line of vampc.cli, with a Ctrl-C that lands while Python
is still importing it (the first few tenths of a second) ending as every other interrupt does: one
line, `vampc: interrupted`, exit status 130, instead of an import's traceback."""
from __future__ import annotations

import sys


def main() -> None:
    try:
        from vampc.cli import main as command_line
    except KeyboardInterrupt:
        sys.stderr.write("vampc: interrupted\n")
        sys.exit(130)
    command_line()
