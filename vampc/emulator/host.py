"""The host driver: trajectories in, port values per set, torques out, and the check against the
reference dynamics.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vampc.dataflow.host import input_value
from vampc.emulator.load import Loaded
from vampc.errors import VampcError, VampcUsageError
from vampc.robot.chain import Chain
from vampc.textio import apart


@dataclass(frozen=True)
class Trajectory:
    """States (count, n) each; `t` the optional time column; `base` a floating base's motions (count, 9):
    ω_0, ω̇_0 and the classical acceleration a_0 of O_0's origin, in O_0."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    t: np.ndarray | None = None
    base: np.ndarray | None = None

    @property
    def count(self) -> int:
        """Number of states."""
        return self.q.shape[0]


def checked_trajectory(chain: Chain, traj, where: str = "emulate") -> Trajectory:
    """`traj` as the network takes it, or VampcError naming what is wrong and where (`where`, the
    state and the column, as a trajectory file's are named): a Trajectory whose q, qd and qdd are
    arrays of states × the chain's joints (real numbers, finite, exactly float64: an integer past
    2**53 is refused rather than rounded), the same number of states in each, at least one; `t`
    one per state; `base` (states × 9) only on a floating-base chain (None there: the base at rest,
    held against gravity). With coupled mimic joints q, qd and qdd may give the independent joints
    only, as a trajectory file does: the followers' states are derived from their leaders'. A
    library caller's arrays had been taken as they came: extra joint columns dropped (another
    robot's trajectory ran), NaN run into NaN torques, a 1-D state an IndexError (a new user's
    find)."""
    from vampc.emulator.trajectory import BASE_COLUMNS, _as_float, _check_finite
    from vampc.robot.mimic import expand, n_free
    if not isinstance(traj, Trajectory):
        raise VampcError(f"{where}: the states must be a vampc.Trajectory(q, qd, qdd, t=None, "
                         f"base=None) of arrays (states × joints), not {type(traj).__name__}")
    n, free = chain.n, n_free(chain)
    joints = None        # the joint columns q gave: n, or the independent joints' `free`
    count = None
    arrays = {}
    for name in ("q", "qd", "qdd", "t", "base"):
        value = getattr(traj, name)
        if value is None and name in ("q", "qd", "qdd"):
            raise VampcError(f"{where}: {name} is missing (None): give an array of states × joints")
        if value is None:
            arrays[name] = None
            continue
        if name == "base" and not chain.floating:
            raise VampcError(f"{where}: base is given but the robot's base is fixed (base applies "
                             "to a floating-base program)")
        arr = np.asarray(value)
        want = 1 if name == "t" else 2
        if name == "base":
            width, what = 9, "9 columns (ω_0, ω̇_0, a_0)"
        else:
            widths = (joints,) if joints is not None else (n, free) if free != n else (n,)
            width = arr.shape[1] if arr.ndim == 2 and arr.shape[1] in widths else widths[0]
            what = (f"{width} columns (the robot's {n} joints" +
                    (f", or its {free} independent ones)" if free != n and joints is None else ")"))
        if arr.ndim != want or (want == 2 and arr.shape[1] != width):
            shape = "(states,)" if name == "t" else f"(states, {width})"
            one = "" if want != 2 or arr.ndim != 1 else f"; (1, {width}) for one state" + (
                f" (or (1, {free}))" if name != "base" and free != n and joints is None else "")
            raise VampcError(f"{where}: {name} has shape {arr.shape}; it must be {shape}: "
                             f"{what if want == 2 else 'one time per state'}{one}")
        if name == "q":
            joints = width
        if count is None:
            count = arr.shape[0]
            if count == 0:
                raise VampcError(f"{where}: no states (q has 0 rows)")
        elif arr.shape[0] != count:
            raise VampcError(f"{where}: {name} has {arr.shape[0]} states where q has {count}")
        columns = ["t"] if name == "t" else BASE_COLUMNS if name == "base" else \
            [f"{name}{j}" for j in range(1, width + 1)]
        out = _as_float(where, arr, name, columns)
        _check_finite(where, out.reshape(count, -1), columns)
        arrays[name] = out
    if joints != n:       # the independent joints: the coupled followers' states derived
        arrays["q"], arrays["qd"], arrays["qdd"] = expand(chain, arrays["q"], arrays["qd"],
                                                          arrays["qdd"])
    if all(arrays[name] is getattr(traj, name) for name in arrays):
        return traj
    return Trajectory(**arrays)


