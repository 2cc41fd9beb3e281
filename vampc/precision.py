"""How narrow a word can be (`vampc precision`, README "Word formats"): a bound on every value's
magnitude and on the torques' error in a word format, beside the error observed on random states.

The bound follows the graph op by op with norms (a vector's Euclidean norm, a matrix's spectral
norm), which rotations preserve, so it does not grow along the chain as per-component intervals do.
Each op of the table states how its result's norm bounds by its operands' (vampc.machine.ops.OpDef
`norm`: a sum |A| + |B|, or a product g |A| |B|); its error then propagates as

    sum      e_A + e_B
    product  g (|A| e_B + |B| e_A + e_A e_B)

plus the op's own rounding: in fixed point each product its module computes is rounded once (2^-F/2
rounding to nearest, 2^-F truncating; sums are exact), in floating point every assignment (half an
ulp of the largest value it can hold). An output scalar's error is at most the result's error norm.

The host inputs' norms come from the states analysed (`Ranges`: joint positions within their limits,
else ±π; speeds within their limits, else ±1; accelerations within ±`qdd`, default 1 as random
states use; a floating base's motions within ±1; a coupled follower's, its leader's through the
coupling, as the random states move it): a rotation A_i has norm 1, and every other input is
affine in one state variable, so its norm is largest at one end of that variable's range. Each is
converted by the host (its rounding, and a few ulps of float64 before it); a constant is exact plus
its conversion. Every register value is at most a product's |A| |B| or a sum's |A| + |B| (a partial
dot product by Cauchy–Schwarz) plus its error: the largest (`peak`) gives the integer bits a
fixed-point word needs so that nothing can overflow. The bound holds for every state in the ranges
(tests compare it with observed errors on every example, both recursions).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vampc.dataflow.graph import Graph, InputKey
from vampc.dataflow.host import BASE_QUANTITIES, input_value
from vampc.errors import VampcError
from vampc.kinds import Quantity
from vampc.machine.arith import Fixed, Fn, Rounding
from vampc.machine.ops import TABLE, Op
from vampc.robot.chain import Chain

ROOT3 = math.sqrt(3.0)


@dataclass(frozen=True)
class Ranges:
    """The states analysed (see the module docstring)."""

    qdd: float = 1.0
    Q_UNLIMITED = math.pi        # |q| and |q̇| of a joint the robot file gives no limit of
    QD_UNLIMITED = 1.0

    def of(self, chain: Chain, key: InputKey, name: str) -> tuple[float, float]:
        """The range of state variable `name` ("q", "qd", "qdd") of the key's joint. A coupled
        follower's (--mimic couple) is its leader's range through the coupling, its own limits
        aside, as the random states move it: analysed within its own limits, a follower driven at 8
        times its leader gave a bound of 7.2e-4 beside an observed error of 0.33 and 517 overflows
        in the word named as holding every value (an independent check's find)."""
        follows = next((m for m in chain.mimic if m.follower == key.joint), None)
        if follows is not None:
            lo, hi = sorted(follows.multiplier * end
                            for end in self.of(chain, InputKey(key.quantity, follows.leader), name))
            shift = follows.offset if name == "q" else 0.0
            return (lo + shift, hi + shift)
        j = chain.joints[key.joint - 1]
        if name == "q":
            return j.limits.q if j.limits.q else (-self.Q_UNLIMITED, self.Q_UNLIMITED)
        if name == "qd":
            v = j.limits.qd if j.limits.qd else self.QD_UNLIMITED
            return (-v, v)
        return (-self.qdd, self.qdd)


def states_analysed(chain: Chain, qdd: float) -> dict:
    """What `Ranges` takes for each state variable, said with the answer (a word is narrowest only
    for these states): the acceleration bound, and the joints whose position or speed limit the
    robot file does not give (±π, ±1 taken instead); a floating base's motions within ±1; the
    coupled followers, moved as their leaders move them (`Ranges.of`), whatever their own limits."""
    followers = {m.follower - 1 for m in chain.mimic}
    own = [j for i, j in enumerate(chain.joints) if i not in followers]
    return {"acceleration": qdd,
            "no_position_limit": [j.name for j in own if not j.limits.q],
            "no_speed_limit": [j.name for j in own if not j.limits.qd],
            "floating_base": bool(chain.floating),
            "coupled": [chain.joints[i].name for i in sorted(followers)]}


def states_line(states: dict, joints: int) -> str:
    """states_analysed as the text output's line."""
    joints -= len(states["coupled"])
    def which(names: list[str], default: str) -> str:
        if not names:
            return "within their limits"
        if len(names) == joints:
            return f"within {default} (the robot file gives no joint a limit)"
        return (f"within their limits, else {default} (joint{'s' if len(names) > 1 else ''} "
                f"{', '.join(names)}: no limit given)")
    q = "±π" if Ranges.Q_UNLIMITED == math.pi else f"±{Ranges.Q_UNLIMITED:g}"
    return (f"states analysed: positions {which(states['no_position_limit'], q)}; speeds "
            f"{which(states['no_speed_limit'], f'±{Ranges.QD_UNLIMITED:g}')}; accelerations within "
            f"±{states['acceleration']:g} (--acceleration)"
            + ("; the floating base's motions within ±1" if states["floating_base"] else "")
            + _coupled_text(states["coupled"]))


def _coupled_text(names: list[str]) -> str:
    if not names:
        return ""
    if len(names) == 1:
        return f"; the coupled joint {names[0]} as its leader moves it, whatever its own limits"
    return (f"; the coupled joints {', '.join(names)} as their leaders move them, whatever their own "
            "limits")


@dataclass(frozen=True)
class Analysis:
    """The bounds: the largest magnitude any register holds (`peak`), and per torque output its
    largest |τ| (`tau_max`) and the largest error (`tau_error`)."""

    peak: float
    tau_max: np.ndarray
    tau_error: np.ndarray
    peak_at: str = ""        # the value whose bound it is (a node's label: 'T16·bwd 11', 'A·3')


def analyse(graph: Graph, chain: Chain, word, ranges: Ranges = Ranges()) -> Analysis:
    """The norm and error bounds of every value of `graph` computed in `word` (VampcError for an
    op without a norm rule)."""
    norm: list[float] = []
    err: list[float] = []
    peak, at = 0.0, -1

    def held(value: float, node: int) -> None:        # (which value sets it: a new user asked)
        nonlocal peak, at
        if value > peak:
            peak, at = value, node
    for nd in graph.nodes:
        if nd.op is Op.INPUT:
            size, scalar = _input_bound(chain, nd.key, ranges)
            e = word.rounding_error(scalar) + 4 * 2.0 ** -53 * scalar     # float64 first, then the word
            norm.append(size)
            err.append((3.0 if nd.shape == "m" else ROOT3) * e)
            held(scalar + e, nd.id)
            continue
        if nd.op is Op.CONST:
            v = np.asarray(nd.value, dtype=float)
            e = float(np.max(np.abs(word.decode(word.fresh().encode(v)) - v)))
            norm.append(spectral_norm(v.reshape(3, 3)) if v.size == 9 else vector_norm(v))
            err.append((3.0 if v.size == 9 else ROOT3) * e)
            held(float(np.max(np.abs(v))) + e, nd.id)
            continue
        entry = TABLE[nd.op]
        if entry.norm is None:
            raise VampcError(f"op {entry.name} states no norm rule (vampc.machine.ops OpDef.norm): "
                             "its values cannot be bounded")
        kind, gain = entry.norm
        (na, nb), (ea, eb) = (norm[a] for a in nd.args), (err[a] for a in nd.args)
        if kind == "sum":
            size, spread, scalar = na + nb, ea + eb, na + nb
        else:
            size, spread, scalar = gain * na * nb, gain * (na * eb + nb * ea + ea * eb), na * nb
        assigns = [a.fn for step in entry.steps for a in step]
        rounded = (sum(fn is Fn.MUL for fn in assigns) if isinstance(word, Fixed) else len(assigns))
        own = rounded * word.rounding_error(scalar + spread)
        norm.append(size)
        err.append(spread + (3.0 if entry.columns == 3 else ROOT3) * own)
        held(scalar + err[-1], nd.id)
    tau_max = np.array([norm[o.node] for o in graph.outputs])
    tau_error = np.array([err[o.node] for o in graph.outputs])
    return Analysis(peak, tau_max, tau_error, _named(graph.nodes[at]) if at >= 0 else "")


_PASS = {"bwd": "the backward pass's node", "npv": "the non-propagated part of node",
         "fwd": "the forward pass's node", "io": "the input of joint"}


def _named(nd) -> str:
    """A graph value in words, with its label: "f of the forward pass's node 1 (fwd1.f)"."""
    what = str(nd.key.quantity) if nd.op is Op.INPUT and nd.key is not None else nd.name
    return f"{what or nd.op.value} of {_PASS.get(str(nd.section), str(nd.section))} {nd.group} ({nd.label})"


def _input_bound(chain: Chain, key: InputKey, ranges: Ranges) -> tuple[float, float]:
    """(norm bound, largest scalar) of one host input over the states analysed."""
    if key.quantity is Quantity.A:
        return 1.0, 1.0
    if key.quantity in BASE_QUANTITIES:            # three components within ±1 (PDD0: minus g)
        g = np.asarray(chain.gravity, dtype=float) if key.quantity is Quantity.PDD0 else np.zeros(3)
        return ROOT3 + vector_norm(g), 1.0 + float(np.max(np.abs(g)))
    name = {Quantity.P_STAR: "q", Quantity.S_STAR: "q", Quantity.ZQD: "qd",
            Quantity.ZQDD: "qdd"}[key.quantity]
    ends = []
    for end in ranges.of(chain, key, name):
        state = {n: np.zeros((1, chain.n)) for n in ("q", "qd", "qdd")}
        state[name][0, key.joint - 1] = end
        ends.append(input_value(chain, key, state["q"], state["qd"], state["qdd"]).reshape(-1))
    return (max(vector_norm(v) for v in ends),
            max(float(np.max(np.abs(v))) for v in ends))


# The bound's norms in Python's float arithmetic, in a fixed order: np.linalg.norm's vector norm is
# a BLAS dot and its spectral norm LAPACK's SVD, whose last bits follow the machine's BLAS kernel
# (`vampc precision --format json` gave examples/arm6.urdf's q10.9 bound as 0.3506447868084065
# under OpenBLAS's default kernel here and ...066 under its Core2 one: a helper's sweep, 2026-12-07).


def vector_norm(v) -> float:
    """The Euclidean norm of v: its squares summed exactly (math.fsum) and rounded once, then the
    square root, scaled by a power of two so that no square overflows: the same bits on every
    machine."""
    values = np.asarray(v, dtype=float).reshape(-1).tolist()
    if any(math.isnan(x) for x in values):
        return math.nan
    largest = max((abs(x) for x in values), default=0.0)
    if largest == 0.0 or not math.isfinite(largest):
        return largest
    scale = math.frexp(largest)[1]
    return math.ldexp(math.sqrt(math.fsum(math.ldexp(x, -scale) ** 2 for x in values)), scale)


def spectral_norm(m) -> float:
    """The largest singular value of a 3x3 matrix: the square root of the largest eigenvalue of
    mᵀm (its entries by math.fsum), found by cyclic Jacobi rotations in Python floats (square roots
    and the four operations only, so the same bits on every machine; within a few ulps of LAPACK's
    SVD, and exact for a diagonal matrix)."""
    rows = np.asarray(m, dtype=float).reshape(3, 3).tolist()
    if any(math.isnan(x) for row in rows for x in row):
        return math.nan                      # (max() passes a NaN by: its norm had come out 0.0)
    largest = max(abs(x) for row in rows for x in row)
    if not math.isfinite(largest):
        return math.inf
    if largest == 0.0:
        return 0.0
    scale = math.frexp(largest)[1]            # (by a power of two, exactly: mᵀm cannot overflow)
    rows = [[math.ldexp(x, -scale) for x in row] for row in rows]
    b = [[math.fsum(rows[k][i] * rows[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    return math.ldexp(math.sqrt(max(0.0, max(_jacobi_eigenvalues(b)))), scale)


def _jacobi_eigenvalues(a: list) -> list:
    """The eigenvalues of a symmetric 3x3 matrix (a list of rows, changed in place) by cyclic
    Jacobi rotations (Numerical Recipes' `jacobi`): each rotation zeroes one off-diagonal entry;
    an entry too small to change either diagonal entry it sits between is set to zero after the
    fourth sweep; done when every off-diagonal entry is zero (some ten sweeps at most)."""
    for sweep in range(50):
        if a[0][1] == 0.0 and a[0][2] == 0.0 and a[1][2] == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = a[p][q]
            if apq == 0.0:
                continue
            g = 100.0 * abs(apq)
            if sweep > 3 and abs(a[p][p]) + g == abs(a[p][p]) and abs(a[q][q]) + g == abs(a[q][q]):
                a[p][q] = a[q][p] = 0.0
                continue
            h = a[q][q] - a[p][p]
            if abs(h) + g == abs(h):
                t = apq / h                          # (θ so large that θ² would overflow)
            else:
                theta = 0.5 * h / apq
                t = 1.0 / (abs(theta) + math.sqrt(1.0 + theta * theta))
                if theta < 0.0:
                    t = -t
            c = 1.0 / math.sqrt(1.0 + t * t)
            s = t * c
            tau = s / (1.0 + c)
            h = t * apq
            a[p][p] -= h
            a[q][q] += h
            a[p][q] = a[q][p] = 0.0
            r = 3 - p - q                            # the third index
            arp, arq = a[r][p], a[r][q]
            a[r][p] = a[p][r] = arp - s * (arq + arp * tau)
            a[r][q] = a[q][r] = arq + s * (arp - arq * tau)
    return [a[0][0], a[1][1], a[2][2]]


def integer_bits(peak: float, fraction: int) -> int:
    """The fewest integer bits (the sign included) of a qI.F word holding every magnitude up to
    `peak`: 2^(I-1) - 2^-F >= peak."""
    bits = 1
    while 2.0 ** (bits - 1) - 2.0 ** -fraction < peak:
        bits += 1
    return bits


def fitted(graph: Graph, chain: Chain, bits: int, rounding_mode: Rounding,
           ranges: Ranges) -> tuple[Fixed, Analysis] | None:
    """The qI.F word of `bits` bits with the fewest integer bits nothing can overflow in, and its
    analysis; None when no split of `bits` is wide enough."""
    for integer in range(1, bits + 1):
        word = Fixed(integer, bits - integer, rounding_mode)
        analysis = analyse(graph, chain, word, ranges)
        if not np.isfinite(analysis.peak):            # (no word of any width holds it)
            return None
        if integer_bits(analysis.peak, word.fraction) <= integer:
            return word, analysis
    return None
