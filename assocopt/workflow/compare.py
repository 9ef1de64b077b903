"""Compare back ends or named models on instances: one row per (instance, method).

>>> res = compare(["instances/example-3d.json"], solvers=["highs", "greedy"])  # doctest: +SKIP
>>> print(res.to_text())                                                       # doctest: +SKIP

Each row records the status, objective, bound, gap, build / solve / total seconds
and the agreement with the instance's recorded optimum.  A method that cannot take
an instance (a 2-D-only back end on a 3-D problem) gives a ``skipped`` row; an
exception inside a back end gives an ``error`` row with its message (the comparison
goes on).  Every instance and method is checked before anything is solved, so bad
input fails fast.

Agreement (``agrees``): a returned assignment whose cost equals the recorded optimum
(relative tolerance :data:`TOLERANCE`).  ``bound_ok``: the reported lower bound does
not exceed the recorded optimum.  :meth:`CompareResult.disagreements` lists the rows
where an answer claimed optimal differs from the record, or a bound exceeds it.
"""

from __future__ import annotations

import csv
import io
import json
import math
import sys
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Sequence, TextIO

from ..runtime.errors import AssocoptError, SolverCapabilityError
from ..problems.problem import OPT_TOL, AssignmentProblem
from ..runtime.progress import Progress

__all__ = ["Method", "CompareResult", "compare", "resolve_methods", "TOLERANCE", "COLUMNS"]

#: Relative tolerance of the agreement with a recorded optimum.
TOLERANCE = OPT_TOL
#: Columns of :meth:`CompareResult.to_csv` (and keys of every row).
COLUMNS = ("instance", "sizes", "candidates", "method", "solver", "formulation", "status",
           "objective", "bound", "gap", "build_s", "solve_s", "total_s", "optimum",
           "agrees", "bound_ok", "message")


@dataclass(frozen=True)
class Method:
    """One column of a comparison: a back end by name, or a named model."""

    label: str
    solver: str
    formulation: str = "ilp"
    kwargs: dict[str, Any] = field(default_factory=dict)

    def run(self, problem: AssignmentProblem) -> Any:
        from ..solving.api import solve
        return solve(problem, self.solver, **self.kwargs)


def resolve_methods(solvers: Sequence[str] | None = None, models: Sequence[str] | None = None,
                    *, time_limit: float | None = None, relax: str | None = None
                    ) -> list[Method]:
    """Methods for back-end names and/or model names (checked: unknown names raise)."""
    from .models import load_model
    from ..solvers import get_backend

    methods: list[Method] = []
    for name in solvers or ():
        cls = get_backend(name)                  # UnknownSolverError lists the valid names
        cls.require()                            # SolverNotInstalledError names the package
        kw: dict[str, Any] = {"relax": relax}
        if time_limit is not None:
            kw["time_limit"] = time_limit
        if relax == "lp":
            formulation = "lp"
        elif name in ("bruteforce", "lagrangian", "lagrangian-exact"):
            formulation = name
        else:
            formulation = "ilp" if cls.exact else "heuristic"
        methods.append(Method(name, name, formulation, kw))
    for name in models or ():
        m = load_model(name)
        get_backend(m.solver).require()
        methods.append(Method(m.name, m.solver, m.formulation,
                              m.solve_kwargs(time_limit=time_limit)))
    if not methods:
        raise AssocoptError("nothing to compare: give back ends (--solvers) or models (--models)")
    labels = [m.label for m in methods]
    dup = next((x for x in labels if labels.count(x) > 1), None)
    if dup is not None:
        raise AssocoptError(f"method {dup!r} given twice")
    return methods


def _matches(value: float | None, optimum: float | None) -> bool | None:
    if value is None or optimum is None:
        return None
    return abs(value - optimum) <= TOLERANCE * max(1.0, abs(optimum))


