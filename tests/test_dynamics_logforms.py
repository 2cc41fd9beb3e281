"""The logarithmic combining forms against the linear recursion (rnea_variables) and against the closed-form
sums of Appendix B, under random bracketings; Appendix D leaves; the printed leaf typos really are typos."""
from dataclasses import replace
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vampc.dynamics import logforms as lf
from vampc.dynamics.reference import rnea, rnea_variables
from vampc.errors import VampcInternalError
from vampc.robot.chain import E_Z
from vampc.robot.random import (
    TREE_SHAPES,
    random_base,
    random_chain,
    random_state,
    random_tree,
)

RTOL = 1e-11
EXAMPLES = settings(max_examples=25, deadline=None)


def assert_close(actual, expected, rtol=RTOL, floor=1e-3):
    """|actual - expected| ≤ rtol · max(max|expected|, floor)."""
    scale = max(np.max(np.abs(expected)), floor)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * scale)


def random_split(seed):
    """A bracketing choosing k uniformly in a..b-1 for every range it is asked about."""
    rng = np.random.default_rng(seed)
    return lambda a, b: int(rng.integers(a, b))


def case(n, seed):
    """A random chain with every endpoint nonzero and one random state (q, q̇, q̈)."""
    chain = random_chain(n, seed, prismatic_fraction=0.4, endpoints=True)
    return chain, lf.State(*(x[0] for x in random_state(chain, 1, seed + 1)))


cases = st.tuples(st.integers(1, 12), st.integers(0, 10_000), st.integers(0, 10_000))


# --- against the linear recursion --------------------------------------------------------------------------

@EXAMPLES
@given(cases)
def test_backward_prefixes_are_the_linear_variables(args):
    n, seed, split_seed = args
    chain, state = case(n, seed)
    linear = rnea_variables(chain, *state)
    prefixes = lf.prefix_backward(chain, state, random_split(split_seed))
    product = np.eye(3)
    for i in range(1, n + 1):
        product = product @ chain.joints[i - 1].A(state.q[i - 1])
        assert_close(prefixes[i].W, product)
        for key in ("omega", "omega_dot", "pdd"):
            assert_close(getattr(prefixes[i], key), linear[key][i - 1])


@EXAMPLES
@given(cases)
def test_forward_suffixes_are_the_linear_variables(args):
    n, seed, split_seed = args
    chain, state = case(n, seed)
    linear = rnea_variables(chain, *state)
    suffixes = lf.suffix_forward(chain, state.q, linear["F"], linear["N"], random_split(split_seed))
    for i in range(1, n + 1):
        assert_close(suffixes[i - 1].f, linear["f"][i - 1])
        assert_close(suffixes[i - 1].n, linear["n"][i - 1])


@EXAMPLES
@given(cases)
def test_log_rnea_equals_rnea(args):
    n, seed, split_seed = args
    chain, state = case(n, seed)
    assert_close(lf.log_rnea(chain, *state, split=random_split(split_seed)), rnea(chain, *state))


def test_batched_states():
    chain = random_chain(6, 4, endpoints=True)
    q, qd, qdd = random_state(chain, 10, 4)
    assert_close(lf.log_rnea(chain, q, qd, qdd), rnea(chain, q, qd, qdd))


# --- against the closed forms of Appendix B, for every range (a, b) -----------------------------------------

