"""The ``rigidkit convert`` command line, checked against scipy.spatial.transform.

Most tests call ``main(argv)`` in-process (fast); a few run ``python -m rigidkit``
and the installed console script in a subprocess. Every number the CLI prints or
writes is compared with scipy's conversion of the same input (an independent
implementation); Euler angles are compared as orientations (rebuilt by scipy) and,
away from gimbal lock, as angles.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation as SciRot

from rigidkit.applications.cli import ALL, main

# Unit-free numbers (quaternions, matrices, MRPs, axes): a few ulp of float64
# from two independent float64 implementations of the same conversion.
ATOL = 5e-15
# Angles: the same relative accuracy, scaled by the angle unit.
ATOL_RAD = 2e-14
ATOL_DEG = ATOL_RAD * 180 / np.pi

FIXED = ["quat", "quat:xyzw", "matrix", "rotvec", "axis-angle", "mrp"]
EULER = ["euler:ZYX", "euler:XYZ", "euler:ZXZ", "euler:yzy", "euler:xyz", "euler:zxy"]
SIZES = {"quat": 4, "quat:xyzw": 4, "matrix": 9, "axis-angle": 4}


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def wxyz(q_xyzw):
    """scipy's scalar-last quaternions, scalar first (``scalar_first=`` needs 1.14)."""
    return np.roll(q_xyzw, 1, axis=-1)


def values_of(name: str, S: SciRot, degrees: bool) -> np.ndarray:
    """scipy's numbers for representation ``name``, shape (N, k) (or (k,))."""
    if name == "quat":
        return wxyz(S.as_quat())
    if name == "quat:xyzw":
        return S.as_quat()
    if name == "matrix":
        m = S.as_matrix()
        return m.reshape(m.shape[:-2] + (9,))
    if name == "rotvec":
        return S.as_rotvec(degrees=degrees)
    if name == "axis-angle":
        rv = S.as_rotvec()
        angle = np.linalg.norm(rv, axis=-1, keepdims=True)
        axis = rv / angle
        return np.concatenate([axis, np.degrees(angle) if degrees else angle], axis=-1)
    if name == "mrp":
        return S.as_mrp()
    return S.as_euler(name.split(":")[1], degrees=degrees)


def check_against_scipy(name: str, got, S: SciRot, degrees: bool) -> None:
    """``got`` (shape (N, k) or (k,)) is representation ``name`` of ``S``."""
    got = np.asarray(got, dtype=np.float64)
    angle_atol = ATOL_DEG if degrees else ATOL_RAD
    if name in ("quat", "quat:xyzw"):
        w = got[..., 0] if name == "quat" else got[..., 3]
        assert np.all(w >= 0), "quaternions are written canonical, w >= 0"
        ref = S.as_quat()
        ref = wxyz(ref) if name == "quat" else ref
        # q and -q are one rotation; which one is "canonical" at w = +-1e-17 is noise.
        sign = np.where(np.sum(got * ref, axis=-1, keepdims=True) < 0, -1.0, 1.0)
        np.testing.assert_allclose(got, sign * ref, rtol=0, atol=ATOL)
    elif name == "matrix":
        np.testing.assert_allclose(got, values_of("matrix", S, degrees), rtol=0, atol=ATOL)
    elif name == "rotvec":
        ref = S.as_rotvec(degrees=degrees)
        np.testing.assert_allclose(got, ref, rtol=0, atol=angle_atol * 4)
    elif name == "axis-angle":
        axis, angle = got[..., :3], got[..., 3]
        np.testing.assert_allclose(np.linalg.norm(axis, axis=-1), 1.0, rtol=0, atol=ATOL)
        assert np.all(angle >= 0)
        rv = S.as_rotvec(degrees=degrees)
        np.testing.assert_allclose(axis * angle[..., None], rv, rtol=0, atol=angle_atol * 4)
    elif name == "mrp":
        np.testing.assert_allclose(got, S.as_mrp(), rtol=0, atol=ATOL)
    else:
        seq = name.split(":")[1]
        rebuilt = SciRot.from_euler(seq, got, degrees=degrees)
        # Orientations, not parameters: the angle between rebuilt and reference.
        assert np.all((rebuilt * S.inv()).magnitude() < 1e-14)
        np.testing.assert_allclose(
            got, S.as_euler(seq, degrees=degrees), rtol=0, atol=angle_atol * 4
        )


def random_rotations(n: int, seed: int) -> SciRot:
    """Haar-random rotations, kept away from gimbal lock of every sequence tested
    (scipy itself is only ~1e-7 accurate there) and from angle pi (where the sign
    of a rotation vector is a convention)."""
    S = SciRot.from_quat(np.random.default_rng(seed).standard_normal((4 * n, 4)))
    keep = S.magnitude() < np.pi - 1e-3
    for name in EULER:
        seq = name.split(":")[1]
        mid = S.as_euler(seq)[:, 1]
        lock = 0.0 if seq[0].lower() == seq[2].lower() else np.pi / 2
        keep &= np.minimum(abs(abs(mid) - lock), abs(mid - np.pi)) > 1e-3
    return S[np.flatnonzero(keep)[:n]]


def number_args(values) -> list:
    return [repr(float(x)) for x in np.ravel(values)]


# -- one rotation on the command line --------------------------------------------------


@pytest.mark.parametrize("degrees", [False, True])
@pytest.mark.parametrize("source", FIXED + EULER)
def test_single_every_source_to_every_target(source, degrees, capsys):
    S = random_rotations(3, seed=len(source) + 10 * degrees)
    for k in range(3):
        argv = ["convert", source, *number_args(values_of(source, S[k], degrees))]
        argv += ["--to", *FIXED, *EULER, "--format", "json"]
        argv += ["--degrees"] if degrees else []
        code, out, err = run(argv, capsys)
        assert (code, err) == (0, "")
        doc = json.loads(out)
        assert doc.pop("degrees") is degrees
        assert list(doc) == FIXED + EULER
        for name, got in doc.items():
            check_against_scipy(name, np.ravel(got), S[k], degrees)


def parse_table(text: str) -> dict:
    """``{name: numbers}`` from the aligned table (matrix rows continue a name)."""
    table, name = {}, None
    for line in text.splitlines():
        if not line.startswith(" "):
            name = line.split()[0]
            table[name] = []
        k = 3 if name == "matrix" else SIZES.get(name, 3)  # numbers on this line
        table[name] += [float(x) for x in line.split()[-k:]]
    return table


def test_the_example_of_the_issue(capsys):
    argv = ["convert", "euler:ZYX", "30", "20", "10", "--degrees"]
    code, out, err = run(argv + ["--to", "quat", "matrix", "rotvec"], capsys)
    assert (code, err) == (0, "")
    S = SciRot.from_euler("ZYX", [30, 20, 10], degrees=True)
    table = parse_table(out)
    assert list(table) == ["quat", "matrix", "rotvec"]
    assert out.splitlines()[0].split()[:5] == ["quat", "w", "x", "y", "z"]
    rows = [line.split()[-5:-3] for line in out.splitlines()[1:4]]
    assert rows == [["row", "1"], ["row", "2"], ["row", "3"]]
    for name, got in table.items():
        check_against_scipy(name, got, S, degrees=True)


