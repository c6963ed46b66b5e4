"""surftrack.label_surfaces(walls="shared", smooth=N) and `labels --walls shared --smooth` against
numpy computations (docs/theory.md §12, "Smoothing the complex"): after smoothing every wall
triangle of a label is reversed in exactly one other label or over the domain's border, at
bit-identical coordinates; the faces are the unsmoothed ones; every vertex lies on its surfel's
segment; every voxel centre is inside its own label's mesh only and random points inside at most
one label, by solid angles; the refusals."""
import json
import subprocess

import numpy as np
import pytest

import surftrack
from test_shared_walls import cli, directed_triangles, reverse, shared, winding_numbers


def volume(surface):
    """The signed volume the mesh encloses (divergence theorem), by numpy."""
    v = surface.vertices[surface.faces.astype(np.int64)]
    return float(np.einsum("fi,fi->f", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6)


def test_smoothed_walls_stay_shared_and_space_stays_partitioned(rng):
    for trial in range(15):
        shape = tuple(int(n) for n in rng.integers(2, 6, size=3))
        count = int(rng.integers(2, 13))
        palette = rng.choice(np.arange(1, 1000), size=count, replace=False).astype(np.uint16)
        labels = palette[rng.integers(0, count, size=shape)]
        plain = shared(labels, background=65535)
        surfaces = shared(labels, background=65535, smooth=int(rng.integers(1, 30)))
        assert sorted(surfaces) == sorted(plain)
        owner = {}
        for label, s in surfaces.items():
            assert np.array_equal(s.faces, plain[label].faces)
            assert set(s.refine) >= {"volume_before", "volume_after", "max_vertex_displacement"}
            assert s.refine["volume_before"] == pytest.approx(volume(plain[label]), rel=1e-9)
            assert s.refine["volume_after"] == pytest.approx(volume(s), rel=1e-9)
            moved = np.linalg.norm(s.vertices - plain[label].vertices, axis=1).max()
            assert s.refine["max_vertex_displacement"] == pytest.approx(moved, rel=1e-12, abs=1e-15)
            # On the segment from c to d, strictly inside it.
            c, d = s.surfels[:, 0].astype(float), s.surfels[:, 1].astype(float)
            axis = np.argmax(np.abs(d - c), axis=1)
            rows = np.arange(len(c))
            t = (s.vertices[rows, axis] - c[rows, axis]) / (d[rows, axis] - c[rows, axis])
            off = s.vertices - (c + t[:, None] * (d - c))
            assert np.abs(off).max() < 1e-12 and t.min() > 0 and t.max() < 1, (trial, label)
            for tri in directed_triangles(s):
                assert tri not in owner, "a directed triangle in two meshes"
                owner[tri] = label
        twins = 0
        for tri, label in owner.items():
            twin = owner.get(reverse(tri))
            if twin is not None:
                assert twin != label
                twins += 1
        plain_owner = {tri for s in plain.values() for tri in directed_triangles(s)}
        assert twins == sum(reverse(tri) in plain_owner for tri in plain_owner), trial
        centres = np.argwhere(np.ones(shape, bool)).astype(float)
        points = -0.9 + rng.uniform(0, 1, size=(12, 3)) * (np.array(shape) + 0.8)
        total = np.zeros(len(points))
        for label, s in surfaces.items():
            w = winding_numbers(s.vertices, s.faces.astype(np.int64), centres)
            assert np.allclose(w, np.round(w), atol=1e-6)
            inside = np.round(w).astype(int)
            assert np.array_equal(inside, (labels[tuple(centres.astype(int).T)] == label).astype(int)), (trial, label)
            wp = winding_numbers(s.vertices, s.faces.astype(np.int64), points)
            assert np.allclose(wp, np.round(wp), atol=1e-6)
            assert set(np.round(wp).astype(int)) <= {0, 1}
            total += np.round(wp)
        assert total.max() <= 1, "a point inside two labels"


def test_smooth_needs_shared_walls():
    labels = np.ones((3, 3, 3), np.uint8)
    with pytest.raises(ValueError, match="shared"):
        surftrack.label_surfaces(labels, walls="independent", smooth=5)
    with pytest.raises(ValueError, match="smooth"):
        shared(labels, smooth=-1)
    assert not getattr(shared(labels, smooth=0)[1], "refine", None)


def test_cli_smooth(tmp_path, rng):
    a = rng.integers(0, 5, size=(6, 5, 4)).astype(np.uint8)
    a.tofile(tmp_path / "a.raw")
    raw = ["--raw-dims", "4,5,6", "--raw-type", "uint8"]
    r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "all.ply", "--walls", "shared", "--smooth", "7",
                        "--json", "--threads", "1"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["smooth_iterations"] == 7
    surfaces = shared(a, smooth=7)
    rows = {row["label"]: row for row in report["labels"]}
    for label, s in surfaces.items():
        assert rows[label]["triangles"] == len(s.faces), label
        assert rows[label]["volume"] == pytest.approx(volume(s), rel=1e-9)
        assert rows[label]["volume_before_smoothing"] == pytest.approx(s.refine["volume_before"], rel=1e-9)
        assert rows[label]["max_vertex_displacement"] == pytest.approx(s.refine["max_vertex_displacement"], rel=1e-9)
    # --smooth without N: the labels' default.
    r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "all.ply", "--walls", "shared", "--smooth", "--json"],
                       cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["smooth_iterations"] == 50
    r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "all.ply", "--walls", "independent", "--smooth", "5"],
                       cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode != 0 and "--walls shared" in r.stderr and len(r.stderr.strip().splitlines()) == 1