class ClosedForms:
    """Appendix B's defining sums, evaluated directly (index 0 = grounding link, n+1 = tip load)."""

    def __init__(self, chain, state, big_f, big_n):
        n, q = chain.n, state.q
        self.n, self.chain = n, chain
        self.A = [np.eye(3)] + [j.A(q[i]) for i, j in enumerate(chain.joints)] + [np.eye(3)] * 2
        self.p = [np.zeros(3)] + [j.p_star(q[i]) for i, j in enumerate(chain.joints)] + [np.zeros(3)]
        self.s = [np.zeros(3)] + [j.s_star(q[i]) for i, j in enumerate(chain.joints)] + [np.zeros(3)]
        self.sigma = np.r_[1, chain.sigmas]
        # σ_j z_{j-1} q̇_j and z_{j-1} q̈_j in O_{j-1}; for j = 0 they stand for ω_0 and ω̇_0
        self.vel = [chain.base_omega] + [E_Z * v for v in state.qd]
        self.acc = [chain.base_omega_dot] + [E_Z * v for v in state.qdd]
        self.big_f = [None] + list(big_f) + [chain.tip_force]
        self.big_n = [None] + list(big_n) + [chain.tip_torque]
        self.omega = lru_cache(None)(self.omega)
        self.omega_dot = lru_cache(None)(self.omega_dot)
        self.f = lru_cache(None)(self.f)

    def W(self, a, b):
        out = np.eye(3)
        for j in range(a, b + 1):
            out = out @ self.A[j]
        return out

    def _sum(self, a, b, term, shift=0):
        return sum((self.W(j + shift, b).T @ term(j) for j in range(a, b + 1)), np.zeros(3))

    def omega(self, a, b):
        return self._sum(a, b, lambda j: self.sigma[j] * self.vel[j])

    def omega_dot(self, a, b):
        return self._sum(a, b, lambda j: self.sigma[j] * (
            self.acc[j] + np.cross(self.omega(a, j - 1), self.vel[j])))

    def Q(self, a, b):
        return self._sum(a, b, lambda j: (1 - self.sigma[j]) * self.vel[j])

    def R(self, a, b):
        return self._sum(a, b, lambda j: self.p[j], shift=1)

    def S(self, a, b):
        return self._sum(a, b, lambda j: np.cross(self.omega(a, j), self.p[j]), shift=1)

    def pdd(self, a, b):
        def term(j):
            w, p, axis = self.omega(a, j), self.p[j], self.A[j].T @ E_Z
            slide = (1 - self.sigma[j]) * (axis * self.acc[j][2] + 2 * np.cross(w, axis * self.vel[j][2]))
            ground = self.chain.base_accel if j == 0 else 0.0
            return ground + np.cross(self.omega_dot(a, j), p) + np.cross(w, np.cross(w, p)) + slide
        return self._sum(a, b, term, shift=1)

    def f(self, a, b):
        return sum((self.W(a + 1, j) @ self.big_f[j] for j in range(a, b + 1)), np.zeros(3))

    def n_(self, a, b):
        def term(j):
            after = self.A[j + 1] @ self.f(j + 1, b) if j < b else np.zeros(3)
            return (self.big_n[j] + np.cross(self.s[j], self.big_f[j]) + np.cross(self.p[j], after))
        return sum((self.W(a + 1, j) @ term(j) for j in range(a, b + 1)), np.zeros(3))


@EXAMPLES
@given(cases, st.data())
def test_every_range_matches_the_closed_forms(args, data):
    n, seed, split_seed = args
    chain, state = case(n, seed)
    linear = rnea_variables(chain, *state)
    closed = ClosedForms(chain, state, linear["F"], linear["N"])
    split = random_split(split_seed)
    a = data.draw(st.integers(0, n))
    b = data.draw(st.integers(a, n))
    back = lf.reduce_range(a, b, lambda i: lf.back_leaf(chain, i, state), lf.back_combine, split, {})
    assert_close(back.W, closed.W(a, b))
    for key in ("omega", "omega_dot", "Q", "R", "S", "pdd"):
        assert_close(getattr(back, key), getattr(closed, key)(a, b))
    a, b = a + 1, data.draw(st.integers(a + 1, n + 1))
    fwd = lf.reduce_range(a, b, lambda i: lf.fwd_leaf(chain, i, state.q, linear["F"], linear["N"]),
                          lf.fwd_combine, split, {})
    assert_close(fwd.W, closed.W(a + 1, b + 1))
    assert_close(fwd.R, closed.A[b + 1].T @ closed.R(a, b))
    assert_close(fwd.f, closed.f(a, b))
    assert_close(fwd.n, closed.n_(a, b))


# --- Appendix D and the printed typos -----------------------------------------------------------------------

@pytest.mark.parametrize("seed", range(3))
def test_unified_leaves_combine_to_the_leaves(seed):
    chain, state = case(5, seed)
    linear = rnea_variables(chain, *state)
    for a in range(chain.n + 1):
        left, right = lf.back_leaf_unified(chain, a, state)
        got, want = lf.back_combine(left, right), lf.back_leaf(chain, a, state)
        for key in ("W", "omega", "omega_dot", "Q", "R", "S", "pdd"):
            assert_close(getattr(got, key), getattr(want, key), rtol=1e-14)
    for a in range(1, chain.n + 2):
        args = (chain, a, state.q, linear["F"], linear["N"])
        got, want = lf.fwd_combine(*lf.fwd_leaf_unified(*args)), lf.fwd_leaf(*args)
        for key in ("W", "R", "f", "n"):
            assert_close(getattr(got, key), getattr(want, key), rtol=1e-14)


