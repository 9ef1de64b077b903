"""``assocopt reproduce``: regenerate the papers' tables and figures.

Contract (every paper): ``reproduce(name, runs, workers, seed, out)`` runs (or resumes)
the paper's Monte Carlo experiments into ``out``, writes ``out/summary.json`` (every
table and curve as records: experiment, setting, method, metric, value, runs, stderr;
plus the parameters used, the paper's and ours marked as ours), the figures as PNG
and ``out/tables.md``, prints the tables, and returns the summary.  ``runs=None``
uses the paper's run count.  Re-running into the same ``out`` resumes: finished
trials are kept, and a larger ``runs`` only adds the missing trials.

>>> "lu2013" in [p["name"] for p in list_papers()]
True
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

from ..runtime.errors import AssocoptError
from . import dong2015, lu2013, xue1999, yan2010, zhang2009

__all__ = ["PAPERS", "Paper", "list_papers", "reproduce", "run"]


@dataclass(frozen=True)
class Paper:
    """A reproducible paper: its name, paper number, title, default run count and
    the function doing the work (``runner(runs, workers, seed, out, **kw) -> dict``)."""

    name: str
    spec: str
    title: str
    default_runs: int
    runner: Callable[..., dict]
    page: str


def _paper(module: Any, spec: str, title: str, default_runs: int) -> Paper:
    """The entry of the reproduction in ``module`` (its ``run``; page
    ``docs/papers/NAME.md``)."""
    name = module.__name__.rsplit(".", 1)[-1]
    return Paper(name, spec, title, default_runs, module.run, f"docs/papers/{name}.md")


PAPERS: dict[str, Paper] = {p.name: p for p in (
    _paper(lu2013, "002", "Lu et al. 2013, multi-passive-sensor data association with KLD/SKLD "
                          "costs: Fig. 1-2, Tables 1-4", 1000),
    _paper(zhang2009, "000", "Zhang et al. 2009, group member matching with position + "
                             "attribute beliefs: Figs. 1-5, Table 1", 1000),
    _paper(xue1999, "003", "Xue et al. 1999, distributed inference decision (DID) against GNN "
                           "and nearest neighbour on four crossing targets", 200),
    _paper(yan2010, "001", "Yan et al. 2010, multi-feature D-S track-to-track association for "
                           "passive TDOA systems: Table 1, Fig. 4", 100),
    _paper(dong2015, "004", "Dong et al. 2015, anti-bias track association by topology "
                            "statistical distance: Figs. 2-7, time per step in place of "
                            "Table 1", 50),
)}


def list_papers() -> list[dict[str, Any]]:
    """Name, paper number, title and default run count of every reproducible paper."""
    return [{"name": p.name, "spec": p.spec, "title": p.title,
             "default_runs": p.default_runs, "page": p.page} for p in PAPERS.values()]


def reproduce(name: str, runs: int | None = None, workers: int = 1, seed: int = 0,
              out: str | Path | None = None, progress: bool = False, *,
              executor: Any = None, options: Mapping[str, Any] | None = None,
              echo: Callable[[str], Any] = print) -> dict[str, Any]:
    """Reproduce paper ``name`` (see the module docstring).

    Parameters
    ----------
    name : str
        A key of :data:`PAPERS` (``list_papers()``).
    runs : int, optional
        Monte Carlo runs per point (default: the paper's, 1000 for lu2013).
    workers : int
        Local worker processes (1 = in this process).
    seed : int
        Master seed; every trial's seed derives from it.
    out : path, optional
        Output directory (default ``results/NAME``).
    progress : bool
        Progress bar on stderr.
    executor : optional
        A ``concurrent.futures`` executor or ``dask.distributed.Client`` to use instead
        of the local pool.
    options : dict, optional
        Paper-specific options (lu2013: ``lu2013.DEFAULTS``, e.g. ``solver``).
    echo : callable
        Receives the rendered tables (``print`` by default).

    Raises
    ------
    AssocoptError
        Unknown paper name, bad runs/workers/seed, or a results store written with
        another seed.
    """
    if name not in PAPERS:
        raise AssocoptError(f"unknown paper {name!r}; valid: {', '.join(sorted(PAPERS))}")
    paper = PAPERS[name]
    runs = paper.default_runs if runs is None else runs
    if not isinstance(runs, int) or isinstance(runs, bool) or runs < 1:
        raise AssocoptError(f"runs must be a positive integer, got {runs!r}")
    if not isinstance(workers, int) or isinstance(workers, bool) or workers < 1:
        raise AssocoptError(f"workers must be a positive integer, got {workers!r}")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise AssocoptError(f"seed must be a non-negative integer, got {seed!r}")
    out = Path("results") / name if out is None else Path(out)
    try:
        return paper.runner(runs, workers, seed, out, progress=progress, executor=executor,
                            options=options, echo=echo)
    except ValueError as exc:
        if isinstance(exc, AssocoptError):
            raise
        raise AssocoptError(str(exc)) from exc


def run(name: str, runs: int | None, workers: int, seed: int, out: str | Path) -> dict[str, Any]:
    """Short form of :func:`reproduce` (no progress bar)."""
    return reproduce(name, runs, workers, seed, out)
