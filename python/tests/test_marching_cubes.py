"""surftrack.marching_cubes against scikit-image's, on random smooth volumes."""
import numpy as np
import pytest
from scipy.spatial import cKDTree

import surftrack
from conftest import closed_oriented_manifold, smooth_volume

skimage_measure = pytest.importorskip("skimage.measure")


def winding_agrees_with_normals(verts, faces, normals):
    """Per face: whether its right-hand normal points the way its vertices' normals do."""
    tri = verts[faces].astype(np.float64)
    face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return np.sum(face_n * normals[faces].sum(axis=1), axis=1) > 0


CASES = [(seed, shape, spacing)
         for seed, (shape, spacing) in enumerate(
             [((12, 13, 14), (1, 1, 1)), ((20, 9, 16), (0.5, 2.0, 1.25)), ((8, 24, 10), (1, 1, 3)),
              ((16, 16, 16), (0.7, 0.7, 0.7))] * 25)]


@pytest.mark.parametrize("seed,shape,spacing", CASES)
def test_vertices_are_lorensens_on_every_inner_grid_edge(seed, shape, spacing):
    rng = np.random.default_rng(seed)
    volume = smooth_volume(rng, shape, sigma=1.5 + (seed % 3) * 0.5)
    level = float(np.quantile(volume, 0.3 + 0.4 * rng.random()))
    verts, faces, normals, values = surftrack.marching_cubes(volume, level, spacing=spacing)
    ref_verts, ref_faces, ref_normals, _ = skimage_measure.marching_cubes(
        volume, level, spacing=spacing, method="lorensen")
    assert verts.dtype == np.float32 and faces.dtype == np.int32 and normals.shape == verts.shape

    # Our vertices on grid edges whose two voxels lie in the domain are exactly Lorensen's.
    # skimage interpolates t = (level - f(c)) / (f(d) - f(c)) in single precision: the tolerance
    # is that rounding, which grows where f(d) - f(c) is small.
    surface = surftrack.extract(volume, level=level, mode="all", spacing=spacing, epsilon=1e-9)
    c, d = surface.surfels[:, 0], surface.surfels[:, 1]
    inner = np.all((d >= 0) & (d < np.array(shape)), axis=1)
    assert inner.sum() == len(ref_verts)
    fc, fd = volume[tuple(c[inner].T)], volume[tuple(d[inner].T)]
    tolerance = (1e-6 + 8 * 2.0 ** -24 * (abs(fc) + abs(fd) + abs(level)) / abs(fd - fc)) * max(spacing)
    dist, idx = cKDTree(verts[inner]).query(ref_verts)
    assert np.all(dist <= tolerance[idx])
    back, rev = cKDTree(ref_verts).query(verts[inner])  # and every one of ours is one of theirs
    assert np.all(back <= tolerance)

    # A closed oriented manifold, whose normals agree in sign with skimage's.
    assert closed_oriented_manifold(faces, len(verts))
    ours = normals[inner][idx]
    assert np.mean(np.sum(ours * ref_normals, axis=1) > 0) > 0.99
    # Faces wound as scikit-image winds them relative to the normals, for both gradient
    # directions: its faces read against its own normals give the sign ours must have.
    for direction in ("descent", "ascent"):
        v, f, n, _ = surftrack.marching_cubes(volume, level, spacing=spacing, gradient_direction=direction)
        rv, rf, rn, _ = skimage_measure.marching_cubes(volume, level, spacing=spacing, method="lorensen",
                                                       gradient_direction=direction)
        assert np.array_equal(v, verts) and np.array_equal(n, normals)
        agree = np.mean(winding_agrees_with_normals(v, f, n))
        ref_agree = np.mean(winding_agrees_with_normals(rv, rf, rn))
        assert (agree > 0.99 and ref_agree > 0.99) or (agree < 0.01 and ref_agree < 0.01), (direction, agree, ref_agree)


def test_refused_and_ignored_arguments():
    volume = smooth_volume(np.random.default_rng(3), (10, 10, 10))
    with pytest.raises(ValueError, match="within volume data range"):
        surftrack.marching_cubes(volume, volume.max() + 1)
    with pytest.raises(ValueError, match="step_size"):
        surftrack.marching_cubes(volume, step_size=2)
    with pytest.raises(ValueError, match="mask"):
        surftrack.marching_cubes(volume, mask=np.ones_like(volume, bool))
    with pytest.raises(ValueError, match="method"):
        surftrack.marching_cubes(volume, method="dual")
    v1, f1, n1, _ = surftrack.marching_cubes(volume, allow_degenerate=False, method="lorensen")
    v2, f2, n2, _ = surftrack.marching_cubes(volume, gradient_direction="ascent")
    assert np.array_equal(v1, v2) and np.array_equal(f1[:, ::-1], f2) and np.array_equal(n1, n2)
