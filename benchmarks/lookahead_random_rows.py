"""The window plan with and without holding a step short of a stop (README, vampc lookahead:
"Retiming window by window"), on random affine torque parts: how many plans come out faster,
slower, or find a way through only one way, and that every plan is within its limits.

    python benchmarks/lookahead_random_rows.py [--sets 600] [--seeds 7,11,12]

Each set: n rows (5-39) of a, b, c for 1-3 joints, a and b scaled by 1, 100 or 10 000 (rows that
disagree, as a path whose q̇ and q̈ do not follow its q gives), effort limits 0.5-3, λ of 0.1, 1 or
10 ms, 3-9 rows ahead. Sets whose gravity part alone is over a limit are left out (the command
refuses them). "Without" is the same planner with NEAR_STOP below 0, so that no step is held.
"""
from __future__ import annotations

import argparse

import numpy as np

from vampc import lookahead
from vampc.errors import VampcError
from vampc.lookahead import Limits, window_plan


def plans(seed: int, sets: int):
    rng = np.random.default_rng(seed)
    for _ in range(sets):
        n, joints = int(rng.integers(5, 40)), int(rng.integers(1, 4))
        a = rng.normal(size=(n, joints)) * rng.choice([1, 100, 1e4])
        b = rng.normal(size=(n, joints)) * 3 * rng.choice([1, 100, 1e4])
        c, qd = rng.normal(size=(n, joints)) * 0.3, rng.normal(size=(n, joints))
        limits = Limits(tuple(rng.uniform(0.5, 3, joints)), (None,) * joints)
        lam, ahead = float(rng.choice([1e-4, 1e-3, 1e-2])), int(rng.integers(3, 10))
        if np.any(np.abs(c) > np.array(limits.tau)):
            continue
        yield a, b, c, qd, limits, ahead, lam


def duration(a, b, c, qd, limits, ahead, lam):
    """(the plan's duration or None where it finds no way through, its worst |τ| / limit)."""
    try:
        x, u, t = window_plan(a, b, c, qd, limits, ahead, lam)
    except VampcError:
        return None, 0.0
    worst = 0.0
    for row in (slice(None, -1), slice(1, None)):         # both rows of every interval
        tau = a[row] * u[:-1, None] + b[row] * x[row][:, None] + c[row]
        worst = max(worst, float(np.max(np.abs(tau) / np.array(limits.tau))))
    return float(t[-1]), worst


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sets", type=int, default=600, help="random sets per seed (default 600)")
    parser.add_argument("--seeds", default="7,11,12")
    args = parser.parse_args()
    held = lookahead.NEAR_STOP
    faster = slower = much_faster = only_with = only_without = both = 0
    ratios, worst = [], 0.0
    for seed in (int(s) for s in args.seeds.split(",")):
        for case in plans(seed, args.sets):
            lookahead.NEAR_STOP = held
            with_rule, w = duration(*case)
            lookahead.NEAR_STOP = -1.0                       # (no step held)
            without, _ = duration(*case)
            lookahead.NEAR_STOP = held
            worst = max(worst, w)
            if with_rule is None or without is None:
                only_with += without is None and with_rule is not None
                only_without += with_rule is None and without is not None
                continue
            both += 1
            r = with_rule / without
            ratios.append(r)
            faster += r < 1 - 1e-9
            much_faster += r < 0.1
            slower += r > 1 + 1e-9
    print(f"{both} sets planned both ways: {faster} faster holding steps ({much_faster} more than 10 "
          f"times), {slower} slower (worst {max(ratios):.3g} times); {only_with} find a way through "
          f"only holding, {only_without} only without; worst |τ| / limit {worst:.10g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
