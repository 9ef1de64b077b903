"""The readers' bulk (numpy) routes against their strict per-entry walks.

Every reader converts a well-formed file in bulk and falls back to the strict walk
otherwise, so that the walk's messages stay the only ones.  These tests read the
same text both ways -- the bulk route as shipped, and the strict route alone (the
bulk converters patched to decline, the parse hooks always on) -- and require the
same problem or the same error text.
"""

from __future__ import annotations

import json
import math
import re
from contextlib import contextmanager
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, strategies as st

from assocopt import AssignmentProblem
from assocopt.runtime.errors import InstanceFormatError
from assocopt.io import json_format, json_scan, read_instance, write_instance
from assocopt.io.common import TextFile, _floats, _lines
from assocopt.io.json_scan import scan_json
from assocopt.io.json_bulk import bulk_costs

PATH = Path("x.json")


@contextmanager
def strict_only():
    """The reader as it was before the bulk routes: strict parse, per-entry walks."""
    def strict_scan(text):
        return json_scan.JsonScan(scan_json(text).depth, True, True, True)
    with mock.patch.object(json_format, "scan_json", strict_scan), \
            mock.patch.object(json_format, "bulk_costs", lambda *a: None), \
            mock.patch.object(json_format, "bulk_indices", lambda *a: None):
        yield


def outcome(text: str):
    """What reading ``text`` gives: ('ok', sizes, tuples, costs) or ('error', message)."""
    try:
        p = json_format._read_json(PATH, text)
    except InstanceFormatError as exc:
        return ("error", str(exc))
    return ("ok", p.sizes, p.tuples.tolist(), p.costs.tolist(), p.slack.tolist())


def both_ways(text: str):
    fast = outcome(text)
    with strict_only():
        strict = outcome(text)
    assert fast == strict
    return fast


#: Raw JSON tokens for one entry: good ones, and every kind of bad one.
RAW = ["1", "-2", "2.5", "-0.0", "1E+2", "1e-400", "1e301", "-1e305", "Infinity", '"inf"',
       '" +Infinity "', '"INF"', "true", "false", "null", '"x"', '"-inf"', "NaN", "-Infinity",
       "1e999", "-1e999", "1" + "0" * 400, "-1" + "0" * 301, "1" + "0" * 400 + ".0",
       "1" + "0" * 250 + "e99", "[1]", "[]", "{}", '{"inf": 1}', "9223372036854775808",
       str(2 ** 70), "123456789012345678901"]


def dense_text(costs_text: str, extra: str = "") -> str:
    return ('{"format": "assocopt-instance", "version": 1, "kind": "dense"' + extra
            + ', "costs": ' + costs_text + "}")


@st.composite
def nested_with_bad_entry(draw):
    """JSON text of nested cost lists with one raw token (maybe bad) at a random place,
    maybe made ragged."""
    shape = draw(st.lists(st.integers(1, 4), min_size=2, max_size=3))
    values = np.array(draw(st.lists(st.floats(-1e6, 1e6, allow_nan=False),
                                    min_size=math.prod(shape), max_size=math.prod(shape))))
    ints = draw(st.booleans())
    nested = values.reshape(shape).round().astype(int).tolist() if ints \
        else values.reshape(shape).tolist()
    pos = [draw(st.integers(0, n - 1)) for n in shape]
    node = nested
    for i in pos[:-1]:
        node = node[i]
    node[pos[-1]] = "@@RAW@@"
    how = draw(st.sampled_from(["entry", "entry", "drop", "scalar"]))
    if how == "drop" and len(node) > 1:
        node.pop(0 if pos[-1] else -1)
    elif how == "scalar" and len(shape) > 2:
        nested[pos[0]][pos[1]] = 7
    return json.dumps(nested).replace('"@@RAW@@"', draw(st.sampled_from(RAW)))


@given(nested_with_bad_entry(), st.booleans())
def test_dense_costs_bulk_equals_strict(costs_text, extension):
    # an "x-" extension holding true makes the literals scan answer True
    extra = ', "x-flag": true' if extension else ""
    both_ways(dense_text(costs_text, extra))


