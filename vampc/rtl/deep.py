"""Amaranth's elaboration, simulation and Verilog conversion recurse once or more per level of an
expression, and a time-multiplexed VAMP's operand multiplexer nests one level per slot: a budget
network's VAMP of 90 slots (the Stanford arm on 2 VAMPs) went past Python's 1 000 frames, a
RecursionError that ended `vampc rtl` as "a bug in vampc" (an audit's find). `deep` runs such a
call in a thread of its own with a large stack and a recursion limit to match (the quadruped's log
recursion on 3 VAMPs, 248 slots a VAMP, converts to Verilog so in 27 s)."""
from __future__ import annotations

import sys
import threading

STACK_BYTES = 512 * 2 ** 20      # reserved, not used: the pages a deep recursion touches
RECURSION_LIMIT = 100_000


def deep(fn, *args, **kwargs):
    """fn(*args, **kwargs) in a thread with STACK_BYTES of stack and RECURSION_LIMIT frames; its
    result, or its exception raised here. The waiting thread takes signals as before (a daemon
    thread: a Ctrl-C or SIGTERM here ends the process with it)."""
    result, failure = [], []

    def run():
        try:
            result.append(fn(*args, **kwargs))
        except BaseException as exc:          # (handed to the caller, as if raised there)
            failure.append(exc)
    try:
        previous = threading.stack_size(STACK_BYTES)
    except (ValueError, RuntimeError):       # (a platform without that stack: as before, inline)
        return fn(*args, **kwargs)
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, RECURSION_LIMIT))
    try:
        try:
            worker = threading.Thread(target=run, name="vampc-rtl", daemon=True)
            worker.start()
        finally:
            threading.stack_size(previous)
        worker.join()
    finally:
        sys.setrecursionlimit(limit)
    if failure:
        raise failure[0]
    return result[0]
