"""`vampc lookahead --retime window` (issue "Trajectory look-ahead", part 3): the speed decided row by
row from the rows in the register. Checked by the reference dynamics (not by the network) that every
retimed row is within its limits, that the path is the same, the velocity continuous and the times
consistent with it; that a decision depends on no row beyond the look-ahead; that the retimed rows'
torques are `vampc emulate`'s bit for bit; and, with the whole path in view, that the duration is
TOPP-RA's time optimum."""
from __future__ import annotations

import re

import numpy as np
import pytest
from click.testing import CliRunner
from test_lookahead import LIMITS, write_path

from vampc.cli import main
from vampc.dynamics.reference import rnea
from vampc.lookahead import Limits, optimal_plan, window_plan
from vampc.robot import load_robot

PUMA = "examples/puma560.yaml"
LIM = np.array([10, 60, 20, 1, 1, 1.0])
RATE = 1000.0


def bump_path(T: float = 0.6, centre: float = 0.3):
    """q(s) = s Δq + a Gaussian-windowed sine, s = t / T: moving at both ends, exact derivatives."""
    t = np.arange(int(round(T * RATE)) + 1) / RATE
    s = t / T
    dq, amp, w, width = np.array([1.2, 0.8, -1.0, 1.5, 1.0, 1.5]) * 0.3, np.array([.3, .2, .3, .4, .3, .4]), 4 * np.pi, 0.15
    env = np.exp(-((s - centre) / width) ** 2)
    env_d = env * (-2 * (s - centre) / width ** 2) / T
    env_dd = env * (4 * (s - centre) ** 2 / width ** 4 - 2 / width ** 2) / T ** 2
    sn, cs = np.sin(w * s), np.cos(w * s)
    q = np.outer(s, dq) + np.outer(env * sn, amp)
    qd = np.outer(np.full_like(s, 1 / T), dq) + np.outer(env_d * sn + env * cs * w / T, amp)
    qdd = np.outer(env_dd * sn + 2 * env_d * cs * w / T - env * sn * (w / T) ** 2, amp)
    return t, q, qd, qdd


def affine_parts():
    """a, b, c of the bump path's rows by the reference dynamics (the window plan's inputs), its
    q', and the limits (the flange's speed limited too)."""
    chain = load_robot(PUMA)
    _, q, qd, qdd = bump_path()
    z = np.zeros_like(q)
    c = rnea(chain, q, z, z)
    a, b = rnea(chain, q, z, qd) - c, rnea(chain, q, qd, qdd) - c
    return a, b, c, qd, Limits(tuple(LIM), (None,) * 5 + (4.0,))


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    folder = tmp_path_factory.mktemp("law")
    program = folder / "puma.vamp.json"
    assert CliRunner().invoke(main, ["compile", PUMA, "-o", str(program)]).exit_code == 0
    (folder / "lim.csv").write_text(LIMITS)
    return folder, program, folder / "lim.csv", write_path(folder, *bump_path())


def retime(setup, *extra, name="w.csv", window=64):
    folder, program, limits, path = setup
    out, tau = folder / name, folder / ("tau-" + name)
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", str(window), "--limits", str(limits), "--retime", "window", "--check",
                                  "-o", str(out), "--torques", str(tau), *extra])
    assert r.exit_code == 0, r.output
    return r.output, np.loadtxt(out, delimiter=",", skiprows=1), tau


def test_the_retimed_path_is_the_same_path_within_every_limit_by_the_reference(setup):
    text, data, _ = retime(setup)
    t, q, qd, qdd = data[:, 0], data[:, 1:7], data[:, 7:13], data[:, 13:19]
    _, q0, qd0, qdd0 = bump_path()
    chain = load_robot(PUMA)
    assert (np.abs(rnea(chain, q0, qd0, qdd0)) > LIM).any()          # the path as given is over
    assert np.array_equal(q, q0)                                     # the same positions, row by row
    tau = rnea(chain, q, qd, qdd)
    assert np.all(np.abs(tau) <= LIM) and np.all(np.abs(qd[:, 5]) <= 4)
    assert np.max(np.abs(tau) / LIM) > 0.999                         # and it uses them
    assert np.all(np.diff(t) > 0) and not qd[0].any() and not qd[-1].any()   # rest to rest
    assert "retimed rows by the reference: 0 violations" in text and "retimed rows by the network: 0" in text


def test_velocity_is_continuous_and_the_times_agree_with_it(setup):
    """Between two rows s̈ is constant: the velocity changes by at most about q̈ Δt (the row's q̈ is
    the next segment's, so allow twice that; a step in velocity would not be bounded so). The speed
    ṡ read back from each row's q̇ against the path's q' gives the row times (a segment of path
    time Δ at constant s̈ takes 2Δ / (ṡ_i + ṡ_i+1)) and each row's q̈ = q'' ṡ² + q' s̈."""
    _, data, _ = retime(setup)
    t, qd, qdd = data[:, 0], data[:, 7:13], data[:, 13:19]
    _, _, d1, d2 = bump_path()
    speed = np.einsum("ij,ij->i", qd, d1) / np.einsum("ij,ij->i", d1, d1)
    came = d2[1:] * speed[1:, None] ** 2 + d1[1:] * (np.diff(speed ** 2) / (2 / RATE))[:, None]
    dt = np.diff(t)[:, None]             # q̈ through an interval: from the row's to the arriving one
    jump = np.abs(np.diff(qd, axis=0))
    bound = np.maximum(np.abs(qdd[:-1]), np.abs(came)) * dt
    assert np.all(jump <= 2 * bound + 1e-12)
    assert np.allclose(qd, d1 * speed[:, None], rtol=1e-12, atol=1e-15)     # along the path
    lam = 1 / RATE
    assert np.allclose(np.diff(t), 2 * lam / (speed[:-1] + speed[1:]), rtol=1e-9)
    accel = np.append(np.diff(speed ** 2) / (2 * lam), 0.0)
    assert np.allclose(qdd, d2 * speed[:, None] ** 2 + d1 * accel[:, None], rtol=1e-6, atol=1e-9)


def test_the_summary_names_the_rows_of_the_slowest_and_fastest_speed(setup):
    """The summary's ṡ range names its rows, read back here from the -o file's q̇ against the path's
    q' (its lowest was often the first step off rest, which a new user took for the path's slowest
    stretch)."""
    text, data, _ = retime(setup)
    _, _, d1, _ = bump_path()
    speed = np.einsum("ij,ij->i", data[:, 7:13], d1) / np.einsum("ij,ij->i", d1, d1)
    found = re.search(r"ṡ \(leaving out the rest at start and end\) (\S+) \(row (\d+)\) to (\S+) "
                      r"\(row (\d+)\) × the path's speed", text)
    assert found, text
    low, high = 1 + int(np.argmin(speed[1:-1])), int(np.argmax(speed))
    assert (int(found[2]), int(found[4])) == (low + 1, high + 1)
    assert float(found[1]) == float(f"{speed[low]:.3g}") and float(found[3]) == float(f"{speed[high]:.3g}")


def test_the_retimed_rows_torques_are_emulates_bit_for_bit(setup):
    folder, program, _, _ = setup
    _, _, tau = retime(setup)
    em = folder / "em.csv"
    r = CliRunner().invoke(main, ["emulate", str(program), "--trajectory", str(folder / "w.csv"), "-o", str(em)])
    assert r.exit_code == 0, r.output
    assert em.read_text() == tau.read_text()


