"""The compile pipeline as one straight line of named stages (README, *Source layout*).

    robot file --load--> Chain --build--> Graph --schedule--> Schedule --allocate--> Network
      --emit--> programs + program stream --document--> program file

Every IR is verified at its stage boundary when `verify` is on (always in the tests).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from vampc.dataflow.graph import Graph
from vampc.errors import VampcError
from vampc.gcpause import gc_paused
from vampc.network.allocate import allocate
from vampc.network.model import Network
from vampc.options import STAGES, CompileOptions  # noqa: F401  (STAGES: the compile stages)
from vampc.program import emit
from vampc.program.words import Packing, Program
from vampc.robot.chain import Chain
from vampc.schedule.asap import Schedule
from vampc.schedule.layout import Layout, layout_and_schedule


@dataclass(frozen=True)
class Compiled:
    """Everything the compiler produced for one robot (a compile stopped after a stage, `until`,
    leaves what later stages make None)."""

    chain: Chain
    options: CompileOptions
    graph: Graph
    schedule: Schedule | None = None
    network: Network | None = None
    numbering: tuple[int, ...] | None = None
    programs: tuple[tuple[Program, ...], ...] | None = None     # per VAMP, its slots
    stream: tuple[emit.StreamEntry, ...] = field(default=())
    layout: Layout | None = None


def overflowing_constants(net, word) -> list[str]:
    """The constant buffers whose values the word cannot hold (the host's conversion saturates or
    wraps them: `vampc emulate` counts them as overflows), by name, in buffer order."""
    if word is None or not hasattr(word, "overflows"):     # (float64: none; float32 and qI.F
        return []                                           # count theirs: 1e39 is inf in float32)
    from vampc.emulator.stream import conversion_overflows
    return [c.name for c in net.consts if conversion_overflows(word, c.value)]


def build_graph(chain: Chain, options: CompileOptions) -> Graph:
    """The dataflow graph for the chosen recursion (its builder in vampc.dataflow.registry)."""
    import numpy as np

    from vampc.dataflow.registry import RECURSIONS
    with np.errstate(over="ignore", invalid="ignore"):   # every constant is checked finite instead
        return RECURSIONS[options.recursion].build(chain, options)      # (GraphBuilder.const)




@gc_paused()
def compile_chain(chain: Chain, options: CompileOptions = CompileOptions(),
                  stage=None, until: str | None = None, check_network: bool = True) -> Compiled:
    """Run every compile stage on a loaded chain; `stage(name)` is told as each of STAGES starts.
    `until`: stop after that stage (a name of STAGES), even where a later stage would fail.
    `check_network` False: the caller runs the network's check (Network.verify) itself."""
    stage = stage or (lambda name: None)
    options.check()
    if until is not None and until not in STAGES:
        raise VampcError(f"unknown stage {until!r} (choose from {', '.join(STAGES)})")
    if options.verify:
        chain.verify()
    stage("graph")
    graph = build_graph(chain, options)        # each stage verifies the IR it hands on
    if until == "graph":
        return Compiled(chain, options, graph)
    return compile_graph(chain, graph, options, stage, until, check_network)


def compile_graph(chain: Chain, graph: Graph, options: CompileOptions = CompileOptions(),
                  stage=None, until: str | None = None, check_network: bool = True) -> Compiled:
    """The stages after the graph (schedule, allocate, emit) on a graph of `chain`'s inputs: a
    graph built by a recursion, or by hand (tests build tiny graphs of new ops this way). `until`:
    stop after that stage; `check_network`: as compile_chain's."""
    stage = stage or (lambda name: None)
    options.check()
    stage("schedule")
    plan = None
    if options.bus == "mlb":
        from vampc.network.bus import schedule_on_bus
        layout, sched, plan = schedule_on_bus(graph, options.timing, options.tiers, options.verify,
                                              options.layout, options.share_passes)
    else:
        layout, sched = layout_and_schedule(graph, options.timing, options.layout,
                                            options.layout_request)
    if until == "schedule":
        return Compiled(chain, options, graph, sched, layout=layout)
    stage("allocate")
    net = allocate(graph, sched, layout, options.verify and check_network)
    if plan is not None:
        from vampc.network.bus import with_bus
        net = with_bus(net, plan, graph, options.verify and check_network)
    if until == "allocate":
        return Compiled(chain, options, graph, sched, net, layout=layout)
    stage("emit")
    numbering = (emit.read_numbering(options.numbering, len(net.vamps),
                                     Packing.of(options.arith()).limit) if options.numbering
                 else emit.default_numbering(net))
    progs = emit.programs(net)
    if options.error_correction:
        from dataclasses import replace

        from vampc.network.checking import checking_for
        net = replace(net, checking=checking_for(net, progs, options.timing,
                                                 options.check_cycles))
        try:
            emit.extraneous_number(numbering, Packing.of(options.arith()))
        except VampcError as exc:        # (the numbers are the --numbering file's, when given)
            if options.numbering:
                raise VampcError(f"{options.numbering}: {exc}") from None
            raise
    return Compiled(chain, options, graph, sched, net, numbering, progs,
                    emit.program_stream(net, progs, numbering, Packing.of(options.arith())),
                    layout)


@gc_paused()
def program_chunks(c: Compiled):
    """The program file's text (without its checksum: write_program stamps it) of a compiled robot,
    as ASCII byte pieces made as they are taken (what write_program streams: the text of a big
    program is never held whole). The summary and the small sections are made at once, with the
    cyclic collector paused: a full collection over a 4096-joint log compile's objects took 0.7 s."""
    from vampc.program.document import program_chunks as chunks
    from vampc.program.format import LayoutDoc
    from vampc.report.counts import summary
    return chunks(c.chain, c.graph, c.schedule, c.network, c.numbering, c.programs, c.stream,
                  c.options.record(), summary(c),
                  LayoutDoc(c.options.layout_name, c.options.share_passes))


@gc_paused()
def program_text(c: Compiled) -> str:
    """The program file's text (without its checksum: write_program stamps it) of a compiled robot."""
    return b"".join(program_chunks(c)).decode("ascii")


@gc_paused()
def program_document(c: Compiled) -> dict:
    """The program-file document of a compiled robot: what a reader of its file gets."""
    from vampc.jsontext import loads
    return loads(program_text(c))