def test_to_all_table_is_aligned_and_round_trips(capsys):
    argv = ["convert", "euler:ZYX", "30", "20", "10", "--degrees", "--to", "all"]
    code, out, err = run(argv, capsys)
    assert (code, err) == (0, "")
    table = parse_table(out)
    assert list(table) == list(ALL)
    S = SciRot.from_euler("ZYX", [30, 20, 10], degrees=True)
    for name, got in table.items():
        assert len(got) == SIZES.get(name, 3)
        check_against_scipy(name, got, S, degrees=True)
    # All digits by default: the table holds exactly the numbers of the JSON output.
    code, js, _ = run(argv + ["--format", "json"], capsys)
    doc = json.loads(js)
    for name, got in table.items():
        assert got == list(np.ravel(doc[name]))
    # Decimal points line up in every column of numbers.
    lines = out.splitlines()
    first_point = {line.index(".", 40) for line in lines}
    assert len(first_point) == 1
    # The default target is all.
    assert run(argv[:-2], capsys)[1] == out


def test_decimals_rounds_the_table(capsys):
    argv = ["convert", "rotvec", "0", "0", "90", "--degrees", "--to", "quat", "matrix"]
    code, out, err = run(argv + ["--decimals", "4"], capsys)
    assert code == 0
    assert out.splitlines()[0].split()[-4:] == ["0.7071", "0.0000", "0.0000", "0.7071"]
    # cos(90 deg) in float64 is 6e-17, and no "-0.0000" appears.
    assert out.splitlines()[1].split()[-3:] == ["0.0000", "-1.0000", "0.0000"]
    assert "-0.0000" not in out


def test_negative_numbers_need_no_quoting(capsys):
    # "-30" and "-.5" match argparse's negative-number pattern; "-1e-3" does not.
    argv = ["convert", "euler:ZYX", "-30", "-.5", "-1e-3", "--degrees", "--to", "quat"]
    code, out, err = run(argv + ["--format", "json"], capsys)
    assert (code, err) == (0, "")
    S = SciRot.from_euler("ZYX", [-30, -0.5, -1e-3], degrees=True)
    check_against_scipy("quat", json.loads(out)["quat"], S, degrees=True)
    # Options may come first; "--" works too.
    code, out2, _ = run(["convert", "--degrees", "--to", "quat", "--format", "json",
                         "--", "euler:ZYX", "-30", "-.5", "-1e-3"], capsys)  # fmt: skip
    assert (code, out2) == (0, out)
    # -inf is read as a number, and rejected as one.
    code, _, err = run(["convert", "rotvec", "1", "-inf", "2"], capsys)
    assert code == 2 and "'-inf' is not finite" in err


@settings(max_examples=60, deadline=None)
@given(
    angles=st.lists(
        st.floats(-720, 720, allow_subnormal=True) | st.floats(-1e-3, 1e-3),
        min_size=3,
        max_size=3,
    )
)
def test_any_number_on_the_command_line_is_read_exactly(angles):
    # repr gives "-1e-05", "-0.0", "5e-324", ...: every spelling must reach the library.
    capture = io.StringIO()
    argv = ["convert", "euler:zyx", *number_args(angles), "--to", "quat", "--degrees"]
    with contextlib.redirect_stdout(capture):
        assert main(argv + ["--format", "json"]) == 0
    got = json.loads(capture.getvalue())["quat"]
    check_against_scipy("quat", got, SciRot.from_euler("zyx", angles, degrees=True), True)


def test_gimbal_lock_warns_on_one_line_and_angles_rebuild(capsys):
    argv = ["convert", "euler:ZYX", "30", "90", "10", "--degrees", "--format", "json"]
    code, out, err = run(argv + ["--to", "euler:ZYX"], capsys)
    assert code == 0
    assert err.startswith("rigidkit: warning: ") and err.count("\n") == 1
    assert "gimbal" in err.lower()
    S = SciRot.from_euler("ZYX", [30, 90, 10], degrees=True)
    rebuilt = SciRot.from_euler("ZYX", json.loads(out)["euler:ZYX"], degrees=True)
    assert (rebuilt * S.inv()).magnitude() < 1e-14


def test_gimbal_lock_in_a_batch_names_the_first_row(tmp_path, capsys):
    angles = np.array([[10.0, 20, 30], [30, 90, 10], [5, -90, 3], [1, 2, 3]])
    np.save(tmp_path / "in.npy", angles)
    argv = ["convert", "--from", "euler:ZYX", "-i", tmp_path / "in.npy", "--degrees"]
    code, _, err = run(argv + ["-o", tmp_path / "out.npy", "--to", "euler:ZYX"], capsys)
    assert code == 0 and err.count("\n") == 1
    assert err.startswith("rigidkit: warning: ") and "row 2 (index 1)" in err
    S = SciRot.from_euler("ZYX", angles, degrees=True)
    rebuilt = SciRot.from_euler("ZYX", np.load(tmp_path / "out.npy"), degrees=True)
    assert np.all((rebuilt * S.inv()).magnitude() < 1e-14)


@pytest.mark.parametrize(
    "argv, words",
    [
        (["quaternion", "1", "0", "0", "0"], ["unknown representation 'quaternion'"]),
        (["quat", "1", "0", "0", "0", "--to", "quats"], ["'quats'", "did you mean 'quat'"]),
        (["euler:XXY", "1", "2", "3"], ["'euler:XXY'", "repeats an axis"]),
        (
            ["rotvec", "1", "2", "3", "--to", "euler:xYz"],
            ["'euler:xYz'", "upper and lower"],
        ),
        (["rotvec", "1", "2"], ["rotvec takes 3 numbers", "got 2"]),
        (["rotvec", "1", "2", "x"], ["value 3 of rotvec is 'x'"]),
        (["rotvec", "1", "nan", "3"], ["'nan' is not finite"]),
        (["quat", "0", "0", "0", "0"], ["zero norm"]),
        (["axis-angle", "0", "0", "0", "1"], ["zero vector"]),
        (["matrix", "1", "0", "0", "0", "1", "0", "0", "0", "-1"], ["not a rotation"]),
        (["matrix", "2", "0", "0", "0", "2", "0", "0", "0", "2"], ["--orthonormalize"]),
        (["--to", "quat", "rotvec", "1", "2", "3"], ["before --to"]),
        ([], ["give a rotation"]),
        (["rotvec", "1", "2", "3", "-o", "x.npy"], ["--output needs --input"]),
    ],
)
def test_user_errors_are_one_line_and_exit_2(argv, words, capsys):
    code, out, err = run(["convert", *argv], capsys)
    assert code == 2 and out == ""
    assert err.startswith("rigidkit: error: ") and err.count("\n") == 1
    for word in words:
        assert word in err


