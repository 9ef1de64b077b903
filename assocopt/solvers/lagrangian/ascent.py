"""Subgradient ascent on ``L(u)`` and the state shared by the phases of a solve.

:class:`_State` carries the incumbent, the best bound, the proof and the history;
:func:`_ascent` runs the Polyak/momentum ascent with primal recovery (and, in exact
mode, the stall rule and the fixing probes supplied by the back end).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from .local_search import _LocalSearch
from .options import OPT_TOL
from .relaxation import _Relaxation


@dataclass
class _State:
    """Progress shared by the phases of one solve (best solution, bound, history)."""

    costs: np.ndarray                   # problem costs
    integer: bool
    incumbent: np.ndarray | None = None   # problem positions
    ub: float = math.inf
    bound: float = -math.inf            # best valid lower bound on the optimum
    theta: float = 2.0
    iterations: int = 0
    history: dict[str, list] | None = None
    proof: str | None = None
    stop: str = ""
    best_recovered: float = math.inf

    def offer(self, positions: np.ndarray) -> None:
        vals = self.costs[positions]
        if float(vals.sum()) > self.ub + OPT_TOL * max(1.0, abs(self.ub)):
            return
        obj = math.fsum(vals.tolist())
        if obj < self.ub:
            self.ub, self.incumbent = obj, np.sort(positions)

    def tol(self) -> float:
        return OPT_TOL * max(1.0, abs(self.ub))

    def closes(self, bound: float) -> bool:
        """Whether ``bound`` proves the incumbent optimal."""
        if not (math.isfinite(self.ub) and math.isfinite(bound)):
            return False
        if self.integer:
            return math.ceil(bound - 1e-6) >= self.ub
        return bound >= self.ub - self.tol()

    def report_bound(self) -> float | None:
        if not math.isfinite(self.bound):
            return None
        b = self.bound
        if self.integer:
            b = float(math.ceil(b - 1e-6))
        return min(b, self.ub) if math.isfinite(self.ub) else b


#: Fixing probes of the exact mode: the first at iteration ``PROBE_FIRST[0]`` on up to
#: ``PROBE_LARGE`` candidates (cheap, and they settle most small problems), else at
#: ``PROBE_FIRST[1]``; each later one after ``PROBE_GROWTH[.]`` times as many
#: iterations.  On large sets the fixing window shrinks several-fold between probes
#: 2x apart (2,000 -> 300 candidates), so probing at 1.5x reaches a searchable window
#: sooner: gated N = 4-5 scans with components of 10,000-50,000 candidates (seeds
#: 51-52 and 71-72) took 3-4 % less in sum; at 1.3x, and at 1.5x on small sets,
#: more probes searched windows they could not settle (1.6 ms a failed search).
PROBE_LARGE = 5_000
PROBE_FIRST = (2, 10)
PROBE_GROWTH = (2.0, 1.5)


def _ascent(rel: _Relaxation, pos: np.ndarray, upad: np.ndarray, st: _State,
            p: dict[str, Any], deadline: float | None, exact: bool,
            ls: "_LocalSearch | None" = None, probe: Any = None) -> np.ndarray:
    """Subgradient ascent on ``L(u)``; returns the best multipliers.

    ``pos`` maps the relaxation's candidates to problem positions.  Every bound found
    is a bound on the optimum of the candidate set, which is at least
    ``min(st.ub, optimum)`` of the problem (removed candidates cannot beat the
    incumbent), so ``st.bound`` is updated with ``min(L, ub)``.
    """
    large = int(rel.K > PROBE_LARGE)
    next_probe, growth = PROBE_FIRST[large], PROBE_GROWTH[large]
    from . import sparse_ascent as sa
    if sa.eligible(rel, deadline, ls, st):   # the evaluation is compiled: the loop too?
        if sa.applies(rel):
            return sa.sparse_ascent(rel, pos, upad, st, p, exact, probe, next_probe,
                                    growth)
        return sa.charged(lambda: _loop(rel, pos, upad, st, p, deadline, exact, ls,
                                        probe, next_probe, growth))
    return _loop(rel, pos, upad, st, p, deadline, exact, ls, probe, next_probe, growth)


def _loop(rel: _Relaxation, pos: np.ndarray, upad: np.ndarray, st: _State,
          p: dict[str, Any], deadline: float | None, exact: bool,
          ls: "_LocalSearch | None", probe: Any, next_probe: int, growth: float
          ) -> np.ndarray:
    """The ascent's loop in Python (:func:`_ascent`)."""
    best_L, best_u = -math.inf, upad.copy()
    since, d_prev = 0, None
    theta = st.theta
    window: list[float] = []
    next_ls = 0
    for it in range(int(p["max_iter"])):
        if it and deadline is not None and time.perf_counter() > deadline:
            st.stop = "time_limit"
            break
        ev = rel.evaluate(upad)
        st.iterations += 1
        L = ev.value
        if it == 0 or L > best_L + 1e-12 * max(1.0, abs(best_L)):
            best_L, best_u, since = L, upad.copy(), 0
        else:
            since += 1
        g = ev.subgradient
        norm2 = float(g @ g)
        if norm2 == 0.0:          # relaxed solution feasible: optimal by exactness
            st.offer(pos[ev.selected])
            st.bound = max(st.bound, min(L, st.ub))
            st.proof = st.proof or "relaxed solution feasible (zero subgradient)"
            st.stop = "proven"
            _record(st, L, best_L)
            return upad.copy()
        if p["recover_every"] and it % int(p["recover_every"]) == 0:
            sel = rel.recover(upad, ev.chosen)
            if sel is not None:
                sol = pos[sel]
                cost = float(st.costs[sol].sum())
                if ls is not None and cost < st.best_recovered and it >= next_ls:
                    st.best_recovered = cost      # improve record recoveries, at most
                    next_ls = it + 5              # every fifth iteration
                    sol = ls.improve(sol)
                st.offer(sol)
        st.bound = max(st.bound, min(best_L, st.ub))
        _record(st, L, best_L)
        if st.closes(best_L):
            st.proof = st.proof or "Lagrangian bound meets the objective"
            st.stop = "proven"
            break
        if math.isfinite(st.ub) and p["gap_tol"] > 0 and \
                st.ub - best_L <= p["gap_tol"] * max(abs(st.ub), 1e-12):
            st.stop = "gap_tol"
            break
        if exact and probe is not None and it + 1 >= next_probe and math.isfinite(st.ub):
            next_probe = max(it + 2, int(next_probe * growth))
            verdict = probe(best_u)
            if verdict:
                st.stop = verdict
                break
        if exact and math.isfinite(st.ub):
            window.append(best_L)
            k = int(p["stall_iter"])
            if len(window) > k and \
                    window[-1] - window[-1 - k] < p["stall_tol"] * (st.ub - best_L):
                st.stop = "stalled"
                break
        if since >= p["patience"]:
            theta *= p["step_decay"]
            since = 0
            if theta < p["step_min"]:
                st.stop = "step_min"
                break
        target = st.ub if math.isfinite(st.ub) else \
            best_L + max(1e-3, 0.05 * abs(best_L))
        d = g if d_prev is None else g + p["deflect"] * d_prev
        dn = float(np.sum(d * d))        # pairwise: the kernel's sum (sparse_ascent)
        if dn <= 1e-12 * norm2:          # the deflection cancelled the subgradient
            d, dn = g, norm2
        step = theta * max(target - L, 1e-12 * max(1.0, abs(L))) / dn
        upad = upad + step * d
        d_prev = d
    else:
        st.stop = "max_iter"
    st.theta = theta
    return best_u


def _record(st: _State, L: float, best: float) -> None:
    if st.history is not None:
        st.history["bound"].append(L)
        st.history["best_bound"].append(best)
        st.history["objective"].append(st.ub if math.isfinite(st.ub) else None)
