"""Instance file reading/writing (assocopt.io): every format, every malformed input."""

from __future__ import annotations

import csv
import json
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, HealthCheck
from hypothesis import strategies as st

import assocopt
from assocopt import AssignmentProblem, InstanceFormatError, InvalidProblemError
from assocopt.io import (FORMATS, detect_format, read_instance, write_instance,
                         write_solution)

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(__file__).resolve().parents[2] / "shared" / "ap_instances"
EXAMPLES = ROOT / "instances"


# ------------------------------------------------------------------ helpers
def write(path: Path, text: str, newline: str = "\n") -> Path:
    path.write_bytes(text.replace("\n", newline).encode())
    return path


def grundel_text(shape, values) -> str:
    return (f"{len(shape)}\n" + " ".join(map(str, shape)) + " \n"
            + "".join(f"{v}\n" for v in values))


def jdoc(**kw) -> dict:
    doc = {"format": "assocopt-instance", "version": 1}
    doc.update(kw)
    return doc


def write_json(path: Path, doc) -> Path:
    path.write_text(json.dumps(doc))
    return path


def same_problem(p: AssignmentProblem, q: AssignmentProblem) -> None:
    assert p.sizes == q.sizes
    assert p.kind == q.kind
    a = {tuple(t): (c, s) for t, c, s in zip(p.tuples.tolist(), p.costs.tolist(),
                                              p.slack.tolist())}
    b = {tuple(t): (c, s) for t, c, s in zip(q.tuples.tolist(), q.costs.tolist(),
                                              q.slack.tolist())}
    assert a == b
    assert p.n_candidates == q.n_candidates


# ------------------------------------------------------------------ Grundel
def test_grundel_last_index_fastest_and_sol_optimum(tmp_path):
    values = list(range(1, 28))
    f = write(tmp_path / "ap3.3.1.txt", grundel_text((3, 3, 3), values))
    write(tmp_path / "ap3.3.1.sol", "\nOPT: 42\n1 1 1\n2 2 2\n3 3 3\n")
    p = read_instance(f)
    assert p.kind == "dense" and p.sizes == (3, 3, 3)
    assert p.costs.dtype == np.float64
    np.testing.assert_array_equal(p.to_cost_matrix(), np.arange(1, 28).reshape(3, 3, 3))
    assert p.name == "ap3.3.1"
    assert p.optimum == 42.0
    assert p.meta["format"] == "grundel"
    assert detect_format(f) == "grundel"


def test_grundel_without_sol_has_no_optimum_and_2d(tmp_path):
    f = write(tmp_path / "tiny.txt", grundel_text((2, 2), [4, 1, 2, 3]), "\r\n")
    p = read_instance(f)
    assert p.sizes == (2, 2) and p.optimum is None
    assert assocopt.solve(p, "highs").objective == 3.0


def test_grundel_ap3_opt_table_fallback(tmp_path):
    f = write(tmp_path / "ap3.2.7.txt", grundel_text((2, 2, 2), range(8)))
    write(tmp_path / "ap3.opt", "ap3.2.6  1\nap3.2.7  7\n")
    p = read_instance(f)
    assert p.optimum == 7.0 and p.meta["optimum_source"] == "ap3.opt"
    g = write(tmp_path / "ap3.2.8.txt", grundel_text((2, 2, 2), range(8)))
    assert read_instance(g).optimum is None          # not listed


def test_grundel_truncated(tmp_path):
    f = write(tmp_path / "ap3.10.1.txt", grundel_text((10, 10, 10), [1] * 998))
    with pytest.raises(InstanceFormatError, match=r"ap3\.10\.1\.txt.*expected 1000 costs, found 998"):
        read_instance(f)


def test_grundel_non_numeric_token_names_line(tmp_path):
    vals = [str(v) for v in range(8)]
    vals[5] = "x7"
    f = write(tmp_path / "g.txt", grundel_text((2, 2, 2), vals))
    with pytest.raises(InstanceFormatError, match=r"g\.txt: non-numeric token 'x7' on line 8"):
        read_instance(f)


