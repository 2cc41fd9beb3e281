"""The program file's types: one msgspec Struct per section and row, named by the file's keys. They
are the format's one definition: the writer (vampc.program.document) builds them from the compiler's
IRs and serialises them generically, the reader decodes a file straight into them (msgspec checks
every type and range while it parses, and says where), and `schemas/program.schema.json` is
generated from them (`python -m vampc.program.format > schemas/program.schema.json`; a test keeps
the shipped file equal to what they generate).

What a type cannot say, because it comes from a registry that tests and extensions add to, is
checked when the sections become IRs: op names and ROM pointers (vampc.machine.ops), layout names
(vampc.schedule.registry). Relations between sections (a slot's node exists, the schedule runs the
graph, every operand arrives in time) are vampc.program.document.compiled_from_doc's.

The Structs are not tracked by the cyclic garbage collector (gc=False: they hold no cycles), so a
big file's hundreds of thousands of rows cost the collector nothing.

msgspec was chosen by measuring (a 32-joint log program on 943 VAMPs, 1.4 MB, median of five runs,
garbage collector paused): a typed decode, types and ranges checked, takes 0.010 s, against 0.030 s
for json.loads and 0.005 s more for jsonschema-rs, and it hands over typed rows instead of dicts.
It does not write floats as Python's repr does (1e-05 becomes 0.00001) nor escape non-ASCII
characters, and program files stay byte-identical to earlier vampc's, so the writer hands it floats
already written as Python's repr (vampc.program.file.number, msgspec.Raw) and escapes what it
writes beyond ASCII (vampc.program.file.encode).
"""
from __future__ import annotations

from typing import Annotated, Any, Literal

import msgspec
from msgspec import UNSET, Meta, Struct, UnsetType

from vampc.kinds import Prefix, Quantity, Recursion, Section, TapKind

WORD_MAX = 16_777_215            # a 24-bit control field
Index = Annotated[int, Meta(ge=0)]
Count = Annotated[int, Meta(ge=1)]
Field24 = Annotated[int, Meta(ge=0, le=WORD_MAX)]
Latency = Annotated[int, Meta(ge=1, le=64)]
Vec3 = Annotated[list[float], Meta(min_length=3, max_length=3)]
Mat3 = Annotated[list[Vec3], Meta(min_length=3, max_length=3)]
Vector = Annotated[list[float], Meta(min_length=3, max_length=9)]


class Limits(Struct, gc=False, forbid_unknown_fields=True):
    q: Annotated[list[float], Meta(min_length=2, max_length=2)] | None
    qd: Annotated[float, Meta(ge=0)] | None
    tau: Annotated[float, Meta(ge=0)] | None


class JointDoc(Struct, gc=False, omit_defaults=True, forbid_unknown_fields=True):
    name: str
    type: Literal["revolute", "prismatic"]
    phi: Mat3
    p_fixed: Vec3
    offset: float
    mass: Annotated[float, Meta(ge=0)]
    com: Vec3
    inertia: Mat3
    axis: Vec3
    limits: Limits
    pre: Annotated[Mat3 | None, Meta(description="A tree: the joint frame's orientation in the "
                                     "parent's frame (identity when absent).")] = None
    shift: Annotated[Vec3 | None, Meta(description="A tree: the joint frame's origin from the "
                                       "parent frame's origin, in the parent's frame (zero when "
                                       "absent).")] = None


class MimicDoc(Struct, gc=False, forbid_unknown_fields=True):
    """A coupled mimic joint (--mimic couple): q_follower = multiplier · q_leader + offset."""

    follower: Annotated[int, Meta(ge=1)]
    leader: Annotated[int, Meta(ge=1)]
    multiplier: float
    offset: float