def port_values(ld: Loaded, traj: Trajectory) -> dict[tuple[int, int], np.ndarray]:
    """What the host writes for every set to each (port, entry): (count, 3) or (count, 9), row-major,
    as words of the network's format (vampc.machine.arith: encode)."""
    cache: dict = {}
    out = {}
    for p in ld.net.ports:
        for j, e in enumerate(p.entries):
            if e.key not in cache:
                cache[e.key] = np.ascontiguousarray(ld.arith.encode(host_values(ld, traj, e.key)))
            out[(p.index, j)] = cache[e.key]
    return out


def host_values(ld: Loaded, traj: Trajectory, key) -> np.ndarray:
    """The real values the host converts and writes for input `key`, every set: (count, 3|9)."""
    return input_value(ld.chain, key, traj.q, traj.qd, traj.qdd, traj.base).reshape(traj.count, -1)


def random_trajectory(chain: Chain, count: int, seed: int) -> Trajectory:
    """States drawn within the joint limits (else ±π rad (±0.5 m prismatic), ±1 rad/s, ±1 rad/s²),
    the same as the first `count` states of any longer run with this seed
    (vampc.emulator.driver.random_states). A coupled follower (vampc.robot.mimic) follows its
    leader, whatever its own limits say."""
    import operator

    from vampc.emulator.driver import States, random_states
    try:
        count, seed = operator.index(count), operator.index(seed)
    except TypeError:
        raise VampcError(f"random_trajectory: count and seed must be integers, not "
                         f"{type(count).__name__} and {type(seed).__name__}") from None
    if seed < 0:
        raise VampcError(f"random_trajectory: seed {seed}: give a seed of 0 or more")
    if count < 1:
        raise VampcError(f"random_trajectory: count {count}: give 1 or more states")
    return random_states(chain, 0, States.random(count, seed).count, seed)


def read_trajectory(path: str | Path, chain: Chain, allow_out_of_limits: bool = False) -> Trajectory:
    """A trajectory from CSV (header q1..qn,qd1..qdn,qdd1..qddn, a floating base's 9 columns, optional
    leading t), .npy or .npz. With coupled mimic joints the file gives the independent joints only
    (vampc.robot.mimic), and the followers' states are derived from their leaders'. States outside
    the joint limits (position and speed) are refused, as `--trajectory` refuses them, unless
    `allow_out_of_limits` (`--allow-out-of-limits`: the API's had been run unchecked, a new user's
    find)."""
    from vampc.emulator.trajectory import read
    from vampc.robot.mimic import expand, n_free
    traj = read(path, n_free(chain), chain.floating, chain.n)
    if chain.mimic:
        traj = Trajectory(*expand(chain, traj.q, traj.qd, traj.qdd), traj.t, traj.base)
    if not allow_out_of_limits:
        check_limits(chain, traj, str(path), how="give allow_out_of_limits=True to run anyway")
    return traj


