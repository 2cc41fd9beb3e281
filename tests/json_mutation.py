"""Random JSON values and one-place mutations of JSON documents, for the schema tests."""
from __future__ import annotations

import copy

from hypothesis import strategies as st

json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=5), inner, max_size=4),
    max_leaves=25)


def paths(node, prefix=()):
    """Every path into a JSON document (dict keys and list indices)."""
    yield prefix
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, child in items:
        yield from paths(child, prefix + (key,))


def mutations(doc):
    """(path, value, delete) triples for `mutate`: a place in `doc`, a JSON value to put there (or
    one of a few values near the schemas' bounds), and whether to remove the key instead."""
    places = [p for p in paths(doc) if p]
    replacement = st.one_of(json_values, st.sampled_from([-1, 0, 2**24, 4096, 1.5, "vamp", "x"]))
    return st.tuples(st.sampled_from(places), replacement, st.booleans())


def mutate(doc, path, value, delete):
    """A copy of `doc` with the value at `path` replaced by `value` (or its key removed)."""
    doc = copy.deepcopy(doc)
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    if delete and isinstance(parent, dict):
        del parent[path[-1]]
    else:
        parent[path[-1]] = value
    return doc
