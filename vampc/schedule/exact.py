"""An exact modulo scheduler for small graphs (`--exact`, with OR-Tools: `pip install "vampc[exact]"`).

It replaces vampc.schedule.budget.modulo_schedule, the heuristic, with a CP-SAT model of the same
problem: every compute op i starts at s_i (after its operands: s_i >= s_a + d_a), runs on m_i of the
K VAMPs (three for an MM) and, successive torque sets entering every II ticks, occupies ticks
s_i mod II .. s_i mod II + d_i - 1 of each of them, round the period. Each VAMP's occupied ticks are
optional intervals on a line of 2·II ticks (each op twice, at r_i = s_i mod II and at r_i + II, so an
overlap round the period is an overlap on the line) under a no-overlap constraint. The latency (the
last torque's finish) is minimised.

`exact_budget` walks II up from the bound: an II the solver proves infeasible is skipped, the first
one it solves is kept with the shortest latency found there; the result says whether that latency
and the II are proven optimal (the time limit may stop the proof).
"""
from __future__ import annotations

from dataclasses import dataclass

from vampc import progress
from vampc.dataflow.graph import Graph
from vampc.errors import VampcError
from vampc.machine.ops import VAMPS_PER_OP, Timing
from vampc.schedule.budget import Placed, bounds, tails


@dataclass(frozen=True)
class Exact:
    """An exact placement and what the solver proved about it."""

    placed: Placed
    interval_optimal: bool     # every smaller interval was proven infeasible
    latency_optimal: bool      # no shorter latency at this interval


def _solver():
    try:
        from ortools.sat.python import cp_model
    except ImportError:
        raise VampcError('--exact needs OR-Tools: pip install "vampc[exact]"') from None
    return cp_model


def _noting(cp_model, text: str):
    """A solution callback that puts each latency the solver finds on the progress bar after `text`
    (only where a bar is drawn; what the solver finds is the same with it or without)."""
    class Noting(cp_model.CpSolverSolutionCallback):
        def on_solution_callback(self) -> None:
            progress.note(f"{text}: latency {self.ObjectiveValue():.0f} flops found so far")
        OnSolutionCallback = on_solution_callback      # (the name older OR-Tools calls)
    return Noting()


def solve(graph: Graph, timing: Timing, k: int, ii: int, horizon: int, seconds: float,
          note: str = ""):
    """(status, Placed or None, latency proven optimal) for one interval; `note`: what the progress
    bar says meanwhile, with the latencies found."""
    cp_model = _solver()
    d = timing.durations
    ops = graph.compute_nodes()
    model = cp_model.CpModel()
    start, rest = {}, {}
    for nd in ops:
        start[nd.id] = model.NewIntVar(0, horizon, f"s{nd.id}")
        rest[nd.id] = model.NewIntVar(0, ii - 1, f"r{nd.id}")
        model.AddModuloEquality(rest[nd.id], start[nd.id], ii)
        for a in nd.args:
            if a in start:
                model.Add(start[nd.id] >= start[a] + d[graph.nodes[a].op])
    on = {}
    lanes: list[list] = [[] for _ in range(k)]
    for nd in ops:
        dur, m = d[nd.op], VAMPS_PER_OP[nd.op]
        chosen = []
        for v in range(k):
            x = on[(nd.id, v)] = model.NewBoolVar(f"x{nd.id}_{v}")
            chosen.append(x)
            for shift in (0, ii):
                s = model.NewIntVar(shift, shift + ii - 1, f"p{nd.id}_{v}_{shift}")
                model.Add(s == rest[nd.id] + shift)
                lanes[v].append(model.NewOptionalIntervalVar(s, dur, s + dur, x, f"i{nd.id}_{v}"))
        model.Add(sum(chosen) == m)
    for lane in lanes:
        model.AddNoOverlap(lane)
    latency = model.NewIntVar(0, horizon + 3 * max(d.values()), "latency")
    for o in graph.outputs:
        model.Add(latency >= start[o.node] + d[graph.nodes[o.node].op])
    model.Minimize(latency)
    solver = cp_model.CpSolver()
    # one worker and a deterministic time limit: the same placement every time, so a program file's
    # schedule can be recomputed and compared (vampc.program.document.compiled_from_doc)
    solver.parameters.max_deterministic_time = seconds
    solver.parameters.num_workers = 1
    solver.parameters.random_seed = 0
    # Ctrl-C and SIGTERM end the command at once: CP-SAT's own SIGINT handler had ended the search
    # as if its time were up and the command had written that placement, exit 0, and a SIGTERM
    # waited for the solver's limit (two minutes: a new user's); the search runs on a thread while
    # this one waits where Python's handlers run, and is stopped when they raise
    solver.parameters.catch_sigint_signal = False
    if note:
        progress.note(note)
    status = _solve_stoppably(solver, model,
                              _noting(cp_model, note) if note and progress.enabled() else None)
    if status not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return status, None, False
    starts = [0] * len(graph.nodes)
    finish = [0] * len(graph.nodes)
    placement: list[tuple[int, ...]] = [()] * len(graph.nodes)
    for nd in ops:
        starts[nd.id] = solver.Value(start[nd.id])
        finish[nd.id] = starts[nd.id] + d[nd.op]
        placement[nd.id] = tuple(v for v in range(k) if solver.Value(on[(nd.id, v)]))
    return status, Placed(tuple(starts), tuple(finish), tuple(placement), ii), \
        status == cp_model.OPTIMAL