def test_orthonormalize_accepts_a_matrix_typed_with_few_digits(capsys):
    m = SciRot.from_euler("ZYX", [30, 20, 10], degrees=True).as_matrix()
    typed = np.round(m, 4)
    code, _, err = run(["convert", "matrix", *number_args(typed), "--to", "quat"], capsys)
    assert code == 2 and "not a rotation" in err
    argv = ["convert", "matrix", *number_args(typed), "--orthonormalize", "--to", "quat"]
    code, out, _ = run(argv + ["--format", "json"], capsys)
    assert code == 0
    u, _, vt = np.linalg.svd(typed)  # the nearest rotation (det(u vt) = +1 here)
    check_against_scipy("quat", json.loads(out)["quat"], SciRot.from_matrix(u @ vt), False)


def test_help_lists_the_representations_and_an_example(capsys):
    code, out, _ = run(["--help"], capsys)
    assert code == 0 and "convert" in out and "rigidkit convert euler:ZYX" in out
    code, out, _ = run(["convert", "--help"], capsys)
    assert code == 0
    for word in [*FIXED, "euler:SEQ", "intrinsic", "extrinsic", "--degrees", "examples"]:
        assert word in out
    code, _, err = run([], capsys)
    assert code == 2 and "usage" in err
    code, _, err = run(["frobnicate"], capsys)
    assert code == 2 and "invalid choice" in err


# -- batches ---------------------------------------------------------------------------


N = 1200  # above the engine's small-batch limit: the numba path is exercised


@pytest.mark.parametrize("source", FIXED + ["euler:ZYX", "euler:zxz"])
def test_batch_npy_against_scipy(source, tmp_path, capsys):
    degrees = source.startswith("euler") or source == "rotvec"
    S = random_rotations(N, seed=5)
    values = values_of(source, S, degrees)
    if source == "matrix":
        values = values.reshape(-1, 3, 3)  # (N, 3, 3) is accepted as well as (N, 9)
    np.save(tmp_path / "in.npy", values)
    targets = ["quat", "matrix", "axis-angle", "euler:ZYX", "mrp", "rotvec"]
    argv = ["convert", "--from", source, "-i", tmp_path / "in.npy"]
    argv += ["-o", tmp_path / "out.npy", "--to", *targets]
    code, out, err = run(argv + (["--degrees"] if degrees else []), capsys)
    assert (code, out, err) == (0, "", "")
    table = np.load(tmp_path / "out.npy")
    assert table.dtype == np.float64 and table.shape == (len(S), 4 + 9 + 4 + 3 + 3 + 3)
    start = 0
    for name in targets:  # columns side by side, in --to order
        k = SIZES.get(name, 3)
        check_against_scipy(name, table[:, start : start + k], S, degrees)
        start += k
    assert sorted(os.listdir(tmp_path)) == ["in.npy", "out.npy"]


def test_batch_csv_round_trip(tmp_path, capsys):
    S = random_rotations(N, seed=6)
    angles = S.as_euler("ZYX", degrees=True)
    lines = ["yaw,pitch,roll", "# a comment line", ""]
    lines += [",".join(number_args(row)) for row in angles]
    (tmp_path / "in.csv").write_text("\n".join(lines) + "\n")
    argv = ["convert", "--from", "euler:ZYX", "-i", tmp_path / "in.csv", "--degrees"]
    code, _, err = run(argv + ["-o", tmp_path / "q.csv", "--to", "quat", "rotvec"], capsys)
    assert (code, err) == (0, "")
    text = (tmp_path / "q.csv").read_text()
    header, *rows = text.splitlines()
    assert header == "quat.w,quat.x,quat.y,quat.z,rotvec.x,rotvec.y,rotvec.z"
    table = np.array([[float(x) for x in row.split(",")] for row in rows])
    assert table.shape == (N, 7)
    check_against_scipy("quat", table[:, :4], S, True)
    check_against_scipy("rotvec", table[:, 4:], S, True)
    # Quaternions alone; then back through CSV -> .npy -> CSV, and the printed digits
    # read back exactly (repr round trip).
    assert run(argv + ["-o", tmp_path / "q4.csv", "--to", "quat"], capsys)[0] == 0
    q4 = (tmp_path / "q4.csv").read_text()
    assert q4.splitlines() == [",".join(r.split(",")[:4]) for r in [header, *rows]]
    argv = [
        "convert",
        "--from",
        "quat",
        "-i",
        tmp_path / "q4.csv",
        "-o",
        tmp_path / "a.npy",
    ]
    assert run(argv + ["--to", "euler:ZYX", "--degrees"], capsys)[0] == 0
    back = np.load(tmp_path / "a.npy")
    check_against_scipy("euler:ZYX", back, S, True)
    # The same conversion written as CSV and as .npy holds the same float64 numbers.
    argv = ["convert", "--from", "euler:ZYX", "-i", tmp_path / "a.npy", "--degrees"]
    argv += ["--to", "all"]
    assert run(argv + ["-o", tmp_path / "b.npy"], capsys)[0] == 0
    assert run(argv + ["-o", tmp_path / "b.csv"], capsys)[0] == 0
    as_csv = np.loadtxt(tmp_path / "b.csv", delimiter=",", skiprows=1)
    columns = (tmp_path / "b.csv").read_text().split("\n", 1)[0].split(",")
    assert columns[:4] == ["quat.w", "quat.x", "quat.y", "quat.z"]
    assert columns[4:8] == ["quat:xyzw.x", "quat:xyzw.y", "quat:xyzw.z", "quat:xyzw.w"]
    assert columns[8:11] == ["matrix.m11", "matrix.m12", "matrix.m13"]
    assert columns[14:17] == ["matrix.m31", "matrix.m32", "matrix.m33"]
    assert columns[17:24] == [
        "rotvec.x",
        "rotvec.y",
        "rotvec.z",
        "axis-angle.x",
        "axis-angle.y",
        "axis-angle.z",
        "axis-angle.angle",
    ]
    assert columns[27:31] == [
        "euler:ZYX.angle1",
        "euler:ZYX.angle2",
        "euler:ZYX.angle3",
        "euler:XYZ.angle1",
    ]
    assert len(columns) == 4 + 4 + 9 + 3 + 4 + 3 + 5 * 3
    np.testing.assert_array_equal(as_csv, np.load(tmp_path / "b.npy"))