def check_limits(chain: Chain, traj: Trajectory, path: str | None = None, speeds: bool = True,
                 integrated: bool = False, how: str | None = None) -> None:
    """Refuse states outside the joint limits (position, and speed unless `speeds` is off), naming
    the row and joint (a coupled follower's by the leader column it is derived from). `integrated`:
    the states are q̈'s of `path` integrated from --q0 and --qd0 (the first state's position is
    --q0's, the others' come of the integration: a look-ahead audit found --q0's blamed on the file).
    `how`: the way round it, said last (for a file, --allow-out-of-limits). `path` None: states
    made in Python (vampc.check_limits), named by their number."""
    if how is None:
        how = "use --allow-out-of-limits to run anyway" if path is not None else ""
    if path is None:        # a caller's Trajectory: checked as emulate checks one (a list, a NaN or
        #                     too few columns had been an AttributeError, passed or an IndexError)
        traj = checked_trajectory(chain, traj, "check_limits")
    from vampc.emulator.trajectory import state_at
    from vampc.robot.mimic import column_names
    derived = {m.follower - 1: column_names(chain, "q")[m.follower - 1].split(" (")[1].rstrip(")")
               for m in chain.mimic}
    for i, j in enumerate(chain.joints):
        lim = j.limits
        bad = np.zeros(traj.count, bool)
        if lim.q:
            bad |= (traj.q[:, i] < lim.q[0]) | (traj.q[:, i] > lim.q[1])
        if lim.qd is not None and speeds:
            bad |= np.abs(traj.qd[:, i]) > lim.qd
        if bad.any():
            row = int(np.argmax(bad))
            via = f"{derived[i]} and the coupling; " if i in derived else ""   # ('from derived from')
            q, qd = traj.q[row, i], traj.qd[row, i]
            # (which limit is broken, said first: a new user compared the numbers by hand on seven
            # robots, each time a speed limit they had not known --trajectory checks)
            broken = []
            if lim.q and not lim.q[0] <= q <= lim.q[1]:
                side = lim.q[0] if q < lim.q[0] else lim.q[1]
                shown, bound = apart(q, side)
                broken.append(f"position {shown} {'below' if q < side else 'above'} {bound}")
            if lim.qd is not None and speeds and abs(qd) > lim.qd:
                shown, bound = apart(abs(qd), lim.qd)
                broken.append(f"speed |qd| = {shown} beyond {bound}")
            limits = ([f"q in [{lim.q[0]:g}, {lim.q[1]:g}]"] if lim.q else []) + \
                ([f"|qd| <= {lim.qd:g}"] if lim.qd is not None and speeds else [])
            where = ("--q0" if integrated and row == 0 else
                     f"check_limits: state {row + 1}" if path is None else
                     f"{path}: {state_at(path, row)}" + (", integrated from --q0 and --qd0"
                                                        if integrated else ""))
            raise VampcError(f"{where}: joint {i + 1} ({j.name}) is outside "
                             f"its limits: {' and '.join(broken)} ({via}limits {', '.join(limits)})"
                             + (f"; {how}" if how else ""))


def check_word_range(word, traj: Trajectory, path: str, chain: Chain | None = None,
                     what: str = "", keys=()) -> None:
    """Refuse a state a fixed-point word cannot hold (a q̇, q̈ or base motion beyond the word's
    range: the host writes them as they are; and of the host's inputs `keys`, those it works out of
    a state that a state can take beyond any word: a prismatic joint's p* and s*, a floating base's
    p̈_0), naming the row and column (and `what` row it is: " as retimed" for the look-ahead's)."""
    from vampc.emulator.trajectory import header, state_at
    if not hasattr(word, "beyond"):                  # float words: nothing to refuse
        return
    top = word.top
    n = traj.q.shape[1]
    columns = [traj.qd, traj.qdd] + ([traj.base] if traj.base is not None else [])
    names = header(n, traj.base is not None)[n:]
    if chain is not None and chain.mimic:       # the file has the independent joints only
        from vampc.robot.mimic import column_names
        names = column_names(chain, "qd") + column_names(chain, "qdd") + names[2 * n:]
    values = np.concatenate(columns, axis=1)
    bad = word.beyond(values)                        # as the host's conversion rounds them
    said = ("give --overflow saturate or --overflow wrap to run it anyway (each overflow "
            "counted)")
    if bad.any():
        row, col = (int(x) for x in np.argwhere(bad)[0])
        where = f"row {row + 1}{what}" if what else state_at(path, row)
        raise VampcError(f"{path}: {where}, column {names[col]}: {values[row, col]:.12g} is "
                         f"beyond {word.name} words, which hold [{-top:g}, {top:g}); {said}")
    # what the host works out of the state and writes too: a prismatic joint's p*_i and s*_i from
    # its q (a slide's q = 150 within its limits ran in q8.8, its overflows counted, exit 0: an
    # audit's), a floating base's p̈_0 = a_0 − g
    from vampc.dataflow.host import input_value
    from vampc.kinds import Quantity
    derived = sorted((k for k in keys if k.quantity in (Quantity.P_STAR, Quantity.S_STAR,
                                                        Quantity.PDD0)),
                     key=lambda k: (k.joint, k.quantity.value))
    q_names = header(n, traj.base is not None)[:n]
    if chain is not None and chain.mimic:
        from vampc.robot.mimic import column_names
        q_names = column_names(chain, "q")
    for key in derived:
        value = input_value(chain, key, traj.q, traj.qd, traj.qdd, traj.base).reshape(traj.count, -1)
        bad = word.beyond(value).any(axis=1)
        if bad.any():
            row = int(np.argmax(bad))
            where = f"row {row + 1}{what}" if what else state_at(path, row)
            shown = ", ".join(f"{x:.12g}" for x in value[row])
            if key.quantity is Quantity.PDD0:
                column = "base_ax..base_az"
                given = ", ".join(f"{x:.12g}" for x in traj.base[row, 6:9])
                why = f"[{given}] gives p̈_0 = a_0 − g = [{shown}] (the host's input for the base)"
            else:
                column = q_names[key.joint - 1]
                name = "p*" if key.quantity is Quantity.P_STAR else "s*"
                why = (f"{traj.q[row, key.joint - 1]:.12g} gives {name}_{key.joint} = [{shown}] "
                       f"(the host's input for prismatic joint {key.joint})")
            raise VampcError(f"{path}: {where}, column {column}: {why}, beyond {word.name} words, "
                             f"which hold [{-top:g}, {top:g}); {said}")


