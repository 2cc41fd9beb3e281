"""Kinds are dispatched exhaustively: every registry keyed by a kind holds each of its members (the
recursions, the prefix shapes), the command line offers exactly the registry's names, and a table
that misses a member is refused when it is made, naming the member."""
from __future__ import annotations

import pytest
from click.testing import CliRunner

from vampc.cli import main
from vampc.dataflow.prefix import SHAPES, prefix_tiers
from vampc.dataflow.registry import PREFIXES, RECURSIONS, prefix_names, recursion_names
from vampc.errors import VampcInternalError
from vampc.kinds import Pass, Prefix, Recursion, Section, TapKind, exhaustive
from vampc.program.format import schema


def test_every_recursion_and_prefix_shape_has_its_entry():
    assert list(RECURSIONS) == list(Recursion) and all(RECURSIONS[r].kind is r for r in Recursion)
    assert list(PREFIXES) == list(Prefix) and PREFIXES is SHAPES
    for shape in Prefix:                     # each builds a verified network over 7 leaves
        assert prefix_tiers(shape, 7)


def test_a_table_missing_a_member_is_refused():
    with pytest.raises(VampcInternalError, match=r"misses \['log'\]"):
        exhaustive({Recursion.LINEAR: 1}, Recursion)
    with pytest.raises(VampcInternalError, match="extra"):
        exhaustive({**{m: 1 for m in Recursion}, "cubic": 2}, Recursion)


def test_the_command_line_and_the_program_schema_offer_the_registry():
    help_text = CliRunner().invoke(main, ["compile", "--help"], terminal_width=200).output
    assert f"[{'|'.join(recursion_names())}]" in help_text
    assert f"[{'|'.join(prefix_names())}]" in help_text
    defs = schema()["$defs"]
    assert sorted(defs["Recursion"]["enum"]) == sorted(recursion_names())
    assert sorted(defs["Prefix"]["enum"]) == sorted(prefix_names())


def test_the_paper_formulas_come_from_the_registry():
    """Section III: 2n + 3 Mults, 6n + 7 Addns; sections IV-V: 2⌈log₂(n+1)⌉ + 5, 6⌈log₂(n+1)⌉ + 10
    (typed here from the paper, not from the code)."""
    assert RECURSIONS[Recursion.LINEAR].paper_latency(6) == (15, 43)
    assert RECURSIONS[Recursion.LOG].paper_latency(6) == (11, 28)
    assert RECURSIONS[Recursion.LOG].paper_latency(7) == (11, 28)
    assert RECURSIONS[Recursion.LOG].paper_latency(8) == (13, 34)


def test_each_tap_kind_has_its_source_vamp():
    from vampc.network.model import Tap, tap_source
    sources = [7, 9]                 # buffer 0 delays VAMP 7, buffer 1 VAMP 9
    got = {kind: tap_source(Tap(kind, 1, 2 if kind is TapKind.BUFFER else 0), sources)
           for kind in TapKind}
    assert got == {TapKind.VAMP: 1, TapKind.BUFFER: 9, TapKind.PORT: None, TapKind.CONST: None,
                   TapKind.BUS: None}     # a bus's source depends on the tick (Bus.drivers)


def test_each_section_belongs_to_its_pass():
    # the non-propagated r̈, F, N are computed from the backward pass's values: they go with it
    assert {s: Pass.of(s) for s in Section} == {Section.BWD: Pass.BACKWARD,
                                                  Section.NPV: Pass.BACKWARD,
                                                  Section.FWD: Pass.FORWARD, Section.IO: None}


def test_a_kind_no_branch_handles_is_an_internal_error():
    from vampc.network.model import Tap, tap_source
    tap = Tap("wire", 0)     # a kind a later feature adds, not yet handled
    with pytest.raises(VampcInternalError, match="no branch handles 'wire'"):
        tap_source(tap, [])