def test_batch_csv_stdin_to_stdout(monkeypatch, capsys):
    monkeypatch.setattr(sys, "stdin", io.StringIO("0,0,0\n0,0,180\n"))
    argv = ["convert", "--from", "rotvec", "-i", "-", "--to", "quat", "--degrees"]
    code, out, err = run(argv, capsys)
    assert (code, err) == (0, "")
    assert out.splitlines()[0] == "quat.w,quat.x,quat.y,quat.z"
    got = np.array([[float(x) for x in line.split(",")] for line in out.splitlines()[1:]])
    S = SciRot.from_rotvec([[0, 0, 0], [0, 0, 180]], degrees=True)
    np.testing.assert_allclose(got, wxyz(S.as_quat(canonical=True)), atol=ATOL)


def test_batch_empty_input(tmp_path, capsys):
    (tmp_path / "in.csv").write_text("w,x,y,z\n")
    argv = ["convert", "--from", "quat", "-i", tmp_path / "in.csv", "--to", "rotvec"]
    assert run(argv + ["-o", tmp_path / "out.npy"], capsys)[0] == 0
    assert np.load(tmp_path / "out.npy").shape == (0, 3)
    assert run(argv + ["-o", "-"], capsys)[1] == "rotvec.x,rotvec.y,rotvec.z\n"


def test_batch_output_replaces_an_existing_file_with_a_normal_mode(tmp_path, capsys):
    np.save(tmp_path / "in.npy", np.eye(4)[:3])
    out = tmp_path / "out.npy"
    argv = [
        "convert",
        "--from",
        "quat",
        "-i",
        tmp_path / "in.npy",
        "-o",
        out,
        "--to",
        "quat",
    ]
    assert run(argv, capsys)[0] == 0
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's 0600
    out.chmod(0o640)
    out.write_bytes(b"old")
    assert run(argv, capsys)[0] == 0
    assert np.load(out).shape == (3, 4) and out.stat().st_mode & 0o777 == 0o640


# Malformed inputs: (input file name, content or array, --from, where, what).
# Rows are counted from 1 over data rows only (no header, comments or blank lines).
_CSV_HEAD = "w,x,y,z\n1,0,0,0\n\n# comment\n0,1,0,0\n"  # data rows 1, 2 on lines 2, 5
MALFORMED = [
    ("in.csv", _CSV_HEAD + "0,0,1\n", "quat", "line 6 (data row 3)", "needs 4 fields"),
    ("in.csv", _CSV_HEAD + "0,0,1,0,\n", "quat", "line 6 (data row 3)", "got 5"),
    ("in.csv", _CSV_HEAD + "0,0,one,0\n", "quat", "line 6 (data row 3)", "'one'"),
    ("in.csv", _CSV_HEAD + "0,0,nan,0\n", "quat", "line 6 (data row 3)", "finite"),
    ("in.csv", _CSV_HEAD + "0,0,1,-inf\n", "quat", "line 6 (data row 3)", "finite"),
    (
        "in.csv",
        _CSV_HEAD + "0,0,0,0\n1,1,1,1\n",
        "quat",
        "line 6 (data row 3)",
        "zero norm",
    ),
    ("in.csv", "1,0,0\n2,0,0\n", "quat", "line 1 (data row 1)", "needs 4 fields"),
    ("in.csv", "0,0,1,0\n0,0,0,0\n", "axis-angle", "line 2 (data row 2)", "zero vector"),
    ("in.npy", "reflection", "matrix", "row 4 (index 3)", "not a rotation"),
    ("in.npy", "scaled", "matrix", "row 4 (index 3)", "scales"),
    ("in.npy", "zero-quat", "quat", "row 4 (index 3)", "zero norm"),
    ("in.npy", "nan", "euler:ZYX", "row 4 (index 3)", "field 2 is nan"),
    ("in.npy", "shape", "quat", "in.npy", "shape (N, 4)"),
]


def _write_malformed(path: Path, content, source):
    if path.suffix == ".csv":
        path.write_text(content)
        return
    k = 9 if source == "matrix" else (3 if source.startswith("euler") else 4)
    a = np.zeros((5, k))
    if source == "matrix":
        a[:] = np.eye(3).ravel()
        a[3] = {"reflection": np.diag([1.0, 1.0, -1.0]), "scaled": 2 * np.eye(3)}[
            content
        ].ravel()
    elif source == "quat":
        a[:, 0] = 1.0
        a[3, 0] = 0.0
    else:
        a[3, 1] = np.nan
    np.save(path, a[:, :3] if content == "shape" else a)


