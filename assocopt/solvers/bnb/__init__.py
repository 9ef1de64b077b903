"""The ``bnb`` back end: compiled (numba) Lagrangian branch and bound for small S-D problems.

* :mod:`.backend` -- the registered back end (one problem);
* :mod:`.batch` -- many independent components in one compiled call (``auto`` and
  the decomposition use it);
* :mod:`.kernels` -- the import point of its compiled kernels, which live in
  :mod:`assocopt.solvers.kernels` with the project's other kernels (importing it
  imports numba; the back end does so only inside ``solve``).

Nothing is imported here.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`;
in :mod:`assocopt.solvers` the top-level modules (:mod:`assocopt.solvers.base`,
:mod:`assocopt.solvers.interruptible`) and :mod:`assocopt.solvers.kernels`.
"""
