"""2-D assignment: the LAP engines and the back ends that solve 2-D problems directly.

* :mod:`.lap` -- the engines: dense (scipy or lapx) and sparse LAPs, with miss costs
  and duals (the 2-D subproblem of the Lagrangian back ends, and of ``auto``);
* :mod:`.direct` -- dense 2-D problems from matrix to :class:`~assocopt.Solution`
  in one pass;
* :mod:`.dense` -- miss costs on a dense matrix without enlarging it;
* :mod:`.sparse` -- gated (sparse) 2-D problems, never densified;
* :mod:`.scipy_lsa` -- the ``scipy-lsa`` back end (``linear_sum_assignment``);
* :mod:`.lapjv` -- the optional ``lapjv`` back end (``pip install lapx``).

Nothing is imported here: a 2-D solve loads only the modules it runs.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`;
in :mod:`assocopt.solvers` the top-level modules (:mod:`assocopt.solvers.base`,
:mod:`assocopt.solvers.scaling`) and :mod:`assocopt.solvers.kernels`.
"""
