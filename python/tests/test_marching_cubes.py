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
    with pytest.raises(ValueError, match="within volume data range"):
        surftrack.marching_cubes(volume, float("nan"))
    with pytest.raises(ValueError, match="step_size"):
        surftrack.marching_cubes(volume, step_size=2)
    with pytest.raises(ValueError, match="mask"):
        surftrack.marching_cubes(volume, mask=np.ones_like(volume, bool))
    with pytest.raises(ValueError, match="method"):
        surftrack.marching_cubes(volume, method="dual")
    with pytest.raises(ValueError, match="gradient_direction"):
        surftrack.marching_cubes(volume, gradient_direction="up")
    with pytest.raises(ValueError, match="allow_degenerate=False is not supported"):
        surftrack.marching_cubes(volume, allow_degenerate=False)
    with pytest.raises(ValueError, match="adjacency pair"):
        surftrack.marching_cubes(volume, adjacency="6-6")
    with pytest.raises(ValueError, match="spacing"):
        surftrack.marching_cubes(volume, spacing=(1, 0, 1))
    with pytest.raises(ValueError, match="threads"):
        surftrack.marching_cubes(volume, threads=-1)
    with pytest.raises(ValueError, match="empty selection.*outside the data range"):
        surftrack.marching_cubes(volume, float(volume.max()))  # no voxel above the maximum
    with pytest.raises(TypeError, match="dtype"):
        surftrack.marching_cubes(volume.astype(np.complex64))
    v1, f1, n1, _ = surftrack.marching_cubes(volume, allow_degenerate=True, method="lorensen")
    v2, f2, n2, _ = surftrack.marching_cubes(volume, gradient_direction="ascent")
    assert np.array_equal(v1, v2) and np.array_equal(f1[:, ::-1], f2) and np.array_equal(n1, n2)


def test_degenerate_triangles_only_where_the_level_is_a_voxel_value():
    """allow_degenerate: a triangle's float32 vertices coincide where the level equals the value
    of a voxel they lie next to (each sits 1e-9 of its edge from that voxel); a level between
    the voxel values gives none. Zero-area triangles counted with numpy."""
    def degenerate(verts, faces):
        t = verts[faces]
        return int(np.sum(np.all(t[:, 0] == t[:, 1], axis=1) | np.all(t[:, 0] == t[:, 2], axis=1)
                          | np.all(t[:, 1] == t[:, 2], axis=1)))
    rng = np.random.default_rng(11)
    for _ in range(5):
        volume = rng.integers(0, 4, (9, 10, 11)).astype(np.uint8)
        verts, faces, _, _ = surftrack.marching_cubes(volume, 1)
        assert degenerate(verts, faces) > 0
        verts, faces, _, _ = surftrack.marching_cubes(volume, 1.5)
        assert degenerate(verts, faces) == 0
        assert closed_oriented_manifold(faces, len(verts))


def numpy_marching_cubes(volume, level, spacing, gradient_direction, adjacency):
    """The arrays as surftrack.marching_cubes made them with numpy from extract()'s Surface
    before its binding wrote them itself: the oracle its arrays must equal bit for bit."""
    array = np.asarray(volume)
    if array.dtype == bool:
        array = array.view(np.uint8)
    surface = surftrack.extract(array, level=level, mode="all", adjacency=adjacency, mapping="linear",
                                spacing=spacing, epsilon=1e-9, figures=False)
    verts = surface.vertices.astype(np.float32)
    faces = surface.faces.astype(np.int32)
    normals = surface.normals.astype(np.float32)
    c, d = surface.surfels[:, 0], surface.surfels[:, 1]
    inside = np.all((d >= 0) & (d < np.array(array.shape)), axis=1)
    values = array[tuple(c.T)].astype(np.float32)
    dv = array[tuple(np.where(inside[:, None], d, c).T)].astype(np.float32)
    values = np.maximum(values, dv)
    if gradient_direction == "descent":
        faces = np.ascontiguousarray(faces[:, ::-1])
    return verts, faces, normals, values


DTYPES = [np.bool_, np.uint8, np.int8, np.uint16, np.int16, np.uint32, np.int32, np.uint64, np.int64,
          np.float32, np.float64]