def test_grundel_nan_token_rejected(tmp_path):
    vals = ["1"] * 8
    vals[0] = "nan"
    f = write(tmp_path / "g.txt", grundel_text((2, 2, 2), vals))
    with pytest.raises(InstanceFormatError, match="non-numeric token 'nan'"):
        read_instance(f, format="grundel")


def test_grundel_bad_header_when_forced(tmp_path):
    f = write(tmp_path / "g.txt", "3 3\n1 2 3\n")
    with pytest.raises(InstanceFormatError, match="line 1 must hold only d"):
        read_instance(f, format="grundel")
    f = write(tmp_path / "h.txt", "40\n1 2\n")
    with pytest.raises(InstanceFormatError, match="d = 40"):
        read_instance(f, format="grundel")


# ------------------------------------------------------------------ Balas-Saltzman
def bs_driver_text(blocks) -> str:
    out = ["AP3 Test Driver", "Wed Nov 11 09:59:09 1992", "", "",
           "n = 2 to 3 by 1; p = 2", "cost range = 0 to 100 spread by 1", "", ""]
    for n, p, vals in blocks:
        out.append(f"N = {n}   PROBLEM = {p}")
        out.append("=" * 45)
        out.extend(str(v) for v in vals)
    return "\n".join(out) + "\n"


@pytest.fixture
def bs_file(tmp_path):
    blocks = [(2, 1, range(8)), (2, 2, range(10, 18)), (3, 1, range(100, 127))]
    return write(tmp_path / "BalasAndSaltzman.txt", bs_driver_text(blocks))


@pytest.mark.parametrize("instance", ["N2_P2", "n2p2", "2,2", (2, 2), 2, "2"])
def test_bs_driver_select(bs_file, instance):
    p = read_instance(bs_file, instance=instance)
    np.testing.assert_array_equal(p.to_cost_matrix(), np.arange(10, 18).reshape(2, 2, 2))
    assert p.name == "BalasAndSaltzman:N2_P2"
    assert p.meta["instance"] == "N2_P2"
    assert detect_format(bs_file) == "balas-saltzman"


def test_bs_driver_last_block(bs_file):
    p = read_instance(bs_file, instance=3)
    assert p.sizes == (3, 3, 3)
    assert p.to_cost_matrix()[2, 2, 2] == 126.0


def test_bs_driver_needs_instance(bs_file):
    with pytest.raises(InstanceFormatError,
                       match=r"BalasAndSaltzman\.txt: no instance chosen: the file holds 3 instances"):
        read_instance(bs_file)


@pytest.mark.parametrize("instance, msg", [
    (4, "position 4 out of range"), (0, "position 0 out of range"),
    ("N5_P1", "no instance N5_P1"), ((9, 9), "no instance N9_P9"),
    ("what", "not understood"), (True, "must not be a bool"),
])
def test_bs_driver_bad_instance(bs_file, instance, msg):
    with pytest.raises(InstanceFormatError, match=msg):
        read_instance(bs_file, instance=instance)


def test_bs_driver_truncated_block(tmp_path):
    f = write(tmp_path / "bs.txt", bs_driver_text([(2, 1, range(8)), (2, 2, range(7))]))
    assert read_instance(f, instance=1).sizes == (2, 2, 2)
    with pytest.raises(InstanceFormatError, match=r"bs\.txt: instance N2_P2: expected 8 costs, found 7"):
        read_instance(f, instance="N2_P2")


def test_bs_driver_crlf(tmp_path):
    f = write(tmp_path / "bs.txt", bs_driver_text([(2, 1, range(8))]), "\r\n")
    assert read_instance(f, instance=1).sizes == (2, 2, 2)


def test_bs_split_crlf_and_name(tmp_path):
    f = write(tmp_path / "balas-n2-instance03.txt", "".join(f"{v}\n" for v in range(8)), "\r\n")
    p = read_instance(f)
    assert p.meta["format"] == "balas-saltzman-split"
    assert p.meta["instance"] == "N2_P3"
    assert p.name == "balas-n2-instance03"
    np.testing.assert_array_equal(p.to_cost_matrix(), np.arange(8).reshape(2, 2, 2))


def test_bs_split_with_header(tmp_path):
    f = write(tmp_path / "one.txt", "3 2\n" + "".join(f"{v}\n" for v in range(8)), "\r\n")
    assert detect_format(f) == "balas-saltzman-split"
    np.testing.assert_array_equal(read_instance(f).to_cost_matrix(),
                                  np.arange(8).reshape(2, 2, 2))


