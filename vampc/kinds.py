"""The kinds vampc names with strings in files and on the command line, as enums.

Each is parsed once, where it enters (a CLI option, a file, CompileOptions), and compared as a member
everywhere else (`graph.recursion is Recursion.LOG`). A member is also the string it names (a str
subclass that prints and encodes as its value), so files, reports and messages read as before.
Layouts are not an enum: new ones can be registered (vampc.schedule.registry).
"""
from __future__ import annotations

import enum


class Kind(str, enum.Enum):
    """A kind named by a string: prints, formats and encodes to JSON as its value."""

    __str__ = str.__str__
    __format__ = str.__format__

    @classmethod
    def parse(cls, value, what: str):
        """The member named `value`; ValueError listing the choices otherwise."""
        try:
            return cls(value)
        except ValueError:
            raise ValueError(f"unknown {what} {value!r} (choose from "
                             f"{', '.join(m.value for m in cls)})") from None

    @classmethod
    def names(cls) -> tuple[str, ...]:
        """Every member's value, in order (the CLI's choices)."""
        return tuple(m.value for m in cls)


class Recursion(Kind):
    """The Newton-Euler formulation: section III's linear recursion or sections IV-V's log one."""

    LINEAR = "linear"
    LOG = "log"


class Prefix(Kind):
    """The prefix-network shape of the log recursion (Sklansky is the paper's)."""

    SKLANSKY = "sklansky"
    BRENT_KUNG = "brent-kung"
    KOGGE_STONE = "kogge-stone"
    LADNER_FISCHER = "ladner-fischer"
    SERIAL = "serial"


class Section(Kind):
    """The part of the algorithm a graph node belongs to: the base-to-tip pass (the paper's
    "backward"), the non-propagated r̈, F, N, the tip-to-base pass ("forward"), or host I/O."""

    BWD = "bwd"
    NPV = "npv"
    FWD = "fwd"
    IO = "io"


class Pass(Kind):
    """The two passes of the recursion as the paper names them."""

    BACKWARD = "backward"
    FORWARD = "forward"