@pytest.mark.parametrize("out_name", ["out.npy", "out.csv"])
@pytest.mark.parametrize("name, content, source, where, what", MALFORMED)
def test_malformed_row_exit_2_and_no_output(
    name, content, source, where, what, out_name, tmp_path, capsys
):
    _write_malformed(tmp_path / name, content, source)
    argv = ["convert", "--from", source, "-i", tmp_path / name, "--to", "quat", "rotvec"]
    # No output file is created ...
    code, out, err = run(argv + ["-o", tmp_path / out_name], capsys)
    assert code == 2 and out == ""
    assert err.startswith("rigidkit: error: ") and err.count("\n") == 1
    assert where in err and what in err
    assert sorted(os.listdir(tmp_path)) == [name]
    # ... and an existing one is left untouched.
    (tmp_path / out_name).write_bytes(b"precious")
    code, _, err2 = run(argv + ["-o", tmp_path / out_name], capsys)
    assert (code, err2) == (2, err)
    assert (tmp_path / out_name).read_bytes() == b"precious"
    assert sorted(os.listdir(tmp_path)) == sorted([name, out_name])


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--to", "quat", "-o", "{d}/out.dat"], ["format of output", ".npy, .csv or .txt"]),
        (["--to", "quat", "-o", "{d}/missing/out.npy"], ["cannot write", "No such file"]),
        (["-o", "{d}/out.npy"], ["needs --to"]),
        (["--to", "quaternion", "-o", "{d}/out.npy"], ["unknown representation"]),
        (["--to", "quat", "-o", "-", "rotvec"], ["give no rotation"]),
        (["--to", "quat", "-o", "-", "--format", "json"], ["--format", "one rotation"]),
    ],
)
def test_batch_argument_errors(extra, words, tmp_path, capsys):
    np.save(tmp_path / "in.npy", np.eye(4))
    argv = ["convert", "--from", "quat", "-i", tmp_path / "in.npy"]
    code, out, err = run(argv + [e.format(d=tmp_path) for e in extra], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    for word in words:
        assert word in err
    assert sorted(os.listdir(tmp_path)) == ["in.npy"]
    code, _, err = run(["convert", "-i", tmp_path / "in.npy", "--to", "quat"], capsys)
    assert code == 2 and "--from" in err
    code, _, err = run(["convert", "--from", "quat", "-i", tmp_path / "nope.npy",
                        "--to", "quat"], capsys)  # fmt: skip
    assert code == 2 and "cannot read" in err


@pytest.mark.parametrize("out_name", ["out.npy", "out.csv"])
@pytest.mark.parametrize(
    "failure", [OSError(28, "No space left on device"), KeyboardInterrupt]
)
def test_a_failed_write_leaves_no_file_behind(
    out_name, failure, tmp_path, capsys, monkeypatch
):
    from rigidkit.applications.cli import command

    np.save(tmp_path / "in.npy", np.eye(4))
    (tmp_path / out_name).write_bytes(b"precious")

    def write_half_then_fail(stream, *args, **kwargs):
        stream.write(b"partial" if "b" in stream.mode else "partial")
        raise failure

    monkeypatch.setattr(command, "write_csv", write_half_then_fail)
    monkeypatch.setattr(np, "save", write_half_then_fail)
    argv = [
        "convert",
        "--from",
        "quat",
        "-i",
        tmp_path / "in.npy",
        "-o",
        tmp_path / out_name,
    ]
    code, _, err = run(argv + ["--to", "rotvec"], capsys)
    if isinstance(failure, OSError):
        assert code == 2 and "No space left on device" in err and err.count("\n") == 1
    else:
        assert code == 130
    assert (tmp_path / out_name).read_bytes() == b"precious"
    assert sorted(os.listdir(tmp_path)) == sorted(["in.npy", out_name])


def _picky_from_mrp(monkeypatch, error):
    """Make ``Rotation.from_mrp`` raise ``error(p)`` when it returns an error."""
    from rigidkit import Rotation

    real = Rotation.from_mrp

    def picky(p):
        exc = error(np.asarray(p))
        if exc is not None:
            raise exc
        return real(p)

    monkeypatch.setattr(Rotation, "from_mrp", staticmethod(picky))


def test_an_error_naming_no_batch_index_is_located_by_bisection(
    tmp_path, capsys, monkeypatch
):
    from rigidkit.errors import RigidkitError

    # Rejects any batch holding the (made-up) bad value 0.5, with no index.
    _picky_from_mrp(
        monkeypatch,
        lambda p: RigidkitError("this MRP is not welcome") if np.any(p == 0.5) else None,
    )
    a = np.zeros((2000, 3))
    a[1234, 2] = a[1500, 0] = 0.5
    np.save(tmp_path / "in.npy", a)
    argv = ["convert", "--from", "mrp", "-i", tmp_path / "in.npy", "--to", "quat"]
    code, _, err = run(argv, capsys)
    assert code == 2
    where = f"{tmp_path / 'in.npy'} row 1235 (index 1234)"
    assert err == f"rigidkit: error: {where}: this MRP is not welcome\n"


@pytest.mark.parametrize("suffix", [".npy", ".csv"])
@pytest.mark.parametrize("message", ["MRP is bad", "MRP at batch index (1234,) is bad"])
def test_the_row_named_comes_from_err_index(suffix, message, tmp_path, capsys, monkeypatch):
    from rigidkit.errors import RigidkitError

    # Every prefix of the batch fails, so bisection would blame the first row: only
    # err.index gives row 1235. The library's own "at batch index" gives way to it.
    _picky_from_mrp(monkeypatch, lambda p: RigidkitError(message, index=(1234,)))
    a = np.zeros((2000, 3))
    path = tmp_path / f"in{suffix}"
    if suffix == ".npy":
        np.save(path, a)
        where = f"{path} row 1235 (index 1234)"
    else:
        path.write_text("x,y,z\n# comment\n" + "0,0,0\n" * 2000)
        where = f"{path} line 1237 (data row 1235)"
    argv = ["convert", "--from", "mrp", "-i", path, "--to", "quat"]
    code, _, err = run(argv + ["-o", tmp_path / "o.npy"], capsys)
    assert (code, err) == (2, f"rigidkit: error: {where}: MRP is bad\n")
    assert not (tmp_path / "o.npy").exists()


def test_a_gimbal_lock_warning_carrying_its_index_is_placed_by_it(
    tmp_path, capsys, monkeypatch
):
    import warnings

    from rigidkit import GimbalLockWarning, Rotation

    real = Rotation.as_euler

    def as_euler(self, *args, **kwargs):
        w = GimbalLockWarning("gimbal lock (made up)")
        w.index = (2,)  # no row of this batch is locked: only the index says 2
        warnings.warn(w, stacklevel=2)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Rotation, "as_euler", as_euler)
    np.save(tmp_path / "in.npy", np.zeros((5, 3)))
    argv = ["convert", "--from", "rotvec", "-i", tmp_path / "in.npy"]
    code, out, err = run(argv + ["--to", "euler:ZYX", "-o", "-"], capsys)
    assert code == 0 and len(out.splitlines()) == 6
    where = f"{tmp_path / 'in.npy'} row 3 (index 2)"
    assert err == f"rigidkit: warning: {where}: gimbal lock (made up)\n"


# -- batch files: nothing lost, nothing guessed ----------------------------------------


def convert_file(tmp_path, capsys, text, source, to="quat", extra=(), name="in.csv"):
    """Run a batch conversion of ``text`` to ``.npy``: (code, table or None, err)."""
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    out = tmp_path / "out.npy"
    argv = ["convert", "--from", source, "-i", path, "-o", out, "--to", to, *extra]
    code, stdout, err = run(argv, capsys)
    assert stdout == ""
    return code, (np.load(out) if code == 0 else None), err


ZYX_DEG = np.array([[10.0, 20.0, 30.0], [40.0, -50.0, 60.0], [-170.0, 5.0, 1.5]])


def test_a_csv_of_quoted_numbers_is_data_not_a_header(tmp_path, capsys):
    # One row: never an empty output.
    one = '"10","20","30"\n'
    code, table, err = convert_file(tmp_path, capsys, one, "euler:ZYX", extra=["--degrees"])
    assert (code, err) == (0, "")
    check_against_scipy(
        "quat", table, SciRot.from_euler("ZYX", [ZYX_DEG[0]], degrees=True), 0
    )
    # Two rows: both converted, none dropped.
    two = "".join(
        ",".join(f'"{x}"' for x in number_args(row)) + "\n" for row in ZYX_DEG[:2]
    )
    code, table, err = convert_file(tmp_path, capsys, two, "euler:ZYX", extra=["--degrees"])
    assert (code, err, table.shape) == (0, "", (2, 4))
    check_against_scipy(
        "quat", table, SciRot.from_euler("ZYX", ZYX_DEG[:2], degrees=True), 0
    )
    # A bad second row is named by its own line.
    bad = '"10","20","30"\n"1","x","3"\n'
    code, _, err = convert_file(tmp_path, capsys, bad, "euler:ZYX", extra=["--degrees"])
    assert code == 2 and "line 2 (data row 2): field 2 is 'x'" in err
    # A quoted header is still a header.
    head = '"w","x","y","z"\n"1","0","0","0"\n'
    code, table, _ = convert_file(tmp_path, capsys, head, "quat", to="rotvec")
    assert code == 0 and table.tolist() == [[0.0, 0.0, 0.0]]


