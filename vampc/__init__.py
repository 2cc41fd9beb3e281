"""vampc: compile robot descriptions into programs for a network of VAMPs (Lathrop, Parallelism in
Manipulator Dynamics), emulate them, and report their cost.

The stages, as functions (the CLI is a thin layer over exactly these):

    chain = vampc.load_robot("examples/puma560.yaml")          # Chain (DH table, URDF or MJCF)
    graph = vampc.build_linear(chain)                          # or vampc.build_log(chain, prefix=...)
    sched = vampc.schedule_asap(graph)                         # latency, critical path
    net = vampc.allocate_systolic(graph, sched)                # VAMPs, buffers, ports, constants
    c = vampc.compile_chain(chain, vampc.CompileOptions())     # all of the above in one call
    doc = vampc.program_document(c)                            # the program file's content
    vampc.summary(c)                                           # the headline figures (a dict)
    rep = vampc.build_report(c, clock_hz=20e6)                 # the whole report (report schema)
    vampc.timing_svg(c.graph, c.layout, c.schedule, "title")   # pictures: also network_svg, report_dot
    ld = vampc.loaded_from_compiled(c)                         # or vampc.load_program(path)
    vampc.emulate(ld, vampc.random_trajectory(chain, 100, 0))  # torques from the emulated network
    vampc.emulate(ld, vampc.Trajectory(q, qd, qdd)).tau        # your own states: arrays states × n
    vampc.rnea(chain, q, qd, qdd)                              # the reference dynamics

Names are resolved on first use, so `import vampc` stays cheap. Bad input raises VampcError (a
VampcUsageError for a rule between options) with one line naming the place; warnings are
VampcWarning (README, Python API).
"""
from __future__ import annotations

import importlib

__version__ = "0.1.0"

_API = {
    "load_robot": "vampc.robot", "load_dh": "vampc.robot", "load_urdf": "vampc.robot",
    "Chain": "vampc.robot.chain", "Joint": "vampc.robot.chain", "JointType": "vampc.robot.chain",
    "random_chain": "vampc.robot.random",
    "rnea": "vampc.dynamics.reference", "rnea_variables": "vampc.dynamics.reference",
    "build_linear": "vampc.dataflow.linear", "build_log": "vampc.dataflow.logarithmic",
    "evaluate": "vampc.dataflow.evaluate", "Timing": "vampc.machine.ops",
    "schedule_asap": "vampc.schedule.asap", "allocate_systolic": "vampc.network.allocate",
    "CompileOptions": "vampc.compiler", "compile_chain": "vampc.compiler",
    "program_document": "vampc.compiler", "program_text": "vampc.compiler",
    "write_program": "vampc.program.file",
    "read_program": "vampc.program.file", "summary": "vampc.report.counts",
    "compare_prefixes": "vampc.report.compare", "render_report": ("vampc.report.text", "render"),
    "build_report": "vampc.report.build", "render_markdown": "vampc.report.text",
    "timing_svg": "vampc.report.timing_chart", "network_svg": "vampc.report.network_drawing",
    "report_dot": "vampc.report.dot",
    "emulate": "vampc.emulator", "load_program": "vampc.emulator",
    "loaded_from_doc": "vampc.emulator", "loaded_from_compiled": "vampc.emulator", "random_trajectory": "vampc.emulator.host",
    "read_trajectory": "vampc.emulator.host", "check_torques": "vampc.emulator.host",
    "check_limits": "vampc.emulator.host",
    "VampcError": "vampc.errors", "VampcUsageError": "vampc.errors", "VampcWarning": "vampc.errors",
    "Trajectory": "vampc.emulator.host", "CheckResult": "vampc.emulator.host",
    "Emulation": "vampc.emulator", "Loaded": "vampc.emulator.load", "Compiled": "vampc.compiler",
}

__all__ = sorted(_API)


def __getattr__(name: str):
    where = _API.get(name)
    if where is None:
        raise AttributeError(f"module 'vampc' has no attribute {name!r}")
    module, attr = where if isinstance(where, tuple) else (where, name)
    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + __all__)
