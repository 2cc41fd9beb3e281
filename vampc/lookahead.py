"""Trajectory look-ahead (section VIII): the torque shift register, limits seen before the arm gets
there, and Hollerbach's uniform time scaling (`vampc lookahead`).

The register has `window` rows. Each row holds one set of inputs (q, q̇, q̈ at time jλ, λ = 1/rate)
wired through the compiled network to its torques. Before motion starts the host fills it with rows
0..window-1; every λ the bottom row goes to the motors and the host writes the next row at the top,
so row r (from 0; the output counts from 1) enters the register at step max(0, r - window + 1) and
is seen min(r, window - 1) steps before it reaches the motors. The network computes every row's
torques as `vampc emulate` does (the stream engine, the same bits). With a clock (`--clock`) the
command says whether the network keeps up: one new row per λ, and with `--retime uniform` its
gravity pass too, against one set per interval of the program.

Limits are the robot's (a URDF's `<limit effort velocity>`, a DH table's `limits`) or a `--limits`
file; a violation is reported with the step at which its row entered and how far ahead that was.

`--retime uniform` (Hollerbach): scaling time by k (t' = k t, q̇' = q̇ / k, q̈' = q̈ / k²) gives
τ' = τ_g + (τ - τ_g) / k², where τ_g is the torque at (q, 0, 0), which the network computes in a
second, gravity-only pass. The smallest k keeping every row within |τ'| <= L and |q̇'| <= q̇_max is

    k² = max(1, max over rows and joints of  d / (L - g)  for d > 0,  -d / (L + g)  for d < 0,
                                             (q̇ / q̇_max)²),     d = τ - τ_g, g = τ_g,

taken over the whole path (a uniform scaling is one k, so the host needs the whole path before motion
starts). Where |τ_g| > L no scaling helps, and the command says so. The k used is the closed form on
limits PLAN_MARGIN tighter (and by the word's error: `word_error`), times (1 + 1e-12), so rounding
never puts a torque over its limit, however close to it gravity comes (1e-12 of k alone did not:
τ_g within rounding of L put τ' over it).

`--retime window` (`window_plan`): the scaling varies along the path, decided row by row from what is
in the register. The path's rows are its samples s_j (spacing Δ = λ of the path as given, q' = q̇,
q'' = q̈ there); the retimed path runs them at speed ṡ, x = ṡ², with s̈ = u constant between two rows
(x_{j+1} = x_j + 2Δ u_j). Its row j is (q_j, q'_j ṡ_j, q''_j x_j + q'_j u_j), and its torque is affine
in (u, x):  τ_j = a_j u + b_j x + c_j. The network gives a, b and c from three passes over each row
as it enters: the row as given (b + c), the gravity pass (q, 0, 0) (c) and the tangent pass
(q, 0, q') (a + c); every other scaling is interpolated exactly between these three. Each λ the host
then solves the window as TOPP-RA solves a whole path: backwards from the last row it sees, the largest
x at each row from which the arm can still stop (x = 0) at that last row within every effort and speed
limit, then forwards one row: the largest x reachable within the limits and inside that set. The plan
is recursively feasible (a row the arm can stop at, it can also rest at, since gravity alone is
within the limits), so no row goes over a limit; the limits used are 1e-9 tighter so rounding cannot
either (a narrower word than float64: each limit tighter by the error its --check allows, `word_error`,
for both retimings; and since a and b, differences of two passes, carry twice that error, which s̈
and ṡ² multiply, the plan keeps every limit for every a and b that far from the network's:
`_spread`; in float64 by FLOAT64_SPREAD of a row's largest torque). The retimed path starts and ends at rest (ṡ = 0, as TOPP-RA's defaults) and its velocity is
continuous (x is); ṡ is at most MAX_SPEED (where the path stands still nothing else bounds it).
Each interval's s̈ is kept within the limits at both its rows (`_bounds`: TOPP-RA's interpolation
discretization): s̈ jumps at a row, and the torque both with the s̈ leaving it (the written q̈) and
with the s̈ arriving at it (`arriving`, which --check checks too) is within them.
`--futures R` chains R registers of `window` rows end to end, so the host sees
R·window rows ahead: each row is still computed once, as it enters (three passes), and R costs
R·window rows of register and the longer backward pass on the host. The rows of the retimed path come
at their new times (the `t` column), not at λ: a row interval shorter than λ needs the network to
keep up with it, which `--clock` checks.
The summary also gives the plan with the whole path in view (`optimal_plan`: the same recursion in
one backward pass, the time-optimal scaling on these rows where no step is held short of its top
(`_short_of_a_cliff`; the summary says so where one is), so what the look-ahead costs is said.

`--retime envelope` (`envelope_plan`): the paper's "several such shift registers ... exploring in
parallel possible futures". `--futures R` registers of `window` rows side by side hold the rows the
host sees as R candidate futures run them (`candidates`: each leaves the arm's row with its own s̈,
then slows at one constant s̈ to rest at the register's last row); the network computes every row
of each (with the s̈ leaving it and, where that changes, the s̈ arriving at it: `candidate_rows`),
and the host takes the fastest candidate it finds within the limits, or keeps the plan taken before
(which stops within the rows it saw) where none is. No torque is interpolated: every row the arm
runs is one the network computed, so a narrower word's error is not multiplied by s̈ or ṡ² (the
window retiming's `_spread`). R costs R (window - 1) rows and more per row of the path, counted in
the summary and held to --clock.

`--accelerations`: q and q̇ integrated from a q̈ profile (`integrate`), each q̈ held for one λ.
`--plot`: per joint, torque over time against its limit, before and after the retiming, and the speed
ṡ over time (`plot_svg`).
Not built yet (issue "Trajectory look-ahead"): a floating base.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from vampc.errors import VampcError, VampcUsageError

K_MARGIN = 1e-12
FLOAT64_SPREAD = 4e-15    # a float64 pass's rounding, of a row's largest torque (`_spread`)


@dataclass(frozen=True)
class Limits:
    """Per joint: the effort limit L (None: none) and the speed limit (None: none)."""

    tau: tuple
    qd: tuple


@dataclass
class Violation:
    row: int
    joint: int
    value: float
    limit: float
    kind: str            # "torque" or "speed"


@dataclass
class Lookahead:
    """What a look-ahead run found: torques of every row, violations, and the retiming."""

    tau: np.ndarray
    violations: list = field(default_factory=list)
    k: float | None = None
    k_closed_form: float | None = None
    k_faster: float | None = None       # the closed form without its max(1, ...), where below 1
    retimed_tau: np.ndarray | None = None
    retimed_violations: list = field(default_factory=list)
    arriving_violations: list = field(default_factory=list)   # window: effort, with the s̈ arriving
    retimed: object = None            # the retimed Trajectory (q, q̇, q̈)
    retimed_t: np.ndarray | None = None   # its row times, from 0
    speed: np.ndarray | None = None   # ṡ at each row
    accel: np.ndarray | None = None   # --retime window: s̈ of the interval leaving each row
    futures: int = 1
    ahead_rows: int = 0               # rows the host sees with --retime window
    word_tolerance: float = 0.0       # the error the network's word may make, of the largest |τ|
    word_error: float = 0.0           # that error, as a torque: of the largest effort limit
    optimal_duration: float | None = None   # --retime window: the plan with the whole path in view
    optimal_held: int = 0                   # its steps held short of their top (_short_of_a_cliff)
    effort: np.ndarray | None = None          # the motors' torques (Gᵀτ: `tau` unless coupled mimics)
    retimed_effort: np.ndarray | None = None  # the same, retimed
    arriving_effort: np.ndarray | None = None  # window, envelope: the same with the s̈ arriving at each row
    retime: str | None = None                 # "uniform", "window" or "envelope"
    envelope: object = None                   # --retime envelope: what each step did (Envelope)

    def new_times(self, times: np.ndarray) -> np.ndarray:
        """The retimed rows' times, from the path's first time (`times`: the rows' as given):
        uniform t' = t0 + k (t - t0); window t0 + the planned times."""
        if self.k is not None:
            return times[0] + (times - times[0]) * self.k
        return times[0] + self.retimed_t

    def planned(self, limits: Limits) -> Limits:
        """The effort limits a retiming plans to: `word_error` inside each, and PLAN_MARGIN (of each)
        more for rounding."""
        return tightened(Limits(tuple(t - self.word_error for t in limits.tau), limits.qd), PLAN_MARGIN)


def limits_of(chain, path: str | None, source: str | None = None, locked=()) -> Limits:
    """The robot's limits, or those of a --limits CSV file (header joint,tau,qd; a joint's row may
    leave qd empty). Every joint with a motor needs an effort limit (VampcError naming the first that
    lacks one, and the file it was looked for in: --limits FILE, else `source`, the robot or program
    file the command was given). Effort limits are per motor: with coupled mimic joints (`--mimic
    couple`) a follower has none, its leader's motor drives both (vampc.robot.mimic: Gᵀτ), so
    `Limits.tau` holds the independent joints' (a follower's is not used); speed limits are per
    joint, followers included. `locked`: joints --lock took out of the robot (a row naming one is
    passed over with a warning)."""
    from vampc.robot.mimic import free_joints
    from vampc.sniff import is_program
    tau = [j.limits.tau for j in chain.joints]
    qd = [j.limits.qd for j in chain.joints]
    given: set = set()               # (joint, "effort" or "speed") the --limits file gave
    lines: dict[int, int] = {}       # joint -> the line of the --limits file naming it
    if path is not None:
        tau, qd, given, lines = _read_limits(path, chain, tau, qd, tuple(locked),
                                             source is not None and is_program(source))
    free = set(free_joints(chain).tolist())
    unused = [chain.joints[i].name for i, what in sorted(given) if what == "effort" and i not in free]
    if unused:                        # a value the file gives is never dropped without a word
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(f"{path}: joint '{unused[0]}' follows another (--mimic couple) and "
                                   "has no motor: its effort limit is not used (its leader's motor "
                                   "carries its torque, bounded by the leader's limit)"), stacklevel=2)
    motors = sorted(free)              # (a follower has no motor, and needs no effort limit)
    missing = [i for i in motors if tau[i] is None]
    if missing:
        where = path or source or chain.source or chain.name
        from vampc.robot.urdf_tree import quoted

        # (every joint is named, up to 10: "joint 'j1' has no effort limit (and 4 more)" left a
        # user of a 32-joint robot guessing which: a new user's find); the line of each that has
        # a row, which the first alone had been, for all (a review's find)
        rows = [lines.get(i) for i in missing]
        if len(missing) == 1:
            said = f"joint '{chain.joints[missing[0]].name}' has no effort limit"
        else:
            said = f"joints {quoted(chain.joints[i].name for i in missing)} have no effort limit"
        if len(missing) == 1 and rows[0]:
            said = f"line {rows[0]}: {said}; give its tau in this row"
        elif any(rows):
            at = ", ".join(f"'{chain.joints[i].name}' line {r}" for i, r in zip(missing, rows) if r)
            said += f"; give each its tau in its row ({at})" + (
                "" if all(rows) else ", or a row joint,tau[,qd] for the others")
        else:
            said += ("; give it a row joint,tau[,qd] in this file" if path is not None else
                     "; give --limits FILE (README, vampc lookahead)")
        raise VampcError(f"{where}: {said}")
    robot = source or chain.source or chain.name
    for i, (j, t, v) in enumerate(zip(chain.joints, tau, qd)):
        for what, x in (("effort", t if i in free else None), ("speed", v)):
            if x is not None and x < SMALLEST_LIMIT:
                came = path if (i, what) in given else robot      # the file the value came from
                # (a DH table's `tau: 0` was told of time scaling on a run without --retime, and
                # not where in the table it stands: a new user's find)
                ours = (i, what) not in given
                from pathlib import Path

                from vampc.robot import JSON_SUFFIXES, YAML_SUFFIXES
                table = ours and Path(str(came)).suffix.lower() in YAML_SUFFIXES + JSON_SUFFIXES \
                    and not is_program(came)        # (a program named prog.json has no such field)
                field = f" (its limits.{'tau' if what == 'effort' else 'qd'})" if table else ""
                raise VampcError(f"{came}: joint '{j.name}': {what} limit {x:g}{field} is below "
                                 f"{SMALLEST_LIMIT:g}: too small to measure "
                                 f"{'torques' if what == 'effort' else 'speeds'} against or to scale "
                                 "time by (their ratios would not fit a float)"
                                 + ("; give the joint's limit in --limits FILE" if ours else ""))
    return Limits(tuple(float(tau[i]) for i in motors),
                  tuple(None if v is None else float(v) for v in qd))


