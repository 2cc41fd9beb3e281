"""The dataflow graph IR: vector operations as nodes, data dependencies as operand references.

A graph is what every builder (linear, logarithmic) produces and every back-end stage (scheduling,
allocation, emission) consumes. It is plain frozen data; networkx is used only for analysis.
"""
from __future__ import annotations

import functools
import math
import operator
from collections import Counter
from dataclasses import dataclass

from msgspec import Struct

from vampc.errors import VampcError, VampcInternalError
from vampc.kinds import Quantity, Recursion, Section
from vampc.machine.ops import OPERAND_SHAPES, Op, result_shape
from vampc.memo import counting

_SECTION, _GROUP, _OP = (operator.attrgetter(name) for name in ("section", "group", "op"))


@dataclass(frozen=True)
class InputKey:
    """A value the host writes every cycle: `quantity` of joint `joint` (see vampc.dataflow.host)."""

    quantity: Quantity   # A, zqd, zqdd, p_star, s_star; a floating base's omega0, ...
    joint: int           # 1-based joint index (0: the floating base)

    def __post_init__(self):
        if not isinstance(self.quantity, Quantity):     # a builder's name, or read from a file
            object.__setattr__(self, "quantity", Quantity(self.quantity))

    @property
    def label(self) -> str:
        """'A3', 'zqd2'; a floating base's 'omega0', not 'omega00' (as README names its ports: the
        pictures had doubled the 0, a new user's find)."""
        return str(self.quantity) if self.joint == 0 else f"{self.quantity}{self.joint}"


class Node(Struct, frozen=True, gc=False):
    """One node. `args` are operand node ids (A then B). `name` is the paper's variable (e.g. "T4").

    `section` says which part of the algorithm the node belongs to: "bwd" (propagated backward, i.e.
    base-to-tip in the paper's naming), "npv" (non-propagated r̈, F, N), "fwd" (tip-to-base), or "io".
    `group` is the recursion node it belongs to (joint index for the linear graph).

    A frozen msgspec Struct the cyclic collector does not track (a big graph is millions of them;
    they hold no cycles): made in a tenth of a dataclass's time. `section` must be a Section.
    """

    id: int
    op: Op
    args: tuple[int, ...] = ()
    name: str = ""
    section: Section = Section.IO
    group: int = 0
    key: InputKey | None = None                # INPUT only
    value: tuple[float, ...] | None = None     # CONST only (3 or 9 scalars, row-major)

    @property
    def shape(self) -> str:
        """'v' (3 scalars) or 'm' (9 scalars)."""
        if self.op is Op.INPUT:
            return "m" if self.key.quantity is Quantity.A else "v"
        if self.op is Op.CONST:
            return "m" if len(self.value) == 9 else "v"
        return result_shape(self.op)

    @property
    def label(self) -> str:
        """A readable unique-ish label: section, group and name."""
        return f"{self.section}{self.group}.{self.name}"


@dataclass(frozen=True)
class Output:
    """Joint torque τ_joint is scalar `component` of node `node`'s result. Past the n joints, "joints"
    n + 1..n + 6 are a floating base's wrench [f_0, n_0]."""

    joint: int
    node: int
    component: int = 2


# graph.meta's fixed words, as the builders write them (and program files are checked against):
# the linear graph's whole meta; a log graph's leaves (by uniform_leaves), ground (by ground in O_0)
# and convention (of a chain, of a tree), beside its prefix, tables and node ids (vampc.dataflow.
# logarithmic._meta)
LINEAR_META = (("convention", "f, n referred to O_{i-1}"), ("recursion", "linear"))
LOG_LEAVES = {False: "separate (Table IV.1)", True: "uniform (Appendix D)"}
LOG_GROUNDS = {True: "O_0", False: "O_-1"}
LOG_CONVENTION = "forward f, n referred to O_{i-1}"
LOG_TREE_CONVENTION = "forward f, n referred to O_{i-1}; subtree sums in O_0"