#: Text files read_instance refuses: (file name, text, format, the error's words).
REJECTED = [
    pytest.param("one.txt", "3 3\n" + "".join(f"{v}\n" for v in range(26)), "auto",
                 "expected 27 costs, found 26", id="bs_split_header_count_mismatch"),
    pytest.param("balas-n10-instance01.txt", "5\n" * 998, "auto",
                 r"balas-n10-instance01\.txt: .*expected 1000 costs, found 998",
                 id="bs_split_truncated_uses_name"),
    pytest.param("x.txt", "5\n" * 10, "balas-saltzman-split",
                 "found 10, which is not a cube", id="bs_split_not_a_cube_when_forced"),
    pytest.param("balas-n3-instance01.txt", "5\n" * 8, "auto", "file name says n = 3",
                 id="bs_split_name_disagrees"),
    pytest.param("assign3.txt", "3\n 7 5 9\n 2 8 4\n 6 3\n", "auto",
                 r"assign3\.txt: .*expected 9 costs, found 8", id="orlib_truncated"),
    pytest.param("a.txt", "2\n1 2 3 4 5\n", "orlib", "expected 4 costs, found 5",
                 id="orlib_extra_numbers"),
    pytest.param("notes.txt", "hello world\n", "auto",
                 r"notes\.txt: unknown format: non-numeric token 'hello'", id="unknown_text"),
    pytest.param("nums.txt", "1 2 3\n4 5 6 7\n", "auto",
                 r"nums\.txt: unknown format \(2 non-blank lines, 7 numbers",
                 id="unknown_numeric_layout"),
    # one number per line, 2 numbers: an OR-Library header or a Balas-Saltzman
    # split file, and the count fits neither
    pytest.param("two.txt", "5\n7\n", "auto",
                 r"two\.txt: cannot tell the format: the layout fits "
                 r".*balas-saltzman-split.*orlib", id="ambiguous_layout"),
]


@pytest.mark.parametrize("name, text, fmt, words", REJECTED)
def test_rejected_text(tmp_path, name, text, fmt, words):
    with pytest.raises(InstanceFormatError, match=words):
        read_instance(write(tmp_path / name, text), format=fmt)


# ------------------------------------------------------------------ OR-Library
def test_orlib_and_assignopt(tmp_path):
    f = write(tmp_path / "assign3.txt", "3\n 7 5 9\n 2 8 4\n 6 3 1\n", "\r\n")
    write(tmp_path / "assignopt.txt", "Data file    Optimal solution value\nassign3   8\n")
    assert detect_format(f) == "orlib"
    p = read_instance(f)
    assert p.sizes == (3, 3) and p.name == "assign3" and p.optimum == 8.0
    assert p.meta["optimum_source"] == "assignopt.txt"
    assert p.to_cost_matrix()[0, 2] == 9.0
    assert assocopt.solve(p, "highs").objective == 8.0


def test_orlib_wrapped_rows(tmp_path):
    f = write(tmp_path / "lap.txt", "2\n1 2 3\n4\n")
    assert read_instance(f).to_cost_matrix().tolist() == [[1, 2], [3, 4]]


# ------------------------------------------------------------------ detection / generic
def test_empty_file(tmp_path):
    for name, text in (("e.txt", ""), ("w.json", "  \n\n")):
        with pytest.raises(InstanceFormatError, match=rf"{re.escape(name)}: the file is empty"):
            read_instance(write(tmp_path / name, text))


def test_binary_file(tmp_path):
    f = tmp_path / "b.bin"
    f.write_bytes(b"\x00\x01\x02garbage")
    with pytest.raises(InstanceFormatError, match="not a text file"):
        read_instance(f)
    g = tmp_path / "c.bin"
    g.write_bytes(b"3\n\xff\xfe\n")
    with pytest.raises(InstanceFormatError, match="not a UTF-8 text file"):
        read_instance(g)


