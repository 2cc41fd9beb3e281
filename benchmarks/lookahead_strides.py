"""An experiment kept for the record (README, vampc lookahead): registers at other strides, planned
so that the arm steps only on rows a register has checked, against TOPP-RA and `--retime window`.

    python benchmarks/lookahead_strides.py [--futures 4] [--window 64]

Register r (r = 0 .. R-1) holds every 2^r-th row of the path, M of them from the arm's row on, so R
registers see 2^(R-1) M rows ahead: the path at 2^r times its speed, sampled every λ (the paper's
registers at different scalings side by side). The plan is a reachability pass over a graph of rows:
from each row to the next row of each register. Each step it solves the window backwards (the set of
x = ṡ² at each row from which the arm can still stop at rest within the rows in view) and moves
forwards along the nearest edge whose set holds its speed. A row the arm does not step on is skipped
(the rows of -o would then be a subset of the path's). Two variants:

- `free`: any edge at any speed. The stop-able sets are intervals from 0 (rest is always feasible),
  the plan is feasible on the rows stepped on, and the graph only grows from step to step, so the
  plan never fails. The script then puts every skipped row back at the speed and s̈ the arm passes
  it (x and s̈ of its segment) and counts those over a limit by the reference dynamics.
- `lambda`: an edge of stride d > 1 only where ṡ >= d at both ends, so the rows stepped on are at
  most λ apart in time (the motors get a row every λ, as the paper's). The sets are then unions of
  intervals; the plan keeps, as an inner approximation that still only grows, the interval from 0.

The torques' affine parts (a, b, c) are the reference dynamics' here (the network's equal them to
about 1e-15: README, vampc lookahead); the paths, limits and TOPP-RA's durations are
benchmarks/lookahead_toppra.py's (needs `pip install "vampc[toppra]"`).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lookahead_toppra import RATE, ROBOTS, make_path, toppra_duration  # noqa: E402

from vampc.dynamics.reference import rnea  # noqa: E402
from vampc.lookahead import _bounds, limits_of, violations, window_plan  # noqa: E402


def view(M: int, R: int, rho: int):
    """For the steps i = rho mod 2^(R-1): the offsets from i of the rows in view (every register's)
    and, per offset, the offsets of the next row of each register (the edges), nearest first."""
    regs = [list(range(M))] + [[(-rho) % 2 ** r + 2 ** r * m for m in range(M)] for r in range(1, R)]
    nodes = sorted({o for reg in regs for o in reg})
    return nodes, {o: sorted({min(t for t in reg if t > o) for reg in regs if reg[-1] > o}) for o in nodes}


def x_range(p, r, P, cap, top, D, need):
    """Per row: [lo, hi], the x in [need, cap] with some u within the effort bounds (p + r x <= u <=
    P + r x per joint) and need <= x + D u <= top; lo > hi: none. Lower bounds are affine in x (their
    maximum convex), upper ones too (their minimum concave): the x where every pair is in order."""
    ones = np.ones(p.shape[:-1] + (1,))
    lp = np.concatenate([p, need[:, None] / D * ones], -1)
    up = np.concatenate([P, top[:, None] / D * ones], -1)
    lr = ur = np.concatenate([r, -ones / D], -1)
    gap = (lp[..., :, None] - up[..., None, :]).reshape(len(p), -1)
    slope = (lr[..., :, None] - ur[..., None, :]).reshape(len(p), -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = -gap / slope
    hi = np.minimum(np.min(np.where(slope > 0, root, np.inf), -1), cap)
    lo = np.maximum(np.max(np.where(slope < 0, root, -np.inf), -1), need)
    never = np.any((slope == 0) & (gap > 0), -1)
    return np.where(never, np.inf, lo), np.where(never, -np.inf, hi)


def stride_plan(a, b, c, qd, limits, M: int, R: int, lam: float, variant: str):
    """(rows stepped on, x, u, times) of the module docstring's plan."""
    n = len(a)
    lo, up, cap = _bounds(a, b, c, qd, limits, 1e-9, 2 * lam)
    J = len(limits.tau)          # each row's own bounds: the collocation the planner had then
    p, r, P = lo[0][:, :J], lo[1][:, :J], up[0][:, :J]
    edges = {}                                       # per step i: [(d, lo, hi, top at the target)]
    for rho in range(min(2 ** (R - 1), n)):
        steps = np.arange(rho, n, 2 ** (R - 1))
        nodes, out = view(M, R, rho)
        top = {}
        for o in reversed(nodes):
            valid = steps + o <= n - 1
            jj = np.where(valid, steps + o, 0)
            parts = []
            for t in out[o]:
                d = t - o
                ok = valid & (steps + t <= n - 1)
                need = np.full(len(steps), 0.0 if d == 1 or variant == "free" else float(d * d))
                lo, hi = x_range(p[jj], r[jj], P[jj], cap[jj], top[t], 2.0 * d * lam, need)
                lo, hi = np.where(ok, lo, np.inf), np.where(ok, hi, -np.inf)
                parts.append((lo, hi))
                if o == 0:
                    for k in np.flatnonzero(ok):
                        edges.setdefault(int(steps[k]), []).append((d, lo[k], hi[k], top[t][k], need[k]))
            best = np.zeros(len(steps))              # the interval from 0 of the union
            for _ in parts:
                for lo, hi in parts:
                    best = np.where((lo <= best) & (lo <= hi), np.maximum(best, hi), best)
            top[o] = np.where(valid, best, 0.0)
    i, x, rows, xs, us = 0, 0.0, [0], [0.0], []
    while i < n - 1:
        tol = 1e-12 * max(1.0, x)
        d, _, _, top_t, need = min(e for e in edges[i] if e[1] - tol <= x <= e[2] + tol)
        up = float(np.min(P[i] + r[i] * x))
        nxt = max(need, min(x + 2 * d * lam * up, top_t))
        us.append((nxt - x) / (2 * d * lam))
        i, x = i + d, nxt
        rows.append(i)
        xs.append(x)
    rows, xs, us = np.array(rows), np.array(xs), np.array(us + [0.0])
    root = np.sqrt(xs)
    return rows, xs, us, np.concatenate([[0.0], np.cumsum(2 * lam * np.diff(rows) / (root[:-1] + root[1:]))])


def skipped_over(chain, q, qd, qdd, rows, x, u, lam, L):
    """The rows the plan skips, each at the x and s̈ of its segment: (how many, how many over a
    limit by the reference dynamics, the worst |τ| / limit)."""
    js, xj, uj = [], [], []
    for k in range(len(rows) - 1):
        for m in range(1, rows[k + 1] - rows[k]):
            js.append(rows[k] + m)
            xj.append(x[k] + 2 * m * lam * u[k])
            uj.append(u[k])
    if not js:
        return 0, 0, 0.0
    js, xj, uj = np.array(js), np.maximum(np.array(xj), 0.0)[:, None], np.array(uj)[:, None]
    tau = rnea(chain, q[js], qd[js] * np.sqrt(xj), qdd[js] * xj + qd[js] * uj)
    ratio = np.max(np.abs(tau[:, :len(L)]) / L, axis=1)
    return len(js), int((ratio > 1).sum()), float(ratio.max())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--futures", type=int, default=4)
    parser.add_argument("--window", type=int, default=64)
    args = parser.parse_args()
    from vampc.robot import load_robot
    lam, M, R = 1.0 / RATE, args.window, args.futures
    print(f"| robot | path | TOPP-RA (s) | window R = 1 | variant | strides 1..{2 ** (R - 1)} | rows stepped on | "
          "most time across a skip | violations on them | skipped rows over a limit | worst |τ|/limit there |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, spec in ROBOTS.items():
        chain = load_robot(str(spec["source"]))
        lim = limits_of(chain, str(spec["limits"]) if spec["limits"] else None)
        L = np.array(lim.tau)
        for kind, T in spec["T"].items():
            t, q, qd, qdd = make_path(kind, T, spec["dq"], spec["amp"])
            best = toppra_duration(chain, t, q, L, lim.qd)
            z = np.zeros_like(q)
            c = rnea(chain, q, z, z)
            a, b = rnea(chain, q, z, qd) - c, rnea(chain, q, qd, qdd) - c
            one = window_plan(a, b, c, qd, lim, M, lam)[2][-1]
            for variant in ("free", "lambda"):
                rows, x, u, times = stride_plan(a, b, c, qd, lim, M, R, lam, variant)
                s = np.sqrt(x)[:, None]
                on = violations(rnea(chain, q[rows], qd[rows] * s, qdd[rows] * s ** 2 + qd[rows] * u[:, None]),
                                qd[rows] * s, lim)
                gaps = np.diff(rows) > 1            # the segments with rows skipped
                across = 1e3 * float(np.diff(times)[gaps].max()) if gaps.any() else 0.0
                skipped, over, worst = skipped_over(chain, q, qd, qdd, rows, x, u, lam, L)
                print(f"| {name} | {kind} | {best:.3f} | {100 * (one / best - 1):+.1f}% | {variant} | "
                      f"{100 * (times[-1] / best - 1):+.1f}% | {len(rows)} of {len(q)} | "
                      f"{across:.1f} ms | {len(on)} | {over} of {skipped} | "
                      f"{worst:.3f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
