"""Mass functions (basic belief assignments) on small finite frames.

A frame of discernment is an ordered tuple of ``n`` element names; a subset ``A``
is the bitmask with bit ``k`` set when element ``k`` is in ``A`` (so ``0`` is the
empty set and ``2**n - 1`` the whole frame).  A mass function is a float64 vector
of length ``2**n`` indexed by bitmask.  The frames of paper 000 are tiny
(``{M, Mbar}`` and 6 target types), so the whole vector is stored.

Two layers:

* :class:`MassFunction` and the functions :func:`conjunctive`, :func:`dempster`,
  :func:`conflict`, :func:`discount`, :func:`pignistic`, :func:`zhang_conflict`,
  :func:`zhang_combination` -- one mass function at a time, validated, with
  element names.
* ``*_vectors`` / ``*_matrix`` functions -- the same operations on stacked mass
  vectors ``(..., 2**n)`` (numpy broadcasting), used to compute matching measures
  for every observation pair in bulk (:mod:`assocopt.tracking.belief.group_matching`).

Rules (paper 000, docs/papers/zhang2009.md):

* Smets' unnormalised conjunctive rule:
  ``m(C) = sum_{A & B = C} m1(A) m2(B)``; the conflict ``K0 = m(empty)`` (eq. 3).
* Dempster's rule: the conjunctive result with ``m(empty)`` removed and the rest
  divided by ``1 - K0``; undefined (:class:`TotalConflictError`) when ``K0 = 1``.
* Paper 000's new conflict measure (eq. 4):
  ``K = sum_{A,B} m1(A) m2(B) (1 - |A & B| / (|A| |B|))`` (disjoint or empty pairs
  count fully), equal to ``1 - <BetP1, BetP2>`` (an identity we derived; tested).
* Paper 000's new combination rule (eqs. 10-11): for ``C != empty``
  ``m(C) = sum_{A & B = C} m1(A) m2(B) |C| / (|A| |B|)``, and ``m(empty)`` is the
  new conflict of ``m1`` and ``m2``; it sums to 1 and equals Smets' rule when
  every focal set is a singleton.

Examples
--------
>>> m1 = MassFunction(("a", "b", "c"), {frozenset("a"): 0.6, frozenset("ab"): 0.4})
>>> m2 = MassFunction(("a", "b", "c"), {frozenset("b"): 0.5, frozenset("abc"): 0.5})
>>> round(conflict(m1, m2), 10)
0.3
>>> dempster(m1, m2).to_dict() == {frozenset("a"): 0.3 / 0.7, frozenset("b"): 0.2 / 0.7,
...                                 frozenset("ab"): 0.2 / 0.7}
True
"""

# The implementation is split by concern (each module's docstring says what it
# holds); this package re-exports the public names so that ``assocopt.tracking.belief.X``
# works for every ``X`` in ``__all__``.
from .combination import (conflict, conflict_matrix, conflict_vectors,  # noqa: F401
                          conjunctive, conjunctive_vectors, dempster, discount,
                          discount_vectors, pignistic, pignistic_vectors)
from .mass import (CONFLICT_TOL, MASS_TOL, MAX_FRAME_SIZE, InvalidMassError,  # noqa: F401
                   MassFunction, TotalConflictError, check_vectors)
from .zhang import (zhang_combination, zhang_combination_vectors,  # noqa: F401
                    zhang_conflict, zhang_conflict_matrix, zhang_conflict_vectors)

__all__ = [
    "InvalidMassError", "TotalConflictError", "MassFunction",
    "conjunctive", "dempster", "conflict", "discount", "pignistic",
    "zhang_conflict", "zhang_combination",
    "conjunctive_vectors", "zhang_combination_vectors", "conflict_vectors",
    "zhang_conflict_vectors", "discount_vectors", "pignistic_vectors",
    "conflict_matrix", "zhang_conflict_matrix", "check_vectors",
    "MAX_FRAME_SIZE", "MASS_TOL", "CONFLICT_TOL",
]