def _solve_stoppably(solver, model, callback):
    """solver.Solve(model, callback) on a thread, stopped when this thread is interrupted."""
    import threading
    done: list = []
    # the search's end, said by the search itself: a signal that interrupts Thread.join can leave
    # the thread marked as ended while it still runs (Python 3.11's join releases the thread's own
    # lock when interrupted), and the command then left with the search in CP-SAT: the process
    # aborted on the way out ("terminate called without an active exception", exit 134 for 143)
    ended = threading.Event()

    def search() -> None:
        try:
            done.append(solver.Solve(model, callback))
        except BaseException as exc:       # raised again on the calling thread
            done.append(exc)
        finally:
            ended.set()
    worker = threading.Thread(target=search, name="vampc-cp-sat", daemon=True)
    stop = getattr(solver, "stop_search", None) or solver.StopSearch
    try:
        worker.start()
        while not ended.wait(0.1):
            pass
    except BaseException:
        # asked again until the search ends: a request made before the solver has set itself up
        # is lost (a review's find: a signal in that gap waited out the solver's limit)
        while not ended.is_set():
            try:
                stop()
                ended.wait(0.1)
            except BaseException:     # a second signal: the search must still end first
                continue
        raise
    if isinstance(done[0], BaseException):
        raise done[0]
    return done[0]


EFFORT = 30.0     # the solver's deterministic time limit per interval (about seconds)


def exact_budget(graph: Graph, timing: Timing, k: int, seconds: float = EFFORT,
                 interval: int | None = None) -> Exact:
    """The smallest interval the solver can place K VAMPs at (from the bound up; or `interval`), and
    the shortest latency there (see the module docstring)."""
    cp_model = _solver()
    b = bounds(graph, timing, k)
    tail = tails(graph, timing)
    work = sum(timing.durations[nd.op] for nd in graph.compute_nodes())
    horizon = work + max(t for t in tail if t is not None)
    ii, proven = b.interval_bound, True
    if interval is not None:
        if interval < ii:         # (the solver had searched minutes for what cannot be: a new user's)
            raise VampcError(f"--exact: no placement of {k} VAMPs at interval {interval} (proven "
                             f"impossible: no interval is below {ii} flops, "
                             + ("the longest op)" if ii > b.interval else
                                f"the work of {b.work} VAMP-ticks over {k} VAMPs, rounded up)"))
        status, placed, optimal = solve(graph, timing, k, interval, horizon, seconds,
                                        f"--exact at interval {interval}")
        if placed is None:
            raise VampcError(f"--exact: no placement of {k} VAMPs at interval {interval} was found "
                             + ("(proven impossible)" if status == cp_model.INFEASIBLE else
                                "within the solver's time limit"))
        return Exact(placed, False, optimal)
    while True:
        status, placed, optimal = solve(graph, timing, k, ii, horizon, seconds,
                                        f"--exact at interval {ii} (from {b.interval_bound})")
        if placed is not None:
            return Exact(placed, proven, optimal)
        if status != cp_model.INFEASIBLE:
            proven = False            # not proven infeasible: the time limit stopped the search
        ii += 1
