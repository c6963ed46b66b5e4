"""surftrack.label_surfaces(walls="shared") against numpy computations (docs/theory.md §12): every
wall triangle of a label reversed in exactly one other label or over the domain's border, at the
same coordinates; every voxel centre inside its own label's mesh only, by solid angles; the
default and bad input."""
import warnings

import numpy as np
import pytest

import surftrack


def winding_numbers(vertices, faces, points):
    """Sum of the signed solid angles of the triangles seen from each point, over 4 pi (Van
    Oosterom and Strackee)."""
    v = vertices[faces][None, :, :, :] - points[:, None, None, :]  # (P, F, 3, 3)
    length = np.linalg.norm(v, axis=-1)
    a, b, c = v[:, :, 0], v[:, :, 1], v[:, :, 2]
    det = np.einsum("pfi,pfi->pf", a, np.cross(b, c))
    den = (length[:, :, 0] * length[:, :, 1] * length[:, :, 2] + np.einsum("pfi,pfi->pf", a, b) * length[:, :, 2]
           + np.einsum("pfi,pfi->pf", a, c) * length[:, :, 1] + np.einsum("pfi,pfi->pf", b, c) * length[:, :, 0])
    return (2 * np.arctan2(det, den)).sum(axis=1) / (4 * np.pi)


def directed_triangles(surface):
    out = []
    for f in surface.faces:
        t = [tuple(surface.vertices[i].tolist()) for i in f]
        k = t.index(min(t))
        out.append(tuple(t[k:] + t[:k]))
    return out


def reverse(t):
    a, b, c = t
    r = [a, c, b]
    k = r.index(min(r))
    return tuple(r[k:] + r[:k])


def shared(labels, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pinch copies are announced as warnings
        return surftrack.label_surfaces(labels, walls="shared", threads=1, **kwargs)


def test_walls_are_shared_and_space_is_partitioned(rng):
    for trial in range(40):
        shape = tuple(int(n) for n in rng.integers(2, 6, size=3))
        count = int(rng.integers(2, 13))
        palette = rng.choice(np.arange(1, 1000), size=count, replace=False).astype(np.uint16)
        labels = palette[rng.integers(0, count, size=shape)]
        # No background in the image: only the outside of the domain is background.
        surfaces = shared(labels, background=65535)
        assert sorted(surfaces) == sorted(int(v) for v in np.unique(labels))
        owner = {}
        for label, s in surfaces.items():
            for t in directed_triangles(s):
                assert t not in owner, "a directed triangle in two meshes"
                owner[t] = label
        for t, label in owner.items():
            twin = owner.get(reverse(t))
            if twin is None:  # over the border: every vertex has a coordinate -0.5 or n - 0.5
                for p in t:
                    assert any(x == -0.5 or x == n - 0.5 for x, n in zip(p, shape)), (trial, t)
            else:
                assert twin != label
        centres = np.argwhere(np.ones(shape, bool)).astype(float)
        for label, s in surfaces.items():
            w = winding_numbers(s.vertices, s.faces.astype(np.int64), centres)
            assert np.allclose(w, np.round(w), atol=1e-6)
            inside = np.round(w).astype(int)
            assert np.array_equal(inside, (labels[tuple(centres.astype(int).T)] == label).astype(int)), (trial, label)


def same_meshes(a, b):
    assert sorted(a) == sorted(b)
    return all(np.array_equal(a[k].vertices, b[k].vertices) and np.array_equal(a[k].faces, b[k].faces) for k in a)


def test_shared_is_the_default_where_it_is_made(rng):
    labels = rng.integers(0, 4, size=(5, 4, 6)).astype(np.uint8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        default = surftrack.label_surfaces(labels, threads=1)
        independent = surftrack.label_surfaces(labels, threads=1, walls="independent")
        assert same_meshes(default, shared(labels))
        assert not same_meshes(default, independent)  # (this image has walls between labels)
        assert same_meshes(surftrack.label_surfaces(labels, threads=1, adjacency="6-26"),
                           shared(labels, adjacency="6-26"))
        # Where shared walls are not made, the default is each label against the rest.
        for kwargs in ({"boundaries": "largest"}, {"adjacency": "18-6"}, {"adjacency": "6-18"},
                       {"seeds": [tuple(int(i) for i in np.argwhere(labels == 1)[0])]}):
            assert same_meshes(surftrack.label_surfaces(labels, threads=1, **kwargs),
                               surftrack.label_surfaces(labels, threads=1, walls="independent", **kwargs)), kwargs


def test_bad_walls_and_refusals():
    labels = np.ones((3, 3, 3), np.uint8)
    with pytest.raises(ValueError, match="walls"):
        surftrack.label_surfaces(labels, walls="both")
    with pytest.raises(ValueError):
        surftrack.label_surfaces(labels, walls="shared", boundaries="largest")


def cli():
    import os
    import pathlib
    path = os.environ.get("SURFTRACK_CLI") or str(
        pathlib.Path(__file__).resolve().parents[2] / "build" / "cli" / "surftrack")
    assert os.access(path, os.X_OK), f"the surftrack CLI is not built at {path}"
    return path


def test_cli_walls(tmp_path, rng):
    import json
    import subprocess
    a = rng.integers(0, 5, size=(6, 5, 4)).astype(np.uint8)
    a.tofile(tmp_path / "a.raw")
    raw = ["--raw-dims", "4,5,6", "--raw-type", "uint8"]
    r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "all.ply", "--walls", "shared", "--json", "--threads", "1"],
                       cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["walls"] == "shared"
    # The same meshes as the Python binding's (C order: the raw file's x is the last axis).
    surfaces = shared(a)
    rows = {row["label"]: row for row in report["labels"]}
    for label, s in surfaces.items():
        assert rows[label]["triangles"] == len(s.faces), label
    # Shared walls by default; independent where they are not made (--largest, 18-6).
    for extra, walls in (([], "shared"), (["--largest"], "independent"), (["--adjacency", "18-6"], "independent")):
        r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "d.ply", "--json", "--threads", "1", *extra],
                           cwd=tmp_path, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert json.loads(r.stdout)["walls"] == walls, extra
        assert r.stderr.count("\n") <= 1  # the pinches in one line at most
    r = subprocess.run([cli(), "labels", "a.raw", *raw, "-o", "all.ply", "--walls", "both"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode != 0 and "--walls" in r.stderr


def test_the_same_meshes_on_1_2_7_threads(rng):
    # The scan is one thread; the labels' meshes are finished in parallel, each the same for any
    # count (pinch splits included: noisy images have many).
    for trial in range(6):
        labels = rng.integers(0, 9, size=tuple(int(n) for n in rng.integers(4, 12, size=3))).astype(np.uint16)
        ref = shared(labels)
        for threads in (2, 7):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                got = surftrack.label_surfaces(labels, walls="shared", threads=threads)
            assert same_meshes(ref, got), (trial, threads)
