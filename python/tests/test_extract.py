"""surftrack.extract: memory orders, dtypes, seeds, geometry and bad input."""
import numpy as np
import pytest

import surftrack
from conftest import ball, smooth_volume

DTYPES = [np.uint8, np.int8, np.uint16, np.int16, np.uint32, np.int32, np.uint64, np.int64,
          np.float32, np.float64, bool]


def canonical(surface):
    """The surface as sets that do not depend on vertex numbering: each vertex by its surfel,
    each triangle by its three surfels rotated to a canonical start (orientation kept)."""
    keys = [tuple(s.reshape(-1)) for s in surface.surfels]
    points = {k: tuple(np.round(p, 9)) for k, p in zip(keys, surface.vertices)}
    tris = set()
    for f in surface.faces:
        t = [keys[i] for i in f]
        r = t.index(min(t))
        tris.add(tuple(t[r:] + t[:r]))
    return points, tris


def test_memory_orders_give_the_same_surface():
    rng = np.random.default_rng(7)
    volume = smooth_volume(rng, (18, 21, 15))
    level = float(np.median(volume))
    ref = canonical(surftrack.extract(volume, level=level, mode="all"))
    fortran = np.asfortranarray(volume)
    assert canonical(surftrack.extract(fortran, level=level, mode="all")) == ref
    big = np.zeros((36, 21, 45))
    big[::2, :, ::3] = volume
    strided = big[::2, :, ::3]
    assert not strided.flags.c_contiguous and not strided.flags.f_contiguous
    assert canonical(surftrack.extract(strided, level=level, mode="all")) == ref
    # A view with negative strides gives the surface of its copy.
    flipped = volume[::-1, :, ::-1]
    assert canonical(surftrack.extract(flipped, level=level, mode="all")) == canonical(
        surftrack.extract(flipped.copy(), level=level, mode="all"))


def test_every_thread_count_gives_the_same_surface():
    volume = smooth_volume(np.random.default_rng(5), (70, 64, 66))
    level = float(np.median(volume))
    ref = surftrack.extract(volume, level=level, mode="all", threads=1)
    for threads in (2, 7, 0):
        s = surftrack.extract(volume, level=level, mode="all", threads=threads)
        assert np.array_equal(s.vertices, ref.vertices) and np.array_equal(s.faces, ref.faces)


def same_arrays(a, b):
    """Byte for byte: the vertices, faces, surfels and per-component figures of two surfaces."""
    return (np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces) and
            np.array_equal(a.surfels, b.surfels) and a.components == b.components and
            a.boundaries_in_image == b.boundaries_in_image)


@pytest.mark.parametrize("seed", [11, 12, 13])
def test_random_images_give_the_same_arrays_on_1_2_7_threads(seed):
    # Noise (many boundaries, cut edges everywhere) on shapes whose slab count is below, near and
    # above the scanner's runs (8 per thread), and a thresholded smooth image; threads 2 and 7
    # split whatever the size (only threads=0 keeps small images on one thread).
    rng = np.random.default_rng(seed)
    shape = [(37, 29, 41), (5, 40, 33), (61, 3, 50)][seed - 11]
    noise = rng.random(shape)
    for volume, level in ((noise, 0.5), (smooth_volume(rng, shape), None)):
        level = float(np.median(volume)) if level is None else level
        for mapping in ("linear", "midpoint"):
            ref = surftrack.extract(volume, level=level, mode="all", mapping=mapping, threads=1)
            assert len(ref.vertices) > 1000
            for threads in (2, 7):
                s = surftrack.extract(volume, level=level, mode="all", mapping=mapping, threads=threads)
                assert same_arrays(s, ref), (threads, mapping)
        ref = surftrack.extract(volume, level=level, mode="largest", threads=1)
        for threads in (2, 7):
            assert same_arrays(surftrack.extract(volume, level=level, mode="largest", threads=threads), ref)


@pytest.mark.parametrize("dtype", DTYPES)
def test_every_dtype_gives_the_same_surface(dtype):
    volume = ball((14, 15, 16), (7, 7.5, 8), 4.5, dtype=np.uint8, value=1).astype(dtype)
    ref = canonical(surftrack.extract(ball((14, 15, 16), (7, 7.5, 8), 4.5, value=1), level=0.5,
                                      mode="all", mapping="midpoint"))
    s = surftrack.extract(volume, level=0.5, mode="all", mapping="midpoint")
    assert canonical(s) == ref
    if np.dtype(dtype).kind in "iu":
        assert canonical(surftrack.extract(volume, label=1, mode="all")) == ref


def test_seeds_and_figures():
    volume = ball((30, 30, 30), (15, 15, 15), 8) + ball((30, 30, 30), (4, 4, 4), 2)
    whole = surftrack.extract(volume, level=50, mode="all")
    assert len(whole.components) == 2 and whole.boundaries_in_image == 2
    largest = surftrack.extract(volume, level=50, mode="largest")
    by_voxel = surftrack.extract(volume, level=50, seed=(15, 15, 15))
    by_point = surftrack.extract(volume, level=50, seed_point=(15.2, 14.9, 15.0))
    assert canonical(largest) == canonical(by_voxel) == canonical(by_point)
    # The surfel count is the number of 6-adjacent (1, 0) voxel pairs of the big ball.
    big = ball((30, 30, 30), (15, 15, 15), 8) > 50
    padded = np.pad(big, 1)
    pairs = sum(int(np.sum(padded & ~np.roll(padded, s, axis=a))) for a in range(3) for s in (1, -1))
    assert len(largest.vertices) == pairs == largest.components[0]["surfels"]
    assert largest.euler == 2 and largest.genus == 0
    c = largest.components[0]
    assert c["volume"] == pytest.approx(4 / 3 * np.pi * 8 ** 3, rel=0.1)
    # Unit outward normals.
    n = largest.normals
    assert np.allclose(np.linalg.norm(n, axis=1), 1)
    assert np.mean(np.sum(n * (largest.vertices - 15), axis=1) > 0) > 0.99