@given(nested_with_bad_entry())
def test_two_d_miss_costs_bulk_equals_strict(miss_text):
    text = ('{"format": "assocopt-instance", "version": 1, "kind": "dense", '
            '"costs": [[1, 2], [3, 4]], "row_miss": ' + miss_text + ', "col_miss": [1, 1]}')
    both_ways(text)


@st.composite
def sparse_text(draw):
    N = draw(st.integers(2, 3))
    sizes = [draw(st.integers(1, 3)) for _ in range(N)]
    tuples = draw(st.lists(st.tuples(*[st.integers(0, n) for n in sizes]), min_size=1,
                           max_size=8, unique=True))
    tuples = [list(t) for t in tuples if any(t)] or [[1] * N]
    costs = draw(st.lists(st.floats(-100, 100, allow_nan=False), min_size=len(tuples),
                          max_size=len(tuples)))
    where = draw(st.sampled_from(["none", "tuples", "costs"]))
    k = draw(st.integers(0, len(tuples) - 1))
    if where == "tuples":
        tuples[k][draw(st.integers(0, N - 1))] = "@@RAW@@"
        raw = draw(st.sampled_from(["2.0", "1.5", "true", "null", '"1"', "[1]", "1e300",
                                    "NaN", "Infinity", str(2 ** 64), "-1"]))
    elif where == "costs":
        costs[k] = "@@RAW@@"
        raw = draw(st.sampled_from(RAW))
    else:
        raw = "0"
    if draw(st.integers(0, 4)) == 0:
        tuples[k].append(1)                        # one tuple too long
    doc = {"format": "assocopt-instance", "version": 1, "kind": "sparse", "sizes": sizes,
           "tuples": tuples, "costs": costs}
    return json.dumps(doc).replace('"@@RAW@@"', raw)


@given(sparse_text())
def test_sparse_bulk_equals_strict(text):
    both_ways(text)


@given(st.integers(2, 3).flatmap(lambda N: st.lists(st.integers(1, 5), min_size=N,
                                                    max_size=N)),
       st.integers(0, 2 ** 32), st.booleans(), st.booleans())
def test_dense_round_trip(tmp_path_factory, sizes, seed, ints, forbid):
    rng = np.random.default_rng(seed)
    C = rng.normal(0, 1e3, size=sizes)
    C = C.round() if ints else C
    if forbid:
        C[rng.random(sizes) < 0.2] = np.inf
        C.reshape(-1)[0] = 1.0                     # keep one candidate
    p = AssignmentProblem.dense(C)
    path = tmp_path_factory.mktemp("rt") / "p.json"
    write_instance(p, path)
    q = read_instance(path)
    assert q.sizes == p.sizes
    np.testing.assert_array_equal(q.tuples, p.tuples)
    np.testing.assert_array_equal(q.costs, p.costs)
    np.testing.assert_array_equal(q.slack, p.slack)
    assert both_ways(path.read_text())[0] == "ok"


@given(st.integers(0, 2 ** 32))
def test_sparse_round_trip(tmp_path_factory, seed):
    from assocopt.workflow.generate import generate_sparse
    p = generate_sparse(np.random.default_rng(seed), (3, 2, 3), decimals=None)
    path = tmp_path_factory.mktemp("rt") / "s.json"
    write_instance(p, path)
    q = read_instance(path)
    np.testing.assert_array_equal(q.tuples, p.tuples)
    np.testing.assert_array_equal(q.costs, p.costs)
    assert both_ways(path.read_text())[0] == "ok"


