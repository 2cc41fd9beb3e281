"""Parallel-prefix network shapes for the logarithmic recursion (paper section IV, Figure IV.2).

A shape over leaves 0..m-1 is a set of combine *triples* (a, k, b): X_{a,b} = X_{a,k} ⊗ X_{k+1,b}, with
a ≤ k < b. Only associativity of ⊗ is assumed (the combining forms of Table IV.1 are not commutative), so
a triple always joins two *adjacent* ranges, left one first. Afterwards every prefix X_{0,i} exists.

Triples are organised in *tiers*: a triple's tier is one more than the later of its operands' tiers
(leaves are tier 0), i.e. the tiers are the ASAP levels of the network and the number of tiers is its
depth. The generators emit triples in dependency order; `_tiers` assigns the levels and checks that
every operand exists and that no range is built twice.

    shape            tiers                triples                          max fan-out (m = 2^L)
    serial           m - 1                m - 1                            1
    sklansky         L                    Σ_{i<m} popcount(i)              m/2
    kogge-stone      L                    m L - 2^L + 1                    L
    brent-kung       2L - 2 (m = 2^L ≥ 4)  2m - popcount(m) - ⌊log2 m⌋ - 1   L
    ladner-fischer   L + 1 (m = 2^L ≥ 8)  m - 1 + sklansky(⌊m/2⌋)          m/4 + 1

with L = ⌈log2 m⌉; at m = 2^L the sizes are (m/2) L, m L - m + 1, 2m - 2 - L and m - 1 + (m/4)(L - 1).
Sklansky is the paper's network (Figure IV.2): at level d every block of 2^{d+1} leaves joins its
lower half's prefix to each partial range of its upper half. Kogge–Stone has the most triples and
fan-out 2 within a tier (a finished prefix is re-read at every later tier, hence L over the whole
network). Brent–Kung (an up-sweep of aligned blocks, then a down-sweep filling the other prefixes) has
the fewest triples at about twice the depth; it is usually drawn with 2L - 1 level-synchronous tiers,
but with ASAP levels the down-sweep's first level overlaps the up-sweep's last, so 2L - 2 here.
Ladner–Fischer is the usual hardware variant (Harris's taxonomy): pairs first, Sklansky over the
pairs, then one tier more for the even positions, which halves Sklansky's fan-out for one extra
tier. Fan-out counts the triples reading one range; readers outside the network (e.g. the
non-propagated variables) are not counted.

For the forward (tip-to-base) pass the same shapes are mirrored (`suffix_tiers`): leaf j becomes leaf
m-1-j and a triple (a, k, b) becomes (m-1-b, m-2-k, m-1-a), so every suffix X_{i,m-1} exists and
operands stay adjacent and in order.
"""
from __future__ import annotations

from collections import Counter
from typing import Callable, Iterator

from vampc.errors import VampcError, VampcInternalError
from vampc.kinds import Prefix, exhaustive

Triple = tuple[int, int, int]
Tiers = tuple[tuple[Triple, ...], ...]


def _levels(m: int) -> int:
    """⌈log2 m⌉ (0 for m = 1)."""
    return max(m - 1, 0).bit_length()


def _serial_triples(m: int) -> Iterator[Triple]:
    for i in range(1, m):
        yield 0, i - 1, i


def _sklansky_triples(m: int) -> Iterator[Triple]:
    for d in range(_levels(m)):
        span = 1 << d
        for a in range(0, m, 2 * span):
            k = a + span - 1
            for b in range(k + 1, min(a + 2 * span, m)):
                yield a, k, b


def _kogge_stone_triples(m: int) -> Iterator[Triple]:
    # After level d, position i holds X_{max(0, i-2^d+1), i}.
    for d in range(_levels(m)):
        span = 1 << d
        for i in range(span, m):
            yield max(0, i - 2 * span + 1), i - span, i


def _brent_kung_triples(m: int) -> Iterator[Triple]:
    levels = _levels(m)
    for d in range(levels):                       # up-sweep: aligned blocks of 2^{d+1}
        span = 1 << d
        for i in range(2 * span - 1, m, 2 * span):
            yield i - 2 * span + 1, i - span, i
    for d in reversed(range(levels - 1)):         # down-sweep: i + 1 an odd multiple (≥ 3) of 2^d
        span = 1 << d
        for i in range(3 * span - 1, m, 2 * span):
            yield 0, i - span, i