@pytest.mark.parametrize("sep", [";", "\t", " ", "  "])
@pytest.mark.parametrize("header", [False, True])
def test_semicolon_tab_and_space_separated_files(sep, header, tmp_path, capsys):
    lines = ["yaw pitch roll".replace(" ", sep)] if header else []
    lines += [sep.join(number_args(row)) for row in ZYX_DEG]
    text = "\n".join(lines) + "\n"
    code, table, err = convert_file(
        tmp_path, capsys, text, "euler:ZYX", extra=["--degrees"]
    )
    assert (code, err) == (0, "")
    check_against_scipy("quat", table, SciRot.from_euler("ZYX", ZYX_DEG, degrees=True), 0)
    # A wrong field count names the delimiter found; a header, what it names.
    code, _, err = convert_file(tmp_path, capsys, text, "quat")
    name = {";": "';'", "\t": "tab"}.get(sep, "spaces")
    want = "the header (yaw, pitch, roll)" if header else f"got 3 (separated by {name})"
    assert code == 2 and want in err


def test_a_decimal_comma_is_explained(tmp_path, capsys):
    code, _, err = convert_file(tmp_path, capsys, "1,5;2;3\n", "euler:ZYX")
    assert code == 2 and "field 1 is '1,5', not a number" in err and "decimal" in err


Q_WXYZ = wxyz(SciRot.from_euler("ZYX", ZYX_DEG, degrees=True).as_quat())


def _columns(header, rows, order):
    return (
        "\n".join([header, *(",".join(repr(float(r[k])) for k in order) for r in rows)])
        + "\n"
    )


@pytest.mark.parametrize(
    "header, order, source",
    [
        # order: which w x y z component is in each column of the file
        ("qx,qy,qz,qw", [1, 2, 3, 0], "quat"),
        ("x,y,z,w", [1, 2, 3, 0], "quat"),
        ("w,x,y,z", [0, 1, 2, 3], "quat:xyzw"),
        ("q_w,q_x,q_y,q_z", [0, 1, 2, 3], "quat:xyzw"),
        ("QW, QX, QY, QZ", [0, 1, 2, 3], "quat"),
        ("quat.w,quat.x,quat.y,quat.z", [0, 1, 2, 3], "quat:xyzw"),
        ("quat:xyzw.x,quat:xyzw.y,quat:xyzw.z,quat:xyzw.w", [1, 2, 3, 0], "quat"),
        ("a,b,c,d", [0, 1, 2, 3], "quat"),  # names no component: file order, warned
    ],
)
def test_a_header_naming_quaternion_components_is_honoured(
    header, order, source, tmp_path, capsys
):
    text = _columns(header, Q_WXYZ, order)
    code, table, err = convert_file(tmp_path, capsys, text, source, to="quat")
    if header == "a,b,c,d":  # an unrecognised header is said, not skipped silently
        assert code == 0 and err.count("\n") == 1
        assert "warning" in err and "line 1" in err and "(a, b, c, d)" in err
        assert "read in the order w, x, y, z" in err
    else:
        assert (code, err) == (0, "")
    check_against_scipy("quat", table, SciRot.from_quat(np.roll(Q_WXYZ, -1, axis=-1)), 0)


@pytest.mark.parametrize(
    "header, seq, order",
    [
        # order: which of (roll, pitch, yaw) = angles about (x, y, z) each column holds
        ("roll,pitch,yaw", "ZYX", [0, 1, 2]),
        ("yaw,pitch,roll", "ZYX", [2, 1, 0]),
        ("pitch,roll,yaw", "xyz", [1, 0, 2]),
        ("Roll,Yaw,Pitch", "YXZ", [0, 2, 1]),
    ],
)
def test_a_roll_pitch_yaw_header_is_honoured(header, seq, order, tmp_path, capsys):
    rpy = np.array([[5.0, 10.0, 20.0], [-30.0, 40.0, 170.0]])  # about x, y, z
    text = _columns(header, rpy, order)
    code, table, err = convert_file(
        tmp_path, capsys, text, f"euler:{seq}", extra=["--degrees"]
    )
    assert (code, err) == (0, "")
    by_axis = {"x": rpy[:, 0], "y": rpy[:, 1], "z": rpy[:, 2]}
    angles = np.stack([by_axis[a] for a in seq.lower()], axis=-1)
    check_against_scipy("quat", table, SciRot.from_euler(seq, angles, degrees=True), 0)


def test_a_column_major_matrix_header_is_honoured(tmp_path, capsys):
    S = random_rotations(5, seed=11)
    m = S.as_matrix()
    header = ",".join(f"r{i}{j}" for j in "123" for i in "123")  # column by column
    text = _columns(header, m.transpose(0, 2, 1).reshape(-1, 9), range(9))
    code, table, err = convert_file(tmp_path, capsys, text, "matrix")
    assert (code, err) == (0, "")
    check_against_scipy("quat", table, S, 0)


@pytest.mark.parametrize(
    "header, source",
    [
        ("qx,qy,qz,qw", "rotvec"),
        ("time,qx,qy,qz", "quat"),
        ("w,x,y,y", "quat"),
        ("roll,pitch,yaw", "euler:ZXZ"),  # two turns about z: roll/pitch/yaw are unclear
        ("x,y,z", "euler:ZYX"),
        ("rotvec.x,rotvec.y,rotvec.z", "mrp"),
        ("euler:XYZ.angle1,euler:XYZ.angle2,euler:XYZ.angle3", "euler:ZYX"),
        ("w,x,y,z", "matrix"),
    ],
)
def test_a_header_contradicting_the_representation_is_rejected(
    header, source, tmp_path, capsys
):
    k = 9 if source == "matrix" else (4 if source.startswith("quat") else 3)
    row = ",".join(["0.1"] * k)
    code, table, err = convert_file(tmp_path, capsys, f"{header}\n{row}\n", source)
    assert code == 2 and err.count("\n") == 1
    assert "line 1: the header" in err and source in err
    assert sorted(os.listdir(tmp_path)) == ["in.csv"]


def test_euler_angles_that_look_like_degrees_are_warned_about(tmp_path, capsys):
    code, out, err = run(["convert", "euler:ZYX", "30", "20", "10", "--to", "quat"], capsys)
    assert code == 0 and err.startswith("rigidkit: warning: ") and err.count("\n") == 1
    assert "2*pi" in err and "degrees" in err
    # Still read as radians, as documented.
    got = parse_table(out)["quat"]
    check_against_scipy("quat", got, SciRot.from_euler("ZYX", [30, 20, 10]), False)
    assert run(["convert", "euler:ZYX", "30", "20", "10", "--degrees"], capsys)[2] == ""
    assert (
        run(["convert", "euler:ZYX", "6.28", "-6.28", "1", "--to", "quat"], capsys)[2] == ""
    )
    # In a batch: the first such row is named.
    text = "0.1,0.2,0.3\n0.1,-7,0.3\n1,2,3\n9,9,9\n"
    code, table, err = convert_file(tmp_path, capsys, text, "euler:ZYX")
    assert code == 0 and table.shape == (4, 4) and err.count("\n") == 1
    assert "line 2 (data row 2)" in err and "looks like degrees" not in err
    assert "look like degrees" in err and "1 more" in err
    assert convert_file(tmp_path, capsys, text, "euler:ZYX", extra=["--degrees"])[2] == ""