# ------------------------------------------------------------ pinned cases
@pytest.mark.parametrize("costs, msg", [
    ("[[1.5, 2.5], [3.5, true]]", r"costs\[1\]\[1\] must be a number or \"inf\", found true"),
    ("[[1.5, false], [3.5, 4.5]]", r"costs\[0\]\[1\] must be a number or \"inf\", found false"),
    ("[[1.5, 2.5], [null, 4.5]]", r"costs\[1\]\[0\] must be a number or \"inf\", found null"),
    ("[[1.5, 2.5], [3.5, " + "1" * 400 + "]]",
     r"costs\[1\]\[1\] is an integer of 400 digits, outside the accepted range"),
    ("[[1.5, 2.5], [3.5, " + str(10 ** 301) + "]]", r"costs\[1\]\[1\] is an integer of 302"),
    ("[[1.5, 2.5], [3.5, 1e999]]", r"invalid JSON: the number 1e999 is outside the float range"),
    ("[[1.5, 2.5], [3.5, 1" + "0" * 310 + ".5]]", r"invalid JSON: the number 1000"),
    ("[[1.5, 2.5], [3.5, \"1.5\"]]", r"costs\[1\]\[1\] must be a number or \"inf\", found the string '1.5'"),
    ("[[1.5, 2.5], [3.5, NaN]]", r"costs\[1\]\[1\] is NaN"),
    ("[[1.5, -Infinity], [3.5, 4.5]]", r"costs\[0\]\[1\] is -inf"),
    ("[[1.5, 2.5], [3.5]]", r"ragged costs: costs\[1\] has 1 entries, expected 2"),
    ("[[[1.5, 2.5]], [{\"inf\": 1, \"+inf\": 2}]]",
     r"ragged costs: costs\[1\]\[0\] is a single value"),
])
def test_bad_entries_among_floats_keep_their_message(costs, msg):
    for extra in ("", ', "x-note": false'):
        kind, message = both_ways(dense_text(costs, extra))
        assert kind == "error"
        assert re.search(msg, message), message


GOOD = st.one_of(st.integers(-10 ** 6, 10 ** 6), st.integers(-2 ** 63, 2 ** 65),
                 st.floats(-1e6, 1e6, allow_nan=False), st.floats(-1e300, 1e300),
                 st.sampled_from([math.inf, "inf", " +Infinity", "INF"]))


@given(st.lists(st.integers(1, 3), min_size=1, max_size=3).flatmap(
    lambda shape: st.tuples(st.just(shape), st.lists(GOOD, min_size=math.prod(shape),
                                                     max_size=math.prod(shape)))))
def test_bulk_tiers_agree_with_the_walk(case):
    """Every route of bulk_costs gives the walk's array on well-formed entries
    (``strings`` is only a hint: a wrong False costs time, never a wrong answer)."""
    shape, flat = case
    nested = np.array(flat, dtype=object).reshape(shape).tolist()
    want = json_format._walk_costs(nested, shape, "costs", PATH)
    for literals in (False, True):
        for strings in (False, True):
            np.testing.assert_array_equal(bulk_costs(nested, shape, literals, strings), want)


def test_numpy_would_turn_a_bool_into_one():
    """The trap the bulk route must avoid: numpy converts True silently."""
    assert np.array([1.0, True]).dtype == np.float64
    assert bulk_costs([[1.0, True]], (1, 2), literals=True) is None


def test_inf_strings_and_infinity_are_forbidden_entries():
    kind, *rest = both_ways(dense_text('[[1.5, "inf"], [" Infinity ", 2], [Infinity, 3]]'))
    assert kind == "ok"
    sizes, tuples, costs, slack = rest
    assert sizes == (3, 2)
    assert [c for c, s in zip(costs, slack) if not s] == [1.5, 2.0, 3.0]


def test_depth_cap_is_kept(tmp_path):
    f = tmp_path / "deep.json"
    f.write_text(dense_text("[" * 150 + "1" + "]" * 150))
    with pytest.raises(InstanceFormatError, match="nested 151 levels deep, more than the 100"):
        read_instance(f)


@pytest.mark.parametrize("text, depth, literals, big", [
    ('{"a": "[[[[ true 1e999"}', 1, False, False),
    ("[1e99, 2.5E-12, -3]", 1, False, False),
    ("[1e100]", 1, False, True),
    ("[1E+0100]", 1, False, True),
    ("[" + "9" * 199 + "]", 1, False, False),
    ("[" + "9" * 200 + "]", 1, False, True),
    ('[[{"x": [null]}]]', 4, True, False),
])
def test_json_scan(text, depth, literals, big):
    scan = scan_json(text)
    assert (scan.depth, scan.literals, scan.big_numbers) == (depth, literals, big)