def test_a_decision_depends_on_no_row_beyond_the_look_ahead():
    """x at row j + 1 is decided at step j from rows j .. j + ahead - 1: changing every row from K on
    leaves x[0 .. K - ahead + 1] as it was, and changes later ones."""
    a, b, c, qd, limits = affine_parts()
    ahead, K = 64, 300
    x, _, _ = window_plan(a, b, c, qd, limits, ahead, 1 / RATE)
    b2 = b.copy()
    b2[K:] *= 3.0                          # the path much faster from row K on
    x2, _, _ = window_plan(a, b2, c, qd, limits, ahead, 1 / RATE)
    keep = K - ahead + 2
    assert np.array_equal(x[:keep], x2[:keep]) and not np.array_equal(x[keep:], x2[keep:])


def test_more_futures_see_further_and_are_never_slower(setup):
    text1, d1, _ = retime(setup, name="r1.csv")
    text4, d4, _ = retime(setup, "--futures", "4", name="r4.csv")
    assert "64 rows ahead (1 × window 64)" in text1 and "256 rows ahead (4 × window 64)" in text4
    # the bump path moves at both ends, the window retiming runs it from rest to rest: said (a new
    # user read the window's longer duration against the uniform one's as a slower optimum)
    assert "from rest to rest (as given 0.6 s, which starts and ends moving)" in text1
    # a violation is seen as its row enters the top register: R × M - 1 steps ahead at most
    assert "window 64 (63 ms ahead)" in text1 and "window 64 × 4 registers (255 ms ahead)" in text4
    assert d4[-1, 0] < d1[-1, 0]
    # R registers of M rows see what one of R·M rows sees: the same plan
    folder, program, limits, path = setup
    out = folder / "w256.csv"
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "256", "--limits", str(limits), "--retime", "window", "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert out.read_text() == (folder / "r4.csv").read_text()


def test_the_summary_says_what_the_look_ahead_costs(setup):
    """The summary gives the plan with the whole path in view (`optimal_plan`) beside the window's:
    its duration is the window plan's when the window sees the whole path (bit for bit: the same
    recursion, in one pass instead of one per step), never longer, and the cost printed is the
    ratio of the two durations (the -o files' last t)."""
    folder, program, limits, path = setup
    rows = len(np.loadtxt(path, delimiter=",", skiprows=1))
    costs = []
    for window, name in ((64, "c1.csv"), (rows, "call.csv")):
        text, out, _ = retime(setup, name=name, window=window)
        found = re.search(r"with the whole path in view \(the time-optimal plan on these rows and "
                          r"limits, from rest to rest\): (\S+) s; seeing (\d+) rows ahead costs "
                          r"([+-][\d.]+)%", text)
        assert found, text
        best, cost = float(found[1]), float(found[3])
        assert int(found[2]) == window
        assert abs(cost - round(100 * (out[-1, 0] / best - 1), 1)) < 0.06
        costs.append(cost)
        if window == rows:                # the whole path in view: the window's plan is the optimum
            assert abs(out[-1, 0] - best) <= 3e-6 * best and cost == 0.0    # (best: 6 digits)
    assert costs[0] > 1.0                 # 64 rows cost something on this path
    a, b, c, qd, lim = affine_parts()
    for whole, one_pass in zip(window_plan(a, b, c, qd, lim, len(qd), 1 / RATE),
                               optimal_plan(a, b, c, qd, lim, 1 / RATE)):
        assert np.array_equal(whole, one_pass)


def test_with_the_whole_path_in_view_the_duration_is_topp_ras_optimum():
    """TOPP-RA (an independent implementation: its own spline of the path, its own LP solver) on the
    same rows and limits, starting and ending at rest, each interval's s̈ checked at both its rows
    (its interpolation discretization, as vampc plans): the window method seeing the whole path finds
    the same time-optimal duration (to 1%: the spline and the samples differ slightly)."""
    toppra = pytest.importorskip("toppra")
    import toppra.algorithm as algo
    import toppra.constraint as constraint
    toppra.setup_logging("ERROR")
    chain = load_robot(PUMA)
    t, q, qd, qdd = bump_path(T=0.15, centre=0.5)
    z = np.zeros_like(q)
    c = rnea(chain, q, z, z)
    a, b = rnea(chain, q, z, qd) - c, rnea(chain, q, qd, qdd) - c
    x, _, times = window_plan(a, b, c, qd, Limits(tuple(LIM), (None,) * 6), len(t), 1 / RATE)
    cons = [constraint.JointTorqueConstraint(
        lambda p, v, acc: rnea(chain, p[None], v[None], acc[None])[0], np.column_stack([-LIM, LIM]),
        np.zeros(6), discretization_scheme=constraint.DiscretizationType.Interpolation)]
    best = algo.TOPPRA(cons, toppra.SplineInterpolator(t, q), gridpoints=t,
                       parametrizer="ParametrizeConstAccel").compute_trajectory(0, 0)
    assert best is not None
    assert abs(times[-1] / best.duration - 1) < 0.01, (times[-1], best.duration)


@pytest.mark.parametrize("args, message", [
    (["--futures", "2"], r"--futures applies with --retime window"),
    (["--retime", "window", "--window", "1", "--futures", "2"],
     r"--retime window sees 2 row\(s\) ahead: it needs at least 3"),
])
def test_window_usage(setup, args, message):
    folder, program, limits, path = setup
    window = [] if "--window" in args else ["--window", "64"]     # (an option given twice: refused)
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  *window, "--limits", str(limits), *args])
    assert r.exit_code == 2 and re.search(message, r.output), r.output
    assert len(r.output.strip().splitlines()) == 1


def test_a_retimed_path_faster_than_the_network_is_refused(setup, tmp_path):
    """Rows closer together than λ need the network sooner: --clock checks the retimed intervals."""
    folder, program, limits, _ = setup
    t, q, qd, qdd = bump_path()
    slow = write_path(tmp_path, t, q, qd * 0.05, qdd * 0.0025, "slow.csv")    # far below the limits
    out = tmp_path / "never.csv"
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(slow), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(limits), "--retime", "window",
                                  "--clock", "25kHz", "-o", str(out)])
    assert r.exit_code == 1 and "the retimed path has rows" in r.output and "cannot keep up" in r.output, r.output
    assert not out.exists()


def rest_paths():
    """Paths that stand still for some rows (q' = 0): no limit bounds the speed there."""
    t = np.arange(300) / RATE
    c = np.array([5, 3, 4, 6, 5, 7.0])
    u = np.clip(t - 0.02, 0, None)                      # at rest for 20 rows, then moving
    start = (t, np.outer(u ** 3, c), np.outer(3 * u ** 2, c), np.outer(6 * u, c))
    u = np.clip(0.28 - t, 0, None)                      # moving, then at rest for 20 rows
    end = (t, np.outer(-u ** 3, c), np.outer(3 * u ** 2, c), np.outer(-6 * u, c))
    still = (t, np.zeros((300, 6)), np.zeros((300, 6)), np.zeros((300, 6)))
    return {"start": start, "end": end, "still": still}


