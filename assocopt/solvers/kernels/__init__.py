"""numba kernels of the ``bnb`` back end and the compiled window search of
``lagrangian-exact``; imported only when one of them runs (importing numba costs
half a second).  :mod:`assocopt.solvers.bnb_kernels` is the one import point."""
