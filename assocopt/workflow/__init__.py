"""The user's workflow around a solve: named models, comparisons, generated instances.

:mod:`.models` reads the named models (``models/*.toml``: a formulation, a back end
and its options), :mod:`.compare` runs back ends or models side by side,
:mod:`.generate` makes instances with proven optima and lists the stored ones.

May import: every other core package (:mod:`assocopt.io` included), never the CLI;
the one plug-in point into :mod:`assocopt.tracking` is ``models.COST_LAYER``.
"""
