"""The registry of recursions and prefix shapes: the one place the command line's choices, the
report's configurations and the program file's types take them from (the layouts have theirs in
vampc.schedule.registry).

Each is keyed by its enum (vampc.kinds.Recursion, Prefix) and must hold every member: `exhaustive`
refuses a table that misses one when the module is imported, so a member added to an enum without
its builder, its paper formula or its shape fails at once instead of falling into somebody's
`else`. A recursion adds a member to Recursion and an entry here (its graph builder and the paper's
latency formula); a prefix shape a member to Prefix and its tier function in
vampc.dataflow.prefix.SHAPES.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from vampc.dataflow.prefix import SHAPES
from vampc.kinds import Prefix, Recursion, exhaustive


@dataclass(frozen=True)
class RecursionKind:
    """A Newton-Euler formulation: how its graph is built and the paper's latency formula for a
    general rotary arm of n joints, (Mults, Addns)."""

    kind: Recursion
    build: Callable          # (chain, CompileOptions) -> Graph
    paper_latency: Callable[[int], tuple[int, int]]
    paper_key: str           # the paper's Table O.1 row (vampc.report.paper)


def _linear(chain, options):
    from vampc.dataflow.linear import build_linear
    return build_linear(chain, verify=options.verify)


def _log(chain, options):
    from vampc.dataflow.logarithmic import build_log
    return build_log(chain, prefix=options.prefix, uniform_leaves=options.uniform_leaves,
                     verify=options.verify)


def _log_tiers(n: int) -> int:
    return math.ceil(math.log2(n + 1))


RECURSIONS: dict[Recursion, RecursionKind] = exhaustive({
    Recursion.LINEAR: RecursionKind(Recursion.LINEAR, _linear,
                                    lambda n: (2 * n + 3, 6 * n + 7), "lathrop_linear"),
    Recursion.LOG: RecursionKind(Recursion.LOG, _log,
                                 lambda n: (2 * _log_tiers(n) + 5, 6 * _log_tiers(n) + 10),
                                 "lathrop_log"),
}, Recursion)

PREFIXES: dict[Prefix, Callable] = SHAPES


def recursion_names() -> tuple[str, ...]:
    """The recursions, in the registry's order (the --recursion choices)."""
    return tuple(m.value for m in RECURSIONS)


def prefix_names() -> tuple[str, ...]:
    """The prefix shapes, in the registry's order (the --prefix choices)."""
    return tuple(m.value for m in PREFIXES)