class RobotDoc(Struct, gc=False, omit_defaults=True, forbid_unknown_fields=True):
    name: str
    n: Count
    source: str
    joints: Annotated[list[JointDoc], Meta(min_length=1)]
    gravity: Vec3
    base_omega: Vec3
    base_omega_dot: Vec3
    tip_force: Vec3
    tip_torque: Vec3
    parents: Annotated[list[Index] | None, Meta(description="A tree: the parent joint (1-based; 0 "
                                                "the base) of every joint, numbered depth-first; "
                                                "absent for a chain.")] = None
    floating: Annotated[bool, Meta(description="A floating base: its motion is host input per "
                                   "torque set, its wrench 6 more outputs (joints n+1..n+6).")] = False
    base_mass: Annotated[float, Meta(ge=0)] | None = None
    base_com: Vec3 | None = None
    base_inertia: Mat3 | None = None
    mimic: Annotated[list[MimicDoc] | None, Meta(description="Coupled mimic joints (1-based): the "
                                                "host derives each follower's inputs from its leader "
                                                "and adds its torque, times the multiplier, to the "
                                                "leader's; absent when there are none.")] = None
    locked: Annotated[list[str] | None, Meta(description="The joints --lock took out of the robot "
                                             "file (their names, as given), so that a limits file "
                                             "naming one is passed over with a warning; absent "
                                             "when there are none.")] = None
    left_out: Annotated[list[str] | None, Meta(description="The robot file's other joints the "
                                               "program does not hold (fixed ones, and those the "
                                               "base, the tip or a locked joint leaves out), so that "
                                               "a limits file naming one is passed over with a "
                                               "warning; absent when there are none.")] = None


class OptionsDoc(Struct, gc=False, forbid_unknown_fields=True):
    """How the program was compiled (vampc.options.CompileOptions.recorded; defaults as there)."""

    recursion: Recursion = Recursion.LINEAR
    prefix: Prefix = Prefix.SKLANSKY
    uniform_leaves: bool = False
    mult_latency: Latency = 1
    add_latency: Latency = 1
    numbering: str | None = None
    layout: str = "systolic"
    share_passes: bool = False
    vamps: Count | None = None
    interval: Count | None = None
    exact: bool = False
    # the word format (vampc.machine.arith): absent for float64, rounding and overflow for qI.F only
    word: Annotated[str, Meta(pattern=r"^(float32|float64|q[0-9]+\.[0-9]+)$")] | UnsetType = UNSET
    rounding: Literal["nearest", "truncate"] | UnsetType = UNSET
    overflow: Literal["saturate", "wrap"] | UnsetType = UNSET
    # the Mostly-Local Bus: absent for point-to-point wiring; the tiers as --tiers gave them
    bus: Literal["p2p", "mlb"] | UnsetType = UNSET
    tiers: str | UnsetType = UNSET
    # limited automatic error correction: absent without it; its compare cycles with it
    error_correction: bool | UnsetType = UNSET
    check_cycles: Annotated[int, Meta(ge=1, le=WORD_MAX)] | UnsetType = UNSET

    def recorded(self) -> dict:
        """The options the file records, as CompileOptions takes them (absent ones left out)."""
        return {k: v for k, v in msgspec.structs.asdict(self).items() if v is not UNSET}


class NodeDoc(Struct, gc=False, omit_defaults=True, forbid_unknown_fields=True):
    id: Index
    op: str
    args: Annotated[list[Index], Meta(max_length=2)]
    name: str
    section: Section
    group: Index
    key: tuple[Quantity, Index] | None = None
    value: Vector | None = None


class GraphDoc(Struct, gc=False, forbid_unknown_fields=True):
    n: Count
    recursion: Recursion
    nodes: list[NodeDoc]
    outputs: list[tuple[int, int, int]]
    meta: dict[str, str] = {}


class ScheduleDoc(Struct, gc=False, forbid_unknown_fields=True):
    mult_latency: Latency
    add_latency: Latency
    latency: Index
    interval: Count
    mults: Index
    adds: Index
    start: list[Index]
    finish: list[Index]
    critical_path: list[Index] = []