# The least |τ| (N·m, or N) a torque's error is measured against: below it the relative error of a
# check is the error over this (README, Word formats: --check).
CHECK_FLOOR = 1e-12


@dataclass(frozen=True)
class CheckResult:
    """Worst errors of emulated torques against the reference."""

    max_abs: float
    max_rel: float
    worst_row: int
    ok: bool
    floored: int = 0        # sets whose largest |τ| is below CHECK_FLOOR (measured against it)


@dataclass(frozen=True)
class WordCheck:
    """Torques computed in a word format narrower than float64 against the float64 reference, per
    column of the torque file (with coupled mimic joints, the independent joints':
    vampc.robot.mimic.reduce_torques) over a whole run: the largest |error|, the largest |τ| of the reference
    (the scale of the relative error), the sum of the squared errors each over the largest squared
    (so it cannot overflow: errors of 7e300, each finite, had an RMS of inf beside them), and the
    sets compared."""

    max_abs: np.ndarray
    max_ref: np.ndarray
    sq_scaled: np.ndarray
    count: int

    @property
    def rel(self) -> np.ndarray:
        """Per joint: the largest error relative to that joint's largest |τ| over the run."""
        with np.errstate(invalid="ignore", over="ignore"):     # (a reference not finite: nan, said)
            return self.max_abs / np.maximum(self.max_ref, CHECK_FLOOR)

    @property
    def scale(self) -> float:
        """The yardstick of `overall`: the largest |τ| of any joint over the run (floored)."""
        return max(float(self.max_ref.max(initial=0.0)), CHECK_FLOOR)

    @property
    def overall(self) -> float:
        """The largest error of any joint relative to the largest |τ| of any joint over the run
        (what --check's tolerance bounds: a joint that barely moves is not its own yardstick)."""
        with np.errstate(invalid="ignore", over="ignore"):     # (a reference not finite: nan, said)
            return float(self.max_abs.max(initial=0.0) / self.scale)

    @property
    def rms(self) -> np.ndarray:
        """Per joint: the root-mean-square error."""
        return self.max_abs * np.sqrt(self.sq_scaled / max(self.count, 1))

    def merged(self, other: WordCheck | None) -> WordCheck:
        """The check over both runs (chunks) of sets."""
        if other is None:
            return self
        top = np.maximum(self.max_abs, other.max_abs)
        return WordCheck(top, np.maximum(self.max_ref, other.max_ref),
                         _rescaled(self.sq_scaled, self.max_abs, top)
                         + _rescaled(other.sq_scaled, other.max_abs, top), self.count + other.count)


def _rescaled(sq_scaled: np.ndarray, scale: np.ndarray, top: np.ndarray) -> np.ndarray:
    """Squares over scale² as squares over top² (top ≥ scale)."""
    return sq_scaled * _over(scale, top) ** 2