@pytest.mark.parametrize("name", ["start", "end", "still"])
def test_a_path_standing_still_is_run_at_most_max_speed(setup, tmp_path, name):
    """Where the path stands still nothing but MAX_SPEED bounds ṡ: the rows there took no time (the
    same t, and q̇ = 0·∞ = nan) or the plan failed."""
    from vampc.lookahead import MAX_SPEED
    folder, program, limits, _ = setup
    t, q, qd, qdd = rest_paths()[name]
    path = write_path(tmp_path, t, q, qd, qdd, f"{name}.csv")
    out = tmp_path / "out.csv"
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(limits), "--retime", "window",
                                  "--check", "-o", str(out)])
    assert r.exit_code == 0, r.output
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.isfinite(got).all()
    steps = np.diff(got[:, 0])
    assert (steps > 0).all()
    assert steps.min() >= 2 / RATE / (2 * MAX_SPEED) * (1 - 1e-12)       # no row faster than MAX_SPEED
    retimed_qd = got[:, 7:13]
    assert not retimed_qd[0].any() and not retimed_qd[-1].any()          # from rest to rest
    assert np.allclose(got[:, 1:7], q)                                   # the same path
    ref = rnea(load_robot(PUMA), got[:, 1:7], retimed_qd, got[:, 13:19])
    assert (np.abs(ref) <= LIM).all() and (np.abs(retimed_qd[:, 5]) <= 4).all()
    # the summary says the wait is not kept, and how long it took, from the file's own times (it
    # gave only the ṡ range: 0.3 s of a pause became 3 ms unsaid, a look-ahead stress test found)
    pause = ~qd[:-1].any(axis=1) & ~qd[1:].any(axis=1)
    # (each time with its prefix: a 10 s wait read "1e+04 ms", an audit's find)
    said = re.search(r"the path stands still \(q' = 0\) over (\d+) intervals?, ([\d.]+) (s|ms|µs) as given: "
                     r"retimed at ṡ up to 100 × the path's speed \(at most 100\), ([\d.]+) (s|ms|µs) \(a time scaling cannot "
                     r"keep a wait", r.output)
    unit = {"s": 1.0, "ms": 1e-3, "µs": 1e-6}
    assert said and int(said[1]) == pause.sum() > 0, r.output
    assert float(said[2]) * unit[said[3]] == pytest.approx(pause.sum() * 1e-3)
    assert float(said[4]) * unit[said[5]] == pytest.approx(steps[pause].sum(), rel=1e-3)


def word_retime(tmp_path, word: str, path, limits):
    """The Puma compiled in `word`, the path window-retimed on it with --check: (result, output)."""
    program = tmp_path / f"{word}.vamp.json"
    assert CliRunner().invoke(main, ["compile", PUMA, "--word", word, "-o", str(program)]).exit_code == 0
    out = tmp_path / "out.csv"
    return CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                     "--window", "64", "--limits", str(limits), "--retime", "window",
                                     "--check", "-o", str(out)]), out


@pytest.mark.parametrize("word", ["float32", "q16.16"])
def test_a_narrower_word_plans_within_its_error_and_stays_within_every_limit(setup, tmp_path, word):
    """The network's torques in a narrower word are off by up to the error its --check allows: the
    plan keeps that much inside each effort limit, so the reference finds none over (planning
    1e-9 inside, as for float64, went over by 1e-6 of a limit in float32 and 6e-5 in q16.16)."""
    folder, _, limits, path = setup
    r, out = word_retime(tmp_path, word, path, limits)
    assert r.exit_code == 0, r.output
    assert "retimed rows by the reference: 0 violations" in r.output
    margin, tolerance = {"float32": ("0.0006", "1e-5"), "q16.16": ("0.06", "0.001")}[word]
    assert (f"planned to effort limits {margin} tighter, and 1e-9 of each: the error a {word} network's "
            f"--check allows ({tolerance} of the largest |τ|, taken of the largest effort limit, 60)"
            in r.output)
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    tau = rnea(load_robot(PUMA), got[:, 1:7], got[:, 7:13], got[:, 13:19])
    assert (np.abs(tau) <= LIM).all()
    assert np.max(np.abs(tau) / LIM) > 0.99                  # and still uses them


def test_a_narrower_word_retimed_without_check_says_its_error_was_not_measured(setup, tmp_path):
    """The plan trusts a narrower word's torques to the error --check allows; a new user's arm in
    q24.8 erred more (1.2e-2 of the largest |τ|), and its retimed paths went up to 1.009 times a
    limit by the reference dynamics, exit 0, unsaid. A retiming in a narrower word without --check
    now warns that the error was not measured; with --check such a run fails (and nothing warns:
    it was measured); a float64 retiming has no word error to warn of."""
    folder, program, limits, path = setup
    coarse = tmp_path / "q24.8.vamp.json"
    assert CliRunner().invoke(main, ["compile", PUMA, "--word", "q24.8", "-o", str(coarse)]).exit_code == 0
    out = tmp_path / "out.csv"
    base = ["--trajectory", str(path), "--rate", "1kHz", "--window", "64", "--limits", str(limits),
            "--retime", "window", "-o", str(out)]
    said = ("the retiming plans each effort limit 0.06 inside, the error --check allows a q24.8 "
            "network (0.001 of the largest |τ|), which this run does not measure")
    r = CliRunner().invoke(main, ["lookahead", str(coarse), *base])
    assert r.exit_code == 0 and said in r.output, r.output
    assert "(--check measures it and fails the run then; vampc precision gives each fixed-point " \
        "width's error)" in r.output, r.output
    single = tmp_path / "f32.vamp.json"           # (vampc precision is for fixed point: not said)
    assert CliRunner().invoke(main, ["compile", PUMA, "--word", "float32", "-o", str(single)]).exit_code == 0
    r = CliRunner().invoke(main, ["lookahead", str(single), *base])
    assert r.exit_code == 0 and "a float32 network (1e-5 of the largest |τ|), which this run does " \
        "not measure" in r.output and "precision" not in r.output, r.output
    r = CliRunner().invoke(main, ["lookahead", str(coarse), *base, "--check", "--write-failed"])
    assert r.exit_code == 1 and said not in r.output, r.output
    assert re.search(r"check against reference RNEA: max relative error [\d.e-]+, tolerance 0\.001: FAILED",
                     r.output), r.output
    r = CliRunner().invoke(main, ["lookahead", str(program), *base])
    assert r.exit_code == 0 and "does not measure" not in r.output, r.output


@pytest.mark.parametrize("write_failed", [False, True])
def test_a_retiming_over_a_limit_fails_and_replaces_no_existing_file(setup, tmp_path, monkeypatch,
                                                                     write_failed):
    """Should the network find a retimed row over a limit (here: a plan made 1% outside them), the
    run fails (it printed the violations and exited 0) and, as emulate's failed --check, replaces no
    existing output unless --write-failed, nor writes a new one beside it (said so). All outputs are
    written together, so a failure or a signal leaves none half done."""
    import vampc.lookahead as la
    monkeypatch.setattr(la, "PLAN_MARGIN", -0.01)
    folder, program, limits, path = setup
    old, new, plot = tmp_path / "old.csv", tmp_path / "new.csv", tmp_path / "p.svg"
    old.write_text("before\n")
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(limits), "--retime", "window",
                                  "-o", str(old), "--torques", str(new), "--plot", str(plot)]
                           + (["--write-failed"] if write_failed else []))
    assert r.exit_code == 1, r.output
    assert re.search(r"retimed rows by the network: \d+ violations, with the s̈ arriving at each row "
                     r"\d+ violations \(worst [\d.]+ × a limit\) FAILED", r.output), r.output
    if write_failed:
        assert old.read_text().startswith("t,q1")
        assert new.exists() and plot.exists() and "--torques " + str(new) + " written although the retiming failed" in r.output
    else:       # (and no new file beside the one kept, which it would not match: since 2026-12-06)
        assert old.read_text() == "before\n" and "-o " + str(old) + " NOT written: the retiming failed" in r.output
        assert not new.exists() and not plot.exists(), r.output
        assert f"--torques {new} NOT written: the retiming failed and {old} is kept" in r.output, r.output