def test_the_positional_representation_works_with_a_file(tmp_path, capsys):
    path = tmp_path / "in.csv"
    path.write_text("\n".join(",".join(number_args(row)) for row in ZYX_DEG) + "\n")
    outs = []
    for spelling in (["euler:ZYX"], ["--from", "euler:ZYX"]):
        out = tmp_path / f"out{len(outs)}.csv"
        argv = ["convert", *spelling, "--input", path, "--output", out, "--to", "quat"]
        code, _, err = run(argv + ["--degrees"], capsys)
        assert (code, err) == (0, "")
        outs.append(out.read_text())
    assert outs[0] == outs[1]
    table = np.loadtxt(io.StringIO(outs[0]), delimiter=",", skiprows=1)
    check_against_scipy("quat", table, SciRot.from_euler("ZYX", ZYX_DEG, degrees=True), 0)
    # Given twice it must agree, and no numbers may follow it.
    argv = ["convert", "quat", "--from", "euler:ZYX", "-i", path, "--to", "quat"]
    code, _, err = run(argv, capsys)
    assert code == 2 and "give no rotation" in err
    code, _, err = run(["convert", "euler:ZYX", "1", "-i", path, "--to", "quat"], capsys)
    assert code == 2 and "give no rotation" in err


@pytest.mark.parametrize("kind", ["object", "structured", "pickle", "text"])
def test_a_npy_that_is_not_a_numeric_array_says_so(kind, tmp_path, capsys):
    path = tmp_path / "in.npy"
    if kind == "object":
        np.save(path, np.array([{"w": 1}, None], dtype=object), allow_pickle=True)
    elif kind == "structured":
        np.save(path, np.zeros(3, dtype=[("w", "f8"), ("x", "f8")]))
    elif kind == "pickle":
        import pickle

        path.write_bytes(pickle.dumps([[1.0, 0.0, 0.0, 0.0]]))
    else:
        path.write_text("1,0,0,0\n")
    argv = ["convert", "--from", "quat", "-i", path, "--to", "quat"]
    code, out, err = run(argv, capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "allow_pickle" not in err
    if kind in ("object", "structured"):
        assert "not a numeric array" in err
    else:
        assert "not a .npy file" in err


def test_fewer_rows_parsed_than_data_lines_is_an_error(tmp_path, capsys, monkeypatch):
    real = np.loadtxt
    monkeypatch.setattr(np, "loadtxt", lambda *a, **k: real(*a, **k)[:-1])
    text = "w,x,y,z\n1,0,0,0\n0,1,0,0\n"
    code, _, err = convert_file(tmp_path, capsys, text, "quat")
    assert code == 2 and "read 1 rows from 2 data lines" in err
    assert sorted(os.listdir(tmp_path)) == ["in.csv"]


def test_a_byte_order_mark_does_not_hide_the_header(tmp_path, capsys):
    text = "\ufeffqx,qy,qz,qw\n0,0,0,1\n".encode()
    code, table, err = convert_file(tmp_path, capsys, text, "quat", to="rotvec")
    assert (code, err, table.tolist()) == (0, "", [[0.0, 0.0, 0.0]])


# -- the two ways to run it from a shell -----------------------------------------------


def _subprocess(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, **kw)


def test_python_dash_m(tmp_path):
    S = random_rotations(1000, seed=7)
    np.save(tmp_path / "in.npy", S.as_rotvec())
    argv = ["convert", "--from", "rotvec", "-i", "in.npy", "-o", "out.csv", "--to", "quat"]
    res = _subprocess([sys.executable, "-m", "rigidkit", *argv], cwd=tmp_path)
    assert (res.returncode, res.stdout, res.stderr) == (0, "", "")
    got = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1)
    check_against_scipy("quat", got, S, degrees=False)
    res = _subprocess([sys.executable, "-m", "rigidkit", "convert", "quat", "0", "0", "0"])
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert res.stderr == "rigidkit: error: quat takes 4 numbers (w, x, y, z), got 3\n"


def test_console_script():
    script = shutil.which("rigidkit", path=os.path.dirname(sys.executable)) or shutil.which(
        "rigidkit"
    )
    assert script, "the rigidkit console script is not installed (pip install -e .)"
    res = _subprocess([script, "convert", "euler:ZYX", "-30", "20", "10", "--degrees"])
    assert (res.returncode, res.stderr) == (0, "")
    table = parse_table(res.stdout)
    assert list(table) == list(ALL)
    S = SciRot.from_euler("ZYX", [-30, 20, 10], degrees=True)
    for name, got in table.items():
        check_against_scipy(name, got, S, degrees=True)
    res = _subprocess([script, "convert", "rotvec", "1", "2", "3", "--to", "nope"])
    assert res.returncode == 2 and res.stderr.count("\n") == 1


# -- the files people have (issue 21, part 4) ---------------------------------------------

EULER_ROWS = np.array([[10.0, 20.0, 30.0], [-40.0, 5.0, 170.0], [0.5, -60.0, 1.0]])


def test_txt_files_are_read_whitespace_separated_as_tum_and_kitti_logs(tmp_path, capsys):
    # A TUM-style log: a '#' comment line, then columns separated by runs of spaces.
    text = "# roll pitch yaw, degrees\n" + "\n".join(
        "  ".join(f"{v:.10f}" for v in row) for row in EULER_ROWS
    )
    code, table, err = convert_file(
        tmp_path, capsys, text, "euler:xyz", extra=["--degrees"], name="in.txt"
    )
    assert (code, err) == (0, "")
    check_against_scipy(
        "quat", table, SciRot.from_euler("xyz", EULER_ROWS, degrees=True), 0
    )
    # .txt out: numbers separated by spaces under a '#' header, read back the same.
    out = tmp_path / "out.txt"
    argv = ["convert", "rpy", "-i", tmp_path / "in.txt", "-o", out, "--to", "quat"]
    assert run(argv + ["--degrees"], capsys)[0] == 0
    lines = out.read_text().splitlines()
    assert lines[0] == "# quat.w quat.x quat.y quat.z"
    np.testing.assert_array_equal(np.loadtxt(out), table)


