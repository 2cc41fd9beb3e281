"""Logarithmic-depth networks on trees (issue 12): path prefixes for the backward pass, subtree sums for
the forward pass. Pure index structures, like vampc.dataflow.prefix; the builder (vampc.dataflow.logtree)
and the numeric proof (vampc.dynamics.logforms) follow them.

Joints 1..n are numbered depth-first (vampc.robot.chain); `parents[i-1]` is joint i's parent, 0 the base.

Backward: path prefixes. X_{a..b} is the product of the leaves on the path from joint a down to joint b
(a an ancestor of b, both included); joint 0 stands for the grounding leaf X_{0,0}. A triple (a, k, b)
makes X_{a..b} = X_{a..k} ⊗ X_{c..b}, c the child of k on the way to b: the operands are adjacent along
the path, left one first, so only associativity is used, as in prefix.py. Every joint j needs its full
prefix X_{top..j}, top = 0 with a grounding leaf, else the joint on the base above j (grounded in O_0,
each joint on the base carries gravity in its leaf).

The scheme: a heavy-path decomposition (each joint's heavy child is the child with the largest subtree,
the first on a tie). Each heavy path v_1..v_m is a chain, and its own prefixes X_{v_1..v_i} come from the
chosen chain shape (prefix.py: Sklansky is the paper's) over its m leaves, plus the grounding leaf in
front when v_1 is on the base. A path whose top hangs on joint p ≠ 0 then takes one combine more per
joint, X_{top..v_i} = X_{top..p} ⊗ X_{v_1..v_i}, as soon as p's full prefix exists. A chain is a single
heavy path: the scheme is then exactly the chain's prefix shape. Every root-to-joint path crosses at most
⌊log2 n⌋ light edges (a light child's subtree is at most half its parent's), so the depth is at most
the chain shape's depth over the longest heavy path plus one tier per light edge: ≤ 2⌈log2(n+1)⌉ for
Sklansky, whatever the tree's shape (a chain, a star, a balanced tree).

Forward: subtree sums. With every joint's force and moment moved into the base frame O_0 (about its
origin: vampc.dataflow.logtree), the forward recursion is a plain sum over each subtree, and in the
depth-first numbering a subtree is the contiguous range [j, end_j). `range_blocks` splits a range into
canonical aligned blocks (at most two per size, as a segment tree does); the blocks are built once for
all ranges (block sums, one VA level per doubling: ⌈log2 n⌉ levels) and each range sums its blocks
earliest first, so its sum is ready about one level after its largest block. Depth ⌈log2 n⌉ + O(1)
additions, with no subtraction (prefix sums differenced would cancel) and no ⊗ tier at all: the
forward pass costs additions where the chain's costs an MV + VA per tier.
"""
from __future__ import annotations

from vampc.dataflow.prefix import prefix_tiers
from vampc.errors import VampcInternalError

Key = tuple[int, int]              # (a, b): X_{a..b} along the path from joint a down to joint b
Triple = tuple[int, int, int]


def children_of(parents) -> list[list[int]]:
    """children[p] for p = 0..n, in joint order."""
    out: list[list[int]] = [[] for _ in range(len(parents) + 1)]
    for i, p in enumerate(parents, 1):
        out[p].append(i)
    return out


def subtree_sizes(parents) -> list[int]:
    """size[j] for j = 0..n (size[0] = n + 1, the base included)."""
    size = [1] * (len(parents) + 1)
    for i in range(len(parents), 0, -1):
        size[parents[i - 1]] += size[i]
    return size


def heavy_paths(parents) -> list[list[int]]:
    """The heavy paths, top to bottom, in the order of their tops (each joint on exactly one)."""
    kids, size = children_of(parents), subtree_sizes(parents)
    heavy = {p: max(c, key=lambda j: (size[j], -j)) for p, c in enumerate(kids) if c and p}
    paths = []
    for top in range(1, len(parents) + 1):
        p = parents[top - 1]
        if p and heavy[p] == top:
            continue
        path = [top]
        while path[-1] in heavy:
            path.append(heavy[path[-1]])
        paths.append(path)
    return paths


def path_prefix_plan(parents, shape: str, ground: bool) -> tuple[tuple[tuple[Triple, ...], ...], list[Key]]:
    """Tiers of (a, k, b) triples (ASAP levels, leaves at level 0) after which every joint's full prefix
    exists, and that prefix's key per joint (module docstring). `ground`: a grounding leaf 0 heads every
    path from the base."""
    level: dict[Key, int] = {(j, j): 0 for j in range(0 if ground else 1, len(parents) + 1)}
    made: list[tuple[int, Triple]] = []
    top = [0] * (len(parents) + 1)

    def combine(a: int, k: int, b: int, left: Key, right: Key) -> None:
        t = 1 + max(level[left], level[right])
        level[a, b] = t
        made.append((t, (a, k, b)))

    for path in heavy_paths(parents):
        _chain_prefixes(path, ground and parents[path[0] - 1] == 0, shape, combine)
        parent = parents[path[0] - 1]
        head = path[0] if parent == 0 and not ground else (0 if parent == 0 else top[parent])
        for j in path:
            top[j] = head
            if parent:
                combine(head, parent, j, (head, parent), (path[0], j))
    tiers: list[list[Triple]] = []
    for t, triple in sorted(made, key=lambda x: x[0]):
        tiers.extend([] for _ in range(t - len(tiers)))
        tiers[t - 1].append(triple)
    return tuple(map(tuple, tiers)), [(top[j], j) for j in range(1, len(parents) + 1)]


