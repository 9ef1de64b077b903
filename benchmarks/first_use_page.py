"""The page of :mod:`first_use`: ``docs/benchmarks-first-use.md`` rendered from the
JSON the benchmark wrote (tests/test_benchmarks_first_use.py checks the committed page
is this function of the committed JSON)."""

from __future__ import annotations

from typing import Any


def _met(value: float, target: float) -> str:
    return "yes" if value <= target else "no"


def route(r: dict[str, Any]) -> str:
    """What a first call did: compiled (or loaded) kernels, ran them interpreted, or
    needed none."""
    if r["compile_s"] > 0 or r["cache_load_s"] > 0:
        return "compiled"
    return "interpreted" if r["interpreted_s"] > 0 else "no kernel"


def _header(data: dict[str, Any]) -> list[str]:
    m, v, t, rule = data["machine"], data["versions"], data["targets"], data["rule"]
    return [
        "# First use: compiled or interpreted kernels",
        "",
        "Measured by `python benchmarks/first_use.py` (numbers below from "
        "`docs/benchmarks-first-use.json`, written by the same run). Each path is one "
        "public call in a fresh interpreter whose numba cache (`NUMBA_CACHE_DIR`) is an "
        "empty folder. Times are of the call alone (wall and CPU of the process from "
        "before the call to after it; the interpreter's start, `import assocopt` and "
        "building the problem are not in them).",
        "",
        "**The default rule** (`assocopt.solvers.kernels.tiers`): a kernel call whose "
        "work is small runs the kernel as plain Python (the same source, loaded a second "
        "time without numba; numba is not even imported), until the interpreted calls of "
        f"that kernel have cost {rule['budget_cold_s']:g} s in the process "
        f"({rule['budget_cached_s']:g} s when numba's disk cache holds it, "
        f"{rule.get('budget_warm_s', rule['budget_cached_s']):g} s when the process "
        "has loaded or compiled another kernel already); a larger "
        "call, or any call after that, compiles the kernel (or loads it from the cache) "
        "and runs it compiled. A search that runs past the budget is solved again "
        "compiled. `ASSOCOPT_JIT=compiled` compiles always, `ASSOCOPT_JIT=interpreted` "
        "never; both routes give the same answers (tests/test_tiers.py).",
        "",
        f"Machine: Python {m['python']}, {m['system']} {m['machine']}, {m['cpus']} CPUs; "
        f"numpy {v['numpy']}, scipy {v['scipy']}, numba {v['numba']}, llvmlite "
        f"{v['llvmlite']}. Load average (1, 5, 15 min) before the run "
        f"{', '.join(f'{x:g}' for x in data['load_before'])}, after it "
        f"{', '.join(f'{x:g}' for x in data['load_after'])}: on a loaded machine the "
        "wall times stretch, the CPU times much less.",
        "",
        f"Targets: a first call with an empty cache at most {t['cold_s']:g} s, all paths "
        f"in one such process at most {t['all_s']:g} s, a first call with the cache "
        f"filled at most {t['warm_s']:g} s; judged on CPU time, on the default rule (a "
        "first call by the default rule on these problems loads nothing, so it costs the "
        "same with the cache filled).",
        "",
    ]


def _tables(data: dict[str, Any]) -> list[str]:
    t = data["targets"]
    lines = [
        "## By the default rule",
        "",
        "| path | route | first call (s) | CPU (s) | numba imported | met (cold) "
        "| met (cached) | load avg |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in data["rows"]:
        a = r["auto"]
        lines.append(
            f"| {r['what']} | {route(a)} | {a['wall_s']:.3f} | {a['cpu_s']:.3f} | "
            f"{'yes' if a['numba'] else 'no'} | {_met(a['cpu_s'], t['cold_s'])} | "
            f"{_met(a['cpu_s'], t['warm_s'])} | {r['load'][0]:g} |")
    lines += [
        "",
        "## Compiled (`ASSOCOPT_JIT=compiled`: what a call large enough to compile pays)",
        "",
        "*Cold*: the kernels compiled into the empty cache; *warm*: a second process "
        "loading them from it. *Compiling* and *cache load* are the parts of the call "
        "(wall time) that `assocopt.solvers.kernels` timed (cache load includes importing "
        "numba and the kernel modules). *Note*: the call said, before compiling, that it "
        "would (one line of the `assocopt` logger).",
        "",
        "| path | cold (s) | cold CPU (s) | compiling (s) | note | warm (s) | "
        "cache load (s) | met (cached) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in data["rows"]:
        c, w = r["cold"], r["warm"]
        lines.append(
            f"| {r['what']} | {c['wall_s']:.2f} | {c['cpu_s']:.2f} | {c['compile_s']:.2f} "
            f"| {'yes' if r['cold_notes'] else 'no'} | {w['wall_s']:.3f} | "
            f"{w['cache_load_s']:.3f} | {_met(w['cpu_s'], t['warm_s'])} |")
    return lines


def render(data: dict[str, Any]) -> str:
    """The docs page for the measurements ``data``."""
    t = data["targets"]
    auto, comp = data["together"]["auto"], data["together"]["compiled"]
    lines = _header(data) + _tables(data) + [
        "",
        "## All paths in one process, cache empty",
        "",
        f"By the default rule: {auto['wall_s']:.2f} s ({auto['cpu_s']:.2f} s CPU, "
        f"{auto['compile_s']:.2f} s compiling); target met: "
        f"{_met(auto['cpu_s'], t['all_s'])}; the process as a whole, interpreter start "
        f"and imports included, {auto['process_s']:.2f} s. Compiled: {comp['wall_s']:.2f} "
        f"s ({comp['cpu_s']:.2f} s CPU, {comp['compile_s']:.2f} s compiling; kernels two "
        f"paths share are compiled once); process {comp['process_s']:.2f} s.",
        "",
        "Where the compile time goes (numba's `numba:compile` events per function and "
        "signature): typing and lowering in numba's Python code and LLVM's optimisation "
        "of each kernel and every kernel it calls; numba's own library functions (`np.argsort`, "
        "array slice assignment with its broadcasting checks, `heapq`) compiled anew for "
        "each signature they meet. Cut: duplicate specialisations (a literal `-1` "
        "argument compiled `augment` twice; growing arrays by slice assignment compiled "
        "numba's broadcasting code for each dtype). A read-only install caches in the "
        "user's cache or, failing that, in a temporary folder of the process "
        "(tests/test_readonly_install.py). `NUMBA_DISABLE_JIT=1` runs every kernel as "
        "plain Python with the same answers (tests/test_disable_jit.py).",
        "",
    ]
    return "\n".join(lines)
