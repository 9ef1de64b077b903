"""Solving a problem: :func:`assocopt.solve` and the methods built on it.

:mod:`.api` picks a back end (``auto``, by :mod:`.choice`), scales costs out of
range, runs it and re-checks its answer; :mod:`.decompose` splits an S-D problem into
its connected components and solves them apart (small ones in one compiled batch);
:mod:`.lp_fixing` solves large S-D problems exactly by LP reduced-cost fixing.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`,
:mod:`assocopt.solvers`.
"""
