"""What a hardware engineer asks for next (`vampc report`, section "Engineering figures"): how busy
each VAMP is, what the host moves per set and per second, the critical path op by op, the bits of
storage, the counters and comparators that read the control registers, and (with `--cpu-reference`) the time a CPU takes per set on this machine.

Utilisation: a VAMP is busy for its ops' durations (an MM member for the MM's) once per torque set;
busy ticks / interval is its share of the time (1 = never idle). Host I/O: the scalars the host
writes into the ports and reads off the outputs per set (constants are loaded once, in Program
Mode), in words of the program's format. Bits: those of vampc.report.counts.word_bits, at the
program's word width (64 for float64).
"""
from __future__ import annotations

import time

PER_VAMP_UP_TO = 4096          # VAMPs: above this the JSON keeps the spread, not every VAMP's figure


def engineering(c, clock_hz: float | None = None) -> dict:
    """The section's figures for a compiled program `c` (vampc.compiler.Compiled)."""
    from vampc.report.counts import control_logic, distinct_port_scalars, word_bits
    net, graph, sched = c.network, c.graph, c.schedule
    duration = sched.timing.durations
    interval = sched.interval
    busy = [sum(duration[graph.nodes[s.node].op] for s in v.slots) for v in net.vamps]
    share = [b / interval for b in busy]
    inputs = sum(p.size for p in net.ports for _ in p.entries)
    outputs = c.chain.n_outputs
    bits = word_bits(c)
    io = {"scalars_in_per_set": inputs, "distinct_scalars_in_per_set": distinct_port_scalars(net),
          "port_writes_per_set": sum(len(p.entries) for p in net.ports),
          "scalars_out_per_set": outputs,
          "bits_in_per_set": bits["host_write_bits_per_set"],
          "bits_out_per_set": bits["host_read_bits_per_set"], "word_bits": bits["bits"]}
    if clock_hz is not None:
        sets = clock_hz / interval
        from vampc.report.clock import per_second, rate
        io.update(sets_per_second=per_second(interval, clock_hz), scalars_in_per_second=rate(inputs * sets),
                  scalars_out_per_second=rate(outputs * sets),
                  bits_in_per_second=rate(bits["host_write_bits_per_set"] * sets),
                  bits_out_per_second=rate(bits["host_read_bits_per_set"] * sets))
    path = [{"node": i, "label": f"{graph.nodes[i].name}·{graph.nodes[i].section} {graph.nodes[i].group}",
             "op": graph.nodes[i].op.value,
             "start": sched.start[i], "flops": duration[graph.nodes[i].op]} for i in sched.critical_path]
    return {"utilisation": {"interval_flops": interval, "mean": round(sum(share) / len(share), 4),
                            "min": round(min(share), 4), "max": round(max(share), 4),
                            "busy_ticks_per_set": sum(busy), "vamp_ticks_per_set": interval * len(busy),
                            "per_vamp": ([round(x, 4) for x in share] if len(share) <= PER_VAMP_UP_TO
                                         else None)},
            "host_io": io, "critical_path": path,
            "bits": {k: bits[k] for k in ("bits", "data_register_bits", "control_register_bits",
                                          "rom_bits", "delay_line_bits", "constant_bits",
                                          "input_port_bits", "program_bits", "checking_control_bits")
                     if k in bits},
            "control_logic": control_logic(c), "cpu_reference": None}


def cpu_reference(chain, sets: int = 200, seed: int = 0) -> dict:
    """Seconds per torque set on this machine, one set at a time: vampc's own reference Newton-Euler
    (numpy), and Pinocchio's rnea when `pin` is installed (the same states). Medians of 3 runs."""
    import numpy as np

    from vampc.dynamics.reference import rnea
    rng = np.random.default_rng(seed)
    n = chain.n
    q, qd, qdd = (rng.uniform(-1, 1, (sets, n)) for _ in range(3))

    def median_per_set(fn) -> float:
        runs = []
        for _ in range(3):
            start = time.perf_counter()
            for k in range(sets):
                fn(k)
            runs.append((time.perf_counter() - start) / sets)
        return sorted(runs)[1]
    with np.errstate(all="ignore"):     # (NumPy's own overflow lines were printed as warnings)
        finite = bool(np.isfinite(rnea(chain, q[:1], qd[:1], qdd[:1])).all())
        seconds = median_per_set(lambda k: rnea(chain, q[k:k + 1], qd[k:k + 1], qdd[k:k + 1]))
    if not finite:
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning("--cpu-reference: the reference torques of the timed states are "
                                   "not finite numbers (the robot's numbers overflow a float): the "
                                   "times are of that arithmetic"), stacklevel=2)
    out = {"sets": sets, "machine": _machine(),
           "measured": [{"what": "vampc's reference Newton-Euler (numpy), one set at a time",
                         "seconds_per_set": seconds}]}
    model, why = _pinocchio_model(chain)
    if model is None:
        out["not_measured"] = f"Pinocchio: not measured ({why})"
    else:
        import pinocchio as pin
        data = model.createData()
        pq = pin.neutral(model)
        pv, pa = (rng.uniform(-1, 1, (sets, model.nv)) for _ in range(2))
        out["measured"].append({"what": f"Pinocchio {pin.__version__} rnea (C++, from the URDF), one "
                                        "set at a time",
                                "seconds_per_set": median_per_set(
                                    lambda k: pin.rnea(model, data, pq, pv[k], pa[k]))})
    return out


def _pinocchio_model(chain):
    """(Pinocchio's model of the robot's URDF, fixed base, "") or (None, why not)."""
    source = str(chain.source or "")
    if not source.lower().endswith(".urdf"):
        return None, "it is timed on a URDF's own model; this robot is not one"
    try:
        import pinocchio as pin
    except ImportError:
        return None, "not installed: pip install pin"
    import os
    if not os.path.isfile(source):     # (pin's C++ printed its own errors on stderr: a new user's find)
        return None, (f"the URDF {source} is not found from here (a program file names the file "
                      "it was compiled from)")
    try:
        model = pin.buildModelFromUrdf(source)
    except Exception:          # pin refusing the file: the figure is left out, and said so
        return None, "it did not load this URDF"
    # Pinocchio times the file's whole robot on a fixed base: not this chain if --lock, --tip or
    # --base took joints out, a floating base was added, or the file is no longer the one compiled
    # (Pinocchio's time of a 9-joint Panda was set beside a 7-joint network: a new user's find)
    names = sorted(str(x) for x in list(model.names)[1:])
    if chain.floating or names != sorted(j.name for j in chain.joints):
        return None, ("Pinocchio's model of the file is not this robot: " + (
            "a floating base" if chain.floating else
            f"{model.nv} joints in the file against {chain.n} here, or other names (--lock, --tip "
            "or --base, or the file changed since the program was compiled)"))
    return model, ""


def _machine() -> str:
    import os
    import platform
    return f"{platform.machine()}, {os.cpu_count()} logical cores, Python {platform.python_version()}"
