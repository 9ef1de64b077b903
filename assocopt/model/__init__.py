"""The optimisation model of a problem and what solving it returns.

:mod:`.formulation` builds the S-D set-partitioning ILP / LP (one sparse matrix, one
column per candidate) that the MILP back ends and the model writers share;
:mod:`.solution` holds :class:`~assocopt.model.solution.Solution` and its status.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`.
"""
