"""rk.io trajectory files: round trips, format detection, exact parsing, and
errors that name the file, the line and what is wrong (nothing half-read)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import rigidkit as rk
from rigidkit.applications.io._parse import _parse_python, parse_table

read, write = rk.io.read_trajectory, rk.io.write_trajectory


def _traj(n=50, seed=0, stamps=True):
    rng = np.random.default_rng(seed)
    t = 1305031102.175304 + np.cumsum(rng.uniform(0.01, 0.05, n)) if stamps else None
    return rk.Trajectory(t, rk.Transform.random(n, rng=rng, scale=10.0))


@pytest.mark.parametrize("fmt", ["tum", "euroc", "csv", "kitti"])
def test_round_trip(tmp_path, fmt):
    traj = _traj(stamps=fmt != "kitti")
    path = tmp_path / f"traj.{fmt}"
    write(path, traj, fmt)
    back = read(path)  # detected from the content
    assert len(back) == len(traj)
    if fmt == "kitti":
        assert back.stamps is None
        # The matrix goes through rotation -> matrix -> nearest rotation.
        np.testing.assert_allclose(
            back.poses.as_matrix(), traj.poses.as_matrix(), rtol=0, atol=1e-14
        )
        return
    np.testing.assert_array_equal(back.positions, traj.positions)
    q_back = back.poses.rotation.as_quat(canonical=True)
    np.testing.assert_allclose(
        q_back, traj.poses.rotation.as_quat(canonical=True), atol=1e-16
    )
    if fmt == "euroc":  # whole nanoseconds
        np.testing.assert_allclose(back.stamps, traj.stamps, rtol=0, atol=5e-7)
    else:
        np.testing.assert_array_equal(back.stamps, traj.stamps)


def test_kitti_stamps_from_a_times_file(tmp_path):
    traj = _traj(10, stamps=False)
    write(tmp_path / "poses.txt", traj, "kitti")
    (tmp_path / "times.txt").write_text("\n".join(f"{0.1 * k:.6e}" for k in range(10)))
    back = read(tmp_path / "poses.txt", stamps=str(tmp_path / "times.txt"))
    np.testing.assert_array_equal(back.stamps, [float(f"{0.1 * k:.6e}") for k in range(10)])
    back = read(tmp_path / "poses.txt", "kitti", stamps=np.arange(10.0))
    np.testing.assert_array_equal(back.stamps, np.arange(10.0))
    (tmp_path / "short.txt").write_text("0\n1\n")
    with pytest.raises(rk.TrajectoryFileError, match="2 times for 10 poses"):
        read(tmp_path / "poses.txt", stamps=str(tmp_path / "short.txt"))


def test_tum_comments_blank_lines_and_crlf(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes(
        b"\xef\xbb\xbf# ground truth\r\n\r\n1.0 1 2 3 0 0 0 1\r\n"
        b"  # a comment\n2.0 4 5 6 0 0 0 2 # trailing comment\n"
    )
    traj = read(path)
    np.testing.assert_array_equal(traj.stamps, [1.0, 2.0])
    np.testing.assert_array_equal(traj.positions, [[1, 2, 3], [4, 5, 6]])
    # The quaternion is normalised (any nonzero norm is accepted, as evo does).
    np.testing.assert_array_equal(traj.poses.rotation.as_quat(), [[1, 0, 0, 0]] * 2)


def test_euroc_extra_columns_and_header(tmp_path):
    path = tmp_path / "data.csv"
    header = (
        "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
        "q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], b_w_RS_S_x [rad s^-1]\n"
    )
    rows = [
        "1403636579758555392,4.688,-1.786,0.783,0.534,-0.153,-0.827,-0.082,0.1,0.2",
        "1403636579763555584,4.688,-1.786,0.787,0.534,-0.153,-0.827,-0.082,0.1,0.2",
    ]
    path.write_text(header + "\n".join(rows) + "\n")
    traj = read(path)
    np.testing.assert_array_equal(
        traj.stamps, [1403636579758555392 / 1e9, 1403636579763555584 / 1e9]
    )
    np.testing.assert_array_equal(traj.positions[1], [4.688, -1.786, 0.787])
    q = np.array([0.534, -0.153, -0.827, -0.082])
    np.testing.assert_allclose(traj.poses.rotation.as_quat()[0], q / np.linalg.norm(q))


def test_euroc_equals_evo(tmp_path):
    pytest.importorskip("evo")
    from evo.tools import file_interface

    traj = _traj(30)
    write(tmp_path / "gt.csv", traj, "euroc")
    theirs = file_interface.read_euroc_csv_trajectory(str(tmp_path / "gt.csv"))
    ours = read(tmp_path / "gt.csv", "euroc")
    np.testing.assert_array_equal(ours.stamps, theirs.timestamps)
    np.testing.assert_array_equal(ours.positions, theirs.positions_xyz)


def test_kitti_equals_evo(tmp_path):
    pytest.importorskip("evo")
    from evo.tools import file_interface

    write(tmp_path / "poses.txt", _traj(30, stamps=False), "kitti")
    theirs = file_interface.read_kitti_poses_file(str(tmp_path / "poses.txt"))
    ours = read(tmp_path / "poses.txt", "kitti")
    np.testing.assert_allclose(
        ours.poses.as_matrix(), np.array(theirs.poses_se3), rtol=0, atol=1e-15
    )


@pytest.mark.parametrize(
    "header,order",
    [
        ("t,x,y,z,qw,qx,qy,qz", [0, 1, 2, 3, 4, 5, 6, 7]),
        ("timestamp;tx;ty;tz;qx;qy;qz;qw", [0, 1, 2, 3, 5, 6, 7, 4]),
        ("qw,qx,qy,qz,pos_x,pos_y,pos_z,time", [4, 5, 6, 7, 1, 2, 3, 0]),
        (
            "field.header.stamp,p.x,p.y,p.z,orientation.x,orientation.y,orientation.z,"
            "orientation.w",
            [0, 1, 2, 3, 5, 6, 7, 4],
        ),
    ],
)
def test_csv_header_names_the_columns(tmp_path, header, order):
    # The columns hold (t, x, y, z, qw, qx, qy, qz) permuted: file column k is
    # value order[k].
    values = np.array(
        [[1.0, 10, 20, 30, 0.5, 0.5, 0.5, 0.5], [2.0, 11, 21, 31, 1, 0, 0, 0]]
    )
    if header.startswith("field"):  # a ROS-style name: stamp is the time
        header = header.replace("field.header.stamp", "stamp")
    delim = ";" if ";" in header else ","
    lines = [header] + [delim.join(repr(float(r[k])) for k in order) for r in values]
    path = tmp_path / "poses.csv"
    path.write_text("\n".join(lines) + "\n")
    traj = read(path)
    np.testing.assert_array_equal(traj.stamps, values[:, 0])
    np.testing.assert_array_equal(traj.positions, values[:, 1:4])
    np.testing.assert_allclose(traj.poses.rotation.as_quat(), values[:, 4:], atol=1e-16)


def test_csv_nanoseconds_and_no_time(tmp_path):
    path = tmp_path / "a.csv"
    path.write_text("t [ns],x,y,z,qw,qx,qy,qz\n1500000000,0,0,0,1,0,0,0\n")
    assert read(path).stamps.tolist() == [1.5]
    path.write_text("x,y,z,qw,qx,qy,qz,speed\n0,0,0,1,0,0,0,9\n")
    traj = read(path)
    assert traj.stamps is None and len(traj) == 1


def test_detection_warns_when_it_guesses(tmp_path):
    path = tmp_path / "a.csv"
    path.write_text(
        "1403636579758555392,1,2,3,1,0,0,0\n1403636579763555584,1,2,3,1,0,0,0\n"
    )
    with pytest.warns(UserWarning, match="read as EuRoC"):
        traj = read(path)
    assert len(traj) == 2
    path.write_text("1,2,3,4,5\n")
    with pytest.raises(rk.TrajectoryFileError, match="cannot tell the format"):
        read(path)
    path.write_text("1 2 3 4 5\n")
    with pytest.raises(rk.TrajectoryFileError, match=r"line 1: cannot tell the format: 5"):
        read(path)


_GOOD = "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n"


@pytest.mark.parametrize(
    "text,line,message",
    [
        (_GOOD + "3.0 1 0 0 0 0 x 1\n", 3, "field 7 is 'x', not a number"),
        ("# header\n" + _GOOD + "\n3.0 1 0 0 0 0 1\n", 5, "7 fields separated by spaces"),
        (_GOOD + "3.0 1 0 0 0 0 0 1 9\n", 3, "9 fields"),
        (_GOOD + "3.0 1 0 0 0 0 0 0\n", 3, "the quaternion has zero norm"),
        (_GOOD + "2.0 1 0 0 0 0 0 1\n", 3, "stamp 2.0 repeats"),
        (_GOOD + "1.5 1 0 0 0 0 0 1\n", 3, "stamp 1.5 goes backwards"),
        (_GOOD + "3.0 nan 0 0 0 0 0 1\n", 3, "field 2 is nan, not finite"),
        (_GOOD + "3.0 1,5 0 0 0 0 0 1\n", 3, "field 2 is '1,5', not a number"),
    ],
)
def test_tum_errors_name_file_line_and_reason(tmp_path, text, line, message):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(rk.TrajectoryFileError) as info:
        read(path, "tum")
    err = info.value
    assert isinstance(err, ValueError)
    assert str(err).startswith(f"{path} line {line}: ")
    assert message in str(err)
    assert err.line == line and err.path == str(path)


@pytest.mark.parametrize("fmt", ["tum", "euroc", "csv"])
def test_zero_quaternion_named_in_a_long_file(tmp_path, fmt):
    # The row of the first zero quaternion among many (the conversion's batch
    # index), as a file line after the header.
    traj = _traj(3000)
    path = tmp_path / f"a.{fmt}"
    write(path, traj, fmt)
    lines = path.read_text().splitlines(keepends=True)
    for row in (1234, 2000):  # two zeros: the first is named
        fields = lines[1 + row].rstrip("\n").split("," if fmt != "tum" else " ")
        fields[-4:] = ["0"] * 4  # the quaternion: the last 4 fields
        lines[1 + row] = ("," if fmt != "tum" else " ").join(fields) + "\n"
    path.write_text("".join(lines))
    with pytest.raises(rk.TrajectoryFileError, match="quaternion has zero norm") as info:
        read(path, fmt)
    assert info.value.line == 1235 + 1 and info.value.index == (1234,)


def test_detection_past_the_first_4_kib(tmp_path):
    # Comments longer than the first block the detection decodes.
    path = tmp_path / "a.txt"
    comments = "".join(f"# comment line {k} " + "x" * 60 + "\n" for k in range(100))
    path.write_text(comments + "\n" * 3 + "1.0 1 2 3 0 0 0 1\n2.0 1 2 4 0 0 0 1\n")
    traj = read(path)
    assert traj.stamps.tolist() == [1.0, 2.0] and traj.positions[1].tolist() == [1, 2, 4]
    csv = tmp_path / "b.csv"
    csv.write_text("\n" * 5000 + "t,x,y,z,qw,qx,qy,qz\n1,2,3,4,1,0,0,0\n")
    assert read(csv).positions.tolist() == [[2.0, 3.0, 4.0]]


def test_kitti_rejects_a_matrix_that_is_not_a_rotation(tmp_path):
    good = "1 0 0 0 0 1 0 0 0 0 1 0\n"
    path = tmp_path / "poses.txt"
    path.write_text(good + good + "1 0 0 0 0 1 0 0 0 0 1.01 0\n")
    with pytest.raises(rk.TrajectoryFileError, match=r"line 3: the 3x3 block is not a rot"):
        read(path)
    path.write_text(good + "-1 0 0 0 0 1 0 0 0 0 1 0\n")  # a reflection
    with pytest.raises(rk.TrajectoryFileError, match=r"line 2: .*det -1"):
        read(path)


def test_unreadable_and_empty_files(tmp_path):
    with pytest.raises(rk.TrajectoryFileError, match="cannot read"):
        read(tmp_path / "missing.txt")
    (tmp_path / "empty.txt").write_text("\n\n")
    with pytest.raises(rk.TrajectoryFileError, match="is empty"):
        read(tmp_path / "empty.txt")
    with pytest.raises(rk.TrajectoryFileError, match="names no column for qw"):
        (tmp_path / "a.csv").write_text("t,x,y,z,a,b,c,d\n1,2,3,4,5,6,7,8\n")
        read(tmp_path / "a.csv")


def test_write_needs_stamps_and_is_whole(tmp_path):
    with pytest.raises(rk.TimestampError):
        write(tmp_path / "a.txt", _traj(3, stamps=False), "tum")
    assert not list(tmp_path.iterdir())  # nothing, not even a temporary file


# -- the parser itself ---------------------------------------------------------------


_ENGINES = {
    "numba": lambda *a: parse_table(*a, engine="numba"),
    "numpy": lambda *a: parse_table(*a, engine="numpy"),
    "python": _parse_python,
}


@pytest.mark.parametrize("engine", list(_ENGINES))
def test_parser_equals_python_float_on_every_token(engine):
    # Tokens on and off the fast path: long mantissas, large exponents,
    # subnormals, signs, no leading digit, inf and nan.
    rng = np.random.default_rng(3)
    x = np.concatenate(
        [
            rng.normal(size=200) * 10.0 ** rng.integers(-30, 30, 200),
            [5e-324, 1.7976931348623157e308, 0.1, 2.0**53 + 1, -0.0],
        ]
    )
    tokens = (
        [repr(float(v)) for v in x]
        + [f"{v:.6f}" for v in x[:50]]
        + [f"{v:.25e}" for v in x[:50]]
        + [f"{v:.12f}" for v in x[:50]]
        + ["+.5", "-7.", "1E5", "1e-400", "123456789012345678901234567890", "inf", "-inf"]
        + ["1305031102.175304000", "0.500000000", "0.000000000001234", "-0.0000"]
        # Past 18 digits (scanned twice), trailing zeros past 2^53, 2^53 + 1.
        + ["1305031102.0000000000", "0000000000000000000001.25", "-100000000000000000000"]
        + ["123456789012345678", "1234567890123456780", "9007199254740993", "25.0e-3"]
        + ["12345678901234567.0e-3", "1.000000000000000000000000e5", "900719925474099300"]
    )
    tokens += ["0"] * (-len(tokens) % 4)
    text = "\n".join(" ".join(tokens[k : k + 4]) for k in range(0, len(tokens), 4))
    data, lines, status, _, _ = _ENGINES[engine](text.encode(), 4, True, None)
    assert status == "ok"
    expected = np.array([float(t) for t in tokens]).reshape(-1, 4)
    assert np.array_equal(data, expected) and lines.tolist() == list(
        range(1, len(expected) + 1)
    )
    assert np.array_equal(np.signbit(data), np.signbit(expected))


@pytest.mark.parametrize("engine", list(_ENGINES))
def test_parser_reports_the_first_problem(engine):
    parse = _ENGINES[engine]
    assert parse(b"1 2 3\n4 5\n", 3, True, None)[2:] == ("count", 2, 2)
    assert parse(b"1 2 3\n4 x 6\n", 3, True, None)[2:] == ("token", 2, 2)
    assert parse(b"1,2,3\n4,,5\n", 3, True, ",")[2:] == ("token", 2, 2)
    assert parse(b"1,2,3,\n", 3, True, ",")[2:] == ("token", 1, 4)
    assert parse(b"1 2 3x\n", 3, True, None)[2:] == ("token", 1, 3)
    # The rows before the problem, with their lines.
    data, lines, *_ = parse(b"# c\n1 2 3\n\n4 5 6\n7 8\n", 3, True, None)
    assert data.tolist() == [[1, 2, 3], [4, 5, 6]] and lines.tolist() == [2, 4]
    # Not exact: further fields are ignored, even words.
    data, *_ = parse(b"1,2,3,a\n", 3, False, ",")
    assert data.tolist() == [[1.0, 2.0, 3.0]]


@pytest.mark.parametrize("threads", ["2", "3", "7"])
def test_parser_in_parts_equals_one_pass(monkeypatch, threads):
    # A file parsed in parts (one per thread) gives the rows, the lines, the
    # slow tokens and the first error of the one-pass parse, wherever it is.
    from rigidkit.applications.io import _parse

    rng = np.random.default_rng(8)
    rows = []
    for k in range(300):
        v = rng.normal(size=4) * 10.0 ** rng.integers(-5, 5, 4)
        kind = k % 7
        if kind == 0:
            rows.append("# a comment line")
        elif kind == 1:
            rows.append("")
        tokens = [repr(float(x)) if kind == 2 else f"{x:.9f}" for x in v]
        rows.append(" ".join(tokens) + (" # trailing" if kind == 3 else ""))
    text = "\r\n".join(rows[:150]) + "\r\n" + "\n".join(rows[150:]) + "\n"
    one = _parse_python(text.encode(), 4, True, None)
    monkeypatch.setattr(_parse, "PARALLEL_MIN", 0)
    monkeypatch.setenv("RIGIDKIT_NUM_THREADS", threads)
    assert len(_parse._parts(text.encode(), int(threads))) == int(threads)
    got = parse_table(text.encode(), 4, True, None, engine="numba")
    assert got[2:] == ("ok", 0, 0)
    np.testing.assert_array_equal(got[0], one[0])
    np.testing.assert_array_equal(got[1], one[1])
    lines = text.encode().split(b"\n")
    for at, bad, expected in [
        (len(lines) - 40, b"1 2 3", ("count", 3)),
        (len(lines) // 2 + 3, b"1 2 x 4", ("token", 3)),
        (len(lines) - 3, b"1 2 3 1" + b"0" * 30 + b"x", ("token", 4)),
    ]:
        broken = b"\n".join(lines[:at] + [bad] + lines[at + 1 :])
        want = _parse_python(broken, 4, True, None)
        got = parse_table(broken, 4, True, None, engine="numba")
        assert got[2:] == want[2:] == (expected[0], at + 1, expected[1])
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])


def test_reader_is_not_np_loadtxt_slow(tmp_path):
    # Not a timing test: the reader must give what np.loadtxt gives.
    traj = _traj(2000)
    write(tmp_path / "a.txt", traj, "tum")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = np.loadtxt(tmp_path / "a.txt")
    back = read(tmp_path / "a.txt")
    np.testing.assert_array_equal(back.stamps, expected[:, 0])
    np.testing.assert_array_equal(back.positions, expected[:, 1:4])
