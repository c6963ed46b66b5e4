"""Neuroglancer's legacy precomputed meshes (surftrack.write_precomputed, `surftrack labels
--format precomputed`), read back by a reader written here from the format's description
(info, <id>:0 manifests, fragments of uint32 count, float32 xyz nanometres, uint32 triangles,
segment_properties/info): each segment's vertices are its label's voxel-face centres found by
brute force with numpy, in nanometres and shifted by half a voxel; the CLI and Python write the
same bytes for the same volume; uint64 ids exact; bad input refused with nothing written."""
import json
import os
import subprocess

import numpy as np
import pytest

import surftrack

CLI = os.environ.get("SURFTRACK_CLI")


def read_precomputed(path):
    """{id: (vertices (N, 3) float32, faces (M, 3) uint32)}, the info and the names."""
    info = json.loads(open(os.path.join(path, "info")).read())
    assert info["@type"] == "neuroglancer_legacy_mesh"
    meshes = {}
    for name in os.listdir(path):
        if not name.endswith(":0"):
            continue
        segid = int(name[:-2])
        manifest = json.loads(open(os.path.join(path, name)).read())
        vertices, faces, base = [], [], 0
        for fragment in manifest["fragments"]:
            data = open(os.path.join(path, fragment), "rb").read()
            n = int(np.frombuffer(data[:4], "<u4")[0])
            v = np.frombuffer(data[4:4 + 12 * n], "<f4").reshape(n, 3)
            rest = np.frombuffer(data[4 + 12 * n:], "<u4")
            assert len(rest) % 3 == 0 and (len(rest) == 0 or rest.max() < n)
            vertices.append(v)
            faces.append(rest.reshape(-1, 3) + base)
            base += n
        meshes[segid] = (np.concatenate(vertices), np.concatenate(faces))
    names = {}
    if "segment_properties" in info:
        props = json.loads(open(os.path.join(path, info["segment_properties"], "info")).read())
        assert props["@type"] == "neuroglancer_segment_properties"
        label = next(p for p in props["inline"]["properties"] if p["type"] == "label")
        names = {int(i): v for i, v in zip(props["inline"]["ids"], label["values"])}
    return meshes, names


def face_centres_nm(labels, label, spacing_zyx, nm_per_unit):
    """The centres of the voxel faces between `label` and anything else, as Neuroglancer x, y, z
    nanometres with voxel i over [i, i + 1): sorted rows."""
    inside = np.pad(labels == label, 1, constant_values=False)
    points = []
    for axis in range(3):
        for step in (1, -1):
            c = np.argwhere(inside & ~np.roll(inside, -step, axis=axis)) - 1
            mid = c.astype(float) + 0.5  # voxel centres at i + 0.5 in Neuroglancer's grid
            mid[:, axis] += 0.5 * step
            points.append(mid)
    zyx = np.concatenate(points) * np.asarray(spacing_zyx) * nm_per_unit
    return np.unique(np.round(zyx[:, ::-1], 2), axis=0)


def test_segments_are_the_labels_voxel_faces_in_nanometres(tmp_path):
    rng = np.random.default_rng(5)
    ids = [2**64 - 1, 2**53 + 1, 2**53, 1, 77]
    for case in range(20):
        shape = tuple(rng.integers(4, 10, size=3))
        labels = np.zeros(shape, np.uint64)
        for _ in range(4):
            lo = rng.integers(0, shape, size=3)
            hi = lo + rng.integers(1, 5, size=3)
            labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = ids[int(rng.integers(len(ids)))]
        if not labels.any():
            continue
        spacing = tuple(float(v) for v in rng.choice([0.004, 0.04, 0.5], size=3))  # micrometres
        surfaces = surftrack.label_surfaces(labels, spacing=spacing, walls="independent")
        out = tmp_path / f"case{case}"
        surftrack.write_precomputed(surfaces, out, axes="zyx", unit="um", spacing=spacing,
                                    names={2**64 - 1: "the last id"})
        meshes, names = read_precomputed(out)
        assert sorted(meshes) == sorted(surfaces)
        if 2**64 - 1 in surfaces:
            assert names[2**64 - 1] == "the last id"
        for segid, (vertices, faces) in meshes.items():
            want = face_centres_nm(labels, np.uint64(segid), spacing, 1e3)
            got = np.unique(np.round(vertices.astype(float), 2), axis=0)
            assert np.allclose(got, want, atol=0.05, rtol=1e-6), (case, segid)
            assert len(vertices) == len(surfaces[segid].vertices)
            # The same triangles, wound to face out of the label in Neuroglancer's x, y, z (the
            # z, y, x columns read as x, y, z mirror: each is reversed), so the enclosed volume
            # is positive: the label's voxels times the voxel volume, in nm^3, up to the
            # midpoint surface's cut corners (at most the voxel count).
            assert np.array_equal(faces, surfaces[segid].faces[:, [0, 2, 1]])
            tri = vertices[faces].astype(np.float64)
            enclosed = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
            voxel = np.prod(spacing) * 1e9
            count = int((labels == np.uint64(segid)).sum())
            assert 0 < enclosed <= count * voxel * (1 + 1e-6), (enclosed, count * voxel)