# The smallest effort or speed limit taken: the scalings are ratios of torques or speeds to their
# limits (squared for the uniform k), and a limit of 1e-300 made k infinite.
SMALLEST_LIMIT = 1e-12


def _read_limits(path: str, chain, tau: list, qd: list, locked: tuple = (), program: bool = False):
    import csv
    import io

    from vampc.emulator.trajectory import cell_number
    from vampc.textio import decode_utf8, shown
    names = {j.name: i for i, j in enumerate(chain.joints)}
    left_out = set(chain.left_out)
    # a cell names a joint as written, or with the spaces round it dropped (a CSV writer pads
    # cells): the joint whose name is that once its own spaces round it are dropped, if only one is
    padded: dict[str, list[str]] = {}
    for j in chain.joints:
        padded.setdefault(j.name.strip(), []).append(j.name)
    try:
        from vampc.textio import read_whole, stdin_hint
        raw = read_whole(path, text=True)
    except OSError as exc:
        raise VampcError(f"{path}: cannot read limits: {exc.strerror or exc}"
                         f"{stdin_hint(path, exc)}") from None
    text = decode_utf8(raw, path, "limits file")     # (a spreadsheet's BOM dropped)
    reader = csv.reader(io.StringIO(text, newline=""))
    try:
        rows = list(reader)
    except csv.Error as exc:
        raise VampcError(f"{path}: line {reader.line_num}: not CSV: {exc}") from None
    head = [c.strip() for c in rows[0]] if rows else []
    while head and not head[-1]:
        head.pop()                    # (a spreadsheet's trailing empty cells, as a row's are taken)
    if head not in (["joint", "tau"], ["joint", "tau", "qd"]):
        # (what the file seems to be, as a trajectory's header says: a new user's torque file)
        seems = ("; the file looks like torques (vampc emulate's output), not limits"
                 if any(c.startswith("tau_") for c in head) else
                 "; the file looks like a trajectory, not limits" if "q1" in head else "")
        raise VampcError(f"{path}: line 1: expected the header joint,tau,qd{seems}")
    tau, qd, given = list(tau), list(qd), set()
    seen: dict[str, int] = {}
    for line, row in enumerate(rows[1:], 2):
        if not row or not any(c.strip() for c in row):
            continue
        name = row[0] if row[0] in names else row[0].strip()
        if name not in names and (row[0] in locked or name in locked):
            import warnings

            from vampc.errors import VampcWarning
            warnings.warn(VampcWarning(f"{path}: line {line}: joint {shown(name)} is locked (--lock): "
                                       "its limits are not used"), stacklevel=3)
            continue
        if name not in names and (row[0] in left_out or name in left_out):
            # (a limits file for the whole robot, used with a sub-chain or naming a fixed joint:
            # "no joint named", and another arm's joint suggested, a new user's find)
            import warnings

            from vampc.errors import VampcWarning
            warnings.warn(VampcWarning(
                f"{path}: line {line}: joint {shown(row[0] if row[0] in left_out else name)} of the "
                "robot file is not one of the joints compiled (a fixed joint, one the base, the tip or "
                "a locked joint leaves out, or one an MJCF equality holds): its limits are not used"),
                stacklevel=3)
            continue
        if name not in names:
            matches = padded.get(name, [])
            if len(matches) != 1:
                from vampc.textio import did_you_mean
                # (a program compiled before robot.left_out was written does not say which of
                # its robot file's joints it leaves out: a review's find)
                older = "" if matches or left_out or not program or not str(
                    chain.source).lower().endswith((".urdf", ".xml")) else (
                    "; if the program was compiled before 2026-12-06, which did not record the "
                    "joints its robot file leaves out, recompile it")
                raise VampcError(f"{path}: line {line}: no joint named {shown(name)}"
                                 + (f" (joints {', '.join(map(shown, matches))} differ only in "
                                    "spaces round their names: write the name as the robot "
                                    "file does, in quotes)" if matches else did_you_mean(name, names))
                                 + older)
            name = matches[0]
        if name in seen:
            raise VampcError(f"{path}: line {line}: joint '{name}' again (line {seen[name]} gave "
                             "its limits)")
        seen[name] = line
        if any(c.strip() for c in row[len(head):]):
            raise VampcError(f"{path}: line {line}: {len(row)} cells; expected {','.join(head)}")
        values = []
        for k, cell in enumerate(row[1:3]):
            cell = cell.strip()
            try:
                x = cell_number(cell) if cell else None
            except ValueError:
                x = -1.0
            if x is not None and not (np.isfinite(x) and x > 0):
                what = "a finite number" if x is not None and not np.isfinite(x) else "a positive number"
                raise VampcError(f"{path}: line {line}: {'tau' if k == 0 else 'qd'} {cell!r} is not "
                                 f"{what}")
            values.append(x)
        values += [None] * (2 - len(values))
        if values[0] is not None:
            tau[names[name]] = values[0]
            given.add((names[name], "effort"))
        if values[1] is not None:
            i = names[name]
            own = qd[i]
            # (a robot's own qd of 0, which its file cannot be run with and the refusal of which
            # says to give it here, divided by zero: exit 3, a new user's find)
            if own is not None and own > 0 and chain.joints[i].sigma != 0 and \
                    abs(values[1] / own - DEGREES) < 0.005 * DEGREES:
                import warnings

                from vampc.errors import VampcWarning
                # (a new user's deg/s limits took 57 times the arm's speed, violations unsaid)
                warnings.warn(VampcWarning(
                    f"{path}: line {line}: joint '{name}': qd {values[1]:g} is 180/π times the "
                    f"robot's own speed limit {own:g} rad/s: degrees per second? (qd is in rad/s)"),
                    stacklevel=3)
            qd[i] = values[1]
            given.add((i, "speed"))
    return tau, qd, given, {names[name]: line for name, line in seen.items()}


DEGREES = 180 / np.pi       # a speed limit this many times the robot's own: written in deg/s?


def integrate(qdd: np.ndarray, q0: np.ndarray, qd0: np.ndarray, rate: float):
    """q and q̇ from a q̈ profile, each q̈_j held for one step λ (exact for that profile):
    q̇_{j+1} = q̇_j + λ q̈_j,  q_{j+1} = q_j + λ q̇_j + λ²/2 q̈_j. Position and velocity are
    continuous (no step can come out: |q_{j+1} - q_j| <= λ |q̇_j| + λ²/2 |q̈_j|)."""
    lam = 1.0 / rate
    prev = np.vstack([np.zeros((1, qdd.shape[1])), qdd[:-1]])        # q̈_0 .. q̈_{j-1}
    qd = qd0 + lam * np.cumsum(prev, axis=0)
    step = lam * np.vstack([np.zeros((1, qdd.shape[1])), qd[:-1]]) + 0.5 * lam ** 2 * prev
    return q0 + np.cumsum(step, axis=0), qd


def read_accelerations(path: str, n: int, rate: float, q0, qd0, of: int | None = None):
    """A q̈ CSV (header qdd1..qddn, optional leading t) integrated into a Trajectory (VampcError
    naming the line and column): read as a trajectory is (vampc.emulator.trajectory.read_table)."""
    from pathlib import Path

    from vampc.emulator.host import Trajectory
    from vampc.emulator.trajectory import _check_finite, program_joints, read_table
    columns = [f"qdd{i}" for i in range(1, n + 1)]
    try:
        qdd, t = read_table(Path(path), columns, program_joints(n, of), what="acceleration table")
    except OSError as exc:
        raise VampcError(f"{path}: cannot read accelerations: {exc.strerror or exc}") from None
    except VampcError as exc:
        if "is 'q1'" in str(exc) or "is 'qd1'" in str(exc):     # a whole trajectory's header
            raise VampcError(f"{exc}; a path of q, qd and qdd is given as --trajectory") from None
        raise
    _check_finite(path, qdd, columns, 2, t)
    with np.errstate(over="ignore", invalid="ignore"):      # (said below, once, naming the place)
        q, qd = integrate(qdd, q0, qd0, rate)
    for name, values in (("qd", qd), ("q", q)):
        bad = np.argwhere(~np.isfinite(values))
        if bad.size:
            r, j = (int(v) for v in bad[0])
            raise VampcError(f"{path}: row {r + 1}: integrating the accelerations from --q0 and --qd0, "
                             f"{name}{j + 1} overflows (it is {values[r, j]}): no path the arm can "
                             "follow")
    return Trajectory(q, qd, qdd, t, None)