def _over(x: np.ndarray, top: np.ndarray) -> np.ndarray:
    """x / top, 0 where top is 0 (a joint without error)."""
    with np.errstate(invalid="ignore", divide="ignore"):     # (an infinite error: said elsewhere)
        return np.where(top > 0, x / np.where(top > 0, top, 1.0), 0.0)


def word_check(chain: Chain, traj: Trajectory, tau: np.ndarray) -> WordCheck:
    """The errors of torques `tau` against the float64 reference RNEA, per column of the torque file
    (with coupled mimic joints, the independent joints' generalized forces, a leader's with its
    followers' torques times their multipliers: vampc.robot.mimic.reduce_torques)."""
    from vampc.dynamics.reference import rnea
    from vampc.robot.mimic import reduce_torques
    ref = reduce_torques(chain, rnea(chain, traj.q, traj.qd, traj.qdd, traj.base))
    err = np.abs(reduce_torques(chain, tau) - ref)
    top = err.max(axis=0, initial=0.0)
    return WordCheck(top, np.abs(ref).max(axis=0, initial=0.0), (_over(err, top) ** 2).sum(axis=0),
                     len(tau))


def check_torques(chain: Chain, traj: Trajectory, tau: np.ndarray, tol: float = 1e-9) -> CheckResult:
    """Compare with the reference RNEA; relative error per set against that set's largest |τ| (the base
    wrench's components included). `tol` is float64's: a program in another word format errs by
    its rounding, so give its own, `ld.arith.check_tolerance` (what `vampc emulate --check` takes:
    README, Word formats). `tau`: states × outputs, as `emulate` returns it. A `tol` that is not
    above 0 and below 1 is refused as `--tolerance` refuses it (VampcUsageError: 0, NaN or -1 had
    failed every check and 2 passed any torque of the right size, unsaid: a new user's find)."""
    from vampc.dynamics.reference import rnea
    from vampc.options import check_tolerance
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)):
        raise VampcUsageError(f"check_torques: tol {tol!r}: give a number above 0 and below 1")
    check_tolerance(float(tol), "check_torques: tol", cli=False)
    traj = checked_trajectory(chain, traj, "check_torques")
    ref = rnea(chain, traj.q, traj.qd, traj.qdd, traj.base)
    tau = np.asarray(tau)
    if tau.shape != ref.shape:
        raise VampcError(f"check_torques: tau has shape {tau.shape}; the states' reference "
                         f"torques have {ref.shape} (states × outputs)")
    err = np.abs(tau - ref)
    top = np.max(np.abs(ref), axis=1, keepdims=True)
    scale = np.maximum(top, CHECK_FLOOR)
    rel = err / scale
    if chain.mimic:      # and the torque file's columns, each set against their own largest |τ|
        from vampc.robot.mimic import reduce_torques
        given, want = reduce_torques(chain, tau), reduce_torques(chain, ref)
        apart = np.abs(given - want)
        err = np.hstack([err, apart])
        rel = np.hstack([rel, apart / np.maximum(np.max(np.abs(want), axis=1, keepdims=True),
                                                 CHECK_FLOOR)])
    worst = int(np.argmax(np.max(rel, axis=1))) if len(rel) else 0
    max_rel = float(rel.max()) if rel.size else 0.0
    return CheckResult(float(err.max()) if err.size else 0.0, max_rel, worst,
                       bool(max_rel <= tol and np.all(np.isfinite(tau))),
                       int(np.count_nonzero(top < CHECK_FLOOR)))


def floor_clause(check, noun: str = "set") -> str:
    """What a check's verdict line says when torques were below CHECK_FLOOR, the least their errors
    are measured against (a CheckResult's sets, a WordCheck's run), else nothing (every torque of
    1e-300 N·m written 0 in q16.16 had passed unexplained: an audit's find)."""
    if isinstance(check, WordCheck):
        top = float(check.max_ref.max(initial=0.0))
        return (f" (every torque is below {CHECK_FLOOR:g} N·m, the least the error is measured "
                f"against: its largest |τ| is {top:.1e})" if top < CHECK_FLOOR else "")
    k = check.floored
    return (f" ({k} {noun}{'' if k == 1 else 's'} whose every torque is below {CHECK_FLOOR:g} N·m, "
            "the least the error is measured against)" if k else "")
