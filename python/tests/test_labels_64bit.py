"""Label ids are exact over the whole of every integer type: uint64 segment ids above 2^53 (where
floats skip integers) stay themselves through the Python API, the CLI, its table and its PLY
files. Oracles: numpy on the voxels, meshio reading the PLY files."""
import csv
import os
import pathlib
import subprocess

import numpy as np
import pytest

import surftrack

TWO53 = 2**53
IDS = [TWO53, TWO53 + 1, 864691135501989106, 864691135501989107, 2**64 - 1]


def cli():
    path = os.environ.get("SURFTRACK_CLI") or str(
        pathlib.Path(__file__).resolve().parents[2] / "build" / "cli" / "surftrack")
    assert os.access(path, os.X_OK), f"the surftrack CLI is not built at {path}"
    return path


def volume(seed):
    rng = np.random.default_rng(seed)
    a = np.zeros((10, 9, 8), np.uint64)
    for label in IDS:  # a few boxes each, overlapping: later labels cut earlier ones
        for _ in range(2):
            lo = rng.integers(0, 6, 3)
            hi = lo + rng.integers(1, 4, 3)
            a[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = np.uint64(label)
    return a


def boundary_faces(a, label):
    """The faces between a voxel of `label` and any other voxel or the outside."""
    inside = np.pad(a == np.uint64(label), 1)
    return sum(int(np.count_nonzero(inside & ~np.roll(inside, s, axis))) for axis in range(3) for s in (1, -1))


@pytest.mark.parametrize("seed", range(20))
def test_label_surfaces_keeps_every_id_exact(seed):
    a = volume(seed)
    present = sorted(int(v) for v in np.unique(a) if v != 0)
    surfaces = surftrack.label_surfaces(a, walls="independent")
    assert sorted(surfaces) == present
    for label, s in surfaces.items():
        assert type(label) is int
        assert s.voxels == int(np.count_nonzero(a == np.uint64(label)))
        assert len(s.vertices) == boundary_faces(a, label)
        alone = surftrack.extract(a, label=label, mode="all")
        assert len(alone.vertices) == len(s.vertices)
    only = present[1:3]
    assert sorted(surftrack.label_surfaces(a, only=only, walls="independent")) == only
    assert sorted(surftrack.label_surfaces(a, only=np.array(only, np.uint64), walls="independent")) == only
    assert sorted(surftrack.label_surfaces(a, label_range=(present[1], present[-1]), walls="independent")) == present[1:]


def test_a_seed_selects_its_own_64_bit_label():
    a = np.zeros((8, 8, 8), np.uint64)
    a[1:3, 1:3, 1:3] = TWO53
    a[5:7, 5:7, 5:7] = TWO53 + 1
    s = surftrack.extract(a, label=TWO53 + 1, seed=(5, 5, 5))
    assert s.vertices.min() == pytest.approx(4.5) and s.vertices.max() == pytest.approx(6.5)
    s = surftrack.extract(a, label=np.uint64(TWO53), mode="largest")
    assert s.vertices.max() == pytest.approx(2.5)


@pytest.mark.parametrize("bad, error", [(2.5, ValueError), (float(TWO53 + 2), ValueError), (2**64, ValueError),
                                        (-1, ValueError), ("1", TypeError), (None, None)])
def test_labels_that_are_not_values_are_refused(bad, error):
    a = volume(1)
    if error is None:
        return
    with pytest.raises(error):
        surftrack.extract(a, label=bad, mode="all")
    with pytest.raises(error):
        surftrack.label_surfaces(a, only=[bad], walls="independent")


PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "<i2", "ushort": "<u2", "int": "<i4", "uint": "<u4",
             "float": "<f4", "double": "<f8"}


def read_ply(path):
    """A binary little-endian PLY of triangles, read from the format's definition with numpy
    (meshio cannot read a face property after the index list): each element as a structured
    array."""
    data = pathlib.Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode().splitlines()
    assert lines[1] == "format binary_little_endian 1.0"
    elements = []
    for line in lines:
        words = line.split()
        if words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and words[1] == "list":
            assert words[2:4] == ["uchar", "int"]
            elements[-1][2].extend([("count", "u1"), (words[4], "<i4", (3,))])  # triangles only
        elif words[0] == "property":
            elements[-1][2].append((words[2], PLY_TYPES[words[1]]))
    out, offset = {}, end
    for name, count, fields in elements:
        dtype = np.dtype(fields)
        out[name] = np.frombuffer(data, dtype, count, offset)
        offset += dtype.itemsize * count
    assert offset == len(data)
    if "face" in out:
        assert np.all(out["face"]["count"] == 3)
    return out