def test_write_failed_applies_with_check_or_retime(setup):
    folder, program, limits, path = setup
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--torques", "x.csv", "--write-failed"])
    assert r.exit_code == 2 and "--write-failed applies with --check or --retime" in r.output, r.output


def test_write_failed_to_standard_output_only_does_not_apply(setup):
    """Standard output is never held back: --write-failed with no file output would do nothing."""
    folder, program, limits, path = setup
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(limits), "--check", "--torques", "-",
                                  "--write-failed"])
    assert r.exit_code == 2 and "standard output is never held back" in r.output, r.output


def test_a_failed_retiming_leaves_the_passing_check_ok(setup, tmp_path, monkeypatch):
    """The reference check of the rows as given says OK when it passes, though the run fails for
    the retiming; and the message names both when both fail."""
    import vampc.lookahead as la
    monkeypatch.setattr(la, "PLAN_MARGIN", -0.01)
    folder, program, limits, path = setup
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(limits), "--retime", "window", "--check",
                                  "--torques", str(tmp_path / "t.csv")])
    assert r.exit_code == 1
    assert re.search(r"tolerance 1e-9: OK; retimed rows by the reference: \d+ violations FAILED", r.output), r.output
    assert "written although the retiming and check failed" in r.output


def test_no_row_is_over_a_limit_with_the_acceleration_arriving_at_it_either(setup):
    """Each written row's q̈ is the s̈ of the interval leaving it; s̈ jumps at the rows, and with the
    s̈ of the interval arriving at it a row was over a limit (a new user's run: up to 1.7 times,
    while --check said 0 violations). The plan keeps both rows of every interval within the limits
    now, and --check says so; worked out here from the written file alone: ṡ from q̇ against the
    path's q', the arriving s̈ from ṡ² of two rows."""
    text, data, _ = retime(setup, name="arr.csv")
    q, qd = data[:, 1:7], data[:, 7:13]
    _, _, d1, d2 = bump_path()
    speed = np.einsum("ij,ij->i", qd, d1) / np.einsum("ij,ij->i", d1, d1)
    x = speed ** 2
    came = np.concatenate([[0.0], np.diff(x) / (2 / RATE)])
    tau = rnea(load_robot(PUMA), q, d1 * speed[:, None], d2 * x[:, None] + d1 * came[:, None])
    over = int((np.abs(tau) > LIM * (1 + 1e-9)).any(axis=1).sum())
    near = int((np.abs(tau) > LIM * (1 - 1e-9)).any(axis=1).sum())
    said = re.search(r"with the s̈ arriving at each row: (\d+) violations?", text)
    assert said, text
    assert over == int(said.group(1)) == 0, (said.group(1), over)
    assert near > 0                      # (the arriving s̈ meets a limit: the plan uses them)


@pytest.mark.parametrize("column, value", [(7, 1e12), (13, 1e13)], ids=["qd", "qdd"])
def test_a_row_whose_speed_or_acceleration_dwarfs_its_tangent_is_never_silently_over_a_limit(
        setup, tmp_path, column, value):
    """A row with a q̇ (or q̈) of 1e12 has b, the torque's part in ṡ², a million million times a,
    its part in s̈: a was taken for zero against b, the row's s̈ left unbounded, and the arm went
    over a limit, exit 0 (by the reference: 1.01 times with the arriving s̈, 2.0 times with the
    leaving one; a new user's run). Now each row is planned with its a; the rounding left is the
    network's to find (x of the row after a spike is the difference of two numbers 1e8 times it):
    checked here by the reference, from the written file, with the s̈ leaving each row and the s̈
    arriving at it, without --check: a row over a limit fails the run, and none is over by more
    than rounding."""
    folder, program, limits, _ = setup
    t, q, d1, d2 = bump_path()
    d1, d2 = d1.copy(), d2.copy()
    (d1 if column == 7 else d2)[20, 0] = value
    path = write_path(tmp_path, t, q, d1, d2)
    out = tmp_path / "out.csv"
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "8", "--limits", str(limits), "--retime", "window",
                                  "-o", str(out), "--write-failed"])
    assert r.exit_code in (0, 1) and "Traceback" not in r.output, r.output
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    got_q, got_qd, got_qdd = data[:, 1:7], data[:, 7:13], data[:, 13:19]
    chain = load_robot(PUMA)
    leaving = np.abs(rnea(chain, got_q, got_qd, got_qdd)) / LIM
    speed = np.einsum("ij,ij->i", got_qd, d1) / np.einsum("ij,ij->i", d1, d1)
    x = speed ** 2
    came = np.concatenate([[0.0], np.diff(x) / (2 / RATE)])
    arriving = np.abs(rnea(chain, got_q, d1 * speed[:, None], d2 * x[:, None] + d1 * came[:, None])) / LIM
    worst = max(leaving.max(), arriving.max())
    assert worst < 1 + 1e-6, worst
    if worst > 1 + 1e-12:                   # (the reference's own rounding aside)
        assert r.exit_code == 1 and re.search(r"retimed rows by the network: \d+ violations?, with the s̈ "
                                              r"arriving at each row 1 violation \(worst 1\.0+\d+ × a "
                                              r"limit\) FAILED", r.output), (worst, r.output)
    else:
        assert r.exit_code == 0, r.output


def _word_program_and_limits(tmp_path, word: str, flange: str):
    """The Puma compiled in `word`, and LIM's limits but the flange's (`tau,qd` of its row)."""
    program = tmp_path / f"{word}.vamp.json"
    assert CliRunner().invoke(main, ["compile", PUMA, "--word", word, "-o", str(program)]).exit_code == 0
    limits = tmp_path / "lim.csv"
    limits.write_text("joint,tau,qd\nwaist,10,\nshoulder,60,\nelbow,20,\nwrist_roll,1,\nwrist_bend,1,\n"
                      f"flange,{flange}\n")
    return program, limits


def test_a_limit_within_a_fixed_point_words_error_is_refused_naming_it(setup, tmp_path):
    """A q16.16 network's torques are off by up to 1e-3 of the run's largest |τ| (--check's
    tolerance: of the largest of any joint), not of each joint's: planned 1e-3 of each limit inside,
    a flange limit of 0.0005 N·m (the shoulder's 60) made both retimings fail on rows the network
    found over (a new user's run) that the reference did not. Such a limit cannot be kept by any
    plan: the command says so before the run, naming the limits file and the joint."""
    folder, _, _, path = setup
    program, limits = _word_program_and_limits(tmp_path, "q16.16", "0.0005,")
    out = tmp_path / "out.csv"
    for how in ("uniform", "window"):
        r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                      "--window", "64", "--limits", str(limits), "--retime", how,
                                      "-o", str(out)])
        assert r.exit_code == 1, r.output
        assert (f"{limits}: joint 'flange': its effort limit 0.0005 is within the error a q16.16 "
                "network's --check allows (0.06: of the largest effort limit, 60)") in r.output
        assert "Traceback" not in r.output and not out.exists()
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(limits)])
    assert r.exit_code == 0, r.output          # (without a retiming, the limits are only reported)


