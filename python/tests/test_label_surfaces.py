"""surftrack.label_surfaces against numpy computations: surfel counts from the 6-adjacent voxel
pairs (label, not label), the binary path (extract with label=), shared interface vertices, and
bad input."""
import numpy as np
import pytest

import surftrack


def direct_surfels(labels, label):
    """The (label, not label) 6-adjacent voxel pairs, the domain border included."""
    inside = np.pad(labels == label, 1)
    return int(sum(np.count_nonzero(inside & ~np.roll(inside, s, axis=a))
                   for a in range(3) for s in (1, -1)))


def voronoi(rng, shape, cells, dtype):
    centres = rng.integers(0, shape, size=(cells, 3))
    grid = np.stack(np.indices(shape), axis=-1)
    d = ((grid[..., None, :] - centres) ** 2).sum(-1)
    return (np.argmin(d, axis=-1) * 3 + 1).astype(dtype)


@pytest.mark.parametrize("dtype", [np.uint8, np.int16, np.uint32, np.int64])
def test_every_label_is_closed_and_counted(rng, dtype):
    for trial in range(6):
        labels = voronoi(rng, (14, 11, 9), int(rng.integers(2, 12)), dtype)
        labels[rng.random(labels.shape) < 0.05] = 0  # background specks
        surfaces = surftrack.label_surfaces(labels, spacing=(0.5, 1.0, 2.0), walls="independent")
        present = sorted(int(v) for v in np.unique(labels) if v != 0)
        assert sorted(surfaces) == present
        for label, s in surfaces.items():
            assert len(s.vertices) == direct_surfels(labels, label)
            assert s.voxels == int(np.count_nonzero(labels == label))
            # Closed: every undirected edge in exactly two faces, in opposite directions.
            f = s.faces.astype(np.int64)
            directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
            keys = directed[:, 0] * len(s.vertices) + directed[:, 1]
            reverse = directed[:, 1] * len(s.vertices) + directed[:, 0]
            assert len(np.unique(keys)) == len(keys)
            assert np.array_equal(np.sort(keys), np.sort(reverse))
            alone = surftrack.extract(labels, label=label, mode="all", spacing=(0.5, 1.0, 2.0))
            assert len(alone.vertices) == len(s.vertices)
            assert sorted(map(tuple, alone.vertices.tolist())) == sorted(map(tuple, s.vertices.tolist()))
            assert s.euler == alone.euler


@pytest.mark.parametrize("seed", [21, 22])
def test_random_label_images_give_the_same_arrays_on_1_2_7_threads(seed):
    # Noise labels (every voxel its own boundary, many labels per cube) and Voronoi cells with
    # background specks, on shapes with fewer planes than slabs and more; every label's arrays
    # byte for byte.
    rng = np.random.default_rng(seed)
    shape = [(9, 33, 27), (30, 14, 19)][seed - 21]
    noise = rng.integers(0, 7, size=shape).astype(np.uint16)
    cells = voronoi(rng, shape, 40, np.uint32)
    cells[rng.random(shape) < 0.03] = 0
    for labels in (noise, cells):
        for boundaries in ("all", "largest"):
            ref = surftrack.label_surfaces(labels, boundaries=boundaries, threads=1, walls="independent")
            assert len(ref) > 5
            for threads in (2, 7):
                got = surftrack.label_surfaces(labels, boundaries=boundaries, threads=threads, walls="independent")
                assert sorted(got) == sorted(ref)
                for label, s in got.items():
                    r = ref[label]
                    assert np.array_equal(s.vertices, r.vertices) and np.array_equal(s.faces, r.faces)
                    assert np.array_equal(s.surfels, r.surfels) and s.components == r.components
                    assert s.voxels == r.voxels and s.boundaries_in_image == r.boundaries_in_image


def test_touching_labels_share_their_interface_vertices(rng):
    labels = voronoi(rng, (16, 16, 16), 6, np.uint16)
    surfaces = surftrack.label_surfaces(labels, walls="independent")
    points = {label: set(map(tuple, s.vertices.tolist())) for label, s in surfaces.items()}
    # Every pair of 6-adjacent voxels of two labels: its midpoint is a vertex of both.
    pairs = 0
    for axis in range(3):
        step = np.eye(3, dtype=int)[axis]
        lo = labels[tuple(slice(0, n - 1) if ax == axis else slice(None) for ax, n in enumerate(labels.shape))]
        hi = labels[tuple(slice(1, None) if ax == axis else slice(None) for ax in range(3))]
        for c in np.argwhere(lo != hi):
            mid = tuple(float(x) for x in c + 0.5 * step)
            assert mid in points[int(labels[tuple(c)])]
            assert mid in points[int(labels[tuple(c + step)])]
            pairs += 1
    assert pairs > 100


def test_selection_and_bad_input(rng):
    labels = voronoi(rng, (10, 10, 10), 4, np.uint16)
    present = sorted(int(v) for v in np.unique(labels))
    assert sorted(surftrack.label_surfaces(labels, only=[present[1]], walls="independent")) == [present[1]]
    assert sorted(surftrack.label_surfaces(labels, label_range=(present[0], present[1]), walls="independent")) == present[:2]
    largest = surftrack.label_surfaces(labels, boundaries="largest", walls="independent")
    assert all(len(s.components) == 1 for s in largest.values())
    with pytest.raises(ValueError, match="integer voxels"):
        surftrack.label_surfaces(labels.astype(np.float32), walls="independent")
    with pytest.raises(ValueError, match="does not occur"):
        surftrack.label_surfaces(labels, only=[999], walls="independent")
    with pytest.raises(ValueError, match="empty selection"):
        surftrack.label_surfaces(labels, only=[], walls="independent")
    with pytest.raises(ValueError, match="empty selection"):
        surftrack.label_surfaces(labels, label_range=(500, 600), walls="independent")
    seeded = surftrack.label_surfaces(labels, seeds=[(0, 0, 0)], background=999, walls="independent")
    assert list(seeded) == [int(labels[0, 0, 0])]
