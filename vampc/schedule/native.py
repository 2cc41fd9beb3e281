"""The list schedule's two loops in C, for big graphs: the priority (each node's longest path to the
end) and the placement of every op on its unit (vampc.schedule.layout.schedule_bound).

Both are the Python loops of vampc.schedule.layout, line for line, on arrays: the same order, the
same first-fit on a unit's busy ticks and dump blocks, so the same schedule (tests/test_schedule_native.py
compares both on real and random graphs). A 4 096-joint log graph (950 000 nodes) takes about 6 s in
Python per folded layout, which a report compares twice.

The C is compiled once and cached as the stream engine's is (vampc.emulator.native: the system C
compiler, the same cache folder, VAMPC_NATIVE=0 to keep to Python, =1 to make a failure an error);
graphs of fewer than MIN_NODES compute nodes stay in Python (no compiler is run for them).
"""
from __future__ import annotations

import ctypes

from vampc.errors import env_switch

MIN_NODES = 50_000

SOURCE = r"""
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct { unsigned char *p; int64_t n; } buf_t;

/* Make b hold at least `need` bytes, the new ones zero. */
static int grow(buf_t *b, int64_t need) {
    if (need <= b->n) return 0;
    int64_t cap = b->n ? b->n : 64;
    while (cap < need) cap *= 2;
    unsigned char *q = realloc(b->p, (size_t)cap);
    if (!q) return -1;
    memset(q + b->n, 0, (size_t)(cap - b->n));
    b->p = q; b->n = cap;
    return 0;
}

/* The first index >= start of `length` zero bytes (beyond the end everything is zero). */
static int64_t find_free(const buf_t *b, int64_t start, int64_t length) {
    int64_t t = start;
    for (;;) {
        int64_t k = t, end = t + length;
        while (k < end && k < b->n && !b->p[k]) k++;
        if (k == end || k >= b->n) return t;
        t = k + 1;
    }
}

/* height[a] = the longest path (ticks) from node a to the end: nodes in topological order. */
void longest_to_end(int64_t nodes, const int64_t *argptr, const int64_t *args,
                    const int64_t *dur, int64_t *height) {
    for (int64_t i = nodes - 1; i >= 0; i--) {
        int64_t h = height[i] + dur[i];
        for (int64_t j = argptr[i]; j < argptr[i + 1]; j++)
            if (height[args[j]] < h) height[args[j]] = h;
    }
}

/* Place the compute nodes of `order` on their units, in that order (start, finish: the ASAP
   schedule on entry). 0, or -1 when memory ran out. */
int64_t list_schedule(int64_t count, const int64_t *order, const int64_t *argptr,
                      const int64_t *args, const unsigned char *is_compute,
                      const int64_t *asap_start, const int64_t *dur, const int64_t *unit,
                      int64_t units, int64_t clock, int64_t *start, int64_t *finish) {
    buf_t *busy = calloc((size_t)units, sizeof(buf_t));
    buf_t *shown = calloc((size_t)units, sizeof(buf_t));
    int64_t rc = 0;
    if (!busy || !shown) { rc = -1; goto done; }
    for (int64_t c = 0; c < count; c++) {
        int64_t i = order[c], ready = asap_start[i], len = dur[i], u = unit[i];
        for (int64_t j = argptr[i]; j < argptr[i + 1]; j++) {
            int64_t a = args[j];
            if (is_compute[a] && finish[a] > ready) ready = finish[a];
        }
        int64_t t = ready;
        for (;;) {
            t = find_free(&busy[u], t, len);
            int64_t block = (t + len) / clock;
            int64_t free_block = find_free(&shown[u], block, 1);
            if (free_block == block) break;
            if (free_block * clock - len > t) t = free_block * clock - len;
        }
        start[i] = t;
        finish[i] = t + len;
        int64_t block = (t + len) / clock;
        if (grow(&busy[u], t + len) || grow(&shown[u], block + 1)) { rc = -1; goto done; }
        memset(busy[u].p + t, 1, (size_t)len);
        shown[u].p[block] = 1;
    }
done:
    if (busy) for (int64_t u = 0; u < units; u++) free(busy[u].p);
    if (shown) for (int64_t u = 0; u < units; u++) free(shown[u].p);
    free(busy);
    free(shown);
    return rc;
}
"""

_LIB: list = []