def _ladner_fischer_triples(m: int) -> Iterator[Triple]:
    for i in range(1, m, 2):                      # pairs X_{2p, 2p+1}
        yield i - 1, i - 1, i
    for a, k, b in _sklansky_triples(m // 2):   # prefixes of the pairs: X_{0, 2p+1}
        yield 2 * a, 2 * k + 1, 2 * b + 1
    for i in range(2, m, 2):                      # the even positions, one tier later
        yield 0, i - 1, i


def serial(m: int) -> Tiers:
    """A chain, X_{0,i} = X_{0,i-1} ⊗ X_{i,i}: the linear recursion (m - 1 tiers)."""
    return _tiers(m, _serial_triples(m))


def sklansky(m: int) -> Tiers:
    """The paper's Figure IV.2 network: ⌈log2 m⌉ tiers, large fan-out."""
    return _tiers(m, _sklansky_triples(m))


def kogge_stone(m: int) -> Tiers:
    """⌈log2 m⌉ tiers, fan-out 2 per tier, the most triples."""
    return _tiers(m, _kogge_stone_triples(m))


def brent_kung(m: int) -> Tiers:
    """Up-sweep then down-sweep: fewer than 2m triples in about 2⌈log2 m⌉ tiers."""
    return _tiers(m, _brent_kung_triples(m))


def ladner_fischer(m: int) -> Tiers:
    """Pairs, Sklansky over the pairs, then the even positions: ⌈log2 m⌉ + 1 tiers."""
    return _tiers(m, _ladner_fischer_triples(m))


# every prefix shape's tier function, one per member of vampc.kinds.Prefix (exhaustive)
SHAPES: dict[Prefix, Callable[[int], Tiers]] = exhaustive({
    Prefix.SKLANSKY: sklansky,
    Prefix.BRENT_KUNG: brent_kung,
    Prefix.KOGGE_STONE: kogge_stone,
    Prefix.LADNER_FISCHER: ladner_fischer,
    Prefix.SERIAL: serial,
}, Prefix)


def _tiers(m: int, triples) -> Tiers:
    """Group triples (in dependency order) by ASAP level; raise VampcInternalError on a bad network."""
    level = {(i, i): 0 for i in range(m)}
    tiers: list[list[Triple]] = []
    for a, k, b in triples:
        if not 0 <= a <= k < b < m or (a, b) in level:
            raise VampcInternalError(f"prefix network over {m} leaves: bad or repeated triple {(a, k, b)}")
        if (a, k) not in level or (k + 1, b) not in level:
            raise VampcInternalError(f"prefix network over {m} leaves: {(a, k, b)} reads a missing range")
        t = 1 + max(level[a, k], level[k + 1, b])
        level[a, b] = t
        tiers.extend([] for _ in range(t - len(tiers)))
        tiers[t - 1].append((a, k, b))
    return tuple(tuple(t) for t in tiers)


def prefix_tiers(shape: str, m: int) -> Tiers:
    """Tiers of (a, k, b) triples of `shape` over m ≥ 1 leaves after which every X_{0,i} exists."""
    if shape not in SHAPES:
        raise VampcError(f"unknown prefix shape {shape!r} (choose from {', '.join(SHAPES)})")
    if m < 1:
        raise VampcInternalError(f"prefix network needs at least one leaf, got {m}")
    tiers = SHAPES[shape](m)
    verify(tiers, m)
    return tiers


def mirror(tiers: Tiers, m: int) -> Tiers:
    """The network reflected end for end: prefixes become suffixes (see the module docstring)."""
    return tuple(tuple((m - 1 - b, m - 2 - k, m - 1 - a) for a, k, b in tier) for tier in tiers)


def suffix_tiers(shape: str, m: int) -> Tiers:
    """Tiers of `shape` mirrored, after which every suffix X_{i,m-1} exists."""
    tiers = mirror(prefix_tiers(shape, m), m)
    verify(tiers, m, suffix=True)
    return tiers


def chain_table(prefix: str, n: int, ground0: bool) -> dict[str, list[tuple[int, int, int, int, int]]]:
    """The recursion nodes of a chain's log graph, per pass, as graph.meta's bwd_nodes and fwd_nodes
    record them: (group, a, k, b, tier) in the order the build opens them (each pass's leaves, then
    its prefix network tier by tier). A program file's are checked against it: the report places
    VAMPs by them (vampc.program.document.check_meta)."""
    first = 1 if ground0 else 0
    bwd = [(a, a, a, 0) for a in range(max(first, 1), n + 1)]
    bwd += [(a + first, k + first, b + first, t)
            for t, tier in enumerate(prefix_tiers(prefix, n + 1 - first), 1) for a, k, b in tier]
    fwd = [(i, i, i, 0) for i in range(1, n + 1)]
    fwd += [(a + 1, k + 1, b + 1, t) for t, tier in enumerate(suffix_tiers(prefix, n), 1)
            for a, k, b in tier]
    return {section: [(g, *row) for g, row in enumerate(rows, 1)]
            for section, rows in (("bwd", bwd), ("fwd", fwd))}


def verify(tiers: Tiers, m: int, suffix: bool = False) -> None:
    """Replay the tiers: operands exist before their tier, no range twice, all prefixes (suffixes) made."""
    have = {(i, i) for i in range(m)}
    for t, tier in enumerate(tiers, 1):
        made = set()
        for a, k, b in tier:
            if not (0 <= a <= k < b < m and (a, k) in have and (k + 1, b) in have):
                raise VampcInternalError(f"tier {t}: triple {(a, k, b)} is invalid or reads a later range")
            if (a, b) in have or (a, b) in made:
                raise VampcInternalError(f"tier {t}: range {(a, b)} built twice")
            made.add((a, b))
        have |= made
    wanted = {(i, m - 1) for i in range(m)} if suffix else {(0, i) for i in range(m)}
    if not wanted <= have:
        raise VampcInternalError(f"network over {m} leaves misses {sorted(wanted - have)[:4]}")


def size(tiers: Tiers) -> int:
    """Number of combine triples (combining nodes)."""
    return sum(len(t) for t in tiers)


def fan_out(tiers: Tiers) -> int:
    """The largest number of triples reading one range (leaves included); 0 for an empty network."""
    reads = Counter()
    for tier in tiers:
        for a, k, b in tier:
            reads[a, k] += 1
            reads[k + 1, b] += 1
    return max(reads.values(), default=0)