class LayoutDoc(Struct, gc=False, forbid_unknown_fields=True):
    name: str
    share_passes: bool


# [kind, index, stage]: where an operand is read (vampc.network.model.Tap). A tuple, not an
# array-like Struct: readers share operands, and a tuple of tuples is its own cache key.
TapDoc = Annotated[tuple[TapKind, Index, Index],
                   Meta(description="[kind, index, stage]: a VAMP's Result, stage `stage` (1-based) "
                                    "of a buffer, a host port, a constant buffer, or the bus of "
                                    "tier `index` in front of the reader")]
Operand = Annotated[list[TapDoc], Meta(min_length=1, max_length=3,
                                       description="One multiplexer input: one tap, or three "
                                                   "carrying an MM group's columns")]
Mux = Annotated[list[Operand], Meta(min_length=1)]


class VampDoc(Struct, gc=False, forbid_unknown_fields=True):
    index: Index
    number: Annotated[int, Meta(ge=1, le=WORD_MAX)]
    a: Mux
    b: Mux


class BufferDoc(Struct, gc=False, forbid_unknown_fields=True):
    index: Index
    source: Index
    stages: Count


class PortEntryDoc(Struct, gc=False, array_like=True, forbid_unknown_fields=True):
    """[quantity, joint, block]: what the host writes to a port, and at which block."""

    quantity: Quantity
    joint: Index
    block: Index


class PortDoc(Struct, gc=False, forbid_unknown_fields=True):
    index: Index
    size: Literal[3, 9]
    entries: list[PortEntryDoc]


class ConstDoc(Struct, gc=False, forbid_unknown_fields=True):
    index: Index
    name: str
    value: Vector


class TierDoc(Struct, gc=False, array_like=True, forbid_unknown_fields=True):
    """[span, offset]: buses of `span` VAMPs end to end along the line from position `offset`."""

    span: Annotated[int, Meta(ge=1, le=WORD_MAX)]
    offset: Annotated[int, Meta(ge=0, le=WORD_MAX)]


class BusWriteDoc(Struct, gc=False, array_like=True, forbid_unknown_fields=True):
    """[source tap, counter, tier]: a bus-write register of the VAMP behind the source."""

    source: TapDoc
    counter: Field24
    tier: Annotated[int, Meta(ge=0, le=63)]


class BusDoc(Struct, gc=False, forbid_unknown_fields=True):
    """The Mostly-Local Bus (README, Mostly-Local Bus): tiers, each VAMP's place on the line (by
    VAMP index), the bus-write registers, and the ticks the bus added to the basic cycle (stretch)
    and to the latency (wait) against the same layout wired point to point."""

    tiers: Annotated[list[TierDoc], Meta(min_length=1, max_length=64)]
    position: list[Index]
    writes: list[BusWriteDoc]
    # ticks against the same layout wired point to point (a folded layout's list schedule can
    # come out shorter on the bus: then negative)
    stretch: int
    wait: int


class CheckingDoc(Struct, gc=False, forbid_unknown_fields=True):
    """Limited automatic error correction (README, Error correction): the VAMPs (by index) in
    their chain of successors, after one extraneous VAMP; the periods a VAMP computes a role it has
    just taken before comparing or driving it."""

    chain: list[Index]
    warmup: Annotated[int, Meta(ge=1, le=WORD_MAX)]
    compare: Annotated[int, Meta(ge=1, le=WORD_MAX)] = 1


class NetworkDoc(Struct, gc=False, omit_defaults=True, forbid_unknown_fields=True):
    period: Annotated[int, Meta(ge=1, le=WORD_MAX)]
    clock: Annotated[int, Meta(ge=1, le=WORD_MAX)]
    vamps: Annotated[list[VampDoc], Meta(min_length=1)]
    buffers: list[BufferDoc]
    ports: list[PortDoc]
    consts: list[ConstDoc]
    bus: BusDoc | None = None
    error_correction: CheckingDoc | None = None


