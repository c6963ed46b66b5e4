"""One stated frame per interface: the CLI writes ITK's LPS by default and RAS with --frame ras;
Python writes the frame of the affine it is given (nibabel's: RAS). Oracle: nibabel's affine
applied by numpy, and surftrack.extract on nibabel's array."""
import json
import os
import pathlib
import subprocess

import nibabel as nib
import numpy as np
import pytest

import surftrack


def cli():
    path = os.environ.get("SURFTRACK_CLI") or str(
        pathlib.Path(__file__).resolve().parents[2] / "build" / "cli" / "surftrack")
    assert os.access(path, os.X_OK), f"the surftrack CLI is not built at {path}"
    return path


def ply_vertices(path):
    data = pathlib.Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    count = int(next(line.split()[2] for line in header if line.startswith("element vertex")))
    return np.frombuffer(data, "<f4", 3 * count, end).reshape(-1, 3).astype(float)


def oblique_affine(seed):
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    affine = np.eye(4)
    affine[:3, :3] = q @ np.diag(rng.uniform(0.5, 2.0, 3))
    affine[:3, 3] = rng.uniform(-50, 50, 3)
    return affine


def sorted_rows(points):
    return points[np.lexsort(points.T[::-1])]


@pytest.mark.parametrize("seed", range(4))
def test_cli_frames_match_nibabel_and_python(tmp_path, seed):
    affine = oblique_affine(seed)
    data = np.zeros((12, 10, 9), np.uint8)
    data[3:8, 2:7, 1:6] = 1
    data[5, 7, 6] = 1
    image = nib.Nifti1Image(data, affine)
    image.set_qform(affine, code=1)
    image.set_sform(affine, code=1)
    image.to_filename(tmp_path / "v.nii.gz")
    # The same surface from Python with nibabel's affine: RAS millimetres.
    expected = surftrack.extract(np.asanyarray(image.dataobj), label=1, mode="all", affine=image.affine).vertices
    for frame, flip in (("ras", np.array([1, 1, 1])), ("lps", np.array([-1, -1, 1]))):
        r = subprocess.run([cli(), "mesh", "v.nii.gz", "--label", "1", "--all", "--frame", frame, "-o", "m.ply",
                            "--json"], cwd=tmp_path, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert json.loads(r.stdout)["frame"] == frame.upper()
        got = ply_vertices(tmp_path / "m.ply")
        assert got.shape == expected.shape
        np.testing.assert_allclose(sorted_rows(got), sorted_rows(expected * flip), atol=1e-4)
    # The first voxel's centre is where nibabel's affine puts it, in the frame asked for.
    r = subprocess.run([cli(), "info", "v.nii.gz", "--frame", "ras", "--json"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    np.testing.assert_allclose(json.loads(r.stdout)["origin"], affine[:3, 3], atol=1e-4)


def test_a_seed_point_is_in_the_frame_asked_for(tmp_path):
    affine = np.diag([2.0, 2.0, 2.0, 1.0])
    affine[:3, 3] = [-40, 30, 10]
    data = np.zeros((20, 20, 20), np.uint8)
    data[2:6, 2:6, 2:6] = 1      # near voxel (4, 4, 4): RAS (-32, 38, 18)
    data[14:18, 14:18, 14:18] = 1
    nib.Nifti1Image(data, affine).to_filename(tmp_path / "two.nii")
    point = (affine @ [4, 4, 4, 1])[:3]
    r = subprocess.run([cli(), "mesh", "two.nii", "--label", "1", "--frame", "ras", "--seed-point",
                        ",".join(map(str, point)), "-o", "s.ply", "--quiet"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    vertices = ply_vertices(tmp_path / "s.ply")
    centre = vertices.mean(axis=0)
    assert np.linalg.norm(centre - (affine @ [3.5, 3.5, 3.5, 1])[:3]) < 1.0


def test_disagreeing_qform_and_sform_are_named(tmp_path):
    data = np.zeros((8, 8, 8), np.uint8)
    data[2:5, 2:5, 2:5] = 1
    q = np.diag([1.0, 1.0, 1.0, 1.0])
    s = q.copy()
    s[:3, 3] = [5, 0, 0]
    image = nib.Nifti1Image(data, q)
    image.set_qform(q, code=1)
    image.set_sform(s, code=2)
    image.to_filename(tmp_path / "forms.nii")
    r = subprocess.run([cli(), "info", "forms.nii", "--json", "--frame", "ras"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert len(info["warnings"]) == 1 and "qform and sform disagree" in info["warnings"][0]
    used = "qform" if np.allclose(info["origin"], q[:3, 3]) else "sform"
    assert np.allclose(info["origin"], (q if used == "qform" else s)[:3, 3])
    assert f"follows the {used}" in info["warnings"][0]
    assert "disagree" in r.stderr
    # Agreeing forms: no warning.
    image.set_sform(q, code=2)
    image.to_filename(tmp_path / "same.nii")
    r = subprocess.run([cli(), "info", "same.nii", "--json"], cwd=tmp_path, capture_output=True, text=True)
    assert json.loads(r.stdout)["warnings"] == [] and r.stderr == ""
