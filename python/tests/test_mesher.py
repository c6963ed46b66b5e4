"""surftrack.Mesher, zmesh's interface: ids against numpy's unique labels, each label's vertices
against the boundary faces numpy finds by brute force (one vertex per voxel face between the
label and anything else, at the face's centre times the anisotropy), every mesh closed and
oriented, decimation keeping the topology, exact uint64 ids, and bad input refused."""
import warnings

import numpy as np
import pytest

import surftrack


def brute_force_face_centres(labels, label, anisotropy):
    """The centres of the voxel faces between `label` and any other value or the outside,
    in physical units, as a set of rounded tuples."""
    inside = np.pad(labels == label, 1, constant_values=False)
    centres = []
    for axis in range(3):
        for step in (1, -1):
            moved = np.roll(inside, -step, axis=axis)
            c = np.argwhere(inside & ~moved) - 1  # voxel of the label, its neighbour not
            mid = c.astype(float)
            mid[:, axis] += 0.5 * step
            centres.append(mid)
    points = np.concatenate(centres) * np.asarray(anisotropy)
    return {tuple(p) for p in np.round(points, 6)}


def edges_of(faces):
    """The directed edges of the faces."""
    return np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])


def expect_closed_oriented(mesh):
    """Every directed edge once, and its reverse once: closed, oriented, manifold at edges."""
    directed = edges_of(mesh.faces.astype(np.int64))
    keys = directed[:, 0] * (len(mesh.vertices) + 1) + directed[:, 1]
    reverse = directed[:, 1] * (len(mesh.vertices) + 1) + directed[:, 0]
    assert len(np.unique(keys)) == len(keys)
    assert np.array_equal(np.sort(keys), np.sort(reverse))


def euler(mesh):
    return len(mesh.vertices) - len(edges_of(mesh.faces)) // 2 + len(mesh.faces)


def random_labels(rng, dtype, ids):
    shape = tuple(rng.integers(4, 12, size=3))
    labels = np.zeros(shape, dtype=dtype)
    for _ in range(int(rng.integers(1, 6))):
        lo = rng.integers(0, shape, size=3)
        hi = lo + rng.integers(1, 6, size=3)
        labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = ids[int(rng.integers(len(ids)))]
    return labels


@pytest.mark.parametrize("dtype,ids", [
    (np.uint8, [1, 2, 3, 255]),
    (np.int16, [1, -7, 300]),
    (np.uint32, [5, 2**32 - 1]),
    (np.uint64, [2**64 - 1, 2**64 - 2, 2**53 + 1, 2**53]),
    (np.int64, [-(2**63), 2**62 + 1]),
])
def test_meshes_are_the_labels_boundaries(dtype, ids):
    rng = np.random.default_rng(11)
    for case in range(40):
        labels = random_labels(rng, dtype, ids)
        anisotropy = tuple(rng.choice([1.0, 4.0, 40.0, 0.5], size=3))
        mesher = surftrack.Mesher(anisotropy)
        mesher.mesh(labels)
        expected = sorted(int(v) for v in np.unique(labels) if v != 0)
        assert mesher.ids() == expected
        for segid in mesher.ids():
            mesh = mesher.get(segid, normals=True)
            assert mesh.segid == segid and type(segid) is int
            assert mesh.vertices.dtype == np.float32 and mesh.faces.dtype == np.uint32
            got = {tuple(p) for p in np.round(mesh.vertices.astype(float), 3)}
            want = {tuple(np.round(p, 3)) for p in brute_force_face_centres(labels, dtype(segid), anisotropy)}
            assert got == want, (case, segid)
            assert len(mesh.vertices) == len(want)
            expect_closed_oriented(mesh)
            assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1, atol=1e-5)


def test_decimation_keeps_topology_and_surfels():
    i, j, k = np.indices((40, 40, 40))
    labels = np.zeros((40, 40, 40), np.uint64)
    labels[(i - 20) ** 2 + (j - 20) ** 2 + (k - 20) ** 2 < 15 ** 2] = 2**64 - 3
    labels[5:15, 5:35, 25:35] = 9  # a slab with a hole through it: genus 1
    labels[8:12, 15:25, 25:35] = 0
    mesher = surftrack.Mesher((1.0, 1.0, 2.0))
    mesher.mesh(labels)
    for segid in mesher.ids():
        full = mesher.get(segid)
        light = mesher.get(segid, reduction_factor=5, max_error=2.0)
        assert len(light.faces) < 0.5 * len(full.faces)
        assert euler(light) == euler(full)
        expect_closed_oriented(light)
        # The vertices stay surfels: each is one of the undecimated mesh's vertices.
        full_set = {tuple(p) for p in np.round(full.vertices, 3)}
        assert {tuple(p) for p in np.round(light.vertices, 3)} <= full_set
        old = mesher.get_mesh(segid, simplification_factor=5, max_simplification_error=2.0)
        assert np.array_equal(old.vertices, light.vertices) and np.array_equal(old.faces, light.faces)
        assert np.array_equal(mesher.get(segid, reduction_factor=1).faces, full.faces)


def test_voxel_centred_erase_clear():
    labels = np.zeros((6, 7, 8), np.uint16)
    labels[1:3, 2:5, 3:6] = 4
    labels[3:5, 2:5, 3:6] = 2
    mesher = surftrack.Mesher((2, 3, 4))
    mesher.mesh(labels)
    plain, centred = mesher.get(4), mesher.get(4, voxel_centered=True)
    assert np.allclose(centred.vertices - plain.vertices, [1.0, 1.5, 2.0])
    assert mesher.get(np.uint16(2)).segid == 2
    mesher.erase(4)
    assert mesher.ids() == [2]
    with pytest.raises(KeyError, match="label 4 was not meshed"):
        mesher.get(4)
    mesher.clear()
    assert mesher.ids() == []
    mesher.mesh(np.zeros((3, 3, 3), np.uint64))  # all background: nothing to mesh
    assert mesher.ids() == []


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="anisotropy"):
        surftrack.Mesher((1, 0, 1))
    with pytest.raises(ValueError, match="anisotropy"):
        surftrack.Mesher((1, 1))
    with pytest.raises(TypeError, match="anisotropy"):
        surftrack.Mesher(3)
    mesher = surftrack.Mesher()
    with pytest.raises(ValueError, match="3-D"):
        mesher.mesh(np.zeros((4, 4), np.uint8))
    with pytest.raises(ValueError, match="integer labels"):
        mesher.mesh(np.zeros((4, 4, 4), np.float32))
    labels = np.zeros((4, 4, 4), np.uint8)
    labels[1:3, 1:3, 1:3] = 1
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesher.mesh(labels, close=False)
    assert any("always closed" in str(w.message) for w in caught)
    with pytest.raises(TypeError, match="integer"):
        mesher.get(1.0)
    with pytest.raises(ValueError, match="reduction_factor"):
        mesher.get(1, reduction_factor=-1)
    with pytest.raises(ValueError, match="max_error"):
        mesher.get(1, reduction_factor=2, max_error=float("nan"))