def check_path(traj, rate: float, path: str) -> np.ndarray:
    """The row times: the file's t column (strictly increasing, every step 1/rate to 1e-9 and the
    times' own rounding), or j/rate."""
    lam = 1.0 / rate
    if traj.t is None:
        _check_rate_against_speeds(traj, lam, rate, path)
        return np.arange(traj.count) * lam
    from vampc.emulator.trajectory import state_at
    t = traj.t
    steps = np.diff(t)
    bad = np.flatnonzero(~(steps > 0))
    if bad.size:
        raise VampcError(f"{path}: {state_at(path, bad[0] + 1)}: t = {float(t[bad[0] + 1])!r} does not come after "
                         f"{float(t[bad[0]])!r} (not a path: time must increase)")
    # 1e-9, and the rounding of the times themselves: Unix timestamps (t = 1.7e9 s) hold a
    # millisecond step only to 2.4e-7 s, and were refused as "t steps by 0.00099992752"
    slack = 1e-9 * max(lam, 1.0) + 4 * np.finfo(float).eps * np.maximum(np.abs(t[1:]), np.abs(t[:-1]))
    off = np.flatnonzero(np.abs(steps - lam) > slack)
    if off.size:
        step = float(steps[off[0]])
        # the right rate, times written short: a step within 0.1% of 1/rate, or every time the
        # grid 1/rate apart rounded to some number of decimals (3 kHz times of 4 or 5 decimals
        # step by 0.0003 and 0.0004, 0.00033 and 0.00034, and were told only that the rate was
        # wrong: a new user's; not a late or missing row: a review's)
        grid = t[0] + np.arange(traj.count) * lam
        # (every step within 0.1%: the first alone took a drift from 1 ms to 1.05 ms for rounding)
        rounded = bool(np.all(np.abs(steps - lam) <= 1e-3 * lam)) or any(
            np.allclose(t, np.round(grid, d), rtol=0, atol=float(slack.max())) for d in range(1, 10))
        # (rows evenly apart at another step: the rate given is off, not the times; the rounding
        # hint had been given of --rate 999.9Hz beside exact times, a look-ahead audit's find)
        even = float(np.ptp(steps)) <= 2 * float(slack.max())
        if even or rounded:
            hint = ("; give the rate the rows were sampled at"
                    + (f" (every step is {step!r}: {1.0 / step:.9g} Hz)" if even else
                       " (times rounded to fewer digits, or held as float32, are off by their "
                       "rounding: write them in full, or leave the t column out, and the rows are "
                       "1/rate apart)"))
        else:       # (no rate fits rows unevenly apart, a retimed path's -o: a new user read one
            #         back and was told to give the rate the rows were sampled at)
            hint = (f"; no rate fits these rows: their steps run from {float(steps.min()):.6g} to "
                    f"{float(steps.max()):.6g} s, and the register takes one row every λ (a row "
                    "late or missing, or rows at other times, as a retimed path's -o has them: "
                    "resample the path at one rate)")
        raise VampcError(f"{path}: {state_at(path, off[0] + 1)}: t steps by {step!r}, not 1/rate = "
                         f"{lam!r}{hint}")
    return t


def _check_rate_against_speeds(traj, lam: float, rate: float, path: str) -> None:
    """A path without a t column: a warning where its positions move other than its velocities say
    at this rate (the trapezoid rule, over all rows and joints), by more than a quarter: a 1 kHz
    path run at --rate 2kHz was planned for half the speed the arm would go, without a word (a new
    user's run)."""
    if traj.count < 3:
        return
    ratio = _speed_ratio(traj, lam)
    if ratio is not None and not 0.8 <= ratio <= 1.25:
        import warnings

        from vampc.errors import VampcWarning
        with np.errstate(over="ignore", divide="ignore"):
            fits = rate / ratio if ratio > 0 else np.inf
        advice = (f"(about {fits:.4g} Hz would fit them)" if np.isfinite(fits) else
                  "(no rate would fit them: its positions and velocities are not of one motion)")
        advice += _t_like(traj, path)
        warnings.warn(VampcWarning(
            f"{path}: its positions move {ratio:.3g} times what its velocities give at "
            f"{rate:g} Hz (the rows 1/rate apart): is --rate the rate the rows were sampled at? "
            f"{advice}"), stacklevel=1)


def _speed_ratio(traj, lam: float) -> float | None:
    """How far the positions move over what the velocities give at step λ (the trapezoid rule,
    over all rows and joints); None where either is nothing, or the ratio is not finite (sums past
    a float). Positions moving 5e-324 a row give 0 (underflowed): the rate check advises no rate
    then (it divided by zero)."""
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        moved = float(np.abs(np.diff(traj.q, axis=0)).sum())
        said = float(np.abs((traj.qd[1:] + traj.qd[:-1]) * (lam / 2)).sum())
        ratio = moved / said if moved > 0 and said > 0 else None
    if ratio is None or not 0 <= ratio < np.inf:
        return None
    return ratio


def check_consistent(traj, lam: float, path: str, columns=None) -> str | None:
    """The warning to give (None: none) at the first row where a joint's q moves, or its q̇
    changes, otherwise than its q̇, or q̈, say over the step λ by the rule the path follows best
    over all its rows, of the trapezoid rule, the value held from the row before, or the one held
    to the row after (vampc's own --accelerations paths hold q̈ over a step; a sampled bang-bang
    profile switches at a row), by more than a quarter of the larger plus 1% of the joint's usual
    step (its 95th percentile) and 1e-12 (rounding): the
    look-ahead plans the motion the q̇ and q̈ columns give, and the arm, going through the rows' q,
    would not keep to the torques planned (a new user's paths: a reversal written with q̈ = 0, a
    q̇ fifty times too large at one row, q alone with q̇ and q̈ zero, retimed 'within the limits'
    while their own finite differences were up to 5.7 times a limit). `columns`: the file's name
    of each joint's q, qd and qdd ({"q": [...], ...}; coupled followers are named by their
    leader's column), else q1.., qd1.., qdd1... None too where the positions move other than the
    velocities say over the whole path: a wrong --rate, which check_path warns of."""
    if traj.count < 2:
        return None
    if traj.t is None:                 # (as _check_rate_against_speeds judges it)
        ratio = _speed_ratio(traj, lam)
        if ratio is not None and not 0.8 <= ratio <= 1.25:
            return None
    for what, x, dx, d2 in (("q", traj.q, traj.qd, "qd"), ("qd", traj.qd, traj.qdd, "qdd")):
        step = np.diff(x, axis=0)
        rules = ((dx[1:] + dx[:-1]) * (lam / 2), dx[:-1] * lam, dx[1:] * lam)
        size = np.maximum.reduce([np.abs(step)] + [np.abs(r) for r in rules])
        # 1% of a joint's usual step (its 95th percentile: a spike would hide the rest)
        tol = 0.25 * size + 0.01 * np.percentile(size, 95, axis=0) + 1e-12
        with np.errstate(invalid="ignore"):
            offs = [np.abs(step - r) > tol for r in rules]
        best = min(range(len(rules)), key=lambda k: int(offs[k].sum()))   # the rule the path
        off = offs[best]                                                   # follows best, all rows
        if off.any():
            r, j = (int(v) for v in np.argwhere(off)[0])
            names = columns or {}
            joint = names[what][j] if what in names else f"{what}{j + 1}"
            other = names[d2][j] if d2 in names else f"{d2}{j + 1}"
            # (how far it goes: one line named of a path whose every step disagreed read as a
            # slip in one row; a new user's find)
            rows, joints = int(off.any(axis=1).sum()), int(off.any(axis=0).sum())
            from vampc.emulator.trajectory import numpy_file
            from vampc.textio import count
            extent = "" if off.sum() == 1 else \
                (f" ({rows} of its {count(len(step), 'step')} disagree{'s' * (rows == 1)} so, in "
                 f"{count(joints, 'joint')})")
            # (a .npy has no lines: its states are named, as every other message names them)
            npy = numpy_file(path)
            first = r + (1 if npy else 2)            # the step's first row, as the file counts it
            where = f"states {first} to {first + 1}" if npy else f"line {first} to {first + 1}"
            # (the trapezoid rule's value was given whatever rule the steps were judged by: nearly
            # q's own change, on a path of held values, beside a warning that they disagree; an
            # audit's find). The rule's value, and the row whose value it holds over the step.
            held = "" if best == 0 else f", held from {'state' if npy else 'line'} {first + best - 1}"
            return (f"{path}: {where}: {joint} changes by {float(step[r, j]):.6g} "
                    f"but {other} gives {float(rules[best][r, j]):.6g} over the step 1/rate{held}"
                    f"{extent}: the "
                    "look-ahead plans the motion the qd and qdd columns give, so where the rows' q "
                    "or qd disagree with them, the arm going through the rows may not keep to its "
                    "limits (write q, qd and qdd of one motion)"
                    + (_t_like(traj, path) if traj.t is None and (what, j) == ("q", 0) else ""))
    return None


def _t_like(traj, path: str) -> str:
    """'; its first column ... a t column ...?' where a .npy read without t has a first column
    stepping evenly from 0, as a t column does: the array then lacks a column (a new user's .npy of
    18 columns for 6 joints and t was read as 18 without t and told only of its q1 and rate), else
    ''. (A CSV's columns and a .npz's arrays are named: a q1 ramping from 0 is q1.)"""
    if not str(path).lower().endswith(".npy"):
        return ""
    first = traj.q[:, 0]
    steps = np.diff(first)
    if len(steps) and first[0] == 0 and steps[0] > 0 and np.allclose(steps, steps[0], rtol=1e-6, atol=0):
        return (f"; its first column (q of joint 1) steps evenly from 0 by {float(steps[0]):.6g}, "
                "as a t column does: a t column and one column too few?")
    return ""


def check_window(window: int, traj, futures: int = 1) -> None:
    """Registers no longer than the path, together (VampcUsageError)."""
    from vampc.textio import count
    if window > traj.count:
        raise VampcUsageError(f"--window {window}: larger than the trajectory "
                              f"({count(traj.count, 'row')})")
    if window * futures > traj.count:
        raise VampcUsageError(f"--window {window} × --futures {futures} = {window * futures} rows: "
                              f"more than the trajectory ({count(traj.count, 'row')})")


# What a run does, in order (the progress bar's stages: vampc.progress.stages), by --retime.
STAGES = {None: ("rows as given",),
          "uniform": ("rows as given", "gravity pass", "planning", "rows as retimed"),
          "window": ("rows as given", "gravity pass", "tangent pass", "planning",
                     "rows as retimed"),
          "envelope": ("rows as given", "gravity pass", "candidate futures", "rows as retimed")}


