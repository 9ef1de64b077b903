"""The user's workflow around a solve: named models, comparisons, generated instances.

:mod:`.models` reads the named models (``models/*.toml``: a formulation, a back end
and its options), :mod:`.compare` runs back ends or models side by side,
:mod:`.generate` makes instances with proven optima and lists the stored ones.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`,
:mod:`assocopt.solvers`, :mod:`assocopt.solving`, :mod:`assocopt.ranking`,
:mod:`assocopt.io`.

Its one plug-in point into the tracking layer is ``models.COST_LAYER`` (the cost
builders of scenario models, looked up by name).
"""
