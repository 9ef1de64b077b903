"""One conformance suite run against every installed back end.

Every exact back end must equal brute force on random small problems of every
family (2-D square / rectangular / with miss costs, axial 3-D and 4-D, S-D with
dummies), agree on known cases, detect infeasibility, handle empty problems and
leave the input untouched.  Each back end is called directly
(``Backend().solve(problem, SolveOptions())``) as well as through
:func:`assocopt.solve`, which answers empty and uncovered problems itself: the
direct calls make sure the back end's own code is what is checked.  The capability
flags, the declared options and the registry are checked here too.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from assocopt import AssignmentProblem, SolverCapabilityError, Status, solve
from assocopt.solvers import Backend, SolveOptions, registered
from assocopt.testing import KINDS, assert_feasible, assert_optimal, problems

from conftest import EXACT, LP, installed


def _kinds_for(name: str) -> tuple[str, ...]:
    if registered()[name].max_ndim == 2:
        return ("square", "rect", "miss")
    return KINDS


@pytest.mark.parametrize("name", [installed(n) for n in EXACT])
def test_exact_backend_equals_brute_force(name):
    integer = None if registered()[name].exact_float_costs else True

    @given(problems(_kinds_for(name), integer=integer))
    def check(p):
        assert_optimal(p, solve(p, name))
    check()


@pytest.mark.parametrize("name", [installed(n) for n, cls in registered().items()
                                  if cls.exact and not cls.exact_float_costs])
def test_scaled_backend_within_its_reported_bound_on_float_costs(name):
    @given(problems(_kinds_for(name), integer=False))
    def check(p):
        sol = solve(p, name)
        ref = solve(p, "bruteforce").objective
        assert sol.status in (Status.OPTIMAL, Status.FEASIBLE), sol.message
        assert_feasible(p, sol)
        assert sol.bound is not None and sol.bound <= ref + 1e-9
        assert sol.objective - ref <= sol.objective - sol.bound + 1e-9
        if sol.status is Status.OPTIMAL:      # a claim made despite rounding holds
            assert_optimal(p, sol)
    check()


@pytest.mark.parametrize("name", [installed(n) for n, cls in registered().items()
                                  if cls.exact and not cls.exact_float_costs])
def test_scaled_backend_proves_optimal_where_the_others_do(name):
    """Float costs rounded to integers: still ``optimal`` when the rounding-corrected
    bound is within the gap every back end counts as zero (here: costs of order 1-10,
    so the rounding error is far below it)."""
    for seed in range(6):
        rng = np.random.default_rng(seed)
        p = AssignmentProblem.dense(rng.normal(size=(4, 4, 4)) * 10 ** (seed % 2))
        ref = solve(p, "highs")
        sol = solve(p, name)
        assert ref.status is Status.OPTIMAL
        assert sol.status is Status.OPTIMAL, sol.message
        assert_optimal(p, sol)
        assert sol.gap <= 1e-9 and sol.info["rounding_gap"] <= 1e-9


@pytest.mark.parametrize("name", [installed(n) for n in LP])
def test_lp_bound_below_ilp_optimum(name):
    @given(problems())
    def check(p):
        lp = solve(p, name, relax="lp")
        ilp = solve(p, "bruteforce")
        assert lp.status is Status.OPTIMAL, lp.message
        assert lp.relaxation == "lp" and lp.x is not None
        assert lp.objective <= ilp.objective + 1e-7 * max(1.0, abs(ilp.objective))
        if lp.integral:   # an integral LP optimum is an ILP optimum
            assert_feasible(p, lp)
            assert lp.objective == pytest.approx(ilp.objective, rel=1e-7, abs=1e-7)
    check()


@given(problems())
def test_greedy_is_feasible_and_never_below_optimum(p):
    g = solve(p, "greedy")
    assert g.status is Status.FEASIBLE, g.message
    assert_feasible(p, g)
    assert g.bound is None
    assert g.objective >= solve(p, "bruteforce").objective - 1e-9


def test_brute_force_counts_every_solution():
    from assocopt.solvers.baseline.bruteforce import count_solutions
    assert count_solutions(AssignmentProblem.dense(np.zeros((4, 4)))) == 24
    assert count_solutions(AssignmentProblem.dense(np.zeros((3, 3, 3)))) == 36
    # 2 targets, 3 sensors with dummies allowed: every partition of the measurements
    T = np.array([t for t in np.ndindex(3, 3, 3) if any(t)])
    assert count_solutions(AssignmentProblem.sparse((2, 2, 2), T, np.zeros(len(T)))) > 4
    # paper 002 with P_D = 1: only full tuples -> (2!)^2 = 4 feasible solutions
    full = np.array([t for t in np.ndindex(3, 3, 3) if all(t)])
    assert count_solutions(AssignmentProblem.sparse((2, 2, 2), full, np.zeros(len(full)))) == 4


KNOWN = [
    # (problem, optimum, chosen tuples): hand-checked small cases
    (AssignmentProblem.dense([[4.0, 1.0, 3.0], [2.0, 0.0, 5.0], [3.0, 2.0, 2.0]]), 5.0,
     [[1, 2], [2, 1], [3, 3]]),
    (AssignmentProblem.two_d([[10.0, 10.0]], row_miss=[1.0], col_miss=[2.0, 3.0]), 6.0,
     [[1, 0], [0, 1], [0, 2]]),
    (AssignmentProblem.two_d([[1.0, np.inf], [np.inf, np.inf]], row_miss=5.0, col_miss=5.0),
     11.0, [[1, 1], [2, 0], [0, 2]]),
    (AssignmentProblem.dense([[[1.0, 9.0], [9.0, 9.0]], [[9.0, 9.0], [9.0, 1.0]]]), 2.0,
     [[1, 1, 1], [2, 2, 2]]),
]


@pytest.mark.parametrize("name", [installed(n) for n in EXACT + ["bruteforce"]])
@pytest.mark.parametrize("case", range(len(KNOWN)))
def test_known_small_cases(name, case):
    p, opt, tuples = KNOWN[case]
    if registered()[name].max_ndim == 2 and p.ndim > 2:
        pytest.skip("2-D back end")
    sol = solve(p, name)
    assert sol.status is Status.OPTIMAL, sol.message
    assert sol.objective == opt
    assert sorted(sol.tuples.tolist()) == sorted(tuples)


@pytest.mark.parametrize("name", [installed(n) for n in EXACT + ["bruteforce"]])
def test_structurally_infeasible(name):
    # rows and columns must all be covered, but 3 rows cannot meet 2 columns
    p = AssignmentProblem.sparse((3, 2), [[1, 1], [2, 2], [3, 1], [3, 2]], [1, 1, 1, 1])
    sol = solve(p, name)
    assert sol.status is Status.INFEASIBLE, sol.message
    assert sol.objective is None and sol.tuples is None


@pytest.mark.parametrize("name", [installed(n) for n in EXACT + ["bruteforce"]])
def test_uncovered_index_is_named(name):
    p = AssignmentProblem.sparse((2, 2), [[1, 1], [2, 1]], [1.0, 2.0])
    sol = solve(p, name)
    assert sol.status is Status.INFEASIBLE
    assert "real index 2 (1-based) of axis 1" in sol.message
    # solve() names the index before any back end runs: the back end itself must
    # find the problem infeasible too
    raw = registered()[name]().solve(p, SolveOptions())
    assert raw.status is Status.INFEASIBLE, raw.message
    assert raw.selected is None
    if p.ndim == 2 and registered()[name].max_ndim is None:
        p3 = AssignmentProblem.sparse((2, 2, 1), [[1, 1, 1], [2, 1, 0], [0, 0, 1]],
                                      [1.0, 2.0, 0.0])
        assert registered()[name]().solve(p3, SolveOptions()).status is Status.INFEASIBLE


@pytest.mark.parametrize("name", [installed(n) for n in EXACT + ["bruteforce", "greedy"]])
def test_empty_problem(name):
    p = AssignmentProblem.dense(np.zeros((0, 0)))
    sol = solve(p, name)
    assert sol.status is Status.OPTIMAL and sol.objective == 0 and len(sol.tuples) == 0
    # the same answer from the back end itself (solve() answers it before dispatch)
    raw = registered()[name]().solve(p, SolveOptions())
    assert raw.status in ((Status.OPTIMAL,) if registered()[name].exact
                          else (Status.OPTIMAL, Status.FEASIBLE)), raw.message
    assert raw.selected is not None and len(raw.selected) == 0


@pytest.mark.parametrize("name", [installed(n) for n in EXACT])
def test_input_not_modified(name):
    rng = np.random.default_rng(7)
    T = np.array([t for t in np.ndindex(3, 3, 3) if any(t)])
    c = rng.normal(size=len(T))
    T0, c0 = T.copy(), c.copy()
    if registered()[name].max_ndim == 2:
        C = rng.random((3, 4))
        C0 = C.copy()
        solve(AssignmentProblem.two_d(C, row_miss=0.5, col_miss=0.5), name)
        assert (C == C0).all()
        return
    solve(AssignmentProblem.sparse((2, 2, 2), T, c), name)
    assert (T == T0).all() and (c == c0).all()


@pytest.mark.parametrize("name", [installed(n) for n in LP])
def test_lp_relaxation_can_be_fractional(name):
    # 3-AP, n = 2: the four zero-cost tuples cover every index twice but no two of
    # them are disjoint, so x = 1/2 on each gives LP = 0 while every integer
    # solution uses a tuple of cost 10.
    zero = [[1, 1, 1], [1, 2, 2], [2, 1, 2], [2, 2, 1]]
    rest = [list(t) for t in np.ndindex(3, 3, 3) if all(t) and list(t) not in zero]
    p = AssignmentProblem.sparse((2, 2, 2), zero + rest, [0.0] * 4 + [10.0] * len(rest))
    assert solve(p, "bruteforce").objective == 10.0
    lp = solve(p, name, relax="lp")
    assert lp.status is Status.OPTIMAL
    assert lp.objective == pytest.approx(0.0, abs=1e-9)
    assert lp.integral is False
    assert lp.tuples is None and lp.selected is None
    assert lp.x[:4] == pytest.approx([0.5] * 4, abs=1e-6)


def test_two_d_only_backend_refuses_3d():
    p = AssignmentProblem.dense(np.ones((2, 2, 2)))
    with pytest.raises(SolverCapabilityError, match="at most 2 axes"):
        solve(p, "scipy-lsa")


def test_lp_only_request_on_ilp_only_backend():
    with pytest.raises(SolverCapabilityError, match="cannot solve LP"):
        solve(AssignmentProblem.dense(np.ones((2, 2))), "bruteforce", relax="lp")


def test_unknown_solver_lists_valid_names():
    from assocopt import UnknownSolverError
    with pytest.raises(UnknownSolverError, match="valid names: .*highs"):
        solve(AssignmentProblem.dense(np.ones((2, 2))), "cplexx")


@pytest.mark.parametrize("kw, match", [
    ({"time_limit": -1}, "time_limit"), ({"mip_gap": -0.1}, "mip_gap"),
    ({"threads": 0}, "threads"), ({"relax": "qp"}, "relax"),
])
def test_bad_options(kw, match):
    from assocopt import InvalidProblemError
    with pytest.raises(InvalidProblemError, match=match):
        solve(AssignmentProblem.dense(np.ones((2, 2))), "highs", **kw)


def test_auto_picks_fast_path_in_2d_and_an_exact_method_otherwise():
    assert solve(AssignmentProblem.dense(np.ones((3, 3))), "auto").solver == "scipy-lsa"
    p = AssignmentProblem.dense(np.random.default_rng(0).random((4, 4, 4)))
    sol = solve(p, "auto")
    assert registered()[sol.solver].exact
    assert_optimal(p, sol)
    assert solve(p, "auto", relax="lp").solver == "highs"


def test_solution_reports_times_and_version():
    sol = solve(AssignmentProblem.dense(np.ones((3, 3, 3))), "highs")
    assert set(sol.times) >= {"build", "solve", "total"}
    assert sol.solver_version
    d = sol.to_dict()
    assert d["status"] == "optimal" and d["time_s"] == sol.times["total"]


# ------------------------------------------------------------ direct calls
ALL = [installed(n) for n in sorted(registered())]


def _direct(name: str, p: AssignmentProblem, **kw):
    return registered()[name]().solve(p, SolveOptions(**kw))


def _check_raw(p: AssignmentProblem, raw, ref: float, exact: bool) -> None:
    """A back end's own answer, before solve()'s checks: feasible, the optimum
    when exact, never below it, and a bound that is valid."""
    tol = 1e-9 * max(1.0, abs(ref))
    if exact:
        assert raw.status is Status.OPTIMAL, raw.message
    selected = raw.selected
    if raw.col_of_row is not None:          # the 2-D engines' answer on a dense view
        checked = p.dense_view.check(raw.col_of_row)
        assert not isinstance(checked, str), checked
        selected = checked.selected
    if selected is not None:
        sel = np.sort(np.asarray(selected, np.int64))
        assert p.violations(sel) is None, p.violations(sel)
        obj = p.objective_of(sel)
        assert obj >= ref - tol
        if exact:
            assert obj == pytest.approx(ref, rel=1e-9, abs=1e-9)
    else:
        assert not exact and raw.status is not Status.OPTIMAL, raw.message
    if raw.bound is not None:
        assert raw.bound <= ref + tol


@pytest.mark.parametrize("name", ALL)
def test_backend_called_directly_matches_brute_force(name):
    cls = registered()[name]
    integer = None if cls.exact_float_costs else True

    @given(problems(_kinds_for(name), integer=integer))
    def check(p):
        ref = solve(p, "bruteforce").objective
        _check_raw(p, _direct(name, p), ref, cls.exact)
        sol = solve(p, name)                     # and through solve()
        if cls.exact:
            assert_optimal(p, sol, reference=ref)
        elif sol.selected is not None:
            assert_feasible(p, sol)
            assert sol.objective >= ref - 1e-9 * max(1.0, abs(ref))
    check()


@pytest.mark.parametrize("name", ALL)
def test_bound_is_valid_and_gives_bound_tells_the_truth(name):
    cls = registered()[name]

    @given(problems(_kinds_for(name), integer=True))
    def check(p):
        ref = solve(p, "bruteforce").objective
        sol = solve(p, name)
        if not cls.gives_bound:
            assert sol.bound is None, f"{name} claims no bound but reported {sol.bound}"
            return
        if sol.status in (Status.OPTIMAL, Status.FEASIBLE):
            assert sol.bound is not None, f"{name} claims a bound but gave none"
            assert sol.bound <= ref + 1e-9 * max(1.0, abs(ref))
    check()


# Options that make a back end stop before it has proven anything, where one
# exists; every other back end with a time limit gets a limit of one nanosecond.
STOPPERS = {
    "bruteforce": {"max_nodes": 1},
    "bnb": {"max_nodes": 1, "probe_every": 0, "max_iter": 1, "recover_every": 0,
            "fallback": False},
}


@pytest.mark.parametrize("name", [installed(n) for n, cls in sorted(registered().items())
                                  if n in STOPPERS or cls.supports_time_limit])
def test_stopped_run_is_never_optimal(name):
    cls = registered()[name]
    rng = np.random.default_rng(11)
    p = (AssignmentProblem.dense(rng.integers(0, 50, (12, 12)).astype(float))
         if cls.max_ndim == 2 else
         AssignmentProblem.dense(rng.integers(0, 50, (7, 7, 7)).astype(float)))
    ref = solve(p, "highs").objective
    kw = STOPPERS.get(name, {})
    limit = None if kw else 1e-9
    for sol in (solve(p, name, time_limit=limit, **kw),
                _finalised(p, name, _direct(name, p, time_limit=limit, extra=dict(kw)))):
        if name in STOPPERS:        # a node cap of its own: not a time limit
            assert sol.status is Status.NODE_LIMIT, sol.message
        if sol.status is Status.OPTIMAL:    # finished within the limit: then truly
            assert sol.objective == ref     # optimal (a stopped run never says so)
        if sol.selected is not None:
            assert p.violations(sol.selected) is None
        if sol.bound is not None:
            assert sol.bound <= ref + 1e-9


def _finalised(p, name, raw):
    from assocopt.solving.api import _finalise
    return _finalise(p, registered()[name], raw, None)


# ------------------------------------------------------------ capability flags
@pytest.mark.parametrize("name", ALL)
def test_lp_flag_tells_the_truth(name):
    cls = registered()[name]
    p = AssignmentProblem.dense(np.array([[4.0, 1.0], [2.0, 3.0]]))
    if cls.lp:
        for sol in (solve(p, name, relax="lp"), _direct(name, p, relax="lp")):
            assert sol.status is Status.OPTIMAL, sol.message
            assert sol.x is not None and float(p.costs @ sol.x) == pytest.approx(3.0)
    else:
        with pytest.raises(SolverCapabilityError, match="LP"):
            solve(p, name, relax="lp")
        with pytest.raises(SolverCapabilityError, match="LP"):
            _direct(name, p, relax="lp")


@pytest.mark.parametrize("name", ALL)
def test_max_ndim_tells_the_truth(name):
    cls = registered()[name]
    p = AssignmentProblem.dense(np.random.default_rng(2).integers(0, 9, (3, 3, 3, 3))
                                .astype(float))
    if cls.max_ndim is not None and cls.max_ndim < 4:
        with pytest.raises(SolverCapabilityError, match="at most"):
            solve(p, name)
        with pytest.raises(SolverCapabilityError, match="at most"):
            _direct(name, p)
        return
    ref = solve(p, "highs").objective
    _check_raw(p, _direct(name, p), ref, cls.exact)


# ------------------------------------------------------------ options
@pytest.mark.parametrize("name", ALL)
def test_unknown_option_is_rejected_with_one_wording(name):
    from assocopt.solvers import OptionError

    p = AssignmentProblem.dense(np.ones((2, 2)) if registered()[name].max_ndim == 2
                                else np.ones((2, 2, 2)))
    wording = rf"^unknown option 'no_such_option' for solver '{name}'; valid options: "
    with pytest.raises(OptionError, match=wording):
        solve(p, name, no_such_option=1)
    with pytest.raises(OptionError, match=wording):
        _direct(name, p, extra={"no_such_option": 1})
    with pytest.raises(OptionError, match=wording):     # even with nothing to solve
        solve(AssignmentProblem.dense(np.zeros((0, 0))), name, no_such_option=1)


@pytest.mark.parametrize("name", ALL)
def test_declared_options_are_consistent(name):
    cls = registered()[name]
    names = [o.name for o in cls.options]
    assert len(set(names)) == len(names), "an option is declared twice"
    assert not set(names) & {"time_limit", "mip_gap", "threads", "verbose", "relax"}
    for o in cls.options:
        assert o.check(o.default) == o.default, f"{o.name}: default {o.default!r} rejected"
        assert o.doc, f"{o.name} has no description"
    defaults = cls.parse_options({})
    assert defaults == {o.name: o.default for o in cls.options}


@pytest.mark.parametrize("kw, option", [
    ({"time_limit": True}, "time_limit"), ({"time_limit": -float("inf")}, "time_limit"),
    ({"time_limit": float("nan")}, "time_limit"), ({"time_limit": -1.0}, "time_limit"),
    ({"time_limit": 0}, "time_limit"), ({"time_limit": "5"}, "time_limit"),
    ({"mip_gap": 1.0}, "mip_gap"), ({"mip_gap": -0.1}, "mip_gap"),
    ({"mip_gap": float("nan")}, "mip_gap"), ({"mip_gap": True}, "mip_gap"),
    ({"threads": 0}, "threads"), ({"threads": 2.0}, "threads"), ({"threads": True}, "threads"),
    ({"verbose": 1}, "verbose"),
])
def test_common_options_checked_in_one_place(kw, option):
    from assocopt.solvers import OptionError

    value = repr(next(iter(kw.values())))
    p = AssignmentProblem.dense(np.ones((2, 2)))
    for call in (lambda: solve(p, "highs", **kw), lambda: SolveOptions(**kw),
                 lambda: solve(AssignmentProblem.dense(np.zeros((0, 0))), "greedy", **kw)):
        with pytest.raises(OptionError) as info:
            call()
        assert info.value.option == option
        assert str(info.value).startswith(f"{option} must be ") and value in str(info.value)


def test_parsed_options_are_recorded():
    p = AssignmentProblem.dense(np.random.default_rng(0).random((3, 3, 3)))
    sol = solve(p, "bruteforce", max_nodes=10_000)
    assert sol.info["options"] == {"max_nodes": 10_000}
    sol = solve(p, "bnb", max_iter=7)
    assert sol.info["options"]["max_iter"] == 7 and sol.info["options"]["fallback"] is True


def _subclasses(cls):
    for sub in cls.__subclasses__():
        yield sub
        yield from _subclasses(sub)


def test_every_backend_subclass_is_registered():
    import assocopt.solvers  # noqa: F401  (imports every back end module)

    found = {sub for sub in _subclasses(Backend) if sub.__module__.startswith("assocopt.")}
    concrete = {sub for sub in found if not sub.__name__.startswith("_")}
    assert concrete, "no back end classes found"
    for sub in concrete:
        assert sub.name, f"{sub.__name__} has no name"
        assert registered().get(sub.name) is sub, f"{sub.__name__} ({sub.name}) is not registered"
    assert set(registered().values()) == concrete


# ------------------------------------------------------------ honest reports
def test_fallback_names_the_method_that_answered():
    p = AssignmentProblem.dense(np.random.default_rng(3).random((7, 7, 7)))
    sol = solve(p, "bnb", max_nodes=1, probe_every=0, max_iter=1, recover_every=0)
    assert_optimal(p, sol)
    assert sol.solver == "lagrangian-exact"
    assert sol.info["requested"] == "bnb" and sol.info["fallback"] == "node budget spent"
    import assocopt
    assert sol.solver_version == assocopt.__version__


def test_own_methods_report_assocopts_version():
    import assocopt
    for name in ("bnb", "lagrangian", "lagrangian-exact", "bruteforce", "greedy"):
        assert registered()[name].version() == assocopt.__version__, name