def test_bad_format_argument_and_instance_for_single(tmp_path):
    f = write(tmp_path / "assign3.txt", "1\n5\n")
    with pytest.raises(InstanceFormatError, match="unknown format 'csv'"):
        read_instance(f, format="csv")
    with pytest.raises(InstanceFormatError, match="holds one instance per file"):
        read_instance(f, instance=1)
    assert set(FORMATS) >= {"auto", "assocopt", "grundel", "balas-saltzman",
                            "balas-saltzman-split", "orlib"}


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_instance(tmp_path / "nope.json")
    with pytest.raises(InstanceFormatError, match="is a directory"):
        read_instance(tmp_path)


# ------------------------------------------------------------------ JSON: reading
def test_json_dense_2d_and_3d(tmp_path):
    f = write_json(tmp_path / "d.json", jdoc(kind="dense", costs=[[4, 1], [2, 3]],
                                             name="two", optimum=3,
                                             optimum_source="by hand", description="tiny"))
    p = read_instance(f)
    assert p.kind == "dense" and p.name == "two" and p.optimum == 3.0
    assert p.meta["optimum_source"] == "by hand" and p.meta["description"] == "tiny"
    same_problem(p, AssignmentProblem.dense([[4, 1], [2, 3]]))
    g = write_json(tmp_path / "e.json", jdoc(kind="dense", costs=np.ones((2, 2, 2)).tolist()))
    q = read_instance(g)
    assert q.sizes == (2, 2, 2) and q.name == "e" and q.optimum is None


def test_json_inf_spellings(tmp_path):
    C = [[1.0, "inf"], [float("inf"), 2.0]]
    f = tmp_path / "i.json"
    f.write_text(json.dumps(jdoc(kind="dense", costs=C)))   # writes Infinity
    assert "Infinity" in f.read_text()
    p = read_instance(f)
    assert p.n_candidates == 2
    np.testing.assert_array_equal(p.to_cost_matrix(), [[1, np.inf], [np.inf, 2]])


def test_json_rectangular_dense_recreates_slack(tmp_path):
    C = [[1, 2, 3], [4, 5, 6]]
    p = read_instance(write_json(tmp_path / "r.json", jdoc(kind="dense", costs=C)))
    same_problem(p, AssignmentProblem.dense(C))
    assert p.slack.sum() == 3


def test_json_two_d_miss_costs(tmp_path):
    C = [[1, "inf"], [2, 3], [4, 5]]
    p = read_instance(write_json(tmp_path / "m.json",
                                 jdoc(kind="dense", costs=C, row_miss=[1, 2, "inf"],
                                      col_miss=0.5)))
    assert p.kind == "two_d"
    same_problem(p, AssignmentProblem.two_d([[1, np.inf], [2, 3], [4, 5]],
                                            [1, 2, np.inf], 0.5))
    q = read_instance(write_json(tmp_path / "n.json", jdoc(kind="dense", costs=[[1, 2]],
                                                           col_miss=[0, 0])))
    same_problem(q, AssignmentProblem.two_d([[1, 2]], None, [0, 0]))


def test_json_sparse(tmp_path):
    doc = jdoc(kind="sparse", sizes=[2, 1, 1], tuples=[[1, 1, 0], [2, 0, 1], [1, 0, 0], [0, 1, 1]],
               costs=[-1, -2, 0, "inf"], **{"x-origin": {"sensor": "radar"}})
    p = read_instance(write_json(tmp_path / "s.json", doc))
    assert p.kind == "sparse" and p.n_candidates == 3     # the "inf" candidate is dropped
    assert p.meta["x-origin"] == {"sensor": "radar"}
    assert assocopt.solve(p, "highs").objective == -3.0


def test_json_sparse_empty(tmp_path):
    p = read_instance(write_json(tmp_path / "z.json", jdoc(kind="sparse", sizes=[0, 0],
                                                           tuples=[], costs=[])))
    assert p.n_candidates == 0


