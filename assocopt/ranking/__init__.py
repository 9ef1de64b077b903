"""Ranked assignments and association probabilities.

:mod:`.kbest` ranks the k best solutions (Murty's method), :mod:`.kbest2d` its
compiled 2-D path, :mod:`.marginals` association probabilities from the ranking.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`,
:mod:`assocopt.solvers`, :mod:`assocopt.solving`.
"""
