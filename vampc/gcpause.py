"""Pausing Python's cyclic garbage collector while a stage builds millions of small objects.

The compiler's IRs and the program document are acyclic: reference counting frees them. But the
cyclic collector's full collections walk every live container, and while millions of containers are
being made they come round again and again, so building a million-VAMP network and its program text
spent a good part of its time walking what it had already built (log recursion, n = 4096, compile_chain + program_text: 41.4 s with the
collector running, 30.1 s with it paused; medians of 3 in one run). The collector is resumed, if it
was on, when the stage ends; it then frees any cycle made meanwhile.
"""
from __future__ import annotations

import contextlib
import gc


@contextlib.contextmanager
def gc_paused():
    """Context manager (and decorator) that pauses the cyclic collector for its duration."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
