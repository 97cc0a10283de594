"""``rigidkit ape``, ``rpe`` and ``kitti``: output, JSON, plots and errors."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

import rigidkit as rk
from rigidkit.applications.cli import main


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    rng = np.random.default_rng(5)
    n = 300
    t = 10.0 + np.arange(n) * 0.05
    twist = np.array([1.0, 0.0, 0.1, 0.0, 0.0, 0.2])
    gt = rk.Transform.exp(np.outer(t - t[0], twist))
    noise = rk.Transform.exp(rng.normal(0, 0.01, (n, 6)))
    S = rk.Similarity(scale=0.5, rotation=rk.Rotation.from_rotvec([0, 0, 1.0]))
    ref = rk.Trajectory(t, gt)
    est = rk.Trajectory(t + rng.normal(0, 0.002, n), gt @ noise).transform(S)
    rk.io.write_trajectory(d / "ref.txt", ref, "tum")
    rk.io.write_trajectory(d / "est.txt", est[::2], "tum")
    return d, ref, est


def _run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _expected_ape(d, method="sim3"):
    ref = rk.io.read_trajectory(d / "ref.txt")
    est = rk.io.read_trajectory(d / "est.txt")
    r, e = rk.trajectory.associate(ref, est)
    aligned, S = rk.trajectory.align(e, r, method=method)
    return rk.trajectory.ape(r, aligned), S


def test_ape_prints_a_table_of_the_statistics(files, capsys):
    d, _, _ = files
    code, out, err = _run(capsys, "ape", d / "ref.txt", d / "est.txt", "--align", "sim3")
    assert code == 0 and err == ""
    expected, S = _expected_ape(d)
    lines = out.splitlines()
    assert lines[0].startswith("APE, translation [m]: 150 pose pairs, alignment sim3")
    printed = {ln.split()[0]: float(ln.split()[1]) for ln in lines[1:]}
    assert list(printed) == ["rmse", "mean", "median", "std", "min", "max", "sse"]
    for key, value in printed.items():
        assert value == pytest.approx(expected.stats[key], abs=5e-7)


def test_ape_json_to_stdout(files, capsys):
    d, _, _ = files
    code, out, _ = _run(
        capsys, "ape", d / "ref.txt", d / "est.txt", "--align", "sim3", "--json", "-"
    )
    doc = json.loads(out)
    expected, S = _expected_ape(d)
    assert code == 0 and doc["n"] == 150 and doc["relation"] == "translation"
    assert doc["stats"] == expected.stats  # every digit
    assert doc["alignment"]["method"] == "sim3"
    assert doc["alignment"]["scale"] == pytest.approx(2.0, rel=0.05)
    np.testing.assert_array_equal(doc["alignment"]["matrix"], S.as_matrix())


def test_ape_equals_evo_ape(files, capsys, tmp_path):
    pytest.importorskip("evo")
    from evo.core import metrics, sync
    from evo.tools import file_interface

    d, _, _ = files
    code, out, _ = _run(
        capsys,
        "ape",
        d / "ref.txt",
        d / "est.txt",
        "--align",
        "se3",
        "--relation",
        "rotation_angle",
        "--degrees",
        "--json",
        "-",
    )
    ref = file_interface.read_tum_trajectory_file(str(d / "ref.txt"))
    est = file_interface.read_tum_trajectory_file(str(d / "est.txt"))
    ref, est = sync.associate_trajectories(ref, est)
    est.align(ref)
    m = metrics.APE(metrics.PoseRelation.rotation_angle_deg)
    m.process_data((ref, est))
    theirs = m.get_all_statistics()
    for key, value in json.loads(out)["stats"].items():
        assert value == pytest.approx(theirs[key], rel=1e-9)


def test_rpe_options_and_json_file(files, capsys, tmp_path):
    d, _, _ = files
    path = tmp_path / "rpe.json"
    code, out, _ = _run(
        capsys,
        "rpe",
        d / "ref.txt",
        d / "est.txt",
        "--align",
        "sim3",
        "--delta",
        "2",
        "--unit",
        "meters",
        "--all-pairs",
        "--relation",
        "rotation_angle",
        "--json",
        path,
    )
    assert code == 0 and out.startswith("RPE, rotation_angle [rad], delta 2.0 meters")
    doc = json.loads(path.read_text())
    ref = rk.io.read_trajectory(d / "ref.txt")
    est = rk.io.read_trajectory(d / "est.txt")
    r, e = rk.trajectory.associate(ref, est)
    aligned, _ = rk.trajectory.align(e, r, method="sim3")
    expected = rk.trajectory.rpe(
        r, aligned, delta=2.0, unit="meters", all_pairs=True, relation="rotation_angle"
    )
    assert doc["n"] == len(expected.errors) and doc["stats"] == expected.stats
    code, _, err = _run(capsys, "rpe", d / "ref.txt", d / "est.txt", "--delta", "1.5")
    assert code == 2 and "whole number" in err


def test_kitti_command_on_files_without_stamps(files, capsys, tmp_path):
    _, ref, est = files
    # The 15 m path scaled to 600 m, so that it holds segments of 100 to 500 m.
    big = rk.Similarity(scale=40.0)
    rk.io.write_trajectory(
        tmp_path / "gt.txt", rk.Trajectory(None, ref.transform(big).poses), "kitti"
    )
    rk.io.write_trajectory(
        tmp_path / "est.txt", rk.Trajectory(None, est.transform(big).poses), "kitti"
    )
    code, out, err = _run(
        capsys,
        "kitti",
        tmp_path / "gt.txt",
        tmp_path / "est.txt",
        "--align",
        "sim3",
        "--json",
        "-",
    )
    assert code == 0, err
    doc = json.loads(out)
    assert doc["segments"] > 0 and set(doc["lengths"]) <= {
        str(L) for L in range(100, 900, 100)
    }
    code, out, err = _run(capsys, "kitti", tmp_path / "gt.txt", tmp_path / "est.txt")
    assert code == 0 and "deg/100m" in out


def test_bad_file_is_one_line_naming_file_and_line(files, capsys, tmp_path):
    d, _, _ = files
    bad = tmp_path / "bad.txt"
    lines = (d / "est.txt").read_text().splitlines()
    lines[5] = lines[5].replace(" ", " x", 1)
    bad.write_text("\n".join(lines) + "\n")
    code, out, err = _run(capsys, "ape", d / "ref.txt", bad)
    assert code == 2 and out == ""
    assert err.startswith(f"rigidkit: error: {bad} line 6: field 2 is 'x")
    assert len(err.splitlines()) == 1
    code, _, err = _run(capsys, "ape", d / "ref.txt", d / "est.txt", "--offset", "1000")
    assert code == 2 and "no pose of est matches" in err


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_plot_writes_a_non_blank_figure(files, capsys, tmp_path, suffix):
    pytest.importorskip("matplotlib")
    d, _, _ = files
    path = tmp_path / f"ape{suffix}"
    code, _, err = _run(
        capsys, "ape", d / "ref.txt", d / "est.txt", "--align", "sim3", "--plot", path
    )
    assert code == 0, err
    data = path.read_bytes()
    if suffix == ".svg":
        assert data.count(b"<path") > 10
        return
    import matplotlib.image

    img = matplotlib.image.imread(path)
    assert img.shape[0] > 200 and img.shape[1] > 600
    # Not blank: many distinct colours (lines, colour map, text).
    assert len(np.unique(img.reshape(-1, img.shape[-1]), axis=0)) > 50


def test_plot_without_matplotlib_names_the_extra(files, capsys, tmp_path, monkeypatch):
    d, _, _ = files
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    code, _, err = _run(
        capsys, "ape", d / "ref.txt", d / "est.txt", "--plot", tmp_path / "a.png"
    )
    assert code == 2 and "pip install 'rigidkit[plot]'" in err
    with pytest.raises(ImportError, match=r"rigidkit\[plot\]"):
        rk.trajectory.plot(rk.io.read_trajectory(d / "ref.txt"))


def test_convert_is_unchanged(capsys):
    code, out, _ = _run(
        capsys,
        "convert",
        "rotvec",
        "0",
        "0",
        "90",
        "--degrees",
        "--to",
        "quat:xyzw",
        "--decimals",
        "6",
    )
    assert code == 0
    assert out == "quat:xyzw  x y z w  0.000000  0.000000  0.707107  0.707107\n"


def test_help_lists_the_trajectory_commands(capsys):
    code, out, _ = _run(capsys, "--help")
    assert code == 0
    assert "ape       absolute pose error" in out
    assert "KITTI odometry errors (% and deg/100 m" in out
    for command in ("ape", "rpe", "kitti"):
        code, out, _ = _run(capsys, command, "--help")
        assert code == 0 and "--align {none,se3,sim3,scale,yaw,origin}" in out