def test_printed_omega_dot_leaf_is_a_typo():
    """Table IV.1 prints ω̇_{a,a} = σ_a A_aᵀ z q̇_a: with it the prefixes no longer match; with q̈ they do."""
    chain, state = case(4, 9)

    def printed_leaf(a):
        leaf = lf.back_leaf(chain, a, state)
        return replace(leaf, omega_dot=leaf.omega) if a else leaf   # σ_a A_aᵀz q̇_a is ω_{a,a}
    wrong = lf.reduce_range(0, chain.n, printed_leaf, lf.back_combine, lf.split_middle, {})
    right = lf.prefix_backward(chain, state)[-1]
    linear = rnea_variables(chain, *state)["omega_dot"][-1]
    assert_close(right.omega_dot, linear)
    assert not np.allclose(wrong.omega_dot, linear)


def test_bad_split_and_leaf_index_are_internal_errors():
    chain, state = case(3, 0)
    with pytest.raises(VampcInternalError, match=r"split\(0, 1\) = 1 is not in 0\.\.0"):
        lf.prefix_backward(chain, state, split=lambda a, b: b)
    with pytest.raises(VampcInternalError, match=r"leaf 5 outside 0\.\.3"):
        lf.back_leaf(chain, 5, state)


# --- trees (issue 12): path prefixes and subtree sums in the base frame ----------------------------------

tree_cases = st.tuples(st.integers(1, 40), st.integers(0, 10_000), st.sampled_from(TREE_SHAPES),
                       st.sampled_from(["sklansky", "brent-kung", "kogge-stone", "ladner-fischer", "serial"]))


@EXAMPLES
@given(tree_cases)
def test_tree_prefixes_are_the_linear_variables(args):
    n, seed, shape, prefix = args
    chain = random_tree(n, seed, shape, prismatic_fraction=0.4, endpoints=True)
    state = lf.State(*(x[0] for x in random_state(chain, 1, seed + 1)))
    linear = rnea_variables(chain, *state)
    prefixes = lf.tree_prefix_backward(chain, state, prefix)
    for i in range(1, n + 1):
        for key in ("omega", "omega_dot", "pdd"):
            assert_close(getattr(prefixes[i - 1], key), linear[key][i - 1])


@EXAMPLES
@given(tree_cases, st.booleans())
def test_tree_log_rnea_equals_rnea(args, floating):
    n, seed, shape, prefix = args
    chain = random_tree(n, seed, shape, prismatic_fraction=0.4, floating=floating, endpoints=True)
    if floating:
        chain = replace(chain, base_omega=np.zeros(3), base_omega_dot=np.zeros(3))
    q, qd, qdd = random_state(chain, 3, seed + 1)
    base = random_base(3, seed + 2) if floating else None
    assert_close(lf.tree_log_rnea(chain, q, qd, qdd, prefix, base), rnea(chain, q, qd, qdd, base))


def test_shifted_leaf_is_a_virtual_leaf_then_the_joint():
    """V_d ⊗ X_{d,d} with the motionless V_d = (I, 0, 0, 0, o_d, 0, 0) is back_leaf's shifted leaf."""
    chain = random_tree(6, 11, "star", prismatic_fraction=0.5)
    state = lf.State(*(x[0] for x in random_state(chain, 1, 3)))
    for a, joint in enumerate(chain.joints, 1):
        leaf = lf.back_leaf(chain, a, state)
        bare = lf.back_leaf(replace(chain, joints=tuple(replace(j, shift=None) for j in chain.joints)),
                            a, state)
        zero = np.zeros(3)
        virtual = lf.Back(np.eye(3), zero, zero, zero, joint.shift_vec, zero, zero)
        both = lf.back_combine(virtual, bare)
        for key in ("W", "omega", "omega_dot", "Q", "R", "S", "pdd"):
            assert_close(getattr(leaf, key), getattr(both, key))
        assert_close(lf.back_combine(*lf.back_leaf_unified(chain, a, state)).R, leaf.R)