@dataclass(frozen=True)
class Graph:
    """A dataflow graph for one robot: nodes in topological order, and the torque outputs."""

    nodes: tuple[Node, ...]
    outputs: tuple[Output, ...]
    n: int
    recursion: Recursion = Recursion.LINEAR
    meta: tuple[tuple[str, str], ...] = ()

    def __post_init__(self):
        if not isinstance(self.recursion, Recursion):     # read from a file, or a builder's name
            object.__setattr__(self, "recursion", Recursion(self.recursion))

    def compute_nodes(self) -> list[Node]:
        """The nodes a VAMP executes (a new list each time, copied from the one kept: a report asks
        about fifty times, a million nodes each for a 4 096-joint log graph)."""
        return list(self._compute_nodes)

    @functools.cached_property
    def _compute_nodes(self) -> tuple[Node, ...]:
        return tuple(nd for nd in self.nodes if nd.op.is_compute)

    def compute_kinds(self) -> Counter:
        """How many compute nodes there are of each (section, group, op): what the cost figures
        count by (vampc.report.counts; one walk over the nodes for all of them, not one each)."""
        return Counter(self._compute_kinds)

    @functools.cached_property
    def _compute_kinds(self) -> Counter:
        return Counter(zip(map(_SECTION, self._compute_nodes), map(_GROUP, self._compute_nodes),
                           map(_OP, self._compute_nodes)))

    def compute_ops(self) -> Counter:
        """How many compute nodes there are of each op."""
        return Counter(self._compute_ops)

    @functools.cached_property
    def _compute_ops(self) -> Counter:
        return Counter(map(_OP, self._compute_nodes))

    def input_keys(self) -> tuple[InputKey, ...]:
        """The host quantities the graph reads (its INPUT nodes' keys, in node order)."""
        return tuple(nd.key for nd in self.nodes if nd.key is not None)

    def to_networkx(self):
        """A networkx DiGraph with an edge producer -> consumer per operand (for analysis only)."""
        import networkx as nx  # imported here: it costs ~0.1 s of start-up and only analysis needs it
        g = nx.DiGraph()
        for nd in self.nodes:
            g.add_node(nd.id)
            for a in nd.args:
                g.add_edge(a, nd.id)
        return g

    def live_nodes(self) -> set[int]:
        """The ids of the nodes some torque output depends on (the outputs' and, back through the
        operands, theirs): what a pruned graph keeps, and what a report counts the rest against."""
        live = {o.node for o in self.outputs}
        for nd in reversed(self.nodes):
            if nd.id in live:
                live.update(nd.args)
        return live

    def consumers(self) -> dict[int, list[int]]:
        """Map node id -> ids of the nodes reading it."""
        out: dict[int, list[int]] = {nd.id: [] for nd in self.nodes}
        for nd in self.nodes:
            for a in nd.args:
                out[a].append(nd.id)
        return out

    def verify(self) -> None:
        """Check ids, topological order, arities and operand shapes; raise VampcInternalError."""
        result = {op: result_shape(op) for op in {nd.op for nd in self.nodes} if op.is_compute}
        shapes: list[str] = []      # per node checked, its result's shape
        operands = {op: OPERAND_SHAPES[op] for op in result if len(OPERAND_SHAPES[op]) == 2}
        for i, nd in enumerate(self.nodes):
            if nd.id != i:
                raise VampcInternalError(f"node {nd.label}: id {nd.id} at position {i}")
            want = operands.get(nd.op)
            args = nd.args
            # (_verify_node's checks of a compute node of two operands, in line and in its order:
            # a million nodes; it says what is wrong)
            if want is not None and len(args) == 2 and 0 <= args[0] < i and \
                    shapes[args[0]] == want[0] and 0 <= args[1] < i and shapes[args[1]] == want[1]:
                shapes.append(result[nd.op])
                continue
            _verify_node(self, nd, shapes)
            shapes.append(result.get(nd.op) or nd.shape)
        joints = sorted(o.joint for o in self.outputs)
        want = self.n + 6 if len(joints) > self.n else self.n    # a floating base's wrench: 6 more
        if joints != list(range(1, want + 1)):
            raise VampcInternalError(f"outputs cover joints {joints}, expected 1..{want}")
        for o in self.outputs:
            if self.nodes[o.node].shape != "v" or not 0 <= o.component < 3:
                raise VampcInternalError(f"output τ{o.joint} reads a bad node/component")


