"""The project's own JSON instance format, version 1 (``docs/instance-format.md``).

Reading (:func:`_read_json` and its strict validation helpers) and writing
(:func:`instance_to_json` and its layout helpers) live together so that the
format's name, version and keys are defined in one place.  Writing the text to a
file atomically is :mod:`.writers`' job.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from ..runtime.errors import InvalidProblemError
from ..problems.problem import AssignmentProblem
from ..problems.validation import MAX_ABS_COST
from .common import MAX_JSON_DEPTH, _fail
from .json_bulk import INF_WORDS, bulk_costs, bulk_indices
from .json_scan import JsonScan, scan_json

#: Value of the ``"format"`` key of the project's JSON instance files.
FORMAT_NAME = "assocopt-instance"
#: Newest version of the JSON instance format this module reads and writes.
FORMAT_VERSION = 1

_COMMON_KEYS = {"format", "version", "kind", "name", "optimum", "optimum_source",
                "description"}
_KIND_KEYS = {"dense": ({"costs"}, {"row_miss", "col_miss"}),
              "sparse": ({"sizes", "tuples", "costs"}, set())}


# =============================================================== reading
def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"duplicate key {k!r}")
        out[k] = v
    return out


_CONSTANTS = {"Infinity": math.inf, "-Infinity": -math.inf, "NaN": math.nan}


def _parse_constant(name: str) -> float:
    # Python's json writes Infinity/NaN; accept them here and reject NaN and -inf
    # where they are used, with their position.
    return _CONSTANTS[name]


def _cost_value(v: Any, where: str, path: Path) -> float:
    if isinstance(v, bool) or v is None:
        raise _fail(path, f"{where} must be a number or \"inf\", found {json.dumps(v)}")
    if isinstance(v, int) and abs(v) > MAX_ABS_COST:
        digits = len(str(abs(v)))
        raise _fail(path, f"{where} is an integer of {digits} digits, outside the accepted "
                          f"range |cost| <= {MAX_ABS_COST:g}")
    if isinstance(v, (int, float)):
        f = float(v)
        if math.isnan(f):
            raise _fail(path, f"{where} is NaN")
        if f == -math.inf:
            raise _fail(path, f"{where} is -inf (only +inf, \"inf\", is allowed: forbidden)")
        return f
    if isinstance(v, str):
        if v.strip().lower() in INF_WORDS:
            return math.inf
        raise _fail(path, f"{where} must be a number or \"inf\", found the string {v!r}")
    raise _fail(path, f"{where} must be a number or \"inf\", found {type(v).__name__}")


def _cost_array(v: Any, where: str, path: Path, min_ndim: int = 0, *,
                scan: JsonScan | None = None) -> np.ndarray:
    """Nested lists of costs -> float64 array, naming the position of any bad entry.

    A well-formed array takes numpy's bulk route (:func:`.json_bulk.bulk_costs`,
    helped by what ``scan`` of the whole file proved); anything else takes the
    per-entry walk of :func:`_walk_costs`, which gives the message.
    """
    shape: list[int] = []
    node = v
    while isinstance(node, list):
        shape.append(len(node))
        if not node:
            break
        node = node[0]
    if len(shape) < min_ndim:
        raise _fail(path, f"{where} must be a nested list of at least {min_ndim} levels "
                          f"(one per axis), found {len(shape)} level(s)")
    if not shape:
        return np.array(_cost_value(v, where, path), dtype=np.float64)
    arr = (bulk_costs(v, shape, True) if scan is None else
           bulk_costs(v, shape, scan.literals, scan.inf_strings))
    return arr if arr is not None else _walk_costs(v, shape, where, path)


def _walk_costs(v: list, shape: list[int], where: str, path: Path) -> np.ndarray:
    """The strict per-entry conversion of nested cost lists of (first-element) ``shape``:
    raises naming the first ragged list or bad entry."""

    def here(idx: list[int]) -> str:
        return where + "".join(f"[{i}]" for i in idx)

    flat: list[Any] = []
    last = len(shape) - 1

    def walk(node: Any, depth: int, idx: list[int]) -> None:
        if not isinstance(node, list):
            raise _fail(path, f"ragged {where}: {here(idx)} is a single value, expected a "
                              f"list of {shape[depth]} (shape {shape})")
        if len(node) != shape[depth]:
            raise _fail(path, f"ragged {where}: {here(idx)} has {len(node)} entries, "
                              f"expected {shape[depth]} like the first one (shape {shape})")
        if depth < last:
            for i, item in enumerate(node):
                walk(item, depth + 1, idx + [i])
            return
        for i, x in enumerate(node):
            t = type(x)
            if t is float or (t is int and -MAX_ABS_COST <= x <= MAX_ABS_COST):
                flat.append(x)
            elif isinstance(x, list):
                raise _fail(path, f"ragged {where}: {here(idx + [i])} is a list, expected a "
                                  f"cost (shape {shape})")
            else:
                flat.append(_cost_value(x, here(idx + [i]), path))

    walk(v, 0, [])
    arr = np.array(flat, dtype=np.float64).reshape(shape)
    bad = np.isnan(arr) | np.isneginf(arr)
    if bad.any():
        first = [int(i) for i in np.argwhere(bad)[0]]
        _cost_value(float(arr[tuple(first)]), here(first), path)   # raises with the position
    return arr


def _int_list(v: Any, where: str, path: Path) -> list[int]:
    if not isinstance(v, list):
        raise _fail(path, f"{where} must be a list of integers, found {type(v).__name__}")
    out = []
    for i, x in enumerate(v):
        if isinstance(x, bool) or not isinstance(x, int):
            if isinstance(x, float) and x.is_integer():
                x = int(x)
            else:
                raise _fail(path, f"{where}[{i}] must be an integer, found {json.dumps(x)}")
        out.append(x)
    return out


def _walk_tuples(tuples: list, n_axes: int, path: Path) -> np.ndarray:
    """The strict per-entry conversion of ``"tuples"``: raises naming the bad entry."""
    T = [_int_list(t, f"tuples[{k}]", path) for k, t in enumerate(tuples)]
    for k, t in enumerate(T):
        if len(t) != n_axes:
            raise _fail(path, f"tuples[{k}] has {len(t)} indices, expected one per "
                              f"axis ({n_axes})")
    return np.array(T) if T else np.zeros((0, n_axes), dtype=np.int64)


def _walk_sparse_costs(costs: list, path: Path) -> np.ndarray:
    """The strict per-entry conversion of a sparse ``"costs"`` list."""
    return np.array([_cost_value(v, f"costs[{k}]", path) for k, v in enumerate(costs)],
                    dtype=np.float64)


def _parse_float(text: str) -> float:
    value = float(text)
    if math.isinf(value):
        raise ValueError(f"the number {text[:40]} is outside the float range")
    return value


def _read_json(path: Path, text: str) -> AssignmentProblem:
    scan = scan_json(text)
    if scan.depth > MAX_JSON_DEPTH:
        raise _fail(path, f"invalid JSON: nested {scan.depth} levels deep, more than the "
                          f"{MAX_JSON_DEPTH} levels an instance file may have")
    # the parse_float hook (a Python call per float) is only needed when a literal
    # may overflow: without one, json's own float() gives the same values.
    hooks = {"parse_float": _parse_float} if scan.big_numbers else {}
    try:
        doc = json.loads(text, object_pairs_hook=_no_duplicates,
                         parse_constant=_parse_constant, **hooks)
    except json.JSONDecodeError as exc:
        # json's own messages may end in "at" ("Unterminated string starting at")
        msg = exc.msg[:-3] if exc.msg.endswith(" at") else exc.msg
        raise _fail(path, f"invalid JSON: {msg} at line {exc.lineno} column "
                          f"{exc.colno}") from None
    except RecursionError:
        raise _fail(path, "invalid JSON: nested too deeply") from None
    except ValueError as exc:
        raise _fail(path, f"invalid JSON: {exc}") from None
    if not isinstance(doc, dict):
        raise _fail(path, f"expected a JSON object at the top level, found {type(doc).__name__}")
    fmt = doc.get("format")
    if fmt != FORMAT_NAME:
        what = "no \"format\" key" if "format" not in doc else f"\"format\": {json.dumps(fmt)}"
        raise _fail(path, f"not an assocopt instance file ({what}; expected "
                          f"\"format\": \"{FORMAT_NAME}\")")
    if "version" not in doc:
        raise _fail(path, "missing key \"version\"")
    version = doc["version"]
    if isinstance(version, bool) or not isinstance(version, int):
        raise _fail(path, f"\"version\" must be an integer, found {json.dumps(version)}")
    if version > FORMAT_VERSION:
        raise _fail(path, f"version {version} is newer than this assocopt reads "
                          f"({FORMAT_VERSION}); upgrade assocopt")
    if version < 1:
        raise _fail(path, f"unsupported version {version} (this assocopt reads 1..{FORMAT_VERSION})")
    if "kind" not in doc:
        raise _fail(path, "missing key \"kind\" (\"dense\" or \"sparse\")")
    kind = doc["kind"]
    if kind not in _KIND_KEYS:
        raise _fail(path, f"unknown kind {json.dumps(kind)}; expected \"dense\" or \"sparse\"")
    required, optional = _KIND_KEYS[kind]
    for key in sorted(required):
        if key not in doc:
            raise _fail(path, f"missing key \"{key}\" (required for kind \"{kind}\")")
    for key in doc:
        if key.startswith("x-") or key in _COMMON_KEYS or key in required or key in optional:
            continue
        other = [k for k, (r, o) in _KIND_KEYS.items() if key in r | o]
        why = f" (used by kind \"{other[0]}\", not \"{kind}\")" if other else ""
        raise _fail(path, f"unknown key \"{key}\"{why}; user extensions must start with \"x-\"")

    name = doc.get("name", path.stem)
    if not isinstance(name, str):
        raise _fail(path, f"\"name\" must be a string, found {json.dumps(name)}")
    optimum = doc.get("optimum")
    if optimum is not None:
        if isinstance(optimum, bool) or not isinstance(optimum, (int, float)) \
                or not math.isfinite(optimum):
            raise _fail(path, f"\"optimum\" must be a finite number, found {json.dumps(optimum)}")
        optimum = float(optimum)
    meta: dict[str, Any] = {"format": "assocopt", "path": str(path), "version": version}
    for key in ("optimum_source", "description"):
        if key in doc and doc[key] is not None:
            if not isinstance(doc[key], str):
                raise _fail(path, f"\"{key}\" must be a string, found {json.dumps(doc[key])}")
            meta[key] = doc[key]
    meta.update({k: v for k, v in doc.items() if k.startswith("x-")})

    try:
        if kind == "dense":
            C = _cost_array(doc["costs"], "costs", path, min_ndim=2, scan=scan)
            rm = doc.get("row_miss")
            cm = doc.get("col_miss")
            if rm is not None or cm is not None:
                if C.ndim != 2:
                    raise _fail(path, f"\"row_miss\"/\"col_miss\" need a 2-D cost matrix, "
                                      f"\"costs\" has {C.ndim} axes")
                rma = None if rm is None else _cost_array(rm, "row_miss", path, scan=scan)
                cma = None if cm is None else _cost_array(cm, "col_miss", path, scan=scan)
                p = AssignmentProblem.two_d(C, rma, cma, name=name, optimum=optimum)
            else:
                p = AssignmentProblem.dense(C, name=name, optimum=optimum)
        else:
            sizes = _int_list(doc["sizes"], "sizes", path)
            tuples = doc["tuples"]
            if not isinstance(tuples, list):
                raise _fail(path, f"\"tuples\" must be a list of index lists, found "
                                  f"{type(tuples).__name__}")
            Ta = bulk_indices(tuples, len(sizes), scan.literals)
            if Ta is None:
                Ta = _walk_tuples(tuples, len(sizes), path)
            costs = doc["costs"]
            if not isinstance(costs, list):
                raise _fail(path, f"\"costs\" must be a list of numbers, found "
                                  f"{type(costs).__name__}")
            if len(costs) != len(Ta):
                raise _fail(path, f"\"costs\" has {len(costs)} entries but \"tuples\" has "
                                  f"{len(Ta)}")
            c = bulk_costs(costs, (len(costs),), scan.literals, scan.inf_strings)
            if c is None:
                c = _walk_sparse_costs(costs, path)
            p = AssignmentProblem.sparse(sizes, Ta, c, name=name, optimum=optimum)
    except InvalidProblemError as exc:
        raise _fail(path, f"invalid problem: {exc}") from exc
    p.meta.update(meta)
    return p


# =============================================================== writing
def _json_cost(v: float) -> Any:
    if math.isinf(v):
        if v > 0:
            return "inf"
        raise InvalidProblemError("cannot write a -inf cost")
    if math.isnan(v):
        raise InvalidProblemError("cannot write a NaN cost")
    if v.is_integer() and abs(v) < 1e15:
        return int(v)
    return v


def _dump_nested(a: np.ndarray, indent: int) -> str:
    """Nested list text: innermost lists on one line, outer levels one item per line."""
    if a.ndim == 1:
        return "[" + ", ".join(json.dumps(_json_cost(float(v))) for v in a) + "]"
    pad = " " * (indent + 2)
    inner = (",\n" + pad).join(_dump_nested(sub, indent + 2) for sub in a)
    return "[\n" + pad + inner + "\n" + " " * indent + "]"


def _dump_rows(rows: Iterable[str], indent: int) -> str:
    rows = list(rows)
    if not rows:
        return "[]"
    pad = " " * (indent + 2)
    return "[\n" + pad + (",\n" + pad).join(rows) + "\n" + " " * indent + "]"


def instance_to_json(problem: AssignmentProblem, *, optimum: float | None = None,
                     optimum_source: str | None = None,
                     description: str | None = None) -> str:
    """The JSON v1 text :func:`write_instance` writes."""
    if not isinstance(problem, AssignmentProblem):
        raise InvalidProblemError(
            f"problem must be an AssignmentProblem, got {type(problem).__name__}")
    if optimum is None:
        optimum = problem.optimum
        if optimum_source is None and optimum is not None:
            optimum_source = problem.meta.get("optimum_source")
    if description is None:
        description = problem.meta.get("description")
    head: list[tuple[str, str]] = [("format", json.dumps(FORMAT_NAME)),
                                   ("version", json.dumps(FORMAT_VERSION))]
    if problem.name is not None:
        head.append(("name", json.dumps(problem.name)))
    if description is not None:
        head.append(("description", json.dumps(str(description))))
    if optimum is not None:
        opt = float(optimum)
        if not math.isfinite(opt):
            raise InvalidProblemError(f"optimum must be finite, got {optimum!r}")
        head.append(("optimum", json.dumps(_json_cost(opt))))
        if optimum_source is not None:
            head.append(("optimum_source", json.dumps(str(optimum_source))))
    body: list[tuple[str, str]] = []
    if problem.kind in ("dense", "two_d"):
        if 0 in problem.sizes:
            raise InvalidProblemError(
                f"a dense problem with an empty axis (sizes {list(problem.sizes)}) cannot be "
                "written as nested lists; build it with AssignmentProblem.sparse")
        head.append(("kind", json.dumps("dense")))
        body.append(("costs", _dump_nested(problem.to_cost_matrix(), 2)))
        if problem.kind == "two_d":
            rm, cm = problem.miss_costs()
            body.append(("row_miss", _dump_nested(rm, 2)))
            body.append(("col_miss", _dump_nested(cm, 2)))
    elif problem.kind == "sparse":
        head.append(("kind", json.dumps("sparse")))
        if problem.slack.any():  # pragma: no cover - sparse problems never have slack
            raise InvalidProblemError("a sparse problem with slack candidates cannot be written")
        body.append(("sizes", json.dumps(list(problem.sizes))))
        body.append(("tuples", _dump_rows((json.dumps(t) for t in problem.tuples.tolist()), 2)))
        costs = [json.dumps(_json_cost(c)) for c in problem.costs.tolist()]
        per_line = 10
        body.append(("costs", _dump_rows((", ".join(costs[k:k + per_line])
                                          for k in range(0, len(costs), per_line)), 2)))
    else:
        raise InvalidProblemError(f"cannot write a problem of kind {problem.kind!r}")
    items = [f"  {json.dumps(k)}: {v}" for k, v in head + body]
    return "{\n" + ",\n".join(items) + "\n}\n"