@given(st.text(st.sampled_from("0123456789eE+-.[]{} ,\"tn"), max_size=60))
def test_scan_proves_what_it_claims(text):
    """``big_numbers=False`` proves no literal overflows: every maximal number-like run
    outside strings then parses to a finite float; ``literals=False`` proves none of
    true/false/null is present outside strings."""
    scan = scan_json(text)
    bare = json_scan._JSON_STRING.sub('""', text)
    if not scan.big_numbers:
        for lit in re.findall(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?", bare):
            assert math.isfinite(float(lit))
    if not scan.literals:
        assert not any(w in bare for w in ("true", "false", "null"))


@given(st.text(st.sampled_from('"[]{}ab\\ 1e'), max_size=40))
def test_string_blanking_equals_the_regex(text):
    """The split at quotes (no backslash, every string closed) blanks exactly what
    the escape-aware regex blanks."""
    bare, _ = json_scan._blank_strings(text)
    assert bare == json_scan._JSON_STRING.sub('""', text).encode()


# ------------------------------------------------------------ text formats
TOKEN = st.text(st.sampled_from("0123456789+-.eE_x \u0661"), min_size=1, max_size=8).map(
    str.strip).filter(bool)


@given(st.lists(TOKEN, max_size=20))
def test_floats_accept_what_numpy_accepted(tokens):
    """float() over the tokens accepts exactly what numpy's str -> float64 cast
    (the former route) accepts, with the same values."""
    try:
        old = np.array(tokens, dtype=np.str_).astype(np.float64)
        old = old if np.isfinite(old).all() else None
    except ValueError:
        old = None
    new = _floats(tokens)
    if old is None:
        assert new is None
    else:
        np.testing.assert_array_equal(new, old)


LINE_TEXT = st.lists(st.sampled_from(["1", "23", " ", "\t", "\n", "\r", "\r\n", "\x0b",
                                      "\x0c", "\x1c", "\x85", "\u2028", "\u3000", "x"]),
                     max_size=40).map("".join)


@given(LINE_TEXT)
def test_layout_equals_the_per_line_split(text):
    lines = _lines(text)
    n, head, one = TextFile(text).layout
    assert n == len(lines)
    assert head == lines[:2]
    assert one == all(len(ln) == 1 for ln in lines[1:])


@given(st.lists(st.integers(1, 4), min_size=2, max_size=3), st.integers(0, 2 ** 32),
       st.floats(0, 1))
def test_dense_grid_equals_nonzero(sizes, seed, p_inf):
    """The broadcast candidate grid of an all-finite array (and the np.nonzero route
    otherwise) against an independent loop over every index tuple."""
    rng = np.random.default_rng(seed)
    C = rng.random(sizes)
    C[rng.random(sizes) < p_inf] = np.inf
    prob = AssignmentProblem.dense(C)
    real = ~prob.slack
    want = [(tuple(i + 1 for i in idx), C[idx]) for idx in np.ndindex(*sizes)
            if np.isfinite(C[idx])]
    got = [(tuple(t), c) for t, c in zip(prob.tuples[real].tolist(), prob.costs[real])]
    assert got == want


@pytest.mark.parametrize("block", [0, 1, 2])
def test_bs_driver_bad_token_names_its_line(tmp_path, block):
    """The tokens before a Balas-Saltzman block are counted only for the message; the
    line it names is the bad token's line in the file."""
    lines = ["AP3 Test Driver", "", "n = 2 to 3 by 1; p = 2", ""]
    for k, (n, p) in enumerate([(2, 1), (2, 2), (3, 1)]):
        lines += [f"N = {n}   PROBLEM = {p}", "=" * 45]
        vals = [str(10 * k + v) for v in range(n ** 3)]
        if k == block:
            vals[5] = "x5"
        lines += [" ".join(vals[:4])] + vals[4:]
    f = tmp_path / "BalasAndSaltzman.txt"
    f.write_text("\n".join(lines) + "\n")
    line = next(i for i, ln in enumerate(lines, 1) if ln == "x5")
    with pytest.raises(InstanceFormatError, match=f"non-numeric token 'x5' on line {line}$"):
        read_instance(f, instance=block + 1)