def _verify_node(g: Graph, nd: Node, shapes: list[str]) -> None:
    """Check one node; `shapes`: the result shapes of the nodes before it."""
    if nd.op is Op.INPUT and nd.key is None or nd.op is Op.CONST and nd.value is None:
        raise VampcInternalError(f"node {nd.label}: missing input key / constant value")
    if not nd.op.is_compute:
        if nd.args:
            raise VampcInternalError(f"node {nd.label}: {nd.op.value} has operands")
        return
    if len(nd.args) != 2:
        raise VampcInternalError(f"node {nd.label}: {nd.op.value} needs 2 operands")
    for arg, want in zip(nd.args, OPERAND_SHAPES[nd.op]):
        if not 0 <= arg < nd.id:
            text = str(arg) if len(str(arg)) <= 20 else f"{str(arg)[:12]}... ({len(str(arg))} digits)"
            raise VampcInternalError(f"node {nd.label}: operand {text} not before it")
        if shapes[arg] != want:
            raise VampcInternalError(f"node {nd.label}: operand {g.nodes[arg].label} is not '{want}'")


class GraphBuilder:
    """Appends nodes in topological order; builders use it to write the paper's tables as code."""

    def __init__(self, n: int, recursion: str):
        self.n, self.recursion = n, recursion
        self.nodes: list[Node] = []
        self.outputs: list[Output] = []
        self._inputs: dict[InputKey, int] = {}
        self._consts: dict[tuple, int] = {}
        self.section, self.group = Section.IO, 0
        self._ids: tuple[int, ...] = ()       # node ids: vampc.memo.counting's ints

    def at(self, section: str, group: int) -> "GraphBuilder":
        """Set the section and group of the nodes added next."""
        self.section, self.group = Section(section), group
        return self

    def _next_id(self) -> int:
        """The next node's id, as the shared int (vampc.memo.counting)."""
        k = len(self.nodes)
        if k >= len(self._ids):
            self._ids = counting(k + 1)
        return self._ids[k]

    def op(self, op: Op, a: int, b: int, name: str) -> int:
        """Add a compute node and return its id (_next_id and _add in line: a 4096-joint log
        graph adds a million)."""
        nodes = self.nodes
        k = len(nodes)
        if k >= len(self._ids):
            self._ids = counting(k + 1)
        node = self._ids[k]
        nodes.append(Node(node, op, (a, b), name, self.section, self.group))
        return node

    def input(self, quantity: str, joint: int) -> int:
        """The (shared) INPUT node for a host quantity of a joint."""
        key = InputKey(quantity, joint)
        if key not in self._inputs:
            node = Node(self._next_id(), Op.INPUT, (), f"{quantity}{joint}", Section.IO, joint,
                        key=key)
            self._inputs[key] = self._add(node)
        return self._inputs[key]

    def const(self, value, name: str, group: int = 0) -> int:
        """A CONST node holding `value` (a 3-vector or 3x3 matrix); equal (name, value) pairs share."""
        flat = tuple(float(x) for x in _flatten(value))
        if not all(map(math.isfinite, flat)):
            where = f" (joint {group})" if group else ""
            raise VampcError(f"the constant {name}{where} is not a finite number: the robot's "
                             "numbers overflow a float once combined (a length or mass too large)")
        k = (name, flat)
        if k not in self._consts:
            node = Node(self._next_id(), Op.CONST, (), name, Section.IO, group, value=flat)
            self._consts[k] = self._add(node)
        return self._consts[k]

    def output(self, joint: int, node: int, component: int = 2) -> None:
        """Declare τ_joint = component of node."""
        self.outputs.append(Output(joint, node, component))

    def build(self, meta: dict | None = None, verify: bool = True) -> Graph:
        """Freeze into a Graph (verified unless `verify` is off)."""
        g = Graph(tuple(self.nodes), tuple(sorted(self.outputs, key=lambda o: o.joint)), self.n,
                  self.recursion, tuple(sorted((meta or {}).items())))
        if verify:
            g.verify()
        return g

    def _add(self, node: Node) -> int:
        self.nodes.append(node)
        return node.id


def _flatten(value):
    import numpy as np
    return np.asarray(value, dtype=float).reshape(-1)
