"""Baselines: exhaustive enumeration (the test oracle) and the greedy heuristic.

* :mod:`.bruteforce` -- every feasible solution enumerated (``bruteforce``; tiny
  problems, and the oracle the other back ends are tested against);
* :mod:`.greedy` -- candidates in increasing cost while they fit (``greedy``).

Nothing is imported here.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`;
in :mod:`assocopt.solvers` the top-level module :mod:`assocopt.solvers.base`.
"""
