"""Monte Carlo experiment runner shared by every paper's reproduction.

An :class:`Experiment` is a grid of *settings* (JSON-ready dicts) x *methods* x
``runs`` Monte Carlo *trials*.  A trial function computes the metrics of one
(setting, trial) for one or several methods::

    trial(setting: dict, methods: list[str], seed: numpy.random.SeedSequence)
        -> {method: {metric: float}}

Every method of a trial gets the **same seed**, so the same simulated data are
costed by every method and the comparison between methods is paired.  (Wrap a
per-method function ``f(setting, method, seed) -> {metric: float}`` with
:class:`PerMethod`.)

Determinism.  The seed of trial ``t`` of a setting is derived from the master seed,
a hash of the setting's canonical JSON and ``t`` (:func:`trial_seed`): it does not
depend on the grid order, the number of workers or the scheduling, so 1 worker or
16 give identical numbers.

Store.  Results go to an embedded SQLite file, one transaction per trial (all of
its methods at once), written by the coordinating process only.  A run that is
interrupted (Ctrl-C, killed, a failing trial) keeps every finished trial; running
the same experiment on the same store again computes only the missing
(setting, method, trial) keys, so nothing is lost or repeated.  A store created with
another master seed or other parameters is refused rather than mixed.

Execution.  ``workers=1`` runs in-process.  ``workers > 1`` uses a
:class:`concurrent.futures.ProcessPoolExecutor` (spawned processes).  Any object
with ``submit(fn, *args)`` returning a future with ``result()`` and ``done()``
works as ``executor`` -- a ``dask.distributed.Client`` does, so a cluster can run
the trials (dask is not a dependency).  The trial function must be picklable (a
module-level function).

Progress.  ``progress=True`` shows a tqdm bar on stderr.

One module per concept: :mod:`.design` (experiments, seeds), :mod:`.store`
(the SQLite store), :mod:`.runner` (execution), :mod:`.summary` (means, paired
differences, report rows, association metrics).
"""

from .design import (SCHEMA_VERSION, Experiment, PerMethod, StoreMismatchError,  # noqa: F401
                     TrialError, setting_key, trial_seed)
from .runner import run_all, run_experiment
from .store import ResultStore
from .summary import (_demo_trial, association_metrics, paired_differences,  # noqa: F401
                      report_records, summarise)

__all__ = ["Experiment", "PerMethod", "ResultStore", "run_experiment", "trial_seed",
           "setting_key", "summarise", "paired_differences", "StoreMismatchError",
           "TrialError", "run_all", "report_records",
           "association_metrics"]