@pytest.mark.skipif(not CLI, reason="SURFTRACK_CLI not set")
def test_cli_and_python_write_the_same_bytes(tmp_path):
    rng = np.random.default_rng(8)
    labels = rng.integers(0, 4, size=(9, 8, 7)).astype(np.uint64) * np.uint64(2**62 + 3)
    raw = tmp_path / "seg.raw"
    labels.tofile(raw)  # x fastest: array index [z, y, x]
    spacing_xyz = (4.0, 5.0, 40.0)
    cli_out = tmp_path / "cli"
    run = subprocess.run([CLI, "labels", str(raw), "--raw-dims", "7,8,9", "--raw-type", "uint64",
                          "--spacing", ",".join(map(str, spacing_xyz)), "--unit", "nm",
                          "--format", "precomputed", "-o", str(cli_out) + "/", "--quiet"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    surfaces = surftrack.label_surfaces(labels, spacing=spacing_xyz[::-1], walls="shared")
    py_out = tmp_path / "py"
    surftrack.write_precomputed(surfaces, py_out, axes="zyx", unit="nm", spacing=spacing_xyz[::-1])
    files = sorted(os.listdir(cli_out))
    assert files == sorted(os.listdir(py_out)) and len(files) == 1 + 2 * len(surfaces)
    for name in files:
        assert (cli_out / name).read_bytes() == (py_out / name).read_bytes(), name


@pytest.mark.skipif(not CLI, reason="SURFTRACK_CLI not set")
def test_bad_output_is_refused_and_nothing_written(tmp_path):
    labels = np.zeros((5, 5, 5), np.uint8)
    labels[1:3, 1:3, 1:3] = 3
    raw = tmp_path / "seg.raw"
    labels.tofile(raw)
    base = [CLI, "labels", str(raw), "--raw-dims", "5,5,5", "--raw-type", "uint8", "--format", "precomputed"]

    def refused(args, says):
        before = sorted(os.listdir(tmp_path))
        run = subprocess.run(base + args, capture_output=True, text=True)
        assert run.returncode != 0 and run.stderr.count("\n") == 1 and says in run.stderr, run.stderr
        assert sorted(os.listdir(tmp_path)) == before  # no output, no hidden temporary

    refused(["-o", str(tmp_path / "a") + "/"], "--unit")  # a raw file's spacing has no unit
    (tmp_path / "file").write_text("x")
    refused(["--unit", "nm", "-o", str(tmp_path / "file")], "not a directory")
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("x")
    refused(["--unit", "nm", "-o", str(tmp_path / "full") + "/"], "not empty")
    refused(["--unit", "nm", "-o", str(tmp_path / "m.ply")], "directory")
    refused(["--unit", "nm", "--background", "3", "-o", str(tmp_path / "b") + "/"], "positive uint64")

    surfaces = surftrack.label_surfaces(labels, walls="independent")
    with pytest.raises(ValueError, match="axes"):
        surftrack.write_precomputed(surfaces, tmp_path / "p", axes="yxz")
    with pytest.raises(ValueError, match="unit"):
        surftrack.write_precomputed(surfaces, tmp_path / "p", axes="zyx", unit="furlong")
    with pytest.raises(ValueError, match="positive uint64"):
        surftrack.write_precomputed({-4: surfaces[3]}, tmp_path / "p", axes="zyx")
    with pytest.raises(ValueError, match="float32"):
        surftrack.write_precomputed(surfaces, tmp_path / "p", axes="zyx", unit="m", spacing=(1e30, 1, 1))
    with pytest.raises(OSError):
        surftrack.write_precomputed(surfaces, tmp_path / "full", axes="zyx")
    assert not (tmp_path / "p").exists()