def test_rpy_is_roll_pitch_yaw_about_the_fixed_axes_in_that_order(capsys):
    roll, pitch, yaw = 10.0, 20.0, 30.0
    code, out, _ = run(
        [
            "convert",
            "rpy",
            roll,
            pitch,
            yaw,
            "--degrees",
            "--to",
            "matrix",
            "--format",
            "json",
        ],
        capsys,
    )
    assert code == 0
    # ROS / URDF: R = Rz(yaw) Ry(pitch) Rx(roll), the same as intrinsic ZYX (y, p, r).
    ref = SciRot.from_euler("ZYX", [yaw, pitch, roll], degrees=True).as_matrix()
    np.testing.assert_allclose(json.loads(out)["matrix"], ref, rtol=0, atol=ATOL)
    code, out, _ = run(["convert", "euler:ZYX", yaw, pitch, roll, "--degrees",
                        "--to", "rpy", "--format", "json"], capsys)  # fmt: skip
    np.testing.assert_allclose(json.loads(out)["rpy"], [roll, pitch, yaw], atol=1e-12)
    code, out, _ = run(["convert", "--help"], capsys)
    assert code == 0
    assert "rpy" in out and "roll, pitch, yaw in that order" in out


def _numbers(text: str) -> list:
    """Every number token of an output (table, JSON, CSV or whitespace text)."""
    out = []
    for token in text.replace(",", " ").replace("[", " ").replace("]", " ").split():
        try:
            float(token)
        except ValueError:
            continue
        out.append(token)
    return out


def test_decimals_apply_to_every_output_format(tmp_path, capsys):
    np.save(tmp_path / "in.npy", EULER_ROWS)
    base = ["convert", "--from", "euler:ZYX", "-i", tmp_path / "in.npy", "--to", "quat",
            "--degrees", "--decimals", "3"]  # fmt: skip
    ref = SciRot.from_euler("ZYX", EULER_ROWS, degrees=True).as_quat(scalar_first=True)
    ref = np.round(ref * np.sign(ref[:, :1]), 3) + 0.0
    for name in ("out.csv", "out.txt", "out.npy"):
        assert run(base + ["-o", tmp_path / name], capsys)[0] == 0
        path = tmp_path / name
        if name.endswith(".npy"):
            got = np.load(path)
        else:
            body = path.read_text().splitlines()[1:]
            assert all(len(t.split(".")[1]) == 3 for t in _numbers("\n".join(body)))
            got = np.loadtxt(path, delimiter="," if name.endswith("csv") else None,
                             skiprows=1)  # fmt: skip
        np.testing.assert_array_equal(got, ref)
    code, out, _ = run(base + ["-o", "-"], capsys)
    assert all(len(t.split(".")[1]) == 3 for t in _numbers(out.split("\n", 1)[1]))
    code, out, _ = run(["convert", "euler:ZYX", 10, 20, 30, "--degrees", "--to", "quat",
                        "--format", "json", "--decimals", "2"], capsys)  # fmt: skip
    got = json.loads(out)["quat"]
    np.testing.assert_array_equal(got, ref[0].round(2))


def test_no_negative_zero_is_ever_written(tmp_path, capsys):
    # (x, y, z, w) = (-0, 0, 0, 1): the library keeps the sign of the zero ...
    q = np.array([[-0.0, 0.0, 0.0, 1.0], [-1e-9, -0.0, 0.0, 1.0]])
    assert np.signbit(rk_quat_xyzw_rotvec(q)).any()
    np.save(tmp_path / "in.npy", q)
    for extra in ([], ["--decimals", "4"]):
        for out in ("-", tmp_path / "out.csv", tmp_path / "out.txt"):
            argv = ["convert", "--from", "quat:xyzw", "-i", tmp_path / "in.npy", "-o", out,
                    "--to", "all", *extra]  # fmt: skip
            code, stdout, _ = run(argv, capsys)
            text = stdout if out == "-" else Path(out).read_text()
            assert code == 0 and _numbers(text)
            assert not [t for t in _numbers(text) if t.startswith("-") and float(t) == 0]
        npy = tmp_path / "out.npy"
        argv = ["convert", "--from", "quat:xyzw", "-i", tmp_path / "in.npy", "-o", npy,
                "--to", "all", *extra]  # fmt: skip
        assert run(argv, capsys)[0] == 0
        got = np.load(npy)
        assert not np.signbit(got[got == 0]).any()
        for fmt in ("table", "json"):
            argv = ["convert", "quat:xyzw", "-0.0", "0", "0", "1", "--to", "all"]
            code, stdout, _ = run([*argv, "--format", fmt, *extra], capsys)
            assert code == 0
            assert not [t for t in _numbers(stdout) if t.startswith("-") and float(t) == 0]


def rk_quat_xyzw_rotvec(q):
    import rigidkit as rk

    return rk.Rotation.from_quat(q, scalar_first=False).as_rotvec()


@pytest.mark.parametrize(
    "separator",
    [",", ";", "\t", " ", "  \t "],
    ids=["comma", "semicolon", "tab", "space", "spaces"],
)
def test_convert_help_lists_every_separator_the_reader_accepts(separator, tmp_path, capsys):
    code, out, _ = run(["convert", "--help"], capsys)
    help_text = " ".join(out.split())
    for words in ("commas (,)", "semicolons (;)", "tabs", "runs of spaces and tabs"):
        assert words in help_text
    text = "\n".join(separator.join(repr(float(v)) for v in row) for row in EULER_ROWS)
    code, table, err = convert_file(
        tmp_path, capsys, text, "euler:ZYX", extra=["--degrees"]
    )
    assert (code, err) == (0, "")
    check_against_scipy(
        "quat", table, SciRot.from_euler("ZYX", EULER_ROWS, degrees=True), 0
    )


def test_the_gimbal_lock_warning_speaks_of_rows(tmp_path, capsys):
    rows = np.array([[0.0, 0.0, 0.0], [10.0, 90.0, 0.0], [1.0, 2.0, 3.0], [0.0, 90.0, 5.0]])
    code, table, err = convert_file(
        tmp_path, capsys, "\n".join(",".join(str(float(v)) for v in r) for r in rows),
        "euler:ZYX", to="euler:ZYX", extra=["--degrees"],
    )  # fmt: skip
    assert code == 0 and err.count("\n") == 1
    assert "line 2 (data row 2)" in err and "2 of 4 rows have their middle angle" in err
    assert "middle angles" not in err and "(first" not in err
    # The angles returned rebuild the rotations (scipy's matrices).
    np.testing.assert_allclose(
        SciRot.from_euler("ZYX", table, degrees=True).as_matrix(),
        SciRot.from_euler("ZYX", rows, degrees=True).as_matrix(), atol=1e-12,
    )  # fmt: skip
    code, _, err = run(["convert", "euler:ZYX", 0, 90, 0, "--degrees", "--to", "euler:ZYX"],
                       capsys)  # fmt: skip
    assert code == 0 and "the middle angle is within" in err
    assert "(single)" not in err and "batch" not in err