class SlotDoc(Struct, gc=False, forbid_unknown_fields=True):
    node: Index
    op: str
    delay_a: Field24
    delay_b: Field24
    delay_r: Field24
    rom: Index
    sel_a: Field24
    sel_b: Field24


class ProgramDoc(Struct, gc=False, forbid_unknown_fields=True):
    vamp: Index
    slots: Annotated[list[SlotDoc], Meta(min_length=1)]


class RootDoc(Struct, gc=False, array_like=True, forbid_unknown_fields=True):
    kind: Literal["port", "const"]
    index: Index


class StreamDoc(Struct, gc=False, forbid_unknown_fields=True):
    root: RootDoc
    targets: list[Index]
    depth: list[Index]
    words: list[tuple[float, float, float]]


class PortWriteDoc(Struct, gc=False, forbid_unknown_fields=True):
    port: Index
    quantity: Quantity
    joint: Index
    tick: Index


class OutputDoc(Struct, gc=False, forbid_unknown_fields=True):
    joint: Count
    vamp: Index
    component: Annotated[int, Meta(ge=0, le=2)]
    tick: Index


class IoDoc(Struct, gc=False, forbid_unknown_fields=True):
    period: Count
    clock: Count
    load_ticks: Index
    port_writes: list[PortWriteDoc]
    outputs: Annotated[list[OutputDoc], Meta(min_length=1)]


# The summary holds the compiler's figures for people reading the file (vampc.report.counts.summary):
# a report recomputes every one from the other sections. These five are always there.
SUMMARY_KEYS = ("interval_flops", "joints", "latency", "recursion", "vamps")


class ProgramFile(Struct, gc=False, forbid_unknown_fields=True):
    """A compiled VAMP network: robot data for the host, dataflow graph, schedule, layout, netlist
    with operand multiplexers, per-VAMP slot programs (delay-A/B/R, ROM pointer, multiplexer
    selects), the Program Mode stream and I/O timing (README, Program file)."""

    format: Literal["vampc-program"]
    version: Literal[2]
    checksum: Annotated[str, Meta(pattern="^sha256:[0-9a-f]{64}$")]
    robot: RobotDoc
    options: OptionsDoc
    graph: GraphDoc
    schedule: ScheduleDoc
    layout: LayoutDoc
    network: NetworkDoc
    programs: Annotated[list[ProgramDoc], Meta(min_length=1)]
    program_stream: list[StreamDoc]
    io: IoDoc
    summary: dict[str, Any]


_DECODER = msgspec.json.Decoder(ProgramFile)


def decode(text: bytes | str) -> ProgramFile:
    """A program file's text as its Structs (msgspec.ValidationError or DecodeError otherwise)."""
    return _DECODER.decode(text)


def from_builtins(doc: dict) -> ProgramFile:
    """A program document held as dicts and lists (json.loads of a file) as its Structs."""
    return msgspec.convert(doc, ProgramFile)


def check_summary(doc: ProgramFile) -> str | None:
    """What the summary lacks of SUMMARY_KEYS, as msgspec would say it; None when it has them."""
    missing = [k for k in SUMMARY_KEYS if k not in doc.summary]
    return f"summary: object missing required field `{missing[0]}`" if missing else None


def schema() -> dict:
    """The JSON Schema of a program file, generated from the Structs."""
    out = msgspec.json.schema(ProgramFile)
    out["$defs"]["ProgramFile"]["properties"]["summary"] = {
        "type": "object", "required": list(SUMMARY_KEYS),
        "description": "The compiler's figures, for people reading the file: a report recomputes "
                       "every one of them from the other sections."}
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            "$id": "https://vampc.invalid/schemas/program.schema.json",
            "title": "vampc program file", **out}


if __name__ == "__main__":
    from vampc.jsontext import dumps
    print(dumps(schema(), indent=1, sort_keys=True))
