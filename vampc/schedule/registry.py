"""The registry of layouts: the one place the CLI's --layout choices, the report's comparison
configurations, the trade-off sweep and the checks of CompileOptions take layouts from.

A layout kind is a name, a help text and a builder `build(graph, timing, request) -> (Layout,
Schedule)`; `grouped` says its VAMPs form fixed units (vampc.schedule.layout.Layout), `by_budget`
that it is made by --vamps / --interval rather than named with --layout, `compared` that the report
lays every robot out in it for its layout comparison, `shares_passes` that it takes --share-passes.
A new layout is added with `register_layout` (tests/test_layout_registry.py registers a round-robin
one).
"""
from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class LayoutRequest:
    """What a compile asks of a layout besides the graph and the latencies."""

    share_passes: bool = False
    vamps: int | None = None
    interval: int | None = None
    exact: bool = False
    verify: bool = True


@dataclass(frozen=True, eq=False)
class LayoutKind:
    """One registered layout (compared by identity)."""

    name: str
    help: str
    build: Callable
    grouped: bool = True
    by_budget: bool = False
    compared: bool = False
    shares_passes: bool = False

    def __repr__(self) -> str:
        return f"<layout {self.name}>"


LAYOUTS: dict[str, LayoutKind] = {}


def register_layout(kind: LayoutKind) -> LayoutKind:
    """Add a layout kind (ValueError if its name is taken)."""
    if kind.name in LAYOUTS:
        raise ValueError(f"layout {kind.name} is already registered")
    LAYOUTS[kind.name] = kind
    return kind


@contextlib.contextmanager
def registered_layout(kind: LayoutKind):
    """`register_layout(kind)` for the duration of a with block (tests)."""
    register_layout(kind)
    try:
        yield kind
    finally:
        del LAYOUTS[kind.name]


def layout_kind(name: str) -> LayoutKind:
    """The registered layout `name`; ValueError listing the choices otherwise."""
    try:
        return LAYOUTS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown layout {name!r} (choose from "
                         f"{', '.join(layout_names())})") from None


def layout_names() -> tuple[str, ...]:
    """The layouts --layout can name, in registration order."""
    return tuple(k.name for k in LAYOUTS.values() if not k.by_budget)


def _systolic(graph, timing, request: LayoutRequest):
    from vampc.schedule.layout import systolic
    return systolic(graph, timing, request.verify)


def _folded(graph, timing, request: LayoutRequest):
    from vampc.schedule.layout import folded
    return folded(graph, timing, request.share_passes, request.verify)


def _budget(graph, timing, request: LayoutRequest):
    from vampc.schedule.budget import budget_schedule
    layout, sched, _ = budget_schedule(graph, timing, request.vamps, request.interval,
                                       request.verify, exact=request.exact)
    return layout, sched


SYSTOLIC = register_layout(LayoutKind(
    "systolic", "one VAMP per op, a new torque set every 4 flops", _systolic, compared=True))
FOLDED = register_layout(LayoutKind(
    "folded", "the paper's single device, one node's (linear) or one tier's (log) VAMPs reused for "
    "every joint or tier, one torque set at a time", _folded, compared=True, shares_passes=True))
BUDGET = register_layout(LayoutKind(
    "budget", "--vamps K / --interval T: ops placed on at most K VAMPs, a new torque set every T "
    "flops", _budget, grouped=False, by_budget=True))


def is_layout(name, kind: LayoutKind) -> bool:
    """Whether the layout named `name` (as a report or a file names it) is `kind`."""
    return LAYOUTS.get(name) is kind
