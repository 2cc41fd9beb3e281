"""Numerical evaluation of a dataflow graph, vectorised over states.

It proves a graph before any hardware exists: its torques must equal the reference RNEA. It evaluates
the graph, not VAMP programs (the emulator does that), but each op as the VAMPs compute it: the op
table's micro-steps (vampc.machine.interp.apply), so its values are bit-equal to the emulator's.
"""
from __future__ import annotations

import numpy as np

from vampc.dataflow.graph import Graph
from vampc.dataflow.host import input_values
from vampc.machine.arith import FLOAT64, canonical_nan
from vampc.machine.interp import apply
from vampc.machine.ops import Op
from vampc.robot.chain import Chain


def evaluate_nodes(graph: Graph, chain: Chain, q, qd, qdd, base=None,
                   arith=FLOAT64) -> list[np.ndarray]:
    """Every node's value for states of shape (N, n) (and floating-base motions (N, 9)): a list indexed
    by node id, (N,3) or (N,3,3); each op in the word format `arith` (vampc.machine.arith), the
    values its words (float64 values for float64)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    keys = [nd.key for nd in graph.nodes if nd.op is Op.INPUT]
    inputs = input_values(chain, keys, q, qd, qdd, base)
    count = q.shape[0]
    vals: list[np.ndarray] = []
    for nd in graph.nodes:     # values as words of the format (the host's conversion: encode)
        if nd.op is Op.INPUT:
            vals.append(arith.encode(inputs[nd.key]))
        elif nd.op is Op.CONST:
            shape = (3, 3) if len(nd.value) == 9 else (3,)
            vals.append(np.broadcast_to(np.reshape(arith.encode(nd.value), shape), (count,) + shape))
        else:
            # (a NaN as the arithmetic makes it: `evaluate` makes the torques' canonical, as the
            # stream engine does, without a check on every op)
            vals.append(apply(nd.op, vals[nd.args[0]], vals[nd.args[1]], arith, canonical=False))
    return vals


def evaluate(graph: Graph, chain: Chain, q, qd, qdd, base=None, arith=FLOAT64) -> np.ndarray:
    """Torques (N, n) (or (n,) for a single state; n + 6 columns with a floating base's wrench)
    computed by evaluating the graph in the word format `arith`."""
    single = np.ndim(q) == 1
    vals = evaluate_nodes(graph, chain, q, qd, qdd, base, arith)
    tau = canonical_nan(arith.decode(np.stack([vals[o.node][:, o.component]
                                               for o in graph.outputs], axis=1)))
    return tau[0] if single else tau