def wanted(compute_nodes: int) -> bool:
    """Whether a graph of this many compute nodes is scheduled in C (VAMPC_NATIVE: 0 never, 1
    always)."""
    mode = env_switch("VAMPC_NATIVE")
    return mode == "1" or (mode != "0" and compute_nodes >= MIN_NODES)


def _library():
    """The compiled SOURCE, or None where it cannot be built (no compiler: the Python loops then
    run; with VAMPC_NATIVE=1 the NativeError is raised)."""
    if _LIB:
        return _LIB[0]
    from vampc.emulator.native import NativeError, _load, compile_cached
    try:
        lib = _load(compile_cached(SOURCE))
    except NativeError:
        if env_switch("VAMPC_NATIVE") == "1":
            raise
        lib = None
    if lib is not None:
        p, i64 = ctypes.c_void_p, ctypes.c_int64     # (int64_t: numpy's int64 on every platform)
        lib.longest_to_end.argtypes = (i64, p, p, p, p)
        lib.longest_to_end.restype = None
        lib.list_schedule.argtypes = (i64, p, p, p, p, p, p, p, i64, i64, p, p)
        lib.list_schedule.restype = i64
    _LIB.append(lib)
    return lib


class Arrays:
    """A graph's operands as compressed rows (argptr, args) and per node its duration and whether a
    VAMP computes it."""

    def __init__(self, graph, duration):
        import itertools
        import operator

        import numpy as np
        nodes, count = graph.nodes, len(graph.nodes)
        # (map and attrgetter: the loops over millions of nodes run in C)
        args = list(map(operator.attrgetter("args"), nodes))
        ops = list(map(operator.attrgetter("op"), nodes))
        self.argptr = np.zeros(count + 1, dtype=np.int64)
        np.cumsum(np.fromiter(map(len, args), dtype=np.int64, count=count), out=self.argptr[1:])
        self.args = np.fromiter(itertools.chain.from_iterable(args), dtype=np.int64,
                                count=int(self.argptr[-1]))
        self.dur = np.fromiter(map(duration.__getitem__, ops), dtype=np.int64, count=count)
        compute = {op: op.is_compute for op in set(ops)}
        self.is_compute = np.fromiter(map(compute.__getitem__, ops), dtype=np.uint8, count=count)


def longest_to_end(graph, duration, arrays: Arrays | None = None) -> list[int] | None:
    """vampc.schedule.layout._longest_to_end in C; None when the library is not available."""
    lib = _library()
    if lib is None:
        return None
    import numpy as np
    a = arrays or Arrays(graph, duration)
    height = np.zeros(len(graph.nodes), dtype=np.int64)
    lib.longest_to_end(len(graph.nodes), a.argptr.ctypes.data, a.args.ctypes.data,
                       a.dur.ctypes.data, height.ctypes.data)
    return height.tolist()


def list_schedule(arrays: Arrays, order, asap, units, unit_count: int, clock: int):
    """(start, finish) lists of the list schedule (vampc.schedule.layout.schedule_bound's loop) in
    C; None when the library is not available."""
    lib = _library()
    if lib is None:
        return None
    import numpy as np

    from vampc.errors import VampcInternalError
    order = np.asarray(order, dtype=np.int64)
    unit = np.asarray(units, dtype=np.int64)
    # the C trusts its indices: check them here (Python's lists would raise IndexError)
    nodes = len(arrays.dur)
    if len(order) and (order.min() < 0 or order.max() >= nodes or unit[order].min() < 0
                       or unit[order].max() >= unit_count) or clock < 1 or \
            len(arrays.args) and (arrays.args.min() < 0 or arrays.args.max() >= nodes):
        raise VampcInternalError("list schedule: a node, operand or unit out of range")
    asap_start = np.asarray(asap.start, dtype=np.int64)
    start = asap_start.copy()
    finish = np.asarray(asap.finish, dtype=np.int64).copy()
    rc = lib.list_schedule(len(order), order.ctypes.data, arrays.argptr.ctypes.data,
                           arrays.args.ctypes.data, arrays.is_compute.ctypes.data,
                           asap_start.ctypes.data, arrays.dur.ctypes.data, unit.ctypes.data,
                           unit_count, clock, start.ctypes.data, finish.ctypes.data)
    if rc != 0:
        raise MemoryError("list schedule: out of memory")
    return start.tolist(), finish.tolist()