@pytest.mark.parametrize("doc, msg", [
    ({"version": 1, "kind": "dense", "costs": [[1]]}, r"no \"format\" key"),
    (jdoc(format="other-thing", kind="dense", costs=[[1]]), r"\"format\": \"other-thing\""),
    ({"format": "assocopt-instance", "kind": "dense", "costs": [[1]]}, "missing key \"version\""),
    (jdoc(version=2, kind="dense", costs=[[1]]), r"version 2 is newer than this assocopt reads \(1\)"),
    (jdoc(version="1", kind="dense", costs=[[1]]), "\"version\" must be an integer"),
    (jdoc(version=0, kind="dense", costs=[[1]]), "unsupported version 0"),
    (jdoc(costs=[[1]]), "missing key \"kind\""),
    (jdoc(kind="triangular", costs=[[1]]), "unknown kind \"triangular\""),
    (jdoc(kind="dense"), "missing key \"costs\""),
    (jdoc(kind="sparse", sizes=[1, 1], costs=[1]), "missing key \"tuples\""),
    (jdoc(kind="dense", costs=[[1, 2], [3]]), r"ragged costs: costs\[1\] has 1 entries, expected 2"),
    (jdoc(kind="dense", costs=[[1, 2], 3]), r"ragged costs: costs\[1\] is a single value"),
    (jdoc(kind="dense", costs=[[1, [2]], [3, 4]]), r"ragged costs: costs\[0\]\[1\] is a list"),
    (jdoc(kind="dense", costs=[1, 2]), "at least 2 levels"),
    (jdoc(kind="dense", costs=[[1, "abc"]]), r"costs\[0\]\[1\] must be a number or \"inf\", found the string 'abc'"),
    (jdoc(kind="dense", costs=[[1, True]]), r"costs\[0\]\[1\] must be a number"),
    (jdoc(kind="dense", costs=[[1, None]]), r"costs\[0\]\[1\] must be a number"),
    (jdoc(kind="dense", costs=[[1, 2]], sizes=[1, 2]), "unknown key \"sizes\" \\(used by kind \"sparse\""),
    (jdoc(kind="dense", costs=[[1]], comment="hi"), "unknown key \"comment\"; user extensions must start with \"x-\""),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 1]], costs=[1], row_miss=[1]), "unknown key \"row_miss\""),
    (jdoc(kind="dense", costs=[[[1]]], row_miss=[1]), "need a 2-D cost matrix"),
    (jdoc(kind="dense", costs=[[1]], name=5), "\"name\" must be a string"),
    (jdoc(kind="dense", costs=[[1]], optimum="5"), "\"optimum\" must be a finite number"),
    (jdoc(kind="dense", costs=[[1]], description=[1]), "\"description\" must be a string"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 1]], costs=[1, 2]), "\"costs\" has 2 entries but \"tuples\" has 1"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 1, 1]], costs=[1]), r"tuples\[0\] has 3 indices"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 1.5]], costs=[1]), r"tuples\[0\]\[1\] must be an integer"),
    (jdoc(kind="sparse", sizes="2", tuples=[[1, 1]], costs=[1]), "sizes must be a list"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples={"a": 1}, costs=[1]), "\"tuples\" must be a list"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 1]], costs=5), "\"costs\" must be a list"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 1]], costs=["-inf"]), r"costs\[0\] must be a number"),
    ([1, 2, 3], "expected a JSON object at the top level"),
])
def test_json_invalid(tmp_path, doc, msg):
    f = write_json(tmp_path / "bad.json", doc)
    with pytest.raises(InstanceFormatError, match=r"bad\.json: .*" + msg):
        read_instance(f)


@pytest.mark.parametrize("text, msg", [
    ('{"format": "assocopt-instance", "version": 1, "kind": "dense", "costs": [[1, NaN]]}',
     r"costs\[0\]\[1\] is NaN"),
    ('{"format": "assocopt-instance", "version": 1, "kind": "dense", "costs": [[1, -Infinity]]}',
     r"costs\[0\]\[1\] is -inf"),
    ('{"format": "assocopt-instance", "version": 1, "kind": "sparse", "sizes": [1, 1], '
     '"tuples": [[1, 1]], "costs": [NaN]}', r"costs\[0\] is NaN"),
    ('{"format": "assocopt-instance", "version": 1, "kind": "dense", "costs": [[1]], '
     '"optimum": NaN}', "\"optimum\" must be a finite number"),
    ('{"format": "assocopt-instance", "version": 1, "kind": "dense", "costs": [[1]], "kind": "dense"}',
     "duplicate key 'kind'"),
    ('{"format": "assocopt-instance", "version": 1, "kind": "dense", "costs": [[1, 2]',
     "invalid JSON: .* at line 1"),
    ('{"format": "assocopt-instance", "version": 1, "kind": "dense',
     "invalid JSON: Unterminated string starting at line 1 column 55$"),
])
def test_json_invalid_text(tmp_path, text, msg):
    f = write(tmp_path / "bad.json", text)
    with pytest.raises(InstanceFormatError, match=r"bad\.json: .*" + msg):
        read_instance(f)


