"""Ranked assignments and association probabilities.

:mod:`.kbest` ranks the k best solutions (Murty's method), :mod:`.kbest2d` its
compiled 2-D path, :mod:`.marginals` association probabilities: per independent cluster
(:mod:`.clusters`), exactly by a hypothesis net (:mod:`.hypothesis_net`), or from the
ranking with a certified bound (:mod:`.kbest_marginals`), or by loopy belief
propagation (:mod:`.lbp`).

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`,
:mod:`assocopt.solvers`, :mod:`assocopt.solving`.
"""
