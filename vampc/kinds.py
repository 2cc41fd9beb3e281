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

    @staticmethod
    def of(section: Section) -> Pass | None:
        """The pass a section's values belong to (the non-propagated ones, computed from the
        backward pass's, with it); None for host I/O."""
        return _PASS_OF[section]


class TapKind(Kind):
    """Where an operand is read (vampc.network.model.Tap): a VAMP's Result, a buffer stage, a host
    port, a constant buffer, or (a network on the Mostly-Local Bus) the bus of one tier in front of
    the reading VAMP."""

    VAMP = "vamp"
    BUFFER = "buffer"
    PORT = "port"
    CONST = "const"
    BUS = "bus"


class SourceKind(Kind):
    """What an operand latch holds by the tick rules (vampc.emulator.timing): a slot's result, a
    port entry, or a constant."""

    SLOT = "slot"
    PORT = "port"
    CONST = "const"


class FlowKind(Kind):
    """An operand of the stream engine's flow (vampc.emulator.stream): an op's result, an input the
    host writes each set, or a constant."""

    OP = "op"
    IN = "in"
    CONST = "const"


class Quantity(Kind):
    """A value the host writes every torque set (vampc.dataflow.host): A_i, z q̇_i, z q̈_i, a
    prismatic joint's p*_i and s*_i, a floating base's motion."""

    A = "A"
    ZQD = "zqd"
    ZQDD = "zqdd"
    P_STAR = "p_star"
    S_STAR = "s_star"
    OMEGA0 = "omega0"
    OMEGA_DOT0 = "omega_dot0"
    PDD0 = "pdd0"


def exhaustive(table: dict, kind: type[Kind]) -> dict:
    """`table`, checked to hold an entry for every member of `kind` and nothing else
    (VampcInternalError naming what is missing or extra): a registry keyed by a kind is then a
    complete dispatch over it."""
    missing = [m.value for m in kind if m not in table]
    extra = [k for k in table if not isinstance(k, kind)]
    if missing or extra:
        from vampc.errors import VampcInternalError
        raise VampcInternalError(f"the {kind.__name__} table misses {missing} and has extra "
                                 f"{extra}")
    return table


def unhandled(value):
    """The end of a dispatch over a kind's members: a member no branch handles is a bug, never a
    silent default (every dispatch names each member it handles)."""
    from vampc.errors import VampcInternalError
    raise VampcInternalError(f"no branch handles {value!r}")


class Engine(Kind):
    """The emulator engine: tick by tick from Program Mode (the specification), or the stream
    engine vectorised over the trajectory."""

    STREAM = "stream"
    TICK = "tick"


_PASS_OF = exhaustive({Section.BWD: Pass.BACKWARD, Section.NPV: Pass.BACKWARD,
                       Section.FWD: Pass.FORWARD, Section.IO: None}, Section)