@pytest.mark.parametrize("doc, msg", [
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 2]], costs=[1]), "index out of range"),
    (jdoc(kind="sparse", sizes=[2, 3, 4], tuples=[[1, 1, 1], [2, 0, 5]], costs=[1, 2]),
     r"tuple 1 = \[2, 0, 5\] has an index out of range: 5 on axis 2, which takes "
     r"0 \(dummy\) \.\. 4"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[1, 1], [1, 1]], costs=[1, 2]), "duplicate candidate"),
    (jdoc(kind="sparse", sizes=[1, 1], tuples=[[0, 0]], costs=[1]), "all-dummy"),
    (jdoc(kind="sparse", sizes=[-1, 1], tuples=[], costs=[]), "non-negative"),
    (jdoc(kind="dense", costs=[[1, 2]], row_miss=[1, 2, 3]), "row_miss must be a scalar or have shape"),
])
def test_json_invalid_problem_is_wrapped(tmp_path, doc, msg):
    f = write_json(tmp_path / "prob.json", doc)
    with pytest.raises(InstanceFormatError, match=r"prob\.json: invalid problem: .*" + msg) as info:
        read_instance(f)
    assert isinstance(info.value.__cause__, InvalidProblemError)


def test_json_detected_with_leading_whitespace(tmp_path):
    f = write(tmp_path / "ws.dat", "\n\n  " + json.dumps(jdoc(kind="dense", costs=[[1]])))
    assert detect_format(f) == "assocopt"
    assert read_instance(f).sizes == (1, 1)


# ------------------------------------------------------------------ JSON: writing
def test_round_trip_dense(tmp_path):
    C = np.array([[[1.5, np.inf], [0.1, 2]], [[-3, 1e-300], [1 / 3, 7e15]]])
    p = AssignmentProblem.dense(C, name="cube")
    write_instance(p, tmp_path / "c.json")
    q = read_instance(tmp_path / "c.json")
    same_problem(p, q)
    assert q.name == "cube"


def test_round_trip_rectangular_dense(tmp_path):
    C = np.array([[1.0, 2.0, np.inf], [4.0, 0.25, 6.0]])
    p = AssignmentProblem.dense(C)
    write_instance(p, tmp_path / "r.json")
    text = (tmp_path / "r.json").read_text()
    assert '"inf"' in text and "Infinity" not in text
    q = read_instance(tmp_path / "r.json")
    same_problem(p, q)
    assert q.slack.sum() == 3          # one zero-cost slack per column of the larger axis


@pytest.mark.parametrize("rm, cm", [([1.0, np.inf], 0.5), (None, [0.0, 1.0, 2.0]),
                                    ([3.0, 4.0], None), (np.inf, np.inf)])
def test_round_trip_two_d(tmp_path, rm, cm):
    p = AssignmentProblem.two_d([[1.0, np.inf, 2.0], [0.5, 3.0, -1.0]], rm, cm)
    write_instance(p, tmp_path / "t.json")
    same_problem(p, read_instance(tmp_path / "t.json"))


def test_round_trip_sparse_and_metadata(tmp_path):
    p = AssignmentProblem.sparse([2, 3, 2], [[1, 1, 1], [2, 0, 2], [0, 3, 0], [1, 2, 0],
                                             [2, 3, 1], [0, 1, 2]],
                                 [0.1, -2.0, 0.0, 1 / 7, 5e-324, -1e300], name="sd")
    f = tmp_path / "s.json"
    write_instance(p, f, optimum=-2.5, optimum_source="hand", description="d")
    q = read_instance(f)
    same_problem(p, q)
    assert np.array_equal(p.tuples, q.tuples)
    assert (q.name, q.optimum, q.meta["optimum_source"], q.meta["description"]) == \
        ("sd", -2.5, "hand", "d")
    # the problem's own recorded optimum is written back by default
    write_instance(q, tmp_path / "again.json")
    r = read_instance(tmp_path / "again.json")
    assert r.optimum == -2.5 and r.meta["optimum_source"] == "hand"


