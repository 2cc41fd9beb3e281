"""Where each VAMP sits in the paper's pictures: the recursion node (a circle of Figures III.1, IV.2,
VI.3) or, for a folded layout, the device node (Figure VI.1) its ops belong to.

A site is (section, index): section "bwd" (propagated, base to tip: the paper's "backward"), "npv"
(non-propagated r̈, F, N) or "fwd"; index is the recursion node's group (joint i for the linear
graph, the node's number for the log graph) in the systolic layout, the device node's position in a
folded one (vampc.schedule.layout.device_nodes). With shared passes the forward ops run on backward
VAMPs, whose site is the backward device node.
"""
from __future__ import annotations

from collections import Counter
from typing import NamedTuple

from vampc import jsontext
from vampc.kinds import Section
from vampc.memo import keep_last
from vampc.schedule.layout import device_nodes
from vampc.schedule.registry import SYSTOLIC, is_layout

SECTIONS = ("bwd", "npv", "fwd")
SECTION_NAMES = {"bwd": "backward", "npv": "non-propagated", "fwd": "forward"}


class Site(NamedTuple):
    """A recursion node (systolic) or device node (folded). A tuple: sites are hashed and compared
    millions of times in a big network's figures."""

    section: str
    index: int

    @property
    def label(self) -> str:
        """'bwd 3'."""
        return f"{self.section} {self.index}"


def unit_sizes(layout) -> list[int]:
    """Per unit: its VAMPs. A budgeted layout has no fixed groups: each VAMP is a unit of its own
    (an MM's three VAMPs each run other ops in between)."""
    if not layout.grouped:
        return [1] * layout.vamp_count
    return list(layout.unit_vamps)


def vamp_units(layout) -> list[int]:
    """Per VAMP index: its unit (VAMPs are numbered unit by unit, three for an MM unit)."""
    out = []
    for unit, size in enumerate(unit_sizes(layout)):
        out.extend([unit] * size)
    return out


def unit_nodes(graph, layout) -> list[list[int]]:
    """Per unit: the compute nodes bound to it, in id order (in a budgeted layout, per VAMP: the
    ops it takes part in, an MM on each of its three)."""
    if not layout.grouped:
        out: list[list[int]] = [[] for _ in range(layout.vamp_count)]
        for nd in graph.compute_nodes():
            for v in layout.placement[nd.id]:
                out[v].append(nd.id)
        return out
    out = [[] for _ in layout.unit_vamps]
    for nd in graph.compute_nodes():
        out[layout.units[nd.id]].append(nd.id)
    return out


def unit_sites(graph, layout) -> list[Site]:
    """Per unit: its site (from the unit's first node; in a budgeted layout, whose VAMPs serve many
    device nodes in turn, the device node most of its ops belong to)."""
    if not layout.grouped:
        device = device_nodes(graph)
        return [Site(*Counter(device(graph.nodes[i]) for i in ids).most_common(1)[0][0])
                if ids else Site(Section.BWD, 0) for ids in unit_nodes(graph, layout)]
    first = unit_firsts(graph, layout.units)
    if is_layout(layout.name, SYSTOLIC):
        return [Site(nd.section, nd.group) for nd in first]
    device = device_nodes(graph)
    return [Site(*device(nd)) for nd in first]


@keep_last(4)
def unit_firsts(graph, units) -> list:
    """Per unit of a binding (`units`: a unit per node), its first compute node (None if none; the
    last few answers are kept)."""
    first = [None] * (max(units, default=-1) + 1)
    for nd in graph.compute_nodes():
        if first[units[nd.id]] is None:
            first[units[nd.id]] = nd
    return first


@keep_last(4)
def vamp_sites(graph, layout) -> list[Site]:
    """Per VAMP index: its site (the last few answers are kept: the wiring figures, the drawing and
    the DOT text of one report all ask for them)."""
    sites = unit_sites(graph, layout)
    return [sites[u] for u in vamp_units(layout)]


def node_table(graph) -> dict[str, list[tuple[int, int, int, int, int]]]:
    """A log graph's recursion nodes per section: (group, a, k, b, tier) rows (tier 0: leaves);
    empty for the linear graph."""
    meta = dict(graph.meta)
    return {s: [tuple(r) for r in jsontext.loads(meta[f"{s}_nodes"])] if f"{s}_nodes" in meta else []
            for s in ("bwd", "fwd")}
