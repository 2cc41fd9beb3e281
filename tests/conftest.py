"""Shared test configuration: the `--update-golden` option and paths every test module uses.

Golden files under tests/golden/ are compared byte for byte; they are rewritten only when pytest runs with
`--update-golden` (and a rewritten golden must be read and checked by a human before it is committed).
"""
from __future__ import annotations

import gc
import os
import signal
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
GOLDEN = Path(__file__).resolve().parent / "golden"

# a one-joint arm (DH YAML): the smallest robot of the RTL and exact-solver tests
ARM1 = """name: arm1
gravity: [0.0, -9.81, 0.0]
joints:
  - {name: shoulder, type: revolute, a: 0.5, alpha: 0.3, d: 0.1, theta: 0.0, mass: 2.0,
     com: [-0.25, 0.01, 0.0], inertia: [0.0008, 0.04, 0.04, 0.0, 0.0, 0.0]}
"""


# The cyclic garbage collector, in each test process. A test process holds some 400 000 objects
# that live to its end (modules, pytest's items, Amaranth, Pinocchio, kept answers), and each full
# collection walked them all: a tenth of the suite's CPU went to the collector (2026-12-06,
# gc.callbacks timing each collection: 43.7 s of 424 s; in a slower hour 54.7 s, 44.8 s of it in
# full collections). So whenever a test process moves on to another module's tests (once a module,
# or more under --dist worksteal, which can hand a module's tests back and forth), what is alive is
# collected and then frozen (gc.freeze: left out of later collections, still freed by reference
# counting), and the youngest generation is collected every GC_YOUNG net new containers, not 700:
# the collector then took 12.3 s of 390 s. A cycle that reaches a frozen object is not collected
# while frozen, so its finalizers would not run; at the session's end everything is unfrozen, and
# pytest's last collections then free such cycles and report what their finalizers raise. Only the
# test processes are set so, not vampc; the tests of vampc's own use of gc.freeze (test_cli_safety)
# unfreeze first, and the rest of their module runs unfrozen.
GC_YOUNG = 10_000
_last_module: list = [None]


def pytest_runtest_setup(item):
    module = item.nodeid.split("::", 1)[0]
    if module != _last_module[0]:
        _last_module[0] = module
        gc.collect()
        gc.freeze()


def pytest_sessionfinish(session):
    gc.unfreeze()


# Signal handlers, in each test process: a test that changes one puts it back. A test that left
# Ctrl-C ignored (vampc's console script ignores signals once it is leaving, and the test of that
# put back SIGTERM's and SIGHUP's handlers only) made a later test in the same process, which sends
# itself SIGINT, wait for ever: the suite hung, or failed, by the order its tests ran in. Each test
# is checked here, and a handler left changed is put back and fails that test's teardown.
_KEPT_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGALRM")
                      if hasattr(signal, name))


# Likewise NumPy's floating-point error handling (np.seterr): `vampc faults` had set it to ignore
# everything for the rest of the process, and every later test in that process of "no NumPy
# warning" then passed whatever the code did (an order-dependence hunt's find).
@pytest.fixture(autouse=True)
def _signal_handlers_and_numpy_errors_put_back():
    import numpy as np
    before = {sig: signal.getsignal(sig) for sig in _KEPT_SIGNALS}
    errors = np.geterr()
    yield
    changed = [sig for sig, old in before.items() if signal.getsignal(sig) != old]
    for sig in changed:
        signal.signal(sig, before[sig])
    left = np.seterr(**errors)               # (both put back before either is said)
    names = ", ".join(signal.Signals(sig).name for sig in changed)
    assert not changed, f"the test left the handler of {names} changed"
    assert left == errors, f"the test left NumPy's error handling changed: {left}, not {errors}"


# Bytecode for the processes the tests start. Where the environment says not to write .pyc files
# (PYTHONDONTWRITEBYTECODE, as this project's machines set it), every `python -m vampc` a test runs
# from the checkout compiled vampc's modules from source again: 0.3-0.4 s a process (a 10-set Puma
# emulate, 2026-12-07: 0.75-1.06 s without vampc's .pyc files, 0.52-0.61 s with them), for some 150
# such processes a run. The test processes and the processes they start write and read bytecode as
# Python does by default (vampc/__pycache__, ignored by git; nothing where a folder is read-only),
# as an installed package has it (pip writes its .pyc files) and as benchmarks/emulate_io.py's
# children do. Set in the first process, before its workers start: they inherit it.
def pytest_configure(config):
    if not hasattr(config, "workerinput"):
        os.environ.pop("PYTHONDONTWRITEBYTECODE", None)


def pytest_sessionstart(session):
    """Tests name the examples as the README does ("examples/planar2.yaml", some when their module
    is imported): they run from the repository's root wherever pytest is started (`pytest
    /path/to/tests/test_x.py` from another folder failed at collection, a tests audit's). Each test
    that writes files writes them under its own tmp_path. (Here, after pytest has resolved the
    paths it was given, such as --junitxml's, against the folder it was started in: a review's.)"""
    os.chdir(ROOT)
    gc.set_threshold(GC_YOUNG, *gc.get_threshold()[1:])       # (the collector: above)


# The example robots the README and the design card promise (DESIGN §1, README).
EXPECTED_EXAMPLES = ("planar2.yaml", "puma560.yaml", "stanford.yaml", "snake64.yaml", "arm6.urdf")


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", default=False,
                     help="Rewrite the golden files under tests/golden/ instead of comparing with them.")


@pytest.fixture
def update_golden(request) -> bool:
    """True when the run was asked to rewrite golden files."""
    return request.config.getoption("--update-golden")


@pytest.fixture
def golden(update_golden):
    """golden(name, text): assert `text` equals tests/golden/NAME byte for byte, with a diff if
    not; with --update-golden, write it there instead (the one path every golden goes through)."""
    import difflib

    def check(name: str, text: str) -> None:
        path = GOLDEN / name
        if update_golden:
            path.write_text(text)
        want = path.read_text()
        diff = "".join(difflib.unified_diff(want.splitlines(True), text.splitlines(True), str(path),
                                            "now"))
        assert text == want, "golden mismatch (rerun with --update-golden if intended):\n" + diff
    return check


def example_paths() -> list[Path]:
    """Every robot file in examples/ (sorted, so test ids are stable)."""
    return sorted(p for p in EXAMPLES.glob("*") if p.suffix in (".yaml", ".yml", ".json", ".urdf"))