def run(ld, traj, window: int, limits: Limits, retime: str | None, emulate_rows,
        path: str = "", futures: int = 1, rate: float = 1.0, word_tolerance: float = 0.0,
        word_range: bool = False, stage=None) -> Lookahead:
    """The register over the trajectory: every row's torques (emulate_rows(traj) -> tau), the
    violations, and with `retime` ("uniform" or "window") the scaling and the retimed rows' torques.
    `path` names the trajectory in messages; `rate` is the rows' rate (Hz). `word_tolerance`: the
    error the network's word format may make (0 for float64), as its --check bounds it: a fraction
    of the run's largest |τ| of any joint, which on a path within the limits is at most the largest
    effort limit; the retiming plans to each limit that much of the largest limit tighter
    (`word_error`), so the reference dynamics stays within them.
    `word_range`: refuse a row of any pass that a fixed-point word cannot hold (as `vampc emulate`
    does unless --overflow is given). `stage(name)` is told as each of STAGES[retime] starts."""
    from vampc.emulator.host import Trajectory
    check_window(window, traj, 1 if retime == "envelope" else futures)   # (envelope: side by side)
    if retime == "envelope" and window < min(4, traj.count):
        # (a register of 3 rows may stop the arm one row before the last, where no constant s̈
        # starts and stops it: the example path was refused at its row 249, an envelope audit's;
        # from 4 rows no plan stops there: `envelope_plan`)
        raise VampcUsageError(f"--window {window}: --retime envelope needs at least 4 rows (or the "
                              "whole path): with 3, a plan may stop the arm one row before the last, "
                              "where no constant s̈ can start it and stop it again")
    check_memory(traj.count, ld.chain.n_outputs, retime, path,
                 futures * window if retime == "envelope" else 0)
    stage = stage or (lambda name: None)

    keys = ld.graph.input_keys() if word_range else ()

    def torques(rows, what: str) -> np.ndarray:       # a pass of the network, every torque finite
        if word_range:
            from vampc.emulator.host import check_word_range
            check_word_range(ld.arith, rows, path, ld.chain, f" {what}" if what else "", keys)
        with np.errstate(all="ignore"):                # (an overflow is said once, below)
            tau = emulate_rows(rows)
        finite(tau, ld, path, what)
        return tau
    from vampc.robot.mimic import free_names, reduce_torques
    names = free_names(ld.chain)                     # the motors', whose effort limits these are

    def effort(rows, what: str) -> np.ndarray:       # a pass's torques at the motors (Gᵀτ)
        return reduce_torques(ld.chain, torques(rows, what))
    stage("rows as given")
    out = Lookahead(torques(traj, ""), futures=futures, retime=retime,
                    ahead_rows=window if retime == "envelope" else window * futures,
                    word_tolerance=word_tolerance,
                    word_error=word_tolerance * max(limits.tau, default=0.0))
    tau = out.effort = reduce_torques(ld.chain, out.tau)
    out.violations = violations(tau, traj.qd, limits)
    if retime is None:
        return out
    zero = np.zeros_like(traj.qd)
    stage("gravity pass")
    g = effort(Trajectory(traj.q, zero, zero, None, None), "in its gravity pass")
    if retime == "envelope":
        return _envelope(out, ld, traj, g, window, limits, futures, rate, emulate_rows, effort,
                         torques, names, word_range, stage, path)
    if retime == "window":
        stage("tangent pass")
    tangent = (effort(Trajectory(traj.q, zero, traj.qd, None, None), "in its tangent pass")
               if retime == "window" else None)
    stage("planning")
    planned = out.planned(limits)
    _check_plannable(out, ld, g, limits, names, retime, path)
    try:
        if retime == "uniform":
            k = uniform_k(tau, g, traj.qd, limits, names)        # the closed form, as defined
            used = uniform_k(tau, g, traj.qd, planned, names)
        else:
            held = []
            # a and b are differences of two passes, each within the word's error, a fraction of
            # the run's largest |τ| (--check's), or in float64 its rounding, FLOAT64_SPREAD of the
            # row's largest: the plan keeps the limits for every a and b that far from the
            # network's (`_spread`)
            largest = np.max(np.abs(np.concatenate([tau, g, tangent], 1)), axis=1, keepdims=True)
            e = 2 * word_tolerance * float(np.max(largest, initial=0.0))
            spread = (e, e) if word_tolerance else (FLOAT64_SPREAD * largest,) * 2
            (x, u, t), optimal = plans(tangent - g, tau - g, g, traj.qd, planned, window * futures,
                                       1.0 / rate, 0.0, held=held, spread=spread)
            out.optimal_duration = None if optimal is None else optimal[2][-1]
            out.optimal_held = len(held)
    except VampcError as exc:
        raise VampcError(f"{path}: {exc}") from None
    if retime == "uniform":
        out.k_closed_form = k
        if k == 1.0:                   # (said: a uniform scaling does not speed a path up)
            out.k_faster = uniform_k(tau, g, traj.qd, limits, names, floor=0.0)
        out.k = used * (1 + K_MARGIN) if used > 1 else 1.0
        out.retimed = Trajectory(traj.q, traj.qd / out.k, traj.qdd / out.k ** 2, None, None)
        out.retimed_t = np.arange(traj.count) * (out.k / rate)
        out.speed = np.full(traj.count, 1.0 / out.k)
    else:
        _scaled(out, traj, x, u, t)
        # each row with the s̈ arriving at it too, from the network's three passes (τ = a u + b x
        # + c, exact): the plan keeps it within the limits, so a row over is its rounding's
        before = np.concatenate([[0.0], u[:-1]])
        came = out.arriving_effort = (tangent - g) * before[:, None] + (tau - g) * x[:, None] + g
        out.arriving_violations = violations(came, np.zeros_like(traj.qd), limits)
    return _run_retimed(out, ld, limits, torques, stage, path, retime)


def _check_plannable(out: Lookahead, ld, g, limits: Limits, names, retime: str, path: str) -> None:
    """Refuse, naming the path, limits the word's error leaves no room under, or a row whose torque
    at rest (`g`, the gravity pass) is over a limit: no retiming (`retime`) keeps such a path within
    them."""
    try:
        check_word_error(limits, names, out.word_error, ld.arith.name)     # (said before, by the command)
        check_gravity(g, limits, names, PLAN_MARGIN, out.word_error, ld.arith.name, retime,
                      at_rest(ld.chain))
    except VampcError as exc:
        raise VampcError(f"{path}: {exc}") from None


def at_scaling(q, d1, d2, x, u, speed=None):
    """Rows of the path (q, q' = d1, q'' = d2) run at ṡ² = x with s̈ = u: the Trajectory (q, q' ṡ,
    q'' ṡ² + q' s̈); `speed`: ṡ, where it is already known (√x otherwise)."""
    from vampc.emulator.host import Trajectory
    speed = np.sqrt(x) if speed is None else speed
    return Trajectory(q, d1 * speed[:, None], d2 * x[:, None] + d1 * u[:, None], None, None)


def _scaled(out: Lookahead, traj, x, u, t) -> None:
    """The retimed path of a scaling varying along it (window, envelope): each row at ṡ² = x with
    the s̈ u leaving it, at times t."""
    out.speed = np.sqrt(x)
    out.retimed = at_scaling(traj.q, traj.qd, traj.qdd, x, u, out.speed)
    out.retimed_t, out.accel = t, u


def _run_retimed(out: Lookahead, ld, limits: Limits, torques, stage, path: str,
                 retime: str) -> Lookahead:
    """The retimed rows through the network (`torques`), their torques at the motors and the
    violations; VampcError first where a time or rate is not finite."""
    from vampc.robot.mimic import reduce_torques
    made = (out.retimed_t, out.speed, out.retimed.qd, out.retimed.qdd)
    if not all(np.isfinite(a).all() for a in made):    # (a safety net: the limits are bounded below)
        raise VampcError(f"{path}: the {retime} retiming gives a time or rate that is not a finite "
                         "number")
    stage("rows as retimed")
    out.retimed_tau = torques(out.retimed, "as retimed")
    out.retimed_effort = reduce_torques(ld.chain, out.retimed_tau)
    out.retimed_violations = violations(out.retimed_effort, out.retimed.qd, limits)
    return out


def _envelope(out: Lookahead, ld, traj, g, window: int, limits: Limits, futures: int, rate: float,
              network, effort, torques, names, word_range: bool, stage, path: str) -> Lookahead:
    """`run`'s --retime envelope: the candidate futures (`envelope_plan`), then the retimed rows,
    with the s̈ leaving each row and with the s̈ arriving at it, through the network."""
    from vampc.emulator.host import Trajectory
    from vampc.robot.mimic import reduce_torques
    planned = out.planned(limits)
    _check_plannable(out, ld, g, limits, names, "envelope", path)
    word = ld.arith

    def evaluate(rows):
        """The network's effort torques of candidate rows, and the rows to refuse: those a
        narrower word cannot hold, or on which it overflows (or a float32's is not finite);
        neither is counted as the run's overflow, since no such row is run."""
        refused = np.zeros(rows.count, bool)
        if word_range:
            refused |= beyond_word(word, rows)
        ok = np.flatnonzero(~refused)
        tau = np.zeros((rows.count, len(names)))
        if ok.size:
            part = Trajectory(rows.q[ok], rows.qd[ok], rows.qdd[ok], None, None)
            before = word.overflows
            with np.errstate(all="ignore"):
                got = reduce_torques(ld.chain, network(part))
            if word.overflows != before:     # which rows: each again, alone
                word.overflows = before
                bad = np.zeros(ok.size, bool)
                for k in range(ok.size):
                    one = Trajectory(part.q[k:k + 1], part.qd[k:k + 1], part.qdd[k:k + 1], None, None)
                    with np.errstate(all="ignore"):
                        network(one)
                    bad[k] = word.overflows != before
                    word.overflows = before
                refused[ok[bad]] = True
            tau[ok] = got
            refused |= ~np.isfinite(tau).all(axis=1)
        return tau, refused

    stage("candidate futures")
    try:
        env = envelope_plan(traj, evaluate, planned, window, futures, 1.0 / rate,
                            _rows_told(stage, traj.count))
    except VampcError as exc:       # (the path named, as every other look-ahead error names it)
        raise VampcError(f"{path}: {exc}") from None
    out.envelope = env
    _scaled(out, traj, env.x, env.u, env.t)
    _run_retimed(out, ld, limits, torques, stage, path, "envelope")
    came = out.arriving_effort = effort(arriving(traj, out), "as retimed, with the s̈ arriving at it")
    out.arriving_violations = violations(came, np.zeros_like(traj.qd), limits)
    return out


def beyond_word(word, rows) -> np.ndarray:
    """Per row: whether a fixed-point `word` cannot hold its q̇ or q̈ (`check_word_range`'s refusal,
    as a mask; the inputs it works out of q alone, p* and s*, are the path's, checked as given)."""
    if not hasattr(word, "beyond"):
        return np.zeros(rows.count, bool)
    return word.beyond(np.concatenate([rows.qd, rows.qdd], axis=1)).any(axis=1)


# Peak memory per row and torque column (bytes), by retiming: the passes' rows and torques, and
# for the window retiming the plan's bounds (four copies of each joint's, at the row and the next).
# Measured 2026-12-05 on the Puma 560 (6 columns), 30 000 to 300 000 rows: about 5.3 kB a row
# with --retime window (1.66 GB at 300 000), 2.6 kB with uniform, 1.1 kB without; these are
# rounded up. --retime envelope is given the window's: its passes are the uniform's and one more,
# its candidates a step's at a time (68 MB peak, the whole process, at 10 000 rows;
# ENVELOPE_BYTES_PER_ROW_COLUMN counts the candidates). The window retiming's block of pairs
# (`_largest_x`) comes on top: a few temporaries of its pairs (176 MB measured, the Puma:
# LARGEST_X_PAIRS of them).
BYTES_PER_ROW_COLUMN = {None: 250, "uniform": 500, "window": 1000, "envelope": 1000}


def pairs_bytes(rows: int, columns: int) -> int:
    """The window retiming's block of pairs of bounds (`_largest_x`), on top of its rows: six
    temporaries of the block's pairs (each row's bounds are four copies of each joint's, at the
    row and the next: 8 a column, and one more)."""
    per_row = (8 * columns + 1) ** 2
    return 6 * 8 * min(rows, _block_rows(per_row)) * per_row