def test_retimed_times_float64_cannot_tell_apart_are_refused_and_rough_ones_said(setup, tmp_path):
    """A path whose t starts at 1.7e9 (a Unix time) and rows 1e-5 s apart: the window retiming's
    rows (as short as λ/100) came out at equal times, exit 0, and the file written could not be
    read back ("does not come after"); at 1 kHz their intervals were off by up to 2% (a new
    user's run). Refused, naming the rows, with nothing written; warned."""
    folder, program, limits, _ = setup
    rows = 50
    zero = np.zeros((rows, 6))
    out = tmp_path / "out.csv"
    for rate, step in (("100kHz", 1e-5), ("1kHz", 1e-3)):
        path = write_path(tmp_path, 1.7e9 + np.arange(rows) * step, zero, zero, zero)
        r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", rate,
                                      "--window", "10", "--limits", str(limits), "--retime", "window",
                                      "-o", str(out)])
        if rate == "100kHz":
            assert r.exit_code == 1 and "float64 cannot tell them apart from a t starting at 1700000000" in r.output
            assert not out.exists()
        else:
            assert r.exit_code == 0, r.output
            assert re.search(r"the retimed rows' times hold their intervals only to [\d.]+% in float64, "
                             r"from t = 1700000000; a t column starting near 0 holds them exactly",
                             r.output), r.output
            t = np.loadtxt(out, delimiter=",", skiprows=1)[:, 0]
            assert (np.diff(t) > 0).all()


def test_retimed_times_too_long_for_float64_blame_the_plan_not_the_first_t(setup, tmp_path):
    """A speed limit of 1e-12 (the least a limits file takes) made a plan of about 1e12 s whose rows
    float64 could not tell apart, and the advice was to start the path's t near 0, which it did (a
    look-ahead audit's find): the plan's own length is said, and the limits suspected."""
    folder, program, limits, _ = setup
    t, q, qd, qdd = bump_path()
    still = 20                                   # the path ends standing still for 20 rows
    path = write_path(tmp_path, np.concatenate([t, t[-1] + np.arange(1, still + 1) / RATE]),
                      np.vstack([q, np.repeat(q[-1:], still, 0)]), np.vstack([qd, np.zeros((still, 6))]),
                      np.vstack([qdd, np.zeros((still, 6))]))
    tiny = tmp_path / "tiny.csv"
    tiny.write_text(limits.read_text().rstrip("\n").rsplit("\n", 1)[0] + "\nflange,1,1e-12\n")
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(tiny), "--retime", "window"])
    assert r.exit_code == 1 and re.search(r"float64 cannot tell them apart at that size: the retimed "
                                          r"path runs [\d.e+]+ s from its first row to its last, so "
                                          r"long for limits far below what the path asks \(check them, "
                                          r"the speed limits above all\)$", r.stderr.strip()), r.output
    assert "starting near 0" not in r.output and " 0 s apart" not in r.output    # (the plan's own)


def test_a_wide_fixed_point_word_plans_to_the_tolerance_given(tmp_path, setup):
    """The word's margin is --check's tolerance of the largest limit (1e-3 for any fixed point):
    a q32.32 program's flange limit of 0.05 N·m is within it and refused, though the word errs by
    7e-10 of the largest |τ|; --tolerance 1e-8 plans to that, and --check holds the run to it (a
    reviewer's find). --tolerance on a float64 program is a usage error."""
    folder, program, _, path = setup
    wide, limits = _word_program_and_limits(tmp_path, "q32.32", "0.05,4")
    args = ["lookahead", str(wide), "--trajectory", str(path), "--rate", "1kHz", "--window", "64",
            "--limits", str(limits), "--retime", "window", "--check"]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 1 and "joint 'flange': its effort limit 0.05 is within the error" in r.output
    r = CliRunner().invoke(main, args + ["--tolerance", "1e-8"])
    assert r.exit_code == 0, r.output
    assert "tolerance 1e-8: OK; retimed rows by the reference: 0 violations" in r.output
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "64", "--limits", str(limits), "--tolerance", "1e-8",
                                  "--check"])
    assert r.exit_code == 2 and "--tolerance applies to a program in a narrower word" in r.output