finite = st.floats(min_value=-1e9, max_value=1e9, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(shape=st.lists(st.integers(1, 3), min_size=2, max_size=3), data=st.data())
def test_round_trip_dense_property(tmp_path, shape, data):
    n = int(np.prod(shape))
    vals = data.draw(st.lists(st.one_of(finite, st.just(math.inf)), min_size=n, max_size=n))
    p = AssignmentProblem.dense(np.array(vals).reshape(shape))
    write_instance(p, tmp_path / "h.json")
    same_problem(p, read_instance(tmp_path / "h.json"))


def test_write_is_atomic_and_overwrites(tmp_path):
    f = tmp_path / "x.json"
    f.write_text("old")
    write_instance(AssignmentProblem.dense([[1.0]]), f)
    assert read_instance(f).sizes == (1, 1)
    assert sorted(os.listdir(tmp_path)) == ["x.json"]       # no temp file left behind
    # a failure before the rename leaves the old file untouched
    with pytest.raises(InvalidProblemError, match="optimum must be finite"):
        write_instance(AssignmentProblem.dense([[2.0]]), f, optimum=float("nan"))
    assert read_instance(f).to_cost_matrix()[0, 0] == 1.0
    with pytest.raises(OSError):
        write_instance(AssignmentProblem.dense([[1.0]]), tmp_path / "no" / "dir.json")
    assert sorted(os.listdir(tmp_path)) == ["x.json"]


def test_write_rejects_non_problem(tmp_path):
    with pytest.raises(InvalidProblemError, match="AssignmentProblem"):
        write_instance([[1, 2]], tmp_path / "y.json")


def test_write_solution(tmp_path):
    p = AssignmentProblem.sparse([2, 2], [[1, 1], [2, 2], [1, 2], [2, 1]], [1, 1, 5, 5])
    sol = assocopt.solve(p, "highs")
    f = tmp_path / "sol.json"
    write_solution(sol, f)
    d = json.loads(f.read_text())
    assert d["status"] == "optimal" and d["objective"] == 2.0
    assert sorted(d["tuples"]) == [[1, 1], [2, 2]]
    write_solution(sol, f, extra={"instance": "x"})
    assert json.loads(f.read_text())["instance"] == "x"
    assert sorted(os.listdir(tmp_path)) == ["sol.json"]


# ------------------------------------------------------------------ shipped files
@pytest.mark.parametrize("name", ["example-2d-miss", "example-3d", "example-sd"])
def test_shipped_examples(name):
    p = read_instance(EXAMPLES / f"{name}.json")
    assert p.name == name
    assert p.optimum is not None
    assert p.meta["optimum_source"] == "proved by HiGHS MILP (gap 0) and exhaustive enumeration"
    sol = assocopt.solve(p, "highs")
    assert sol.status.value == "optimal"
    assert sol.objective == pytest.approx(p.optimum, abs=1e-9)


def test_examples_kinds():
    assert read_instance(EXAMPLES / "example-2d-miss.json").kind == "two_d"
    assert read_instance(EXAMPLES / "example-3d.json").sizes == (3, 3, 3)
    sd = read_instance(EXAMPLES / "example-sd.json")
    assert sd.kind == "sparse" and sd.ndim == 3 and (sd.tuples == 0).any()


def test_doc_examples_parse(tmp_path):
    text = (ROOT / "docs" / "instance-format.md").read_text()
    blocks = re.findall(r"```json\n(.*?)```", text, re.S)
    assert len(blocks) >= 3
    for k, block in enumerate(blocks):
        p = read_instance(write(tmp_path / f"doc{k}.json", block))
        sol = assocopt.solve(p, "highs")
        assert sol.status.value == "optimal"
        if p.optimum is not None:
            assert sol.objective == pytest.approx(p.optimum)


# ------------------------------------------------------------------ public benchmark files
def _known_values() -> dict[tuple[str, str], float]:
    with open(SHARED / "known_values.csv", newline="") as f:
        return {(r["file"], r["instance"]): float(r["value"]) for r in csv.DictReader(f)}


@pytest.fixture(scope="module")
def shared():
    if not (SHARED / "known_values.csv").is_file():
        pytest.skip(f"public benchmark instances not present at {SHARED}")
    return SHARED


def test_shared_grundel(shared):
    f = shared / "grundel_ap3" / "ap3.10.1.txt"
    p = read_instance(f)
    sol_line = next(ln for ln in (shared / "grundel_ap3" / "ap3.10.1.sol").read_text().splitlines()
                    if ln.strip())
    recorded = float(sol_line.split(":")[1])
    assert p.optimum == recorded == _known_values()[("grundel_ap3/ap3.10.1.txt", "ap3.10.1")]
    assert p.sizes == (10, 10, 10)
    assert assocopt.solve(p, "highs").objective == recorded


def test_shared_balas_saltzman_split(shared):
    f = shared / "balas_saltzman" / "split" / "balas-n6-instance03.txt"
    p = read_instance(f)
    assert p.meta["format"] == "balas-saltzman-split" and p.sizes == (6, 6, 6)
    expected = _known_values()[("balas_saltzman/split/balas-n6-instance03.txt", "N6_P3")]
    assert assocopt.solve(p, "highs").objective == expected


def test_shared_balas_saltzman_split_header_equals_block(shared):
    # the one split file with a "3 20" header holds the same numbers as its block
    split = read_instance(shared / "balas_saltzman" / "split" / "balas-n20-instance05.txt")
    block = read_instance(shared / "balas_saltzman" / "BalasAndSaltzman.txt", instance="N20_P5")
    assert split.sizes == (20, 20, 20)
    np.testing.assert_array_equal(split.to_cost_matrix(), block.to_cost_matrix())


def test_shared_balas_saltzman_block(shared):
    f = shared / "balas_saltzman" / "BalasAndSaltzman.txt"
    with pytest.raises(InstanceFormatError, match="holds 60 instances"):
        read_instance(f)
    p = read_instance(f, instance=(10, 2))
    assert p.name == "BalasAndSaltzman:N10_P2"
    expected = _known_values()[("balas_saltzman/BalasAndSaltzman.txt", "N10_P2")]
    assert assocopt.solve(p, "highs").objective == expected


def test_shared_orlib(shared):
    p = read_instance(shared / "orlib_lap" / "assign100.txt")
    assert p.sizes == (100, 100)
    assert p.optimum == 305.0       # from the sibling assignopt.txt
    assert _known_values()[("orlib_lap/assign100.txt", "assign100")] == 305.0
    assert assocopt.solve(p, "highs").objective == 305.0


# ------------------------------------------------------------------ detection of damaged files
def test_truncated_grundel_detected_without_name_hint(tmp_path):
    f = write(tmp_path / "data.txt", grundel_text((4, 4, 4), [1] * 60))
    with pytest.raises(InstanceFormatError, match=r"data\.txt: Grundel 4x4x4 instance: expected 64 costs, found 60"):
        read_instance(f)


def test_truncated_orlib_row_looking_like_grundel_header(tmp_path):
    # "3" then a row "7 5 9" also reads as a Grundel header d=3, sizes 7 5 9
    text = "3\n7 5 9\n2 8 4\n6 3\n"
    with pytest.raises(InstanceFormatError, match=r"assign3\.txt: OR-Library 3x3 instance: expected 9 costs, found 8"):
        read_instance(write(tmp_path / "assign3.txt", text))
    with pytest.raises(InstanceFormatError,
                       match=r"data\.txt: cannot tell the format: the layout fits grundel .*orlib"):
        read_instance(write(tmp_path / "data.txt", text))
    # complete, it is OR-Library whatever its name
    assert read_instance(write(tmp_path / "full.txt", text + "1\n")).sizes == (3, 3)


def test_split_layout_free_when_nothing_else_fits(tmp_path):
    f = write(tmp_path / "cube.txt", "1 2 3 4\n5 6 7 8\n")
    assert detect_format(f) == "balas-saltzman-split"
    assert read_instance(f).sizes == (2, 2, 2)