def test_geometry_and_mirrored_frames():
    volume = ball((20, 20, 20), (10, 10, 10), 6)
    base = surftrack.extract(volume, level=50, mode="largest")
    s = surftrack.extract(volume, level=50, mode="largest", spacing=(2, 1, 0.5), origin=(1, 2, 3))
    assert np.allclose(s.vertices, base.vertices * [2, 1, 0.5] + [1, 2, 3])
    mirror = np.diag([-1.0, 1.0, 1.0])
    m = surftrack.extract(volume, level=50, mode="largest", direction=mirror)
    assert np.allclose(m.vertices, base.vertices * [-1, 1, 1])
    assert m.components[0]["volume"] == pytest.approx(base.components[0]["volume"])
    assert m.components[0]["volume"] > 0  # still outward in physical space


def test_progress_and_write(tmp_path):
    volume = ball((20, 20, 20), (10, 10, 10), 6)
    stages = []
    s = surftrack.extract(volume, level=50, seed=(10, 10, 10),
                          progress=lambda stage, i, n, count: stages.append(stage))
    assert stages[:3] == ["seed", "track", "convert"]
    out = tmp_path / "ball.ply"
    s.write(out)
    assert out.stat().st_size > 0
    with pytest.raises(ValueError, match="extension"):
        s.write(tmp_path / "ball.xyz")
    assert not (tmp_path / "ball.xyz").exists()


def test_max_seed_distance_and_a_geometry_beyond_the_float_range():
    # A box at k in [0, 3] of a 600 voxels long volume: the seed (4, 4, 599) is 595.5 voxels
    # from its face at k = 3.5.
    volume = np.zeros((8, 8, 600), np.uint8)
    volume[2:6, 2:6, :4] = 200
    with pytest.raises(ValueError, match="within 256 voxels.*max_seed_distance"):
        surftrack.extract(volume, level=100, seed=(4, 4, 599))
    with pytest.raises(ValueError, match="within 595 voxels"):
        surftrack.extract(volume, level=100, seed=(4, 4, 599), max_seed_distance=595)
    near = surftrack.extract(volume, level=100, seed=(4, 4, 599), max_seed_distance=596)
    assert near.seed_distance == 595.5
    assert canonical(near) == canonical(surftrack.extract(volume, level=100, mode="largest"))
    unbounded = surftrack.extract(volume, level=100, seed=(4, 4, 599), max_seed_distance=float("inf"))
    assert canonical(unbounded) == canonical(near)
    for bad in (0, -1, float("nan")):
        with pytest.raises(ValueError, match="max_seed_distance"):
            surftrack.extract(volume, level=100, seed=(4, 4, 599), max_seed_distance=bad)
    # A spacing that puts the vertices beyond the float range (inf in double, or only in float).
    for spacing in ((1e300, 1e300, 1e300), (1, 1e38, 1)):
        with pytest.raises(ValueError, match="beyond the float range"):
            surftrack.extract(volume, level=100, mode="largest", spacing=spacing)
    with pytest.raises(ValueError, match="beyond the float range"):
        surftrack.label_surfaces(volume // 200, spacing=(1e300, 1, 1))


@pytest.mark.parametrize("volume,kwargs,error,message", [
    (np.zeros((4, 4)), {}, ValueError, "3-D"),
    (np.zeros((0, 4, 4)), {}, ValueError, "empty"),
    (np.zeros((4, 4, 4), complex), {}, TypeError, "dtype"),
    (np.zeros((4, 4, 4), object), {}, TypeError, "dtype"),
    (np.array([[["a"]]]), {}, TypeError, "dtype"),
    (np.arange(64.0).reshape(4, 4, 4), {"level": 100, "mode": "all"}, ValueError, "outside the data range"),
    (np.arange(64.0).reshape(4, 4, 4), {"level": 10, "seed": (9, 0, 0)}, ValueError, "outside the image domain"),
    (np.zeros((4, 4, 4)), {"level": 0.5, "seed": (1, 1, 1)}, ValueError, "no boundary surfel near it"),
    (np.zeros((4, 4, 4)), {"level": 0.5, "seed": (1, 1, 1), "seed_rule": "ray"}, ValueError, "not on any boundary"),
    (np.arange(64.0).reshape(4, 4, 4), {"level": 10, "adjacency": "8-4", "mode": "all"}, ValueError, "adjacency"),
    (np.arange(64.0).reshape(4, 4, 4), {"level": 10, "mapping": "cubic", "mode": "all"}, ValueError, "mapping"),
    (np.arange(64.0).reshape(4, 4, 4), {"level": 10}, ValueError, "seed"),
    (np.arange(64, dtype=np.uint8).reshape(4, 4, 4), {"label": 300, "mode": "all"}, ValueError, "label 300"),
    (np.arange(64.0).reshape(4, 4, 4), {"level": 10, "mode": "all", "spacing": (1, 0, 1)}, ValueError, "spacing"),
    (np.arange(64.0).reshape(4, 4, 4), {"level": 10, "mode": "all", "threads": -1}, ValueError, "threads -1"),
])
def test_bad_input(volume, kwargs, error, message):
    with pytest.raises(error, match=message):
        surftrack.extract(volume, **kwargs)