def _chain_prefixes(path: list[int], grounded: bool, shape: str, combine) -> None:
    """The chain shape over the path's leaves (the grounding leaf 0 first when `grounded`)."""
    nodes = ([0] if grounded else []) + path
    for tier in prefix_tiers(shape, len(nodes)):
        for a, k, b in tier:
            combine(nodes[a], nodes[k], nodes[b], (nodes[a], nodes[k]), (nodes[k + 1], nodes[b]))


def verify_plan(parents, tiers, keys: list[Key], ground: bool) -> None:
    """Replay a plan: every triple joins two existing adjacent path pieces, nothing is built twice, and
    every joint's full prefix is made (VampcInternalError otherwise)."""
    n = len(parents)
    have = {(j, j) for j in range(0 if ground else 1, n + 1)}
    above = [0] + list(parents)

    def path_child(k: int, b: int) -> int:
        c = b
        while above[c] != k:
            if c == 0:
                raise VampcInternalError(f"tree prefix: {k} is not above {b}")
            c = above[c]
        return c

    for t, tier in enumerate(tiers, 1):
        made = set()
        for a, k, b in tier:
            c = path_child(k, b) if k != b else None
            if c is None or (a, k) not in have or (c, b) not in have or (a, b) in have | made:
                raise VampcInternalError(f"tier {t}: triple {(a, k, b)} is invalid or repeated")
            made.add((a, b))
        have |= made
    missing = [key for key in keys if key not in have]
    if missing:
        raise VampcInternalError(f"tree prefix misses {missing[:4]}")


def range_blocks(lo: int, hi: int) -> list[tuple[int, int]]:
    """[lo, hi) as canonical aligned blocks (level, index): block (l, i) covers [i·2^l, (i+1)·2^l)."""
    out = []
    while lo < hi:
        level = 0
        while lo % (2 << level) == 0 and lo + (2 << level) <= hi:
            level += 1
        out.append((level, lo >> level))
        lo += 1 << level
    return out


def block_sources(level: int, index: int, count: int) -> list[tuple[int, int]]:
    """The two halves a block sums (one when the upper half lies past `count` positions)."""
    halves = [(level - 1, 2 * index), (level - 1, 2 * index + 1)]
    return [h for h in halves if h[1] << h[0] < count]


def tree_depths(parents, shape: str, ground: bool, floating: bool = False) -> dict[str, int]:
    """Depth figures of a tree for the report: joints, leaves, height (the level-by-level depth), heavy
    paths, light edges on the worst path, backward ⊗ tiers, forward addition levels (of the ranges the
    graph sums: `floating` adds the whole range, the base wrench's), ⌈log2(n+1)⌉."""
    n = len(parents)
    tiers, _ = path_prefix_plan(parents, shape, ground)
    kids = children_of(parents)
    paths = heavy_paths(parents)
    starts = {p[0] for p in paths}
    light = [0] * (n + 1)
    depth = [0] * (n + 1)
    for j in range(1, n + 1):
        p = parents[j - 1]
        depth[j] = depth[p] + 1
        light[j] = light[p] + (1 if j in starts and p else 0)
    return {"joints": n, "leaves": sum(1 for j in range(1, n + 1) if not kids[j]),
            "height": max(depth), "heavy_paths": len(paths), "light_edges": max(light),
            "backward_tiers": len(tiers), "forward_levels": subtree_sum_levels(parents, floating),
            "log2": max(n, 0).bit_length()}


def subtree_sum_levels(parents, floating: bool) -> int:
    """Addition levels of the forward subtree sums the log tree graph builds (vampc.dataflow.logtree):
    each joint j's subtree, positions [j - 1, j - 1 + size_j), and the whole [0, n) only for a floating
    base's wrench (a fixed base's is pruned). The report gave the worst range [lo, n) instead, a chain's
    ranges, ⌈log2 n⌉: a fixed-base tree with several joints on the base sums no range that long (a
    quadruped's legs of 3 joints: 2 levels, not 4). Each range of m positions takes ⌈log2 m⌉ levels."""
    size = subtree_sizes(parents)
    ranges = [(j - 1, j - 1 + size[j]) for j in range(1, len(parents) + 1)]
    if floating:
        ranges.append((0, len(parents)))
    return max((range_sum_levels(lo, hi) for lo, hi in ranges), default=0)


def chain_sum_levels(n: int) -> int:
    """The forward addition levels the report gave a tree until 2026-12-08: the worst range [lo, n)
    of a chain of n joints (a program file of then stores it: vampc.program.document reads it as
    counted before, not as an edit)."""
    return max((range_sum_levels(lo, n) for lo in range(n)), default=0)


def range_sum_levels(lo: int, hi: int) -> int:
    """Addition levels of the sum of positions [lo, hi): its blocks' levels, then their sum."""
    return earliest_sum(sorted(level for level, _ in range_blocks(lo, hi)))


def earliest_sum(ready: list[int]) -> int:
    """When a sum of items ready at the given levels is ready, adding the two earliest each time."""
    import heapq
    heap = list(ready)
    heapq.heapify(heap)
    while len(heap) > 1:
        a, b = heapq.heappop(heap), heapq.heappop(heap)
        heapq.heappush(heap, max(a, b) + 1)
    return heap[0] if heap else 0
