"""surftrack.label_surfaces(walls="shared", max_error=, reduce=) and `labels --walls shared
--max-error --reduce` against numpy computations (docs/theory.md §12, "Decimating the complex"):
after decimation every wall triangle of a label is reversed in exactly one other label or lies on
the outside's wall, at bit-identical coordinates; every vertex is one the undecimated labels had,
at the same point; each label's mesh stays closed and oriented with the Euler characteristic and
components it had (counted by numpy); by solid angles, no point inside two labels; the CLI's PLY and table read back with numpy; the
refusals."""
import json
import subprocess

import numpy as np
import pytest

import surftrack
from test_complex_smoothing import volume
from test_labels_64bit import read_ply
from test_shared_walls import cli, directed_triangles, reverse, shared, winding_numbers


def topology(surface):
    """(closed and oriented, Euler characteristic, components) of a mesh, by numpy."""
    f = surface.faces.astype(np.int64)
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    forward = {tuple(e) for e in directed.tolist()}
    closed = len(forward) == len(directed) and all((b, a) in forward for a, b in forward)
    used = np.unique(f)
    edges = {tuple(sorted(e)) for e in directed.tolist()}
    parent = {int(v): int(v) for v in used}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for a, b in edges:
        parent[find(a)] = find(b)
    components = len({find(int(v)) for v in used})
    return closed, len(used) - len(edges) + len(f), components


def blocks(rng, shape, count, size):
    """A label image of random blocks of `size` voxels: flat walls with room to decimate."""
    coarse = rng.integers(0, count, size=tuple(-(-n // size) for n in shape))
    palette = rng.choice(np.arange(1, 1000), size=count, replace=False).astype(np.uint16)
    big = np.repeat(np.repeat(np.repeat(palette[coarse], size, 0), size, 1), size, 2)
    return np.ascontiguousarray(big[:shape[0], :shape[1], :shape[2]])


def test_decimated_walls_stay_shared(rng):
    total_before = total_after = 0
    for trial in range(6):
        shape = tuple(int(n) for n in rng.integers(6, 10, size=3))
        labels = blocks(rng, shape, int(rng.integers(2, 6)), int(rng.integers(2, 5)))
        kwargs = [{"max_error": 0.4}, {"reduce": 0.7}, {"max_error": 0.5, "reduce": 0.6}][trial % 3]
        smooth = 10 if trial % 2 else 0
        plain = shared(labels, background=65535, smooth=smooth)
        surfaces = shared(labels, background=65535, smooth=smooth, **kwargs)
        assert sorted(surfaces) == sorted(plain)
        points = {tuple(p) for s in plain.values() for p in s.vertices.tolist()}
        owner = {}
        for label, s in surfaces.items():
            # Every vertex one of the undecimated complex, at the same point: nothing moved.
            assert {tuple(p) for p in s.vertices.tolist()} <= points
            assert s.refine["triangles_before"] == len(plain[label].faces)
            assert s.refine["triangles_after"] == len(s.faces) <= len(plain[label].faces)
            assert s.refine["volume_after"] == pytest.approx(volume(s), rel=1e-9)
            if "reduce" in kwargs:
                assert s.refine["target_triangles"] == round((1 - kwargs["reduce"]) * len(plain[label].faces))
            closed, euler, components = topology(s)
            assert closed, (trial, label)
            assert (euler, components) == topology(plain[label])[1:], (trial, label)
            total_before += len(plain[label].faces)
            total_after += len(s.faces)
            for tri in directed_triangles(s):
                assert tri not in owner, "a directed triangle in two meshes"
                owner[tri] = label
        for tri, label in owner.items():
            twin = owner.get(reverse(tri))
            if twin is not None:
                assert twin != label
            elif not smooth:  # on the outside's wall: every point a midpoint on the domain's border
                p = np.array(tri)
                assert np.all(np.any((p == -0.5) | (p == np.array(shape) - 0.5), axis=1)), (trial, tri)
        # No two labels overlap: at random points every label's winding number is 0 or 1 and
        # their sum at most 1. (Not the voxel centres: the collapses keep the walls within
        # max_error, not every voxel inside, and a wall may pass through one.)
        queries = -0.9 + rng.uniform(0, 1, size=(300, 3)) * (np.array(shape) + 0.8)
        total = np.zeros(len(queries))
        for label, s in surfaces.items():
            w = winding_numbers(s.vertices, s.faces.astype(np.int64), queries)
            assert np.allclose(w, np.round(w), atol=1e-6)
            assert set(np.round(w).astype(int)) <= {0, 1}, (trial, label)
            total += np.round(w)
        assert total.max() <= 1, (trial, "a point inside two labels")
    assert total_after < 0.8 * total_before, (total_before, total_after)


def test_decimation_needs_shared_walls_and_good_values():
    labels = np.ones((3, 3, 3), np.uint8)
    with pytest.raises(ValueError, match="shared"):
        surftrack.label_surfaces(labels, walls="independent", max_error=0.5)
    with pytest.raises(ValueError, match="shared"):
        surftrack.label_surfaces(labels, walls="independent", reduce=0.5)
    with pytest.raises(ValueError, match="max error"):
        shared(labels, max_error=-1.0)
    with pytest.raises(ValueError, match="reduction"):
        shared(labels, reduce=1.5)


def test_cli_decimation(tmp_path, rng):
    a = blocks(rng, (8, 7, 6), 4, 3).astype(np.uint16)
    a.tofile(tmp_path / "a.raw")
    raw = ["--raw-dims", "6,7,8", "--raw-type", "uint16"]

    def run(*extra):
        r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "all.ply", "--walls", "shared", "--json",
                            "--threads", "1", *extra], cwd=tmp_path, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        return json.loads(r.stdout), read_ply(tmp_path / "all.ply")
    plain, _ = run()
    report, ply = run("--max-error", "0.4", "--reduce", "0.5")
    assert report["max_error"] == 0.4 and report["reduce"] == 0.5
    before = {row["label"]: row for row in plain["labels"]}
    rows = {row["label"]: row for row in report["labels"]}
    assert sorted(rows) == sorted(before)
    points = ply["vertex"][["x", "y", "z"]]
    points = np.stack([points["x"], points["y"], points["z"]], axis=1).astype(float)
    owner = {}
    for label, row in rows.items():
        faces = ply["face"]["vertex_indices"][ply["face"]["label"] == label].astype(np.int64)
        assert row["triangles"] == len(faces) < before[label]["triangles"], label
        assert row["triangles_before_decimation"] == before[label]["triangles"]
        assert row["target_triangles"] == round(0.5 * before[label]["triangles"])
        assert row["volume_before_decimation"] == pytest.approx(before[label]["volume"], rel=1e-9)
        v = points[faces]
        assert row["volume"] == pytest.approx(np.einsum("fi,fi->f", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6,
                                              rel=1e-5)
        assert before[label]["euler"] == row["euler"] and before[label]["boundaries"] == row["boundaries"]
        for f in faces:
            t = [tuple(points[i]) for i in f]
            k = t.index(min(t))
            owner[tuple(t[k:] + t[:k])] = label
    # Twins between labels, or the outside's wall on the domain's border.
    for tri, label in owner.items():
        twin = owner.get(reverse(tri))
        assert twin != label
        if twin is None:
            p = np.array(tri)
            assert np.all(np.any((p == -0.5) | (p == np.array([6, 7, 8]) - 0.5), axis=1))
    r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "all.ply", "--walls", "independent", "--max-error", "0.5"],
                       cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode != 0 and "--walls shared" in r.stderr and len(r.stderr.strip().splitlines()) == 1