def test_a_window_that_sees_the_whole_path_plans_the_whole_path_plan():
    """A register of at least the path's rows sees to the last row at every step: its plan is the
    whole-path plan bit for bit, from one backward pass (a 20 000-row path with --window 20000
    took 62.6 s with a backward pass per step, 1.6 s now; the same 95.483 s duration), and one row
    fewer in view is another plan."""
    rng = np.random.default_rng(0)
    n = 300
    s = np.linspace(0, 1, n)
    a = 1 + 0.5 * np.sin(np.outer(s, [3, 5, 7]) + rng.uniform(0, 3, 3))
    b = np.cos(np.outer(s, [2, 4, 6])) * rng.uniform(0.2, 2, 3)
    c = 0.3 * np.sin(np.outer(s, [1, 2, 3]))
    qd = np.cos(np.outer(s, [1, 2, 3]))
    limits = Limits((2.0, 2.5, 3.0), (None, None, None))
    whole = optimal_plan(a, b, c, qd, limits, 1e-3)
    for ahead in (n, n + 7):
        got = window_plan(a, b, c, qd, limits, ahead, 1e-3)
        assert all(np.array_equal(g.view(np.uint64), w.view(np.uint64)) for g, w in zip(got, whole))
    shorter = window_plan(a, b, c, qd, limits, n // 4, 1e-3)
    assert shorter[2][-1] > whole[2][-1]


def test_a_step_that_meets_the_whole_paths_pass_takes_its_values(monkeypatch):
    """Each step's backward pass stops where it meets the whole path's (4000 rows in view on the
    benchmark's 8001-row slow path planned in 0.8 s instead of 4.8 s): the plan is, bit for bit,
    that of a backward pass per step from the last row it sees to its own row, written out here
    row by row."""
    from vampc import lookahead
    from vampc.lookahead import _bounds, _forward, _largest_x, _top_under
    rng = np.random.default_rng(3)
    seen, inside = [], [False]        # rows the per-step backward passes worked on, outside the
    backward = lookahead._backward    # whole path's pass (_backward), which is not counted
    monkeypatch.setattr(lookahead, "_top_under", lambda lo, base, H, two_d: (
        None if inside[0] else seen.append(H.size), _top_under(lo, base, H, two_d))[1])
    monkeypatch.setattr(lookahead, "_backward", lambda *a: (
        inside.__setitem__(0, True), backward(*a), inside.__setitem__(0, False))[1])
    work = [0, 0]
    for trial in range(8):
        n, joints = int(rng.integers(40, 100)), int(rng.integers(1, 4))
        s = np.linspace(0, 1, n)
        a = (1 + 0.8 * np.sin(np.outer(s, rng.uniform(1, 9, joints)) + rng.uniform(0, 3, joints)))
        b = np.cos(np.outer(s, rng.uniform(1, 9, joints))) * rng.uniform(0.2, 3, joints)
        c = 0.3 * np.sin(np.outer(s, rng.uniform(1, 4, joints)))
        qd = np.cos(np.outer(s, rng.uniform(1, 4, joints)))
        speed = tuple(float(rng.uniform(0.1, 0.6)) if trial % 2 else None for _ in range(joints))
        limits = Limits(tuple(rng.uniform(1.5, 3, joints)), speed)
        lam = float(rng.choice([1e-3, 1e-2, 3e-2]))
        two_d = 2 * lam
        lo, up, cap = _bounds(a, b, c, qd, limits, 1e-9, two_d)
        base = _largest_x(lo, up, cap, np.full(n, np.inf), two_d)
        for ahead in (3, 5, 17, n // 2, n - 1):
            H, H2 = np.zeros(n), np.zeros(n)      # each step's top at its row + 1, + 2
            for i in range(n):
                end, h = min(i + ahead - 1, n - 1), 0.0
                for j in range(end - 1, i, -1):       # the top at row j, from a stop at row end
                    h = _top_under(tuple(v[j:j + 1] for v in lo), base[j:j + 1], np.array([h]), two_d)[0]
                    if j == i + 2:
                        H2[i] = h
                H[i] = h
            want = _forward(lo, up, H, lam, "", H2=H2)
            seen.clear()
            forwards = []              # the window's plan alone: its own forward pass, not the
            monkeypatch.setattr(lookahead, "_forward", lambda *a, **k: (   # whole path's too, which
                forwards.append(1), _forward(*a, **k))[1])                  # may fail where it does not
            got = window_plan(a, b, c, qd, limits, ahead, lam)
            assert all(np.array_equal(g.view(np.uint64), w.view(np.uint64)) for g, w in zip(got, want))
            assert len(forwards) == 1
            monkeypatch.setattr(lookahead, "_forward", _forward)
            work[0] += sum(seen)
            work[1] += (n - ahead) * (ahead - 2)   # a pass per step, every row it sees
    assert work[0] < 0.9 * work[1], work   # the shortcut was taken (at rows a speed limit caps)


def test_a_whole_path_plan_that_finds_no_way_through_leaves_the_windows_plan(monkeypatch, setup):
    """The whole path's plan is only the summary's comparison: where its forward pass fails (rounding
    on random affine parts, found by a review: a window of 3 rows got through) the run failed with
    its error. Now the window's plan stands and the summary says the comparison is not made."""
    from vampc import lookahead
    from vampc.errors import VampcError
    rng = np.random.default_rng(284)
    n, joints = int(rng.integers(8, 40)), int(rng.integers(1, 4))
    a, b = rng.normal(size=(n, joints)), rng.normal(size=(n, joints)) * 3
    c, qd = rng.normal(size=(n, joints)) * 0.3, rng.normal(size=(n, joints))
    limits = Limits(tuple(rng.uniform(0.2, 3, joints)), (None,) * joints)
    lam = float(rng.choice([1e-4, 1e-3, 1e-2]))
    with pytest.raises(VampcError, match="no speed keeps every joint within its limit"):
        optimal_plan(a, b, c, qd, limits, lam)
    window, whole = lookahead.plans(a, b, c, qd, limits, 3, lam)
    assert whole is None
    assert all(np.array_equal(w, v) for w, v in zip(window, window_plan(a, b, c, qd, limits, 3, lam)))
    # the command: its summary says so, and the run goes on
    forward = lookahead._forward

    def failing(lo, up, H, lam, seen, *rest, **named):
        if seen == "path":
            raise VampcError("row 5: no speed keeps every joint within its limit here")
        return forward(lo, up, H, lam, seen, *rest, **named)
    monkeypatch.setattr(lookahead, "_forward", failing)
    text, out, _ = retime(setup, name="nowhole.csv")
    assert ("with the whole path in view: that plan found no way through these rows (rounding "
            "where the window's plan got through), so what seeing only the register's rows costs "
            "is not said") in text


# A path of five UR10 rows whose q̇ and q̈ (eight times too large) disagree with its q: each row's
# affine torque parts (tangent - gravity, as given - gravity, gravity; reference RNEA) and q'.
CLIFF_A = [[67009.1859962273, 246873.89457055327, 108518.3953180417, 1526.5959123958075, 105.31354119479265, 43.90190039959007], [25.358148865075314, 5497.6520599132255, 1950.5947770822436, 28.087103616566058, 28.586627365088187, -0.7403869458361073], [-99892.7951148527, -287751.04782993987, -120490.35546463272, -1278.9147097820626, -51.62867356848345, -22.590314561815557], [21266.28247380848, 8907.2492831235, 2088.0323084194147, 5.500705216813982, 10.693572768768531, -2.98284075000096], [190898.67894985038, 326257.03166394343, 129575.16394512307, 1053.4144628848278, 32.70899448341367, -4.867340401465816]]
CLIFF_B = [[5424527197.221681, -4434357901.859601, 811949909.4584347, 29016546.814506017, -8033168.017840226, -957220.2515962673], [-129996022.78526957, 1419811237.1713922, 588097741.929234, 8582282.502840785, 1155963.715318531, 218216.46572610812], [4984584295.177835, -3030319110.2091885, 174357091.60971203, 36509987.186031535, -3776893.4069872824, -1071715.830459531], [-832769896.7920761, -1317950959.974378, -530781057.43898034, -1848044.144226434, -477754.05808973545, 95340.66028301208], [6331248866.230807, -1819701910.027446, -655132345.0276498, 47298406.785691455, -2712981.8190316968, -1427646.7645161522]]
CLIFF_C = [[-2.146442142481819e-15, -64.99255894479757, -33.54143499184799, -0.21369180186274062, 0.0, 0.0], [5.987032357536111e-17, -1.6182260881525163, -4.152621403513077, -0.05485351528890609, 0.0, 0.0], [-3.700853030968608e-16, -93.1224548988809, -32.65125260229699, -0.16447069436291373, 0.0, 0.0], [-1.5628952113240016e-15, -109.01797866601449, -22.222198626014478, 0.22091829402880772, 0.0, 0.0], [1.4374075189944257e-15, -111.3547141590996, -31.41050672036693, -0.08928328060576002, 0.0, 0.0]]
CLIFF_QD = [[21249.55592153876, 24219.46710584651, 20619.46710584651, 28389.37829015426, 25019.46710584651, 27159.289474462013], [2399.9999999999964, 1599.999999999996, -2000.000000000004, 1999.9999999999952, 2399.999999999996, -3000.0000000000055], [-16449.55592153876, -21019.46710584651, -24619.46710584651, -24389.37829015426, -20219.46710584651, -33159.28947446201], [2400.0000000000105, 1600.0000000000125, -1999.9999999999875, 2000.0000000000146, 2400.0000000000123, -2999.999999999983], [21249.55592153876, 24219.46710584651, 20619.46710584651, 28389.37829015426, 25019.46710584651, 27159.289474462013]]
CLIFF_LIMITS = Limits((200.0, 200.0, 100.0, 20.0, 20.0, 20.0), (1000.0,) * 6)


def test_a_step_at_the_top_of_its_speeds_does_not_brake_the_next_row_to_a_stop():
    """At the very top of a row's feasible speeds one s̈ alone is left; the greedy forward step took
    it, and it braked the next row to ṡ = 6.8e-12: 2.9e8 s for five rows (a new user's find, on a
    path whose rows disagree; TOPP-RA's greedy pass gave 250.8 s, a uniform scaling 22.9 s). The step
    now takes the speed that leaves the two intervals fastest: 21.0 s. Every row within its limits,
    with the s̈ leaving it and arriving at it (τ = a u + b x + c, checked here, not by the planner)."""
    a, b, c, qd = (np.array(v) for v in (CLIFF_A, CLIFF_B, CLIFF_C, CLIFF_QD))
    lam = 1e-3
    for x, u, t in (window_plan(a, b, c, qd, CLIFF_LIMITS, 5, lam),
                    optimal_plan(a, b, c, qd, CLIFF_LIMITS, lam)):
        assert 20 < t[-1] < 22
        assert np.allclose(np.diff(x), 2 * lam * u[:-1], rtol=0, atol=1e-20)
        assert x[0] == x[-1] == 0
        for row, s_dd in ((slice(None, -1), u[:-1]), (slice(1, None), u[:-1])):
            tau = a[row] * s_dd[:, None] + b[row] * x[row][:, None] + c[row]
            assert np.all(np.abs(tau) <= np.array(CLIFF_LIMITS.tau) * (1 + 1e-12))


def test_the_summary_says_when_the_whole_path_plan_held_a_step_short(setup):
    """Where a step was held short of its top speed, the whole path's plan is not proven time-optimal
    (the greedy pass is where no step is): the summary said "the time-optimal plan" all the same.
    A five-row Puma path whose q̇ and q̈ (sixteen times too large) disagree with its q, which the
    plan before it could not retime at all (row 4: "the arm cannot move on"); the retimed rows
    within every limit by the reference (--check)."""
    folder = setup[0]
    T, w = 0.004, 6 * np.pi
    t = np.arange(5) / RATE
    s = t / T
    dq, amp = np.array([1.2, 0.8, -1.0, 1.0, 1.2, -1.5]) * 0.3, np.array([0.5, 0.6, 0.6, 0.7, 0.6, 0.8]) * 0.3
    q = np.outer(s, dq) + np.outer(np.sin(w * s), amp)
    qd = 16 * (np.outer(np.full_like(s, 1 / T), dq) + np.outer(w / T * np.cos(w * s), amp))
    qdd = 16 * np.outer(-(w / T) ** 2 * np.sin(w * s), amp)
    path = write_path(folder, t, q, qd, qdd, name="cliff.csv")
    r = CliRunner().invoke(main, ["lookahead", str(setup[1]), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "5", "--limits", str(setup[2]), "--retime", "window", "--check",
                                  "-o", str(folder / "cliff-out.csv")])
    assert r.exit_code == 0, r.output
    found = re.search(r"with the whole path in view \(the fastest plan found on these rows and limits, "
                      r"from rest to rest; not "
                      r"proven time-optimal, since at 1 row the fastest speed would have braked the next "
                      r"row and a slower one was taken: README, vampc lookahead\): (\S+) s", r.output)
    assert found, r.output        # (its duration the window's: the window holds the whole path)
    out = np.loadtxt(folder / "cliff-out.csv", delimiter=",", skiprows=1)
    assert abs(float(found[1]) - (out[-1, 0] - out[0, 0])) <= 1e-5 * float(found[1])
    assert "retimed rows by the reference: 0 violations; with the s̈ arriving at each row: 0 violations" in r.output


def test_a_step_held_short_of_a_stop_decides_from_its_own_rows_only(monkeypatch):
    """Holding a step short of its top (`_short_of_a_cliff`) weighs the row after next by the top
    there; it took the next step's, which sees one row further: changing a row beyond the look-ahead
    changed a decision (4 of 3476 on random rows; found checking the change). On random rows where a
    window step is held: every decision from the rows in view only, changing every row from K on."""
    from vampc import lookahead
    from vampc.errors import VampcError
    rng = np.random.default_rng(5)
    held = []
    real = lookahead._short_of_a_cliff

    def counting(*args):
        short = real(*args)
        held.append(short < args[-1])
        return short
    monkeypatch.setattr(lookahead, "_short_of_a_cliff", counting)
    checked = 0
    for _ in range(3000):
        n, joints = int(rng.integers(8, 30)), int(rng.integers(1, 4))
        a = rng.normal(size=(n, joints)) * rng.choice([1, 100, 1e4])
        b = rng.normal(size=(n, joints)) * 3 * rng.choice([1, 100, 1e4])
        c, qd = rng.normal(size=(n, joints)) * 0.3, rng.normal(size=(n, joints))
        limits = Limits(tuple(rng.uniform(0.5, 3, joints)), (None,) * joints)
        lam, ahead = float(rng.choice([1e-4, 1e-3, 1e-2])), int(rng.integers(3, 7))
        if np.any(np.abs(c) > np.array(limits.tau)):
            continue
        held.clear()
        try:
            x, _, _ = window_plan(a, b, c, qd, limits, ahead, lam)
        except VampcError:
            continue
        if not any(held):
            continue
        checked += 1
        for K in range(ahead, n):
            a2, b2 = a.copy(), b.copy()
            a2[K:] *= -2.0
            b2[K:] *= 3.0
            try:
                x2, _, _ = window_plan(a2, b2, c, qd, limits, ahead, lam)
            except VampcError:
                continue
            assert np.array_equal(x[:K - ahead + 2], x2[:K - ahead + 2]), K
        if checked == 25:
            break
    assert checked == 25


def test_a_slow_path_where_every_joint_turns_back_at_once_is_planned_within_its_limits():
    """q = Δq (1 - cos(2π t / 8 s)) / 2 on the Puma: within its limits as given, every joint at rest
    in the middle (q' = 0). Near that row the next row's bound on s̈ hardly depends on it (d of
    4.5e-7), and the plan said "row 3998: no speed keeps every joint within its limit here", with
    any window, the whole path's too (a new user's find, 2026-12-05: rounding of 1e-6 in s̈,
    compared after dividing by d). Planned now, faster than as given, within every limit by the
    reference dynamics with the s̈ leaving each row and with the s̈ arriving at it."""
    chain = load_robot(PUMA)
    t = np.arange(8001) / RATE
    dq, w = np.array([.5, .4, .3, .2, .3, .2]), 2 * np.pi / 8
    q = np.outer(1 - np.cos(w * t), dq) / 2
    qd, qdd = np.outer(np.sin(w * t), dq) * w / 2, np.outer(np.cos(w * t), dq) * w * w / 2
    z = np.zeros_like(q)
    c = rnea(chain, q, z, z)
    a, b = rnea(chain, q, z, qd) - c, rnea(chain, q, qd, qdd) - c
    limits = Limits(tuple(LIM), (None,) * 5 + (4.0,))
    assert np.all(np.abs(b + c) <= LIM)                              # within its limits as given
    for plan in (window_plan(a, b, c, qd, limits, 64, 1 / RATE), optimal_plan(a, b, c, qd, limits, 1 / RATE)):
        x, u, times = plan
        assert times[-1] < 8.0
        leaving = a * u[:, None] + b * x[:, None] + c
        arriving = a * np.concatenate([[0.0], u[:-1]])[:, None] + b * x[:, None] + c
        assert np.all(np.abs(leaving) <= LIM) and np.all(np.abs(arriving) <= LIM)
        assert np.all(np.abs(qd[:, 5] * np.sqrt(x)) <= 4.0)


def minimum_jerk_path(T: float = 3.0):
    """q = Δq (10 s³ - 15 s⁴ + 6 s⁵), s = t / T: a rest-to-rest path whose q' is near 0 at both
    ends, exact derivatives."""
    t = np.arange(int(round(T * RATE)) + 1) / RATE
    s, dq = t / T, np.array([1.5, 0.7, -1.2, 2.0, 1.5, 2.0])
    h, hd = 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5, (30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4) / T
    hdd = (60 * s - 180 * s ** 2 + 120 * s ** 3) / T ** 2
    return t, np.outer(h, dq), np.outer(hd, dq), np.outer(hdd, dq)


@pytest.mark.parametrize("word", ["float32", "q16.16"])
def test_a_narrower_words_error_in_a_and_b_is_not_multiplied_past_a_limit(setup, tmp_path, word):
    """Near the ends of a rest-to-rest path q' is near 0, so a (the tangent pass less the gravity
    pass) is small and s̈ large: the word's error in a, multiplied by s̈, took the retimed path
    1.25 times over a limit by the reference in q16.16 and 1.005 times in float32 (a look-ahead
    stress test's find, 2026-12-05; the run failed, said FAILED). Planned for every a and b within
    the word's error of the network's, the reference finds none over."""
    _, _, limits, _ = setup
    path = write_path(tmp_path, *minimum_jerk_path())
    r, out = word_retime(tmp_path, word, path, limits)
    assert r.exit_code == 0, r.output          # (with the s̈ arriving at each row too, by --check)
    assert "with the s̈ arriving at each row: 0 violations" in r.output
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    tau = rnea(load_robot(PUMA), got[:, 1:7], got[:, 7:13], got[:, 13:19])
    assert (np.abs(tau) <= LIM).all(), np.max(np.abs(tau) / LIM)


def test_float64_rounding_in_a_is_not_multiplied_past_a_limit_either(tmp_path):
    """A 7-joint arm (tests/data/arm7.urdf), bang-coast-bang accelerations at 8 kHz integrated on
    the box: where the integrated path nearly stops (q' about 1e-7) s̈ is about 1e7, and float64's
    rounding in a, so multiplied, took joint2 1.85e-9 over its limit by the reference, beyond the
    1e-9 the plan keeps inside (a look-ahead stress test's find, 2026-12-05: the run failed).
    Planned for every a and b within FLOAT64_SPREAD of a row's largest torque, none is over."""
    rate, n, rows = 8000, 7, 4000
    acc = np.zeros((rows, n))
    for j in range(n):
        a = 0.6 * (1 + j % 3) * (-1) ** j
        acc[: rows // 4, j], acc[rows // 2: 3 * rows // 4, j] = a, -a
        acc[3 * rows // 4:, j] = 0.3 * a * np.sin(np.linspace(0, 6, rows - 3 * rows // 4))
    path = tmp_path / "acc.csv"
    np.savetxt(path, np.column_stack([np.arange(rows) / rate, acc]), delimiter=",", comments="",
               header="t," + ",".join(f"qdd{j + 1}" for j in range(n)), fmt="%.17g")
    r = CliRunner().invoke(main, ["lookahead", "tests/data/arm7.urdf", "--accelerations", str(path),
                                  "--q0", "0,0,0,-1.5,0,1.5,0.7", "--qd0", "0,0,0,0,0,0,0", "--rate", "8000Hz",
                                  "--window", "64", "--retime", "window", "--check", "-o", str(tmp_path / "o.csv")])
    assert r.exit_code == 0, r.output
    assert "retimed rows by the reference: 0 violations; with the s̈ arriving at each row: 0 violations" in r.output


def test_the_bounds_are_taken_in_blocks_with_the_same_numbers(monkeypatch):
    """`_largest_x` worked out every pair of bounds of every row at once: about 84 kB a row on the
    Puma, so a 300 000-row path (5 minutes at 1 kHz) was killed by the system at 23 GB with nothing
    said (an audit's find); then in blocks of 2048 rows, which for a 16-joint arm's 129 × 129 pairs
    a row still made 1.1 GB of temporaries (a review's). Now in blocks of LARGEST_X_PAIRS pairs:
    the same plan bit for bit at any block size, and the numpy memory of a 2 500-row plan of 16
    joints stays small."""
    import tracemalloc

    from vampc import lookahead
    a, b, c, qd, limits = affine_parts()
    whole = window_plan(a, b, c, qd, limits, 64, 1 / RATE, spread=(1e-9, 1e-9))
    for rows in (1, 7, 256):
        monkeypatch.setattr(lookahead, "LARGEST_X_PAIRS", rows * 49 * 49)
        got = window_plan(a, b, c, qd, limits, 64, 1 / RATE, spread=(1e-9, 1e-9))
        assert all(np.array_equal(g.view(np.uint64), w.view(np.uint64)) for g, w in zip(got, whole))
    monkeypatch.undo()
    # (16 joints: both the pairs of every row at once, 1.6 GB, and blocks of 2048 rows, 1.1 GB, go
    # past the bound here; a block of pairs takes 174 MB)
    s = np.linspace(0, 1, 2500)[:, None]
    k = np.arange(1, 17)
    sixteen = [1 + 0.5 * np.sin(3 * s * k), 0.5 * np.cos(2 * s * k), 0.3 * np.sin(s * k), np.cos(s * k)]
    tracemalloc.start()
    try:
        window_plan(*sixteen, Limits((2.0,) * 16, (None,) * 16), 64, 1 / RATE, spread=(1e-9, 1e-9))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 350e6, peak


def test_a_path_too_long_for_the_memory_is_refused_before_any_pass(setup, tmp_path, monkeypatch):
    """A path whose run cannot fit in half the memory available is one line, exit 1, before the
    network runs, and no file is written. The pairs of bounds are counted for the rows' block (a
    fixed 236 MB had been counted for ten rows too, and less than one row's pairs for a chain of a
    thousand joints: a review's find)."""
    from vampc.lookahead import pairs_bytes
    assert pairs_bytes(10, 6) == 48 * 10 * 49 ** 2
    assert pairs_bytes(10 ** 6, 6) == 48 * (2048 * 49 * 49 // 49 ** 2) * 49 ** 2
    assert pairs_bytes(5, 1000) == 48 * 8001 ** 2        # one row: more than the block's pairs
    from vampc.emulator import driver
    folder, program, limits, path = setup
    rows = len(path.read_text().splitlines()) - 1
    # 1 000 bytes a row and column, and the pairs of bounds of the rows' block: 601 rows, each 49 × 49
    # (6 joints in four copies at the row and the next, and one more), six temporaries of 8 bytes
    need = rows * 6 * 1000 + 6 * 8 * rows * 49 ** 2
    monkeypatch.setattr(driver, "_available_memory", lambda: 2 * need - 2)
    out = tmp_path / "o.csv"
    for retime, refused in (("window", True), ("uniform", False)):
        r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate",
                                      "1kHz", "--window", "64", "--limits", str(limits), "--retime",
                                      retime, "-o", str(out)])
        if refused:
            assert r.exit_code == 1 and r.stderr.count("\n") == 1 and not out.exists(), r.output
            assert re.search(rf"{path}: {rows:,} rows need about 0\.1 GiB with --retime window "
                             r"\(0\.1 GiB available\); run the path in parts", r.stderr), r.stderr
        else:
            assert r.exit_code == 0, r.output


@pytest.mark.parametrize("retime", [["window"], ["envelope", "--clock", "150kHz"]],
                         ids=["window", "envelope-clock"])
def test_the_columns_disagreeing_are_said_before_an_error_they_may_cause(setup, tmp_path, retime):
    """A q̈ of 1e300 in one row: the window retiming's error named only the retimed rows' times (t =
    5.6e+141), while the warning that the path's q̇ and q̈ disagree there, said by every other run
    once it went through, was never said (a new user's find). It comes first now, before any error
    that ends the run after the network's passes (the envelope's clock too: a review's)."""
    folder, program, limits, _ = setup
    t, q, qd, qdd = bump_path()
    qdd = qdd.copy()
    qdd[100, 1] = 1e300
    path = write_path(tmp_path, t, q, qd, qdd)
    r = CliRunner().invoke(main, ["lookahead", str(program), "--trajectory", str(path), "--rate", "1kHz",
                                  "--window", "16", "--limits", str(limits), "--retime", *retime])
    assert r.exit_code == 1, r.output
    lines = r.output.splitlines()
    assert len(lines) == 2 and lines[1].startswith(f"vampc: error: {path}: "), r.output
    assert re.match(rf"vampc: warning: {re.escape(str(path))}: line 10[12] to 10[23]: qd2 changes by \S+ but qdd2 "
                    r"gives \S+ over the step 1/rate", lines[0]), r.output
