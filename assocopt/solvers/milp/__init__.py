"""The MILP back ends: the exact-cover ILP (and its LP relaxation) handed to a solver.

* :mod:`.highs` -- HiGHS through highspy (``highs``, the default exact back end);
* :mod:`.scipy_milp` -- ``scipy.optimize.milp`` (``scipy``);
* :mod:`.ortools_cpsat` -- OR-Tools CP-SAT (``ortools-cpsat``, integer costs);
* :mod:`.ortools_mip` -- OR-Tools model builder over SCIP, GLOP for the LP (``ortools-mip``);
* :mod:`.cvxpy_backend` -- cvxpy over an installed MILP solver (``cvxpy``);
* :mod:`.limited` -- time limits that hold: a solve in a warm worker process that can be ended.

Each back end imports its solver package only inside ``solve``.  Nothing is imported
here.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`;
in :mod:`assocopt.solvers` the top-level modules (:mod:`assocopt.solvers.base`,
:mod:`assocopt.solvers.status`, :mod:`assocopt.solvers.interruptible`).
"""
