"""Named association models: one TOML file per model, referred to by its file stem.

A model fixes *how* an assignment problem is solved: the formulation, the back end
and its options, and -- for scenario models -- the cost builder that turns a scan into
the problem.  A user adds a model by writing a TOML file; no code is needed::

    # models/highs-ilp.toml
    description = "Exact ILP with HiGHS (branch and cut)"
    formulation = "ilp"      # ilp | lp | lagrangian | lagrangian-exact | heuristic | bruteforce
    solver = "highs"         # a name from `assocopt solvers`

    [options]                # all optional
    time_limit = 60.0        # seconds
    mip_gap = 0.0            # relative gap at which to stop (0: prove optimality)
    threads = 1
    # any other key is a back-end option, e.g. CP-SAT's  scale = 1000

    [cost]                   # scenario models only
    builder = "pattipati"    # a cost from assocopt.tracking.costs.COSTS
    [cost.params]
    normalisation = "printed"

Lookup (:func:`find_model`): a name with a path separator or ending in ``.toml`` is a
file path; any other name is a file stem, searched in the folders of the environment
variable ``ASSOCOPT_MODEL_PATH`` (``os.pathsep``-separated), then the project's
``models/`` folder (in a source checkout), then the copies shipped inside the
package (``assocopt/data/models``).  Validation is strict: an unknown key, a value of
the wrong type or range, an unknown or incompatible back end, or back-end options the
back end rejects raise :class:`ModelError` naming the key and the file.

>>> m = load_model("highs-ilp")
>>> m.formulation, m.solver
('ilp', 'highs')
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

from ..runtime.errors import AssocoptError

__all__ = ["Model", "ModelError", "FORMULATIONS", "COMMON_OPTIONS", "load_model",
           "find_model", "list_models", "model_dirs", "MODEL_PATH_ENV"]

#: Formulations a model may name.
FORMULATIONS = ("ilp", "lp", "lagrangian", "lagrangian-exact", "heuristic", "bruteforce")
#: Options understood by every back end (see :func:`assocopt.solve`).
COMMON_OPTIONS = ("time_limit", "mip_gap", "threads", "verbose")
#: Environment variable: extra folders searched for model files, first.
MODEL_PATH_ENV = "ASSOCOPT_MODEL_PATH"

_TOP_KEYS = ("description", "formulation", "solver", "options", "cost")
_COST_KEYS = ("builder", "params")
#: Back end used when a formulation implies one and the file names none.
_DEFAULT_SOLVER = {"lagrangian": "lagrangian", "lagrangian-exact": "lagrangian-exact",
                   "bruteforce": "bruteforce", "heuristic": "greedy"}

_PACKAGE_MODELS = Path(__file__).resolve().parents[1] / "data" / "models"
_PROJECT_MODELS = Path(__file__).resolve().parents[2] / "models"


class ModelError(AssocoptError, ValueError):
    """A model file is missing, malformed, or names something invalid."""


@dataclass(frozen=True)
class Model:
    """A named association model (see the module docstring for the file format).

    Attributes
    ----------
    name : str
        The file stem.
    formulation : str
        One of :data:`FORMULATIONS`.
    solver : str
        Back end name (see :func:`assocopt.solvers.registered`).
    options : mapping
        ``time_limit``, ``mip_gap``, ``threads``, ``verbose`` and back-end options.
    cost : mapping or None
        ``{"builder": name, "params": {...}}`` for scenario models.
    description : str
    path : Path or None
        The file the model was read from.
    """

    name: str
    formulation: str
    solver: str
    options: Mapping[str, Any] = field(default_factory=dict)
    cost: Mapping[str, Any] | None = None
    description: str = ""
    path: Path | None = None

    @property
    def relax(self) -> str | None:
        """``"lp"`` for the LP relaxation, else None (the value passed to ``solve``)."""
        return "lp" if self.formulation == "lp" else None

    def solve_kwargs(self, **overrides: Any) -> dict[str, Any]:
        """Keyword arguments for :func:`assocopt.solve`; ``overrides`` win over the file.

        An override of None leaves the model's value in place.
        """
        kw: dict[str, Any] = {"relax": self.relax, **dict(self.options)}
        kw.update({k: v for k, v in overrides.items() if v is not None})
        return kw

    def solve(self, problem: Any, **overrides: Any) -> Any:
        """Solve ``problem`` with this model; returns a :class:`~assocopt.Solution`.

        ``overrides`` (``time_limit=``, ``mip_gap=``, ``threads=``, back-end options)
        replace the model's values for this call.  ``solution.info["model"]`` records
        the model name.

        Examples
        --------
        >>> from assocopt import AssignmentProblem
        >>> load_model("highs-ilp").solve(AssignmentProblem.dense([[4, 1], [2, 3]])).objective
        3.0
        """
        from ..solving.api import solve

        sol = solve(problem, self.solver, **self.solve_kwargs(**overrides))
        sol.info["model"] = self.name
        return sol

    def build_problem(self, scan: Any, **params: Any) -> Any:
        """The S-D problem of ``scan`` with this model's cost builder (scenario models)."""
        if self.cost is None:
            raise ModelError(f"model {self.name!r} has no [cost] table (not a scenario model)")
        kw = {**dict(self.cost.get("params", {})), **params}
        return _cost_layer().build_problem(scan, self.cost["builder"], **kw)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description of the model."""
        return {"name": self.name, "formulation": self.formulation, "solver": self.solver,
                "options": dict(self.options),
                "cost": None if self.cost is None else
                {"builder": self.cost["builder"], "params": dict(self.cost.get("params", {}))},
                "description": self.description,
                "path": None if self.path is None else str(self.path)}


#: The tracking layer that owns the cost builders of scenario models.  It is found by
#: name when a model has a ``[cost]`` table (like a plug-in), so the core never
#: imports tracking code and loading a plain model does not load it.
COST_LAYER = "assocopt.tracking.costs"


def _cost_layer() -> Any:
    import importlib

    return importlib.import_module(COST_LAYER)


# ----------------------------------------------------------------------- lookup
def model_dirs() -> list[Path]:
    """The folders searched for a model stem, in order (existing ones only)."""
    dirs = [Path(p) for p in os.environ.get(MODEL_PATH_ENV, "").split(os.pathsep) if p]
    dirs += [_PROJECT_MODELS, _PACKAGE_MODELS]
    seen: list[Path] = []
    for d in dirs:
        if d.is_dir() and d.resolve() not in [s.resolve() for s in seen]:
            seen.append(d)
    return seen


def _is_path(name: str) -> bool:
    return name.endswith(".toml") or "/" in name or os.sep in name or \
        (os.altsep is not None and os.altsep in name)


def _stems() -> dict[str, Path]:
    found: dict[str, Path] = {}
    for d in model_dirs():
        for f in sorted(d.glob("*.toml")):
            found.setdefault(f.stem, f)
    return found


def find_model(name_or_path: str | os.PathLike[str]) -> Path:
    """The file of a model given by stem or path; :class:`ModelError` if none."""
    name = os.fspath(name_or_path)
    if not isinstance(name, str) or not name:
        raise ModelError(f"a model name must be a non-empty string, got {name_or_path!r}")
    stems = _stems()
    if _is_path(name):
        path = Path(name)
        if path.is_file():
            return path
        if path.name == name and path.stem in stems:     # "highs-ilp.toml": the stem
            return stems[path.stem]
        raise ModelError(f"model file {name} not found")
    if name in stems:
        return stems[name]
    where = ", ".join(str(d) for d in model_dirs()) or "no model folder found"
    valid = ", ".join(sorted(stems)) or "none"
    raise ModelError(f"unknown model {name!r}; available: {valid} (searched: {where}; "
                     f"or pass a path to a .toml file)")


def load_model(name_or_path: str | os.PathLike[str], *, check_options: bool = True) -> Model:
    """Read and validate a model by file stem or path.

    ``check_options``: check the back end's own options against its declaration
    (:mod:`assocopt.solvers.options`, no trial solve), so that an unknown or bad
    back-end option fails here, naming the file (names a back end passes through to
    its solver are judged only when that solver is installed).
    """
    return _parse_file(find_model(name_or_path), check_options=check_options)


def list_models(*, check_options: bool = False) -> list[Model]:
    """Every model found by stem (the first of each name in :func:`model_dirs`)."""
    return [_parse_file(p, check_options=check_options) for _, p in sorted(_stems().items())]


# ----------------------------------------------------------------------- validation
def _fail(path: Path, key: str, message: str) -> ModelError:
    return ModelError(f"{path}: {key}: {message}")


def _type_name(v: Any) -> str:
    return {bool: "a boolean", int: "an integer", float: "a number", str: "a string",
            dict: "a table", list: "an array"}.get(type(v), type(v).__name__)


def _parse_file(path: Path, *, check_options: bool) -> Model:
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{path}: invalid TOML: {exc}") from None
    except OSError as exc:
        raise ModelError(f"{path}: cannot read the model file: {exc.strerror or exc}") from None
    return _from_dict(doc, path, check_options=check_options)


def _from_dict(doc: dict[str, Any], path: Path, *, check_options: bool) -> Model:
    from ..solvers import get_backend, registered

    for key in doc:
        if key not in _TOP_KEYS:
            raise _fail(path, key, f"unknown key; valid top-level keys: {', '.join(_TOP_KEYS)}")
    description = doc.get("description", "")
    if not isinstance(description, str):
        raise _fail(path, "description", f"must be a string, found {_type_name(description)}")
    if "formulation" not in doc:
        raise _fail(path, "formulation", f"missing (one of {', '.join(FORMULATIONS)})")
    formulation = doc["formulation"]
    if formulation not in FORMULATIONS:
        raise _fail(path, "formulation", f"unknown value {formulation!r}; valid: "
                                         f"{', '.join(FORMULATIONS)}")
    solver = doc.get("solver", _DEFAULT_SOLVER.get(formulation))
    if solver is None:
        raise _fail(path, "solver", f"missing (a back end for formulation {formulation!r}; "
                                    "see 'assocopt solvers')")
    if not isinstance(solver, str):
        raise _fail(path, "solver", f"must be a string, found {_type_name(solver)}")
    if solver not in registered():
        valid = ", ".join(sorted(registered()))
        raise _fail(path, "solver", f"unknown solver {solver!r}; valid: {valid}")
    cls = get_backend(solver)
    why = _incompatible(formulation, solver, cls)
    if why:
        raise _fail(path, "solver", why)
    options = _options(doc.get("options", {}), path)
    cost = _cost(doc["cost"], path) if "cost" in doc else None
    model = Model(name=path.stem, formulation=formulation, solver=solver,
                  options=MappingProxyType(options), cost=cost, description=description,
                  path=path)
    extras = {k: v for k, v in options.items() if k not in COMMON_OPTIONS}
    if check_options and extras:
        _check_backend_options(cls, extras, path)
    return model


def _incompatible(formulation: str, solver: str, cls: Any) -> str | None:
    """Why back end ``cls`` cannot run ``formulation`` (None if it can)."""
    if formulation == "lp":
        return None if cls.lp else f"{solver!r} cannot solve LP relaxations (formulation 'lp')"
    if formulation in ("bruteforce", "lagrangian", "lagrangian-exact"):
        return None if solver == formulation else \
            f"formulation {formulation!r} needs solver {formulation!r}, not {solver!r}"
    if not cls.integer:
        return f"{solver!r} solves LP relaxations only; use formulation 'lp'"
    if formulation == "heuristic":
        return None if not cls.exact else \
            f"{solver!r} is exact; use formulation 'ilp' (or 'bruteforce')"
    # ilp
    if solver in ("bruteforce", "lagrangian", "lagrangian-exact"):
        return f"use formulation {solver!r} for solver {solver!r}"
    return None if cls.exact else \
        f"{solver!r} is a heuristic (no proof of optimality); use formulation 'heuristic'"


def _options(raw: Any, path: Path) -> dict[str, Any]:
    """The ``[options]`` table: the common options checked by the one checker of
    :mod:`assocopt.solvers.options`; back-end options must be plain values."""
    from ..solvers.options import COMMON_OPTIONS as DECLARED

    if not isinstance(raw, dict):
        raise _fail(path, "options", f"must be a table ([options]), found {_type_name(raw)}")
    common = {o.name: o for o in DECLARED}
    out: dict[str, Any] = {}
    for key, v in raw.items():
        where = f"options.{key}"
        if key in common:
            try:
                v = common[key].check(v)
            except ValueError as exc:
                raise _fail(path, where, str(exc)) from None
        elif isinstance(v, (list,)) or hasattr(v, "isoformat"):
            raise _fail(path, where, f"back-end options must be numbers, strings, booleans "
                                     f"or tables, found {_type_name(v)}")
        out[key] = v
    return out


def _cost(raw: Any, path: Path) -> Mapping[str, Any]:
    if not isinstance(raw, dict):
        raise _fail(path, "cost", f"must be a table ([cost]), found {_type_name(raw)}")
    for key in raw:
        if key not in _COST_KEYS:
            raise _fail(path, f"cost.{key}", f"unknown key; valid: {', '.join(_COST_KEYS)}")
    builder = raw.get("builder")
    if not isinstance(builder, str) or not builder:
        raise _fail(path, "cost.builder", f"must name a cost builder, found {builder!r}")
    params = raw.get("params", {})
    if not isinstance(params, dict):
        raise _fail(path, "cost.params", f"must be a table, found {_type_name(params)}")
    try:
        import inspect

        COSTS, build_costs = _cost_layer().COSTS, _cost_layer().build_costs
    except ImportError as exc:   # pragma: no cover - the costs package ships with assocopt
        raise _fail(path, "cost.builder", f"cost builders unavailable: {exc}") from exc
    if builder not in COSTS:
        raise _fail(path, "cost.builder", f"unknown cost builder {builder!r}; valid: "
                                          f"{', '.join(COSTS)}")
    accepted = [n for n, p in inspect.signature(build_costs).parameters.items()
                if p.kind is inspect.Parameter.KEYWORD_ONLY]
    for key, v in params.items():
        if key not in accepted:
            raise _fail(path, f"cost.params.{key}", f"unknown parameter; valid: "
                                                    f"{', '.join(accepted)}")
        if not isinstance(v, (str, int, float, bool)):
            raise _fail(path, f"cost.params.{key}", f"must be a plain value, found "
                                                    f"{_type_name(v)}")
    return MappingProxyType({"builder": builder, "params": MappingProxyType(dict(params))})


def _check_backend_options(cls: Any, extras: dict[str, Any], path: Path) -> None:
    """The back end's own options checked against its declaration (no trial solve)."""
    from ..solvers.options import OptionError

    if not cls.is_available() and cls.native_options:
        declared = {o.name for o in cls.options}
        extras = {k: v for k, v in extras.items() if k in declared}
    try:
        cls.parse_options(extras)
    except OptionError as exc:
        raise _fail(path, f"options.{exc.option}",
                    f"rejected by back end {cls.name!r}: {exc}") from None