def _block_rows(pairs_per_row: int) -> int:
    """Rows of `_largest_x`'s block: LARGEST_X_PAIRS pairs, at least one row (a chain of more than
    277 joints has more pairs in one row)."""
    return max(1, LARGEST_X_PAIRS // pairs_per_row)


# --retime envelope: the peak of a step's candidate rows (at most 2 a register row: leaving and
# arriving), per row and torque column: 632 MB measured for --futures 4096 --window 64 on the Puma
# (6 columns, 2026-12-05: about 200 bytes), taken twice over.
ENVELOPE_BYTES_PER_ROW_COLUMN = 400


def check_memory(rows: int, columns: int, retime: str | None, path: str,
                 register_rows: int = 0) -> None:
    """Refuse, before any pass, a path whose run would not fit in half the memory available (a
    300 000-row path was killed by the system at 23 GB, nothing said, before the plan's bounds were
    taken in blocks; a longer one still can be). `register_rows`: --retime envelope's R × M rows of
    candidates a step (--futures 65536 ran out of memory: an audit's)."""
    from vampc.emulator import driver
    candidates = 2 * register_rows * columns * ENVELOPE_BYTES_PER_ROW_COLUMN
    need = rows * columns * BYTES_PER_ROW_COLUMN[retime] + \
        (pairs_bytes(rows, columns) if retime == "window" else 0) + candidates
    avail = driver.short_of_memory(need)
    if avail is None:
        return
    how = f" with --retime {retime}" if retime else ""
    if candidates > need / 2:
        raise VampcError(f"{path}: {register_rows:,} rows of candidates a step (--futures × "
                         f"--window) and the path's {rows:,} need about {need / 2**30:.1f} GiB"
                         f"{how} ({avail / 2**30:.1f} GiB available); give fewer --futures or a "
                         "shorter --window")
    raise VampcError(f"{path}: {rows:,} rows need about {need / 2**30:.1f} GiB{how} "
                     f"({avail / 2**30:.1f} GiB available); run the path in parts")


def check_new_times(res: Lookahead, times: np.ndarray, path: str) -> None:
    """The retimed rows' times as written (from the path's first time): VampcError where two
    cannot be told apart in float64 (a path whose t starts at 1.7e9, rows 1e-8 s apart: the file
    written could not be read back), and a warning where the intervals are held only roughly."""
    import warnings

    from vampc.errors import VampcWarning
    new = res.new_times(times)
    planned = np.diff(res.retimed_t if res.k is None else (times - times[0]) * res.k)
    got = np.diff(new)
    # what makes the times large: the path's first t, or the retimed path's own length (a speed
    # limit of 1e-12 made a plan of 1.3e12 s, and the advice to start t near 0 was for a t that did:
    # a look-ahead audit's find)
    span = float(new[-1] - new[0])
    own = abs(times[0]) <= span
    if (got <= 0).any():
        i = int(np.argmax(got <= 0))
        why = (f"at that size: the retimed path runs {span:.3g} s from its first row to its last, "
               "so long for limits far below what the path asks (check them, the speed limits "
               "above all)" if own else
               f"from a t starting at {times[0]:.12g}; give the path a t column starting near 0")
        apart = f" {planned[i]:.3g} s apart," if planned[i] > 0 else ""     # (the plan's own: "0 s")
        raise VampcError(f"{path}: rows {i + 1} and {i + 2} as retimed,{apart} both come at t = "
                         f"{float(new[i])!r}: float64 cannot tell them apart {why}")
    with np.errstate(divide="ignore", invalid="ignore"):
        off = np.abs(got - planned) / planned
    worst = float(np.max(off[planned > 0], initial=0.0))
    if worst > 1e-6:
        why = (f"over the retimed path's {span:.3g} s (limits far below what the path asks make it "
               "so long)" if own else f"from t = {times[0]:.12g}; a t column starting near 0 holds "
               "them exactly")
        warnings.warn(VampcWarning(
            f"{path}: the retimed rows' times hold their intervals only to {100 * worst:.2g}% in "
            f"float64, {why}"), stacklevel=1)


def finite(tau: np.ndarray, ld, path: str, what: str = "") -> None:
    """VampcError naming the first torque of a pass (`what`) that is not finite, as `vampc emulate`
    says it (vampc.emulator.driver.non_finite): a non-finite number is never a result."""
    from vampc.emulator.driver import non_finite
    found = non_finite(ld, tau)
    if found is not None:
        raise VampcError(f"{path}: row {found[0] + 1}{f' {what}' if what else ''}, {found[1]}")


def tightened(limits: Limits, margin: float) -> Limits:
    """The effort limits `margin` (of each) tighter; the speed limits as they are (the host works
    speeds out itself, in float64)."""
    if not margin:
        return limits
    return Limits(tuple(t * (1 - margin) for t in limits.tau), limits.qd)


def check_word_error(limits: Limits, names, error: float, word: str) -> None:
    """VampcError where an effort limit is no larger than `error`, the torque a `word` network may
    be off by: no retiming can promise to keep it."""
    for name, lim in zip(names, limits.tau):
        if lim <= error:
            raise VampcError(f"joint '{name}': its effort limit {lim:.12g} is within the error a "
                             f"{word} network's --check allows ({error:.3g}: of the largest effort "
                             f"limit, {max(limits.tau):.12g}): no retiming can promise to keep it "
                             "(give the word's error as a smaller --tolerance, if --check finds it "
                             "within that, or use a wider word: vampc precision names one)")


def at_rest(chain) -> str:
    """What makes a robot's torque at rest (its gravity pass, q̇ = q̈ = 0), for messages: "gravity
    alone", or gravity, the tip load and the base's motion as the robot has them (a tip load on
    a robot without gravity had been called "gravity alone": a fuzz audit's)."""
    parts = [what for what, values in (("gravity", [chain.gravity]),
                                       ("the tip load", [chain.tip_force, chain.tip_torque]),
                                       ("the base's motion", [chain.base_omega, chain.base_omega_dot]))
             if any(np.any(v) for v in values)]
    if len(parts) <= 1:
        return f"{parts[0] if parts else 'gravity'} alone"
    return ", ".join(parts[:-1]) + f" and {parts[-1]}"


def check_gravity(g: np.ndarray, limits: Limits, names, margin: float = 0.0, error: float = 0.0,
                  word: str | None = None, retime: str = "uniform", rest: str = "gravity alone") -> None:
    """VampcError where the torque at rest (gravity alone, or what `rest` says makes it: `at_rest`)
    is beyond a limit, or inside it by less than the retiming keeps: `error` (the torque a `word`
    network may be off by) and `margin` of the rest. No uniform scaling helps there; the window
    retiming (`retime` "window") plans to be able to stop at any row it sees, so it needs every row
    restable, though a path braking through such rows may exist (a look-ahead stress test's Puma
    shoulder swinging through 46 N·m of gravity against 44: the message had said no time scaling
    helps)."""
    lim = np.array(limits.tau)
    g = g[:, :len(lim)]
    alone = np.argwhere(np.abs(g) > (lim - error) * (1 - margin))
    if alone.size:
        r, j = (int(x) for x in alone[0])
        kept = f"{margin:g} of it" if not error else f"{error:.3g} and {margin:g} of the rest"
        why = (f"rounding and the error a {word} network's --check allows" if error else
               "rounding and the network's word")
        how = (f"beyond its limit {lim[j]:.12g}" if abs(g[r, j]) > lim[j] else
               f"closer to its limit {lim[j]:.12g} than {kept}, the margin the retiming keeps for "
               f"{why}")
        then = ("no time scaling helps" if retime == "uniform" else
                f"the {retime} retiming plans to be able to stop at every row it sees, so it "
                "needs the arm able to rest at each (a path braking through such rows is not "
                "planned)")
        raise VampcError(f"row {r + 1}: joint '{names[j]}' needs {g[r, j]:.12g} at rest "
                         f"({rest}), {how}: {then}")


PLAN_MARGIN = 1e-9
# The fastest the window retiming runs a path: ṡ at most MAX_SPEED times the path's own speed.
# Where the path stands still (q' = 0: at rest at its start or end, or waiting), no limit bounds ṡ,
# and without this the rows there would take no time at all (the same t, and q̇ = 0·∞).
MAX_SPEED = 100.0


def _stage(a, b, c, L):
    """Each row's effort limits as bounds on u affine in x: u >= p + r x and u <= P + r x per joint
    (±inf where a joint's a is zero; both bounds of a joint share the slope r = -b/a), and the
    bound on x alone from those joints."""
    lo, hi = -L - c, L - c
    # a joint's a is taken for zero only within the rounding of the tangent pass less the gravity
    # pass it is (of c, the torque at rest, and of the limit): not of b, which a u need not be
    # small against (a row of the path with a q̇ or q̈ of 1e12 has b a million million times a, and
    # its s̈ was left unbounded, the arm going over a limit: a new user's find, 2026-12-04)
    tiny = np.abs(a) <= 1e-12 * (np.abs(c) + L)
    sa = np.where(tiny, 1.0, a)
    r = np.where(tiny, 0.0, -b / sa)
    p = np.where(tiny, -np.inf, np.where(a > 0, lo, hi) / sa)
    P = np.where(tiny, np.inf, np.where(a > 0, hi, lo) / sa)
    with np.errstate(divide="ignore", invalid="ignore"):
        alone = np.where(tiny & (b > 0), hi / b, np.where(tiny & (b < 0), lo / b, np.inf))
    return p, r, P, np.min(alone, axis=-1)


# pairs of bounds `_largest_x` takes at a time: 2048 rows of a 6-joint arm, about 40 MB a temporary
# (a review found 2048 rows of a 64-joint chain's 513 × 513 pairs, 18 GB, when blocks were of rows)
LARGEST_X_PAIRS = 2048 * 49 * 49


def _largest_x(lo, up, cap, H, two_d):
    """Per row (leading axes): the largest x in [0, cap] with some u within the bounds
    u d >= n + s x (`lo`) and u d <= n + s x (`up`), each a triple (n, s, d) of arrays over its
    last axis, d >= 0, and 0 <= x + 2Δu <= H. The bounds are affine in x, the feasible x an interval
    holding 0, so its top is the least root among the pairs (lower, upper) that cross, each pair
    compared without dividing by d (a bound of the next row can have d near 0, where it is a bound
    on x alone). Rows are taken a block at a time, of at most LARGEST_X_PAIRS pairs: every pair
    of bounds of a row is a temporary (a 6-joint arm's 49 × 49 per row, a 64-joint one's 513 × 513,
    several times over), and the whole path's at once took about 84 kB a row on the Puma (a
    300 000-row path at 1 kHz was killed at 23 GB: an audit's find)."""
    rows = _block_rows((lo[0].shape[-1] + 1) * (up[0].shape[-1] + 1))
    if lo[0].ndim == 2 and len(lo[0]) > rows:
        return np.concatenate([
            _largest_x(tuple(v[k:k + rows] for v in lo), tuple(v[k:k + rows] for v in up),
                       cap[k:k + rows], H[k:k + rows], two_d)
            for k in range(0, len(lo[0]), rows)])
    shape = lo[0].shape[:-1] + (1,)
    ln = np.concatenate([lo[0], np.zeros(shape)], -1)
    ls = np.concatenate([lo[1], np.full(shape, -1.0)], -1)
    ld = np.concatenate([lo[2], np.full(shape, two_d)], -1)
    un = np.concatenate([up[0], H[..., None]], -1)
    us = np.concatenate([up[1], np.full(shape, -1.0)], -1)
    ud = np.concatenate([up[2], np.full(shape, two_d)], -1)
    with np.errstate(over="ignore", invalid="ignore"):
        gap = ud[..., None, :] * ln[..., :, None] - ld[..., :, None] * un[..., None, :]
        slope = ud[..., None, :] * ls[..., :, None] - ld[..., :, None] * us[..., None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.where(slope > 0, -gap / slope, np.inf)
    root = np.where(np.isnan(root), np.inf, root)
    return np.clip(np.minimum(cap, root.reshape(root.shape[:-2] + (-1,)).min(-1)), 0.0, None)


def _top_under(lo, base, H, two_d):
    """`_largest_x(lo, up, cap, H, two_d)` from `base`, the same with H = inf (computed once per
    row): only the pairs of a lower bound with the bound x + 2Δu <= H depend on H, so a step of the
    backward pass works out those, not every pair (the same roots, the same numbers)."""
    n, sl, d = lo
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        gap = two_d * n - d * H[..., None]
        slope = two_d * sl + d
        root = np.where(slope > 0, -gap / slope, np.inf)
    root = np.where(np.isnan(root), np.inf, root)
    return np.clip(np.minimum(base, root.min(-1)), 0.0, None)


def _spread(a, b, c, L, spread):
    """The affine parts and limits as four copies of each joint, a ± ea and b ± eb (`spread` =
    (ea, eb), numbers or columns of one per row): a scaling within the limits of
    every copy is within them for every a, b within (ea, eb) of those the network gave (a u + b x is
    largest at a corner of that box), so the error the network's word may make in a pass is not
    multiplied by s̈ or ṡ² past the limits. Where the path nearly stands still (q' near 0: its ends,
    a pause) a is small and s̈ can be large: planned on a and b as given, a q16.16 network's
    retiming of a rest-to-rest path went 1.25 times over the Puma's waist limit by the reference
    dynamics, a float32 one 1.005 times, a float64 one 1.85e-9 over its limit at 8 kHz (a
    look-ahead stress test's finds, 2026-12-05). (float64's b too: its error is absolute, of the
    row's largest torque, not rounding of b x, which a small b need not be near, and x reaches
    MAX_SPEED² where the path stands still: a review's find; four copies, not two, made a 10 000-row
    plan 2.4 s, not 1.2 s.)"""
    ea, eb = spread
    if not np.any(ea) and not np.any(eb):
        return a, b, c, L
    a, b = np.concatenate([a + ea, a - ea, a + ea, a - ea], 1), \
        np.concatenate([b + eb, b + eb, b - eb, b - eb], 1)
    c, L = np.tile(c, 4), np.tile(L, 4)
    return a, b, c, L


def _bounds(a, b, c, qd, limits: Limits, margin: float, two_d: float, spread=(0.0, 0.0)):
    """The bounds on the s̈ u of the interval leaving each row, (lower, upper), each a triple (n, s, d)
    of arrays (rows × bounds): u d >= n + s x and u d <= n + s x in the row's x (`_largest_x`):
    the effort limits (`_stage`, `margin` tighter) at that row and at the next, where the
    arm arrives with the same u at x + 2Δu (`two_d` = 2Δ), so the torque at both rows of every
    interval is within them (TOPP-RA's interpolation discretization; the row alone, its collocation,
    left the s̈ arriving at a row unchecked: up to 1.5 times a limit there). And each row's cap on x:
    the x-alone bound, MAX_SPEED and the speed limits."""
    n = len(limits.tau)
    a, b, c, L = _spread(a[:, :n], b[:, :n], c[:, :n], np.array(limits.tau) * (1 - margin), spread)
    with np.errstate(over="ignore"):     # (a limit near the float range: its bound is inf, as it is)
        p, r, P, cap = _stage(a, b, c, L)
    cap = np.minimum(cap, speed_caps(qd, limits))
    # the next row's p' + r' x' <= u <= P' + r' x' with x' = x + 2Δu: u m >= p' + r' x and
    # u m <= P' + r' x, m = 1 - 2Δ r'; where m < 0 both are negated, which swaps them
    nxt = lambda v, fill: np.concatenate([v[1:], np.full((1, v.shape[1]), fill)])   # noqa: E731
    p1, r1, P1 = nxt(p, -np.inf), nxt(r, 0.0), nxt(P, np.inf)
    m = 1.0 - two_d * r1
    neg = m < 0
    slope = np.concatenate([r, np.where(neg, -r1, r1)], 1)          # (a lower and an upper bound
    scale = np.concatenate([np.ones_like(p), np.abs(m)], 1)         # of one row share these)
    return ((np.concatenate([p, np.where(neg, -P1, p1)], 1), slope, scale),
            (np.concatenate([P, np.where(neg, -p1, P1)], 1), slope, scale), cap)


def window_plan(a, b, c, qd, limits: Limits, ahead_rows: int, lam: float,
                margin: float = PLAN_MARGIN, spread=(0.0, 0.0)):
    """The window-by-window scaling of the module docstring: per row x = ṡ², u = s̈ and the new row
    times (from 0). a, b, c: the affine parts of each row's torque (rows × joints); qd: q' of each
    row (for the speed limits); ahead_rows: how many rows the host sees (the row leaving included);
    margin: how much (of each) tighter than the effort limits to plan."""
    return plans(a, b, c, qd, limits, ahead_rows, lam, margin, optimal=False, spread=spread)[0]


def optimal_plan(a, b, c, qd, limits: Limits, lam: float, margin: float = PLAN_MARGIN,
                 spread=(0.0, 0.0)):
    """`window_plan` with the whole path in view, in one backward pass: the time-optimal scaling on
    these rows and limits (TOPP-RA's, tested) where no step is held short of its top
    (`_short_of_a_cliff`), against which a window's plan is measured."""
    two_d = 2.0 * lam
    lo, up, cap = _bounds(a, b, c, qd, limits, margin, two_d, spread)
    base = _largest_x(lo, up, cap, np.full(len(a), np.inf), two_d)
    return _forward(lo, up, _backward(lo, base, len(a), two_d), lam, "path")


def plans(a, b, c, qd, limits: Limits, ahead_rows: int, lam: float, margin: float = PLAN_MARGIN,
          optimal: bool = True, held: list | None = None, spread=(0.0, 0.0)):
    """(`window_plan`, `optimal_plan`), sharing their bounds and the whole path's backward pass
    (`optimal` False: the window's plan alone, None for the other, whose forward pass may fail
    where the window's does not).

    Each step's backward pass runs from the last row it sees towards its own row; where it meets
    the whole path's pass (the same top at the same row: both at a row's cap, say) the two are the
    same recursion from there on, so the step takes the whole pass's value at its row and stops.
    The same numbers as a pass per step to the end (tested). Planning with 4000 rows in view took
    3.1 s instead of 6.5 s on a 10 000-row path, 0.8 s instead of 4.8 s on an 8001-row one (the
    benchmark's early and slow Puma paths at 10 s and 8 s); at 64 rows about the same."""
    if ahead_rows < 3:
        raise VampcUsageError(f"--retime window sees {ahead_rows} row(s) ahead: it needs at least 3 "
                              "(--window × --futures) to start and still be able to stop")
    n_rows = len(a)
    two_d = 2.0 * lam
    lo, up, cap = _bounds(a, b, c, qd, limits, margin, two_d, spread)
    base = _largest_x(lo, up, cap, np.full(n_rows, np.inf), two_d)    # every pair but H's, once
    whole = _backward(lo, base, n_rows, two_d)       # whole[i]: the set's top at row i + 1
    seen = f"{ahead_rows} rows it sees; give a longer --window or more --futures"
    if ahead_rows >= n_rows:     # every step sees to the last row: the whole pass serves them all
        window = _forward(lo, up, whole, lam, seen, held)
        return window, window if optimal else None     # (the same numbers: the optimum)
    rows = np.arange(n_rows)
    end = np.minimum(rows + ahead_rows - 1, n_rows - 1)     # the last row each step sees
    H = whole.copy()               # per step: its top at its row + 1 (the whole pass's, once met)
    H2 = np.concatenate([whole[1:], [0.0]])      # and at its row + 2 (`_short_of_a_cliff`'s)
    step = np.flatnonzero(end < n_rows - 1)      # (a step that sees the last row is the whole pass)
    h = np.zeros(step.size)                      # each step's top at row end - d: 0 at its end
    for d in range(1, ahead_rows - 1):
        j = end[step] - d
        second = j == step + 1                   # h is its top at its own row + 2
        H2[step[second]] = h[second]
        done = j < step + 1                      # reached its own row + 1: h is its top there
        H[step[done]] = h[done]
        step, h, j = step[~done], h[~done], j[~done]
        if not step.size:
            break
        h = _top_under(tuple(v[j] for v in lo), base[j], h, two_d)
        met = h == whole[j - 1]                  # the whole pass's top at row j: the same from here
        step, h = step[~met], h[~met]
    H[step] = h
    H = np.where(rows + 1 <= end, H, 0.0)        # a step at the last row it sees stops there
    H2 = np.where(rows + 2 <= end, H2, 0.0)
    window = _forward(lo, up, H, lam, seen, H2=H2)     # (its failure said first, as before)
    if not optimal:
        return window, None
    try:                 # (the whole path's plan is a comparison: where its forward pass finds no
        return window, _forward(lo, up, whole, lam, "path", held)   # way through, rounding in a path
    except VampcError:   # the window's plan got through, that plan is not said, not the run failed)
        return window, None


def _backward(lo, base, n_rows: int, two_d: float) -> np.ndarray:
    """The stop-able sets' tops with the whole path in view, one backward pass: H[i], the top of
    the set at row i + 1 (0 at the last row)."""
    H = np.zeros(n_rows)
    for i in range(n_rows - 3, -1, -1):
        k = slice(i + 1, i + 2)
        H[i] = _top_under(tuple(v[k] for v in lo), base[k], H[i + 1:i + 2], two_d)[0]
    return H


def _forward(lo, up, H, lam: float, seen: str, held: list | None = None, H2=None):
    """From rest at the first row: each next x the largest reachable within the row's bounds on u
    (`_bounds`: a bound of d near 0 bounds x alone, which H already holds, and is left out here) and
    at most H (the stop-able set's top at that row), so (x, u, row times)."""
    n_rows, two_d = len(H), 2.0 * lam
    x, u = np.zeros(n_rows), np.zeros(n_rows)
    pieces = _reach_pieces(up, two_d)
    # H2[i]: the top at row i + 2 as the step at row i sees it (the whole path's H, shifted, when
    # it sees the whole path; never a later step's view: the decision would see past its rows)
    H2 = np.concatenate([H[1:], [0.0]]) if H2 is None else H2
    for i in range(n_rows - 1):
        xi = x[i]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            lows = (lo[0][i] + lo[1][i] * xi) / lo[2][i]
            tops = (up[0][i] + up[1][i] * xi) / up[2][i]
        low = float(np.max(np.where(lo[2][i] > 1e-9, lows, -np.inf)))
        top = float(np.min(np.where(up[2][i] > 1e-9, tops, np.inf)))
        nxt = max(0.0, min(xi + two_d * top, float(H[i])))
        if i + 2 < n_rows:
            short = _short_of_a_cliff(pieces[0][i + 1], pieces[1][i + 1], float(H2[i]), float(xi),
                                      max(0.0, xi + two_d * low), nxt)
            if short < nxt and held is not None:
                held.append(i + 1)         # (the row, from 0, whose speed was held short)
            nxt = short
        ui = (nxt - xi) / two_d
        if ui < low - 1e-7 * max(1.0, abs(low)) and not _within_rounding(lo, i, xi, ui):
            raise VampcError(f"row {i + 1}: no speed keeps every joint within its limit here "
                             "(the look-ahead found no way through)")
        x[i + 1], u[i] = nxt, ui
    root = np.sqrt(x)
    with np.errstate(divide="ignore"):
        steps = two_d / (root[:-1] + root[1:])
    stuck = np.flatnonzero(~np.isfinite(steps))
    if stuck.size:
        raise VampcError(f"row {stuck[0] + 1}: the arm cannot move on within the limits while still "
                         f"able to stop within the {seen}")
    return x, u, np.concatenate([[0.0], np.cumsum(steps)])


def _within_rounding(lo, i: int, x: float, u: float) -> bool:
    """Whether u keeps row i's lower bounds u d >= n + s x (those `_forward` uses, d > 1e-9) within
    the rounding of their own terms, compared without dividing by d. A bound of the next row whose
    d is small but not 1e-9 (a' + 2Δb' near 0: the next row's torque hardly depends on u) divides
    the rounding of n + s x, two large terms that nearly cancel, by d: on a slow path where every
    joint turns back at once (q' = 0 at one row) 4.5e-7 of d made 2e-9 of x a 1e-6 miss in u, and
    the plan said no speed kept the limits, on a path within them as given (a new user's find,
    2026-12-05). In torque, the miss allowed is 1e-12 of |L ± c| + |b x| + |a u| (the next row's
    likewise): where those terms are a few limits, as in that case, far under PLAN_MARGIN; where
    they are large and cancel (running at the speed cap towards a rest) it can be more, but there
    the test in u before this one already allows more still. Either way a row over a limit is
    found by the network's pass over the retimed rows (FAILED), not passed in silence."""
    n, s, d = lo[0][i], lo[1][i], lo[2][i]
    keep = (d > 1e-9) & np.isfinite(n)
    with np.errstate(invalid="ignore", over="ignore"):
        over = np.where(keep, n + s * x - d * u, 0.0)
        scale = np.where(keep, np.abs(n) + np.abs(s * x) + np.abs(d * u), 0.0)
    return bool(np.all(over <= 1e-12 * scale))


NEAR_STOP = 1e-6        # a next row's fastest x this small against the step's own: braked to a stop


def _reach_pieces(up, two_d: float):
    """Per row, the affine pieces (alpha + beta x) whose least is the fastest x reachable at the row
    after from x at this row, x + 2Δ top(x), by the row's upper bounds on u (`_bounds`; those of d
    near 0, bounds on x alone, left out as `_forward` leaves them: alpha = inf)."""
    n, sl, d = up
    keep = d > 1e-9
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        alpha = np.where(keep, two_d * n / np.where(keep, d, 1.0), np.inf)
        beta = np.where(keep, 1.0 + two_d * sl / np.where(keep, d, 1.0), 0.0)
    return np.where(np.isnan(alpha), np.inf, alpha), np.where(np.isfinite(beta), beta, 0.0)


def _short_of_a_cliff(alpha, beta, h: float, now: float, least: float, most: float) -> float:
    """The next row's x in [least, most] (this row's: `now`; `most`: the greedy step's, the largest
    reachable and stop-able). Greedy is time-optimal where a faster row leaves the row after it no
    slower; at the very top of a row's feasible speeds, though, one s̈ alone may be left, and it can
    brake the row after to a stop: on a path whose q̇ and q̈ disagree with its q, the plan took
    ṡ = 6.3e-12 at the last-but-one row, 3·10⁸ s, where a hair less speed before it left 2.6e-4
    (a new user's find; TOPP-RA's greedy pass got 250 s there, this 21 s). So where the fastest
    reachable x of the row after, g(x) = min(h, min(alpha + beta x)) (`_reach_pieces`: concave,
    piecewise affine), is a stop at `most` (at most NEAR_STOP of it) and falls towards it, the step
    takes, among the ends and the corners of g, the x whose two intervals, to the next row and on
    to g(x), take the least time. Elsewhere `most`, as before. Held wherever g merely falls, the
    step made 2 of 1800 plans on random affine parts slower, one 25 000 times (a lower speed now
    led the plan onto a stop further on); held only before a stop, `benchmarks/lookahead_random_rows.py`
    counts 139 of 1586 faster (8 more than 10 times), 2 slower (1.62 times at worst) and 5 that
    find a way through only so. None of the README's paths meets such a row: their outputs are the
    same bytes."""
    if not most - least > 1e-9 * most:     # (a choice within rounding: no choice, and none made)
        return most

    def pieces_at(x: float) -> np.ndarray:      # (g(x) is min(h, their least); nan: no bound)
        with np.errstate(invalid="ignore", over="ignore"):
            at = alpha + beta * x
        return np.where(np.isnan(at), np.inf, at)
    at = pieces_at(most)
    least_at = float(np.min(at))
    if not least_at <= NEAR_STOP * most or h <= least_at:   # (no stop after it, or h holds it)
        return most
    if float(np.max(beta[at <= least_at + 1e-12 * abs(least_at)])) >= 0:     # g does not fall here
        return most
    lines = [(h, 0.0)] + [(a, b) for a, b in zip(alpha.tolist(), beta.tolist()) if np.isfinite(a)]
    points = [least, most]
    for k, (a1, b1) in enumerate(lines):
        for a2, b2 in lines[k + 1:]:
            if b1 != b2:
                x = (a2 - a1) / (b1 - b2)
                if least < x < most and np.isfinite(x):
                    points.append(x)

    def time(x: float) -> float:       # (of the two intervals, per 2Δ)
        after = max(0.0, min(h, float(np.min(pieces_at(x)))))
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            return 1.0 / (np.sqrt(now) + np.sqrt(x)) + 1.0 / (np.sqrt(x) + np.sqrt(after))
    best = min(points, key=lambda x: (time(x), -x))
    return best if time(best) < time(most) * (1 - 1e-9) else most


# --retime envelope: the R candidate futures of a step leave the arm's row with s̈ u_r = U (2 (r + 1) / R
# - 1), r = 0 .. R - 1 (R = 4: -U/2, 0, U/2 and U), or from rest U (r + 1) / R. U starts at
# ENVELOPE_U, doubles after a try whose fastest candidate was within the limits (unless a speed cap
# held it, and at most to the s̈ reaching the top speed in one row), and halves after one where it
# was not (though not below the s̈ of the plan the arm keeps), so the fastest candidate follows the
# largest s̈ the limits allow. Chosen by measuring against other families (README, vampc
# lookahead: The envelope of futures).
ENVELOPE_U = 1.0
ENVELOPE_FUTURES = 4       # --futures' default with --retime envelope
# A row where the arm stands at rest and no candidate is within the limits: it waits there and
# tries again with U halved, at most this many times, then the path is refused.
ENVELOPE_TRIES = 64


@dataclass
class Envelope:
    """What `envelope_plan` did at each row of the path (the arm leaving it)."""

    x: np.ndarray          # ṡ² at the row
    u: np.ndarray          # s̈ of the interval leaving it
    t: np.ndarray          # the row's new time, from 0
    rows: np.ndarray       # rows of candidate futures the network computed to decide it
    tries: np.ndarray      # candidate sets tried (more than 1: the arm waited there, at rest)
    chosen: np.ndarray     # the taken candidate (0 .. R - 1); -1: the plan taken before, kept
    scale: np.ndarray      # U of the candidates taken (`candidates`), at the last try
    refused: int = 0       # candidate rows a narrower word could not hold or overflowed on


def candidates(x0: float, U: float, cap: np.ndarray, futures: int, lam: float) -> np.ndarray:
    """The R candidate futures from a row where the arm runs at x0 = ṡ², over the m rows of `cap`
    (each row's cap on x; the first is the row leaving, the last the register's last): candidate r
    leaves the row with s̈ u_r (ENVELOPE_U), then slows at one constant s̈ to rest (x = 0) at the
    last row, the gentlest such stop, all under the caps. x of each (R × m); a candidate whose next
    row would be at rest or beyond (x <= 0 there) is nan."""
    m = len(cap)
    r = np.arange(futures) + 1.0
    u = U * r / futures if x0 == 0 else U * (2.0 * r / futures - 1.0)
    x1 = x0 + 2.0 * lam * u
    x = x1[:, None] * (m - 1 - np.arange(m)) / max(m - 2, 1)
    x = np.minimum(x, cap)
    x[:, 0], x[:, -1] = x0, 0.0
    x[x1 <= 0] = np.nan
    return x


def speed_caps(qd: np.ndarray, limits: Limits) -> np.ndarray:
    """Each row's cap on x = ṡ²: MAX_SPEED and the speed limits (PLAN_MARGIN inside)."""
    cap = np.full(len(qd), MAX_SPEED ** 2)
    for j, v in enumerate(limits.qd):
        if v is not None:
            with np.errstate(divide="ignore", over="ignore"):    # (inf: no bound, as MAX_SPEED caps)
                cap = np.minimum(cap, (v * (1 - PLAN_MARGIN) / np.abs(qd[:, j])) ** 2)
    return cap


def candidate_rows(traj, first: int, x: np.ndarray, lam: float):
    """The rows of candidate futures `x` (R × m, from row `first`) the network computes: each row
    but the last with the s̈ leaving it, and with the s̈ arriving at it where that differs (always
    at the last, where the arm comes to rest; the last's own torque at rest is gravity's, and the
    first's arriving s̈ is the committed one). (Trajectory, the candidate of each row)."""
    R, m = x.shape
    u = np.diff(x, axis=1) / (2.0 * lam)                       # R × (m - 1)
    rows = np.arange(first, first + m)
    leave_r, leave_j = np.divmod(np.arange(R * (m - 1)), m - 1)
    came = np.ones((R, m - 1), bool)                           # arriving at rows 1 .. m - 1
    # (a constant s̈ taken from x's differences differs in its last bits: not a row of its own,
    # 57% of a run's rows had been such, an envelope audit's; the limits are planned 1e-9 inside,
    # so 1e-12 of a·s̈ cannot cross one)
    came[:, :-1] = ~np.isclose(u[:, 1:], u[:, :-1], rtol=1e-12, atol=0.0)
    come_r, come_j = np.nonzero(came)
    come_j = come_j + 1
    r = np.concatenate([leave_r, come_r])
    j = np.concatenate([leave_j, come_j])
    i = rows[j]
    return at_scaling(traj.q[i], traj.qd[i], traj.qdd[i], x[r, j],
                      np.concatenate([u[leave_r, leave_j], u[come_r, come_j - 1]])), r


def _rows_told(stage, total: int):
    """progress(i) for envelope_plan: the row, and once a few seconds have gone the time left at
    the rate so far."""
    begun = time.monotonic()

    def told(i: int) -> None:
        text = f"candidate futures, row {i + 1} of {total}"
        gone = time.monotonic() - begun
        if i > 0 and gone >= 2.0:
            from vampc.textio import rough_time
            text += f", about {rough_time(gone * (total - 1 - i) / i)} left"
        stage(text)
    return told


def envelope_plan(traj, evaluate, limits: Limits, window: int, futures: int, lam: float,
                  progress=None) -> Envelope:
    """--retime envelope: R registers of `window` rows side by side, each holding the rows the host
    sees (the arm's row and the next window - 1) as one candidate future runs them (`candidates`:
    the same rows at another speed). Every step the network computes every candidate's rows
    (`candidate_rows`) and the host takes the fastest candidate whose every torque is within
    `limits` (|τ| <= L: the limits the run plans to), its speeds within their caps by making;
    where none is, it keeps the plan it took before (a candidate of an earlier step, which comes to
    rest within the rows it saw then). A step at rest with no candidate within the limits waits
    there and tries again, slower (ENVELOPE_TRIES). Every plan kept was computed by the network
    whole, each of its rows as the arm will run it, so the arm never runs a row the network has not
    found within the limits, and never needs to (it can always stop within the rows it saw).
    `evaluate(rows)`: the network's effort torques of a Trajectory's rows and a mask of the rows
    to refuse (a narrower word that could not hold or overflowed on them). `progress(i)`: told the
    row every so often."""
    n_rows = traj.count
    L = np.array(limits.tau, float)
    cap = speed_caps(traj.qd, limits)
    out = Envelope(np.zeros(n_rows), np.zeros(n_rows), np.zeros(n_rows), np.zeros(n_rows, int),
                   np.zeros(n_rows, int), np.zeros(n_rows, int), np.zeros(n_rows))
    plan = np.zeros(1)           # the committed plan's x from this row on: at rest, nowhere to go
    U = ENVELOPE_U
    top = MAX_SPEED ** 2 / (2.0 * lam)     # the s̈ to the top speed from rest in one row: U's most
    last = time.monotonic()          # when the bar was last told
    for i in range(n_rows - 1):
        # (every 256 rows, or half a second: on the tick engine a row's candidates took 0.3 s, and
        # the bar said row 1 for 61 s: a new user's find)
        if progress is not None and (i % 256 == 0 or time.monotonic() - last >= 0.5):
            progress(i)
            last = time.monotonic()
        m = min(window, n_rows - i)
        x0 = out.x[i]
        if i + m - 1 == n_rows - 2 and (x0 > 0 or m >= 4):
            # no plan stops at the last row but one, where the arm at rest could not go on: a
            # constant s̈ cannot start and stop it in the one interval left (a register ending
            # there had left the arm so, the path refused: an envelope audit's). With a window of
            # 4 rows or more (`run`) no plan does: from rest at row n - 4 the register reaches the
            # last row
            m -= 1
        if not traj.qd[i:i + m].any():
            # the path stands still over the whole register: no torque depends on the speed, so
            # the candidates go straight to the top speed (U had doubled a row at a time from 1:
            # 7 rows standing still took 91 ms, the window retiming's 0.08 ms, an audit's)
            U = top
        for _ in range(ENVELOPE_TRIES):
            out.tries[i] += 1
            out.scale[i] = U
            kept = (plan[1] - plan[0]) / (2.0 * lam) if len(plan) > 1 else 0.0   # (its s̈)
            xs = candidates(x0, U, cap[i:i + m], futures, lam)
            bad = np.isnan(xs[:, 1])
            if not bad.all():
                rows, of = candidate_rows(traj, i, np.nan_to_num(xs[~bad]), lam)
                of = np.flatnonzero(~bad)[of]
                tau, refused = evaluate(rows)
                out.rows[i] += rows.count
                out.refused += int(refused.sum())
                over = np.any(np.abs(tau[:, :len(L)]) > L, axis=1) | refused
                np.logical_or.at(bad, of, over)
            # U doubles where the fastest was within the limits and not held by a cap at its next
            # row (where the path stands still every candidate is, at the top speed: U had grown
            # to 2^100 in a pause, and the move after it was refused or slowed 900 times: an
            # envelope audit's), halves where it was over
            held = xs[-1, 1] < x0 + 2.0 * lam * U * (1 - 1e-9)
            # (and not below the s̈ of the plan taken before: braking, U had halved every row to
            # 1e-12, and took 40 rows of hours each to grow back: an envelope audit's)
            if bad[-1]:
                U = max(U / 2, abs(kept))
            elif not held:
                U = min(U * 2, top)
            if not bad.all():
                r = int(np.flatnonzero(~bad)[-1])     # the fastest within the limits
                plan = xs[r]
                out.chosen[i] = r
                break
            out.chosen[i] = -1
            if x0 > 0 or (len(plan) > 1 and plan[1] > 0):
                break                    # none: the plan taken before
        else:                   # (the slowest tried: U / R of the last try, not U halved after it)
            raise VampcError(f"row {i + 1}: the arm is at rest and no candidate future is within "
                             f"the limits, down to an s̈ of {out.scale[i] / futures:.3g} leaving it")
        if x0 == 0 and plan[1] == 0:    # (one interval left: no s̈ starts and stops in it)
            raise VampcError(f"row {i + 1}: the arm came to rest one row before the last, where no "
                             "constant s̈ can start it and stop it again; give a longer --window")
        out.x[i + 1] = plan[1]
        out.u[i] = (plan[1] - plan[0]) / (2.0 * lam)
        plan = plan[1:]
    speed = np.sqrt(out.x)
    with np.errstate(divide="ignore"):
        out.t[1:] = np.cumsum(2.0 * lam / (speed[:-1] + speed[1:]))
    return out


def arriving(traj, res: Lookahead):
    """--retime window or envelope: each retimed row as the arm arrives at it, with the s̈ of the
    interval before it (the written row's q̈ is the s̈ leaving it; the first row is at rest), a
    Trajectory."""
    return at_scaling(traj.q, traj.qd, traj.qdd, res.speed ** 2,
                      np.concatenate([[0.0], res.accel[:-1]]), res.speed)


def violations(tau: np.ndarray, qd: np.ndarray, limits: Limits) -> list:
    """Every (row, joint) over its effort or speed limit, in row order."""
    found = []
    lim = np.array(limits.tau)
    over = np.abs(tau[:, :len(lim)]) > lim
    for r, j in zip(*np.nonzero(over)):
        found.append(Violation(int(r), int(j), float(tau[r, j]), float(lim[j]), "torque"))
    for j, v in enumerate(limits.qd):
        if v is not None:
            for r in np.flatnonzero(np.abs(qd[:, j]) > v):
                found.append(Violation(int(r), j, float(qd[r, j]), v, "speed"))
    return sorted(found, key=lambda x: (x.row, x.joint, x.kind))


def uniform_k(tau: np.ndarray, g: np.ndarray, qd: np.ndarray, limits: Limits, names,
              floor: float = 1.0) -> float:
    """The smallest k of the module docstring (VampcError where gravity alone breaks a limit);
    `floor` 0: without its max(1, ...), the k that would run a path within its limits faster."""
    n = len(limits.tau)
    lim = np.array(limits.tau)
    tau, g = tau[:, :n], g[:, :n]
    d = tau - g
    with np.errstate(divide="ignore", invalid="ignore"):
        need = np.where(d > 0, d / (lim - g), np.where(d < 0, -d / (lim + g), 0.0))
    k2 = max(floor, float(np.max(need, initial=0.0)))
    if not np.isfinite(k2):
        r, j = (int(x) for x in np.argwhere(~np.isfinite(need))[0])
        raise VampcError(f"row {r + 1}: joint '{names[j]}' sits at its limit {lim[j]:g} "
                         "at rest: no time scaling helps")
    for j, v in enumerate(limits.qd):
        if v is not None:
            k2 = max(k2, float(np.max((qd[:, j] / v) ** 2, initial=0.0)))
    return float(np.sqrt(k2))


def ahead(row: int, window: int) -> tuple[int, int]:
    """(the step at which a row enters the register, how many steps before the motors take it)."""
    return max(0, row - window + 1), min(row, window - 1)


def plot_svg(joints, times: np.ndarray, res: Lookahead, limits: Limits, title: str,
             fmt: str = "svg") -> str | bytes:
    """Per motor (`joints`: the chain's independent joints), torque over time against ±its limit,
    in its unit (N·m revolute, N prismatic): the path as given, and the retimed one (its own time
    axis) when there is one, with a last panel of the speed ṡ over time. SVG text (`fmt` "png" or
    "pdf": those bytes, as the report's pictures: vampc.report.svg.rendered)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # (a joint named 'a$_$' is text; the salt makes the ids of markers and clips, so the same run
    # gives the same bytes, as the report's pictures do)
    with matplotlib.rc_context({"text.parse_math": False, "svg.hashsalt": "vampc"}):
        return _plot(plt, joints, times, res, limits, title, fmt)


def _plot(plt, joints, times: np.ndarray, res: Lookahead, limits: Limits, title: str,
          fmt: str = "svg") -> str | bytes:
    import io
    n = len(limits.tau)
    panels = n + (res.retimed is not None)
    fig, axes = plt.subplots(panels, 1, figsize=(8, 1.6 * panels + 0.8), sharex=True, squeeze=False)
    if res.retimed is not None:
        new_t = res.new_times(times)
        label = (f"uniform (k = {res.k_closed_form:.4g})" if res.k is not None else
                 f"envelope ({res.futures} futures of {res.ahead_rows} rows)" if res.retime == "envelope"
                 else f"window ({res.ahead_rows} rows ahead)")
    for j, ax in enumerate(axes[:n, 0]):
        ax.plot(times, res.effort[:, j], lw=1, color="tab:red", label="as given")
        if res.retimed is not None:
            ax.plot(new_t, res.retimed_effort[:, j], lw=1, color="tab:blue", label=f"retimed, {label}")
        for sign in (1, -1):
            ax.axhline(sign * limits.tau[j], color="black", lw=0.8, ls="--")
        ax.set_ylabel(f"{joints[j].name}\n({'N·m' if joints[j].sigma else 'N'})", fontsize=8)
        ax.tick_params(labelsize=7)
    if res.retimed is not None:
        ax = axes[n, 0]
        ax.plot(new_t, res.speed, lw=1, color="tab:blue")
        ax.axhline(1.0, color="tab:red", lw=0.8, ls=":")
        ax.set_ylabel("speed ṡ\n(1 = as given)", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 0].legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("time (s)")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    if fmt != "svg":
        from vampc.report.svg import rendered
        try:
            return rendered(fig, fmt)
        finally:
            plt.close(fig)
    out = io.StringIO()
    fig.savefig(out, format="svg", metadata={"Date": None})
    plt.close(fig)
    return out.getvalue()