def _row(problem: AssignmentProblem, method: Method, sol: Any | None, message: str = "",
         status: str | None = None) -> dict[str, Any]:
    opt = problem.optimum
    row: dict[str, Any] = {
        "instance": problem.name, "sizes": "x".join(map(str, problem.sizes)),
        "candidates": int((~problem.slack).sum()), "method": method.label,
        "solver": method.solver, "formulation": method.formulation,
        "status": status, "objective": None, "bound": None, "gap": None,
        "build_s": None, "solve_s": None, "total_s": None, "optimum": opt,
        "agrees": None, "bound_ok": None, "message": message}
    if sol is None:
        return row
    t = sol.times
    row.update(status=str(sol.status), objective=sol.objective, bound=sol.bound, gap=sol.gap,
               build_s=t.get("build"), solve_s=t.get("solve"), total_s=t.get("total"),
               message=" ".join(str(sol.message).split()))
    if sol.has_solution:
        row["agrees"] = _matches(sol.objective, opt)
    if sol.bound is not None and opt is not None:
        row["bound_ok"] = sol.bound <= opt + TOLERANCE * max(1.0, abs(opt))
    return row


def _run_one(problem: AssignmentProblem, method: Method, repeat: int) -> dict[str, Any]:
    best = None
    for _ in range(repeat):
        try:
            sol = method.run(problem)
        except SolverCapabilityError as exc:
            return _row(problem, method, None, str(exc), status="skipped")
        except AssocoptError as exc:
            return _row(problem, method, None, str(exc), status="error")
        except Exception as exc:  # noqa: BLE001 - one failing back end must not stop the table
            return _row(problem, method, None, f"{type(exc).__name__}: {exc}", status="error")
        if best is None or sol.times.get("total", math.inf) < best.times.get("total", math.inf):
            best = sol
    return _row(problem, method, best)


def _load(item: Any, fmt: str, instance: Any) -> AssignmentProblem:
    if isinstance(item, AssignmentProblem):
        return item
    from ..io import read_instance
    return read_instance(item, format=fmt, instance=instance)


def compare(instances: Iterable[Any], *, solvers: Sequence[str] | None = None,
            models: Sequence[str] | None = None, time_limit: float | None = None,
            relax: str | None = None, repeat: int = 1, format: str = "auto",
            instance: Any = None, progress: bool | None = None,
            on_row: Callable[[dict[str, Any]], None] | None = None) -> "CompareResult":
    """Solve every instance with every method; returns a :class:`CompareResult`.

    Parameters
    ----------
    instances : iterable of paths or AssignmentProblem
    solvers, models : sequences of names
        Back ends (``"highs"``...) and/or named models (``"highs-ilp"`` or paths).
    time_limit : float, optional
        Seconds per solve (overrides the models' own limits).
    relax : None or "lp"
        For ``solvers``: solve LP relaxations instead.
    repeat : int
        Solve each pair this many times and keep the fastest run (timings).
    progress : bool, optional
        Progress bar on stderr (tqdm); default: when stderr is a terminal.
    on_row : callable, optional
        Called with each row as soon as it is done.
    """
    if isinstance(repeat, bool) or not isinstance(repeat, int) or repeat < 1:
        raise AssocoptError(f"repeat must be a positive integer, got {repeat!r}")
    methods = resolve_methods(solvers, models, time_limit=time_limit, relax=relax)
    problems = [_load(item, format, instance) for item in instances]
    if not problems:
        raise AssocoptError("no instances to compare")
    if progress is None:
        progress = bool(getattr(sys.stderr, "isatty", lambda: False)()) and \
            len(problems) * len(methods) > 1
    bar = Progress(len(problems) * len(methods), progress, "compare", unit="run",
                   stream=sys.stderr, leave=False)
    rows = []
    try:
        for p in problems:
            for m in methods:
                row = _run_one(p, m, repeat)
                rows.append(row)
                if on_row is not None:
                    on_row(row)
                bar.update(1, f"{p.name} {m.label}")
    finally:
        bar.close()
    return CompareResult(rows, [m.label for m in methods])


