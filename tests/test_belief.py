"""assocopt.tracking.belief: validation, closed forms of paper 000, an independent dict-based
oracle, and algebraic properties (hypothesis)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, strategies as st

from assocopt.tracking.belief import (InvalidMassError, MassFunction, TotalConflictError, conflict,
                             conflict_matrix, conflict_vectors, conjunctive,
                             conjunctive_vectors, dempster, discount, discount_vectors,
                             pignistic, pignistic_vectors, zhang_combination,
                             zhang_combination_vectors, zhang_conflict, zhang_conflict_matrix,
                             zhang_conflict_vectors)

F3 = ("a", "b", "c")
S = frozenset


# ------------------------------------------------- independent oracle (dicts)
def _oracle_conj(m1: dict, m2: dict) -> dict:
    out: dict = {}
    for (A, x), (B, y) in itertools.product(m1.items(), m2.items()):
        out[A & B] = out.get(A & B, 0.0) + x * y
    return out


def _oracle_zhang(m1: dict, m2: dict) -> dict:
    out: dict = {S(): 0.0}
    for (A, x), (B, y) in itertools.product(m1.items(), m2.items()):
        C = A & B
        if not C:
            out[S()] += x * y
            continue
        w = len(C) / (len(A) * len(B))
        out[C] = out.get(C, 0.0) + x * y * w
        out[S()] += x * y * (1 - w)
    return out


def _oracle_betp(m: dict, frame) -> dict:
    rest = 1.0 - m.get(S(), 0.0)
    return {w: sum(v / len(A) for A, v in m.items() if w in A) / rest for w in frame}


def _close(d1: dict, d2: dict, atol=1e-12) -> bool:
    keys = set(d1) | set(d2)
    return all(abs(d1.get(k, 0.0) - d2.get(k, 0.0)) <= atol for k in keys)


# ------------------------------------------------------------- strategies
@st.composite
def masses(draw, frame=F3, allow_empty=False, singletons=False):
    n = len(frame)
    if singletons:
        subsets = [S({e}) for e in frame]
    else:
        subsets = [S(c) for r in range(0 if allow_empty else 1, n + 1)
                   for c in itertools.combinations(frame, r)]
    chosen = draw(st.lists(st.sampled_from(subsets), min_size=1, max_size=len(subsets),
                           unique=True))
    w = draw(st.lists(st.floats(0.01, 1.0), min_size=len(chosen), max_size=len(chosen)))
    total = sum(w)
    return MassFunction(frame, {A: x / total for A, x in zip(chosen, w)})


# ------------------------------------------------------------- validation
@pytest.mark.parametrize("bad, match", [
    ({S("a"): -0.1, S("ab"): 1.1}, "negative"),
    ({S("a"): 0.5, S("b"): 0.4}, "sum to"),
    ({S("a"): 0.5, S({"z"}): 0.5}, "not in the frame"),
    ({"a": 1.0}, "set of element names"),
    ({S("a"): float("nan"), S("b"): 1.0}, "not finite"),
    ({S("a"): "0.5", S("b"): 0.5}, "real number"),
    ({S("a"): 0.5, ("a",): 0.5}, "given twice"),
])
def test_invalid_masses_are_errors(bad, match):
    with pytest.raises(InvalidMassError, match=match):
        MassFunction(F3, bad)


@pytest.mark.parametrize("frame, match", [("abc", "string"), ({"a", "b"}, "ordered"),
                                          (("a", "a"), "duplicate"), ((), "at least one")])
def test_invalid_frames_are_errors(frame, match):
    with pytest.raises(InvalidMassError, match=match):
        MassFunction(frame, {S("a"): 1.0})


def test_to_dict_keeps_empty_set_with_mass_and_drops_zeros():
    m = MassFunction(F3, {S(): 0.25, S("a"): 0.75, S("b"): 0.0})
    assert m.to_dict() == {S(): 0.25, S("a"): 0.75}
    assert MassFunction(F3, {S("a"): 1.0}).to_dict() == {S("a"): 1.0}


def test_accessors_belief_plausibility_commonality():
    m = MassFunction(F3, {S("a"): 0.5, S("ab"): 0.3, S("abc"): 0.2})
    assert m[{"a"}] == 0.5 and m.mass(("a", "b")) == 0.3
    assert m.belief({"a", "b"}) == pytest.approx(0.8)
    assert m.plausibility({"b"}) == pytest.approx(0.5)
    assert m.commonality({"a"}) == pytest.approx(1.0)
    assert m.commonality({"b"}) == pytest.approx(0.5)


def test_frames_in_another_order_are_aligned_and_different_frames_refused():
    m1 = MassFunction(("a", "b"), {S("a"): 0.6, S("ab"): 0.4})
    m2 = MassFunction(("b", "a"), {S("b"): 0.5, S("ab"): 0.5})
    assert _close(conjunctive(m1, m2).to_dict(), _oracle_conj(m1.to_dict(), m2.to_dict()))
    with pytest.raises(InvalidMassError, match="different frames"):
        conjunctive(m1, MassFunction(("a", "c"), {S("a"): 1.0}))


# ------------------------------------------------------- against the oracle
@given(masses(allow_empty=True), masses(allow_empty=True))
def test_conjunctive_matches_oracle(m1, m2):
    assert _close(conjunctive(m1, m2).to_dict(), _oracle_conj(m1.to_dict(), m2.to_dict()))


@given(masses(allow_empty=True), masses(allow_empty=True))
def test_zhang_combination_matches_oracle_and_sums_to_one(m1, m2):
    out = zhang_combination(m1, m2)
    assert _close(out.to_dict(), _oracle_zhang(m1.to_dict(), m2.to_dict()))
    assert math.fsum(out.to_dict().values()) == pytest.approx(1.0, abs=1e-12)   # sums to 1
    assert out.empty_mass == pytest.approx(zhang_conflict(m1, m2), abs=1e-12)    # eq. 11


@given(masses(), masses())
def test_dempster_is_normalised_conjunctive(m1, m2):
    c = conjunctive(m1, m2).to_dict()
    k = c.pop(S(), 0.0)
    if 1 - k < 1e-9:
        return
    expected = {A: v / (1 - k) for A, v in c.items()}
    assert _close(dempster(m1, m2).to_dict(), expected, atol=1e-9)
    assert conflict(m1, m2) == pytest.approx(k, abs=1e-12)


def test_dempster_total_conflict_raises():
    m1 = MassFunction(F3, {S("a"): 1.0})
    m2 = MassFunction(F3, {S("b"): 0.3, S("c"): 0.7})
    assert conflict(m1, m2) == 1.0
    with pytest.raises(TotalConflictError, match="total conflict"):
        dempster(m1, m2)


@given(masses(allow_empty=True), st.floats(0.0, 1.0))
def test_discount_matches_definition(m, r):
    d = discount(m, r).to_dict()
    exp = {A: r * v for A, v in m.to_dict().items()}
    exp[S(F3)] = exp.get(S(F3), 0.0) + 1 - r
    assert _close(d, {A: v for A, v in exp.items() if v > 0})


@pytest.mark.parametrize("r", [-0.1, 1.5, float("nan"), True])
def test_discount_rejects_bad_reliability(r):
    with pytest.raises(InvalidMassError, match="reliability"):
        discount(MassFunction.vacuous(F3), r)


@given(masses(allow_empty=True))
def test_pignistic_matches_oracle(m):
    if m.empty_mass > 1 - 1e-9:
        return
    p = pignistic(m)
    assert list(p) == list(F3)
    assert _close(p, _oracle_betp(m.to_dict(), F3), atol=1e-12)
    assert math.fsum(p.values()) == pytest.approx(1.0)


def test_pignistic_of_total_conflict_raises():
    with pytest.raises(TotalConflictError):
        pignistic(MassFunction(F3, {S(): 1.0}))


# --------------------------------------------------- paper 000 closed forms
@given(masses(), masses())
def test_new_conflict_equals_one_minus_betp_inner_product(m1, m2):   # K = 1 - <BetP1, BetP2>
    b1, b2 = pignistic(m1), pignistic(m2)
    assert zhang_conflict(m1, m2) == pytest.approx(1 - sum(b1[w] * b2[w] for w in F3), abs=1e-12)


@given(masses(), masses())
def test_new_conflict_is_at_least_traditional_and_in_unit_interval(m1, m2):
    k0, k = conflict(m1, m2), zhang_conflict(m1, m2)
    assert -1e-12 <= k0 <= k + 1e-12 and k <= 1 + 1e-12


@given(masses(singletons=True), masses(singletons=True))
def test_new_rule_equals_smets_rule_for_singleton_focal_sets(m1, m2):
    assert zhang_combination(m1, m2).isclose(conjunctive(m1, m2))
    assert zhang_conflict(m1, m2) == pytest.approx(conflict(m1, m2), abs=1e-12)


def test_vacuous_self_conflict_is_five_sixths():   # ignorance counts as conflict
    v = MassFunction.vacuous(tuple("abcdef"))
    assert zhang_conflict(v, v) == pytest.approx(5 / 6)
    assert conflict(v, v) == 0.0


def test_hand_computed_example_of_new_rule():
    # m1: {a}: .6, {a,b}: .4 ; m2: {a,b}: .5, {b,c}: .5
    m1 = MassFunction(F3, {S("a"): 0.6, S("ab"): 0.4})
    m2 = MassFunction(F3, {S("ab"): 0.5, S("bc"): 0.5})
    out = zhang_combination(m1, m2).to_dict()
    # {a}: .6*.5*1/2 = .15 ; {a,b}: .4*.5*2/4 = .1 ; {b}: .4*.5*1/4 = .05 ; rest on empty
    assert _close(out, {S("a"): 0.15, S("ab"): 0.1, S("b"): 0.05, S(): 0.7})
    assert zhang_conflict(m1, m2) == pytest.approx(0.7)
    assert conflict(m1, m2) == pytest.approx(0.3)


# ------------------------------------------------------- algebraic properties
@given(masses(allow_empty=True), masses(allow_empty=True))
def test_conjunctive_and_new_rule_are_commutative(m1, m2):
    assert conjunctive(m1, m2).isclose(conjunctive(m2, m1))
    assert zhang_combination(m1, m2).isclose(zhang_combination(m2, m1))


@given(masses(allow_empty=True), masses(allow_empty=True), masses(allow_empty=True))
def test_conjunctive_is_associative(m1, m2, m3):
    left = conjunctive(conjunctive(m1, m2), m3)
    assert left.isclose(conjunctive(m1, conjunctive(m2, m3)))
    assert left.isclose(conjunctive(m1, m2, m3))


@given(masses(allow_empty=True))
def test_vacuous_is_neutral_for_conjunctive(m):
    assert conjunctive(m, MassFunction.vacuous(F3)).isclose(m)
    assert conjunctive(MassFunction.vacuous(F3), m).isclose(m)


# ----------------------------------------------------------- bulk versions
@given(st.lists(masses(allow_empty=True), min_size=2, max_size=4),
       st.lists(masses(allow_empty=True), min_size=1, max_size=3))
def test_bulk_functions_equal_single_ones(xs, ys):
    A = np.array([m.vector for m in xs])
    B = np.array([m.vector for m in ys])
    K0 = conflict_matrix(A, B)
    K = zhang_conflict_matrix(A, B)
    for i, j in itertools.product(range(len(xs)), range(len(ys))):
        assert K0[i, j] == pytest.approx(conflict(xs[i], ys[j]), abs=1e-12)
        assert K[i, j] == pytest.approx(zhang_conflict(xs[i], ys[j]), abs=1e-12)
    conj = conjunctive_vectors(A[:, None, :], B[None, :, :])
    zh = zhang_combination_vectors(A[:, None, :], B[None, :, :])
    assert conj.shape == zh.shape == (len(xs), len(ys), 8)
    for i, j in itertools.product(range(len(xs)), range(len(ys))):
        assert np.allclose(conj[i, j], conjunctive(xs[i], ys[j]).vector, atol=1e-12)
        assert np.allclose(zh[i, j], zhang_combination(xs[i], ys[j]).vector, atol=1e-12)
    assert np.allclose(conflict_vectors(A[:, None], B[None]), K0, atol=1e-12)
    assert np.allclose(zhang_conflict_vectors(A[:, None], B[None]), K, atol=1e-12)


def test_bulk_discount_and_pignistic():
    m = MassFunction(F3, {S("a"): 0.5, S("bc"): 0.5})
    v = np.stack([m.vector, MassFunction.vacuous(F3).vector])
    d = discount_vectors(v, np.array([0.3, 0.9]))
    assert np.allclose(d[0], discount(m, 0.3).vector)
    assert np.allclose(pignistic_vectors(v)[0], list(pignistic(m).values()))
    with pytest.raises(InvalidMassError, match="last axis"):
        conflict_matrix(np.ones((2, 3)) / 3, np.ones((2, 3)) / 3)


def test_from_vector_validates():
    with pytest.raises(InvalidMassError, match="shape"):
        MassFunction.from_vector(F3, [1.0, 0.0])
    with pytest.raises(InvalidMassError, match="negative"):
        MassFunction.from_vector(("x",), [1.5, -0.5])
    assert MassFunction.from_vector(("x",), [0.0, 1.0]).to_dict() == {S("x"): 1.0}