def random_volume(rng, dtype, shape):
    """Noise or a smooth field in the type's range: many ties with integer levels, values beyond
    2^53 for the 64-bit integers (rounded twice through float64), NaN voxels in floats."""
    dtype = np.dtype(dtype)
    if dtype == bool:
        return rng.random(shape) < 0.5
    if dtype.kind in "ui":
        info = np.iinfo(dtype)
        if dtype.itemsize == 8 and rng.random() < 0.5:
            base = np.int64(2) ** 60 if dtype.kind == "i" else np.uint64(2) ** 63
            return (base + rng.integers(0, 1 << 20, shape).astype(dtype) * 997).astype(dtype)
        lo, hi = max(int(info.min), -50), min(int(info.max), 50)
        return rng.integers(lo, hi + 1, shape).astype(dtype)
    volume = (smooth_volume(rng, shape, 1.0) * 200 - 100).astype(dtype)
    if rng.random() < 0.5:
        volume[rng.random(shape) < 0.05] = np.nan
    return volume


def assert_same_arrays(got, want):
    names = ("verts", "faces", "normals", "values")
    for name, g, w in zip(names, got, want):
        assert g.dtype == w.dtype and g.shape == w.shape, (name, g.dtype, w.dtype, g.shape, w.shape)
        assert g.flags.c_contiguous, name
        assert np.array_equal(g, w, equal_nan=(name == "values")), name


EQUALITY_CASES = [(seed, dtype) for seed in range(4) for dtype in DTYPES]


@pytest.mark.parametrize("seed,dtype", EQUALITY_CASES)
def test_the_same_arrays_as_the_numpy_conversion(seed, dtype):
    """The binding's arrays are exactly the numpy conversion's (numpy_marching_cubes), for every
    dtype, both gradient directions, spacing, the adjacency pairs, and 1, 2 or 7 threads."""
    rng = np.random.default_rng(1000 + seed)
    shape = tuple(int(n) for n in rng.integers(3, 17, 3))
    volume = random_volume(rng, dtype, shape)
    finite = volume[~np.isnan(volume)] if volume.dtype.kind == "f" else volume
    if finite.min() == finite.max():
        return
    # A voxel value (ties: vertices 1e-9 from a voxel) or a level between two of them.
    values = np.unique(finite.astype(np.float64))
    level = float(values[rng.integers(0, len(values) - 1)])
    if seed % 2:
        level = float((values[0] + values[-1]) / 2)
    spacing = (1.0, 1.0, 1.0) if seed == 0 else tuple(float(x) for x in rng.uniform(0.3, 3.0, 3))
    adjacency = ("26-6", "18-6", "6-18", "6-26")[seed]
    for direction in ("descent", "ascent"):
        want = numpy_marching_cubes(volume, level, spacing, direction, adjacency)
        for threads in (1, 2, 7):
            got = surftrack.marching_cubes(volume, level, spacing=spacing, gradient_direction=direction,
                                           adjacency=adjacency, threads=threads)
            assert_same_arrays(got, want)


def test_the_same_arrays_on_a_large_mesh_in_any_memory_order():
    """Enough vertices for many blocks per thread (the normals' vertex -> triangle index, the
    faces rewound in place); Fortran-ordered and reversed arrays give the C-ordered array's."""
    rng = np.random.default_rng(7)
    volume = (smooth_volume(rng, (40, 44, 48), 0.7) * 1000).astype(np.float32)
    level = float(np.median(volume))
    want = numpy_marching_cubes(volume, level, (0.5, 1.0, 2.0), "descent", "26-6")
    assert len(want[0]) > 50000
    for threads in (1, 2, 7, 0):
        assert_same_arrays(surftrack.marching_cubes(volume, level, spacing=(0.5, 1.0, 2.0), threads=threads), want)
    assert_same_arrays(surftrack.marching_cubes(np.asfortranarray(volume), level, spacing=(0.5, 1.0, 2.0)), want)
    flipped = volume[::-1]
    want_flipped = numpy_marching_cubes(np.ascontiguousarray(flipped), level, (0.5, 1.0, 2.0), "descent", "26-6")
    assert_same_arrays(surftrack.marching_cubes(flipped, level, spacing=(0.5, 1.0, 2.0)), want_flipped)


def test_the_arrays_own_their_memory():
    """No copy: each array is a view of the engine's buffer, kept alive by a capsule, writable,
    and outlives the others and the volume."""
    volume = smooth_volume(np.random.default_rng(5), (20, 20, 20))
    level = float(np.median(volume))
    verts, faces, normals, values = surftrack.marching_cubes(volume, level)
    for a in (verts, faces, normals, values):
        assert not a.flags.owndata and type(a.base).__name__ == "PyCapsule" and a.flags.writeable
    want = numpy_marching_cubes(volume, level, (1, 1, 1), "descent", "26-6")
    del volume, verts, normals, values
    import gc
    gc.collect()
    assert np.array_equal(faces, want[1])
    faces[:] = 0  # writable, and freed once with its capsule