def _fmt(v: Any, digits: int = 10) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "NO"
    if isinstance(v, float):
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:.{digits}g}"
    return str(v)


def _time(v: float | None) -> str:
    if v is None:
        return "-"
    return f"{v * 1000:.1f}ms" if v < 1 else f"{v:.2f}s"


@dataclass
class CompareResult:
    """Rows of a comparison (dicts with the keys :data:`COLUMNS`) and the method labels."""

    rows: list[dict[str, Any]]
    methods: list[str]

    def disagreements(self) -> list[dict[str, Any]]:
        """Rows claiming ``optimal`` with another cost than the record, or a bound above it."""
        return [r for r in self.rows
                if (r["status"] == "optimal" and r["formulation"] != "lp" and r["agrees"] is False)
                or r["bound_ok"] is False]

    def errors(self) -> list[dict[str, Any]]:
        """Rows whose back end failed (status ``error``)."""
        return [r for r in self.rows if r["status"] == "error"]

    def to_records(self) -> list[dict[str, Any]]:
        """The rows, JSON-ready (non-finite numbers as strings)."""
        from ..io import jsonable
        return jsonable([dict(r) for r in self.rows])

    def to_json(self) -> str:
        return json.dumps(self.to_records(), indent=2, allow_nan=False)

    def to_csv(self) -> str:
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=list(COLUMNS), lineterminator="\n")
        w.writeheader()
        for r in self.to_records():
            w.writerow({k: ("" if r[k] is None else r[k]) for k in COLUMNS})
        return buf.getvalue()

    def to_frame(self) -> Any:
        """A pandas DataFrame of the rows (needs pandas)."""
        import pandas as pd
        return pd.DataFrame(self.rows, columns=list(COLUMNS))

    def to_text(self) -> str:
        """A fixed-width table; ``optimum?`` says how each answer compares with the record."""
        head = ("instance", "sizes", "method", "status", "objective", "bound", "gap",
                "build", "solve", "optimum?")
        table = [head]
        for r in self.rows:
            table.append((r["instance"] or "-", r["sizes"], r["method"], r["status"] or "-",
                          _fmt(r["objective"]), _fmt(r["bound"]),
                          "-" if r["gap"] is None else f"{r['gap']:.3g}",
                          _time(r["build_s"]), _time(r["solve_s"]), self._verdict(r)))
        widths = [max(len(row[i]) for row in table) for i in range(len(head))]
        lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in table]
        notes = [f"  {r['instance']} / {r['method']}: {r['message']}" for r in self.rows
                 if r["status"] in ("error", "skipped") and r["message"]]
        if notes:
            lines += ["", "notes:"] + notes
        bad = self.disagreements()
        lines.append("")
        n_opt = sum(1 for r in self.rows if r["optimum"] is not None)
        lines.append(f"{len(self.rows)} runs, {n_opt} with a recorded optimum, "
                     f"{sum(1 for r in self.rows if r['agrees'])} matching it, "
                     f"{len(bad)} disagreeing, {len(self.errors())} errors")
        return "\n".join(lines)

    @staticmethod
    def _verdict(r: dict[str, Any]) -> str:
        opt = r["optimum"]
        if opt is None:
            return "-"
        if r["agrees"] is True:
            return "match"
        if r["agrees"] is False:
            obj = r["objective"]
            rel = (obj - opt) / max(abs(opt), 1e-12)
            tag = "DIFFERS" if r["status"] == "optimal" else "worse"
            return f"{tag} ({100 * rel:+.3g} %)"
        if r["bound_ok"] is False:
            return "BOUND ABOVE OPTIMUM"
        if r["formulation"] == "lp" and r["objective"] is not None:
            return "bound ok"
        return "-"

    def write(self, stream: TextIO, fmt: str = "text") -> None:
        """Write as ``"text"``, ``"json"`` or ``"csv"``."""
        text = {"text": self.to_text, "json": self.to_json, "csv": self.to_csv}[fmt]()
        stream.write(text if text.endswith("\n") else text + "\n")

