"""The assignment problem and its values.

:mod:`.problem` holds :class:`~assocopt.problems.problem.AssignmentProblem` (the S-D
problem as a sparse cost tensor, dummy index 0); :mod:`.twod` and :mod:`.twod_tables`
its dense 2-D view; :mod:`.indexing` the candidate tuples' positions; :mod:`.values`
and :mod:`.validation` the checks of costs, sizes and tuples that name the bad entry.

May import: :mod:`assocopt.runtime`.
"""