def run(*args, cwd):
    return subprocess.run([cli(), *map(str, args)], cwd=cwd, capture_output=True, text=True)


def test_cli_mesh_labels_table_and_ply_are_exact(tmp_path):
    a = volume(7)
    present = sorted(int(v) for v in np.unique(a) if v != 0)
    # numpy's (z, y, x) array written in C order is the raw file's x-fastest layout.
    a.tofile(tmp_path / "seg.raw")
    raw = ["--raw-dims", f"{a.shape[2]},{a.shape[1]},{a.shape[0]}", "--raw-type", "uint64"]
    for label in present:
        r = run("mesh", "seg.raw", *raw, "--label", label, "--all", "-o", "one.ply", "--quiet", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        assert len(read_ply(tmp_path / "one.ply")["vertex"]) == boundary_faces(a, label)
    r = run("mesh", "seg.raw", *raw, "--label", 2**64, "--all", "-o", "x.ply", cwd=tmp_path)
    assert r.returncode != 0 and "not an integer label" in r.stderr
    assert not (tmp_path / "x.ply").exists()

    r = run("labels", "seg.raw", "--walls", "independent", *raw, "-o", "out/", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    with open(tmp_path / "out" / "labels.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(row["label"]) for row in rows] == present
    for row in rows:
        assert int(row["voxels"]) == int(np.count_nonzero(a == np.uint64(int(row["label"]))))
        assert row["label"] in row["file"]

    r = run("labels", "seg.raw", "--walls", "independent", *raw, "-o", "all.ply", "--labels", f"{present[1]}-{present[-1]}", "--quiet",
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ply = read_ply(tmp_path / "all.ply")
    assert ply["vertex"].dtype["label_high"] == np.dtype("<u4")  # no negative label: unsigned
    for element in ("vertex", "face"):
        high = ply[element]["label_high"].astype(np.uint64)
        low = ply[element]["label_low"].astype(np.uint64)
        labels = (high << np.uint64(32)) | low
        assert sorted(int(v) for v in np.unique(labels)) == present[1:]
    surfaces = surftrack.label_surfaces(a, walls="independent")
    for label in present[1:]:  # the face labels: each label's triangles
        assert int(np.count_nonzero(labels == np.uint64(label))) == len(surfaces[label].faces)
    vertex_labels = (ply["vertex"]["label_high"].astype(np.uint64) << np.uint64(32)) | ply["vertex"]["label_low"]
    for label in present[1:]:
        assert int(np.count_nonzero(vertex_labels == np.uint64(label))) == boundary_faces(a, label)


def test_cli_small_labels_keep_the_int_property(tmp_path):
    a = np.zeros((6, 6, 6), np.int64)
    a[1:3, 1:3, 1:3] = -5
    a[3:5, 3:5, 3:5] = 7
    a.tofile(tmp_path / "small.raw")
    r = run("labels", "small.raw", "--walls", "independent", "--raw-dims", "6,6,6", "--raw-type", "int64", "-o", "all.ply", "--quiet",
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ply = read_ply(tmp_path / "all.ply")
    assert sorted(np.unique(ply["vertex"]["label"]).tolist()) == [-5, 7]
    assert sorted(np.unique(ply["face"]["label"]).tolist()) == [-5, 7]


def test_cli_negative_wide_labels_are_signed_words(tmp_path):
    a = np.zeros((6, 6, 6), np.int64)
    a[1:3, 1:3, 1:3] = -(2**40) - 3
    a[3:5, 3:5, 3:5] = 2**62 + 1
    a.tofile(tmp_path / "wide.raw")
    r = run("labels", "wide.raw", "--walls", "independent", "--raw-dims", "6,6,6", "--raw-type", "int64", "-o", "all.ply", "--quiet",
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ply = read_ply(tmp_path / "all.ply")
    assert ply["face"].dtype["label_high"] == np.dtype("<i4")
    labels = ply["face"]["label_high"].astype(np.int64) * 2**32 + ply["face"]["label_low"].astype(np.int64)
    assert sorted(np.unique(labels).tolist()) == [-(2**40) - 3, 2**62 + 1]
