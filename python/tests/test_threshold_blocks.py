"""The bindings scan_threshold_block / merge_threshold_fragments (docs/theory.md, "Thresholds by
blocks"): a volume cut into random blocks, each scanned from its own box, merged into exactly
surftrack.extract(mode="all") of the whole volume (vertices bit-equal, same order, same faces,
figures), for both mappings; the vertex count against numpy's count of the boundary surfels."""
import numpy as np
import pytest

import surftrack
from surftrack import _surftrack


def direct_surfels(inside):
    """The (1, 0) 6-adjacent voxel pairs of a binary volume, the domain border included."""
    padded = np.pad(inside, 1)
    return int(sum(np.count_nonzero(padded & ~np.roll(padded, s, axis=a)) for a in range(3) for s in (1, -1)))


def cuts(rng, n):
    """A random partition of [0, n): one block, all of length 1, or a few random cuts."""
    kind = rng.integers(0, 4)
    if kind == 0:
        return [0, n]
    if kind == 1:
        return list(range(n + 1))
    return sorted({0, n, *(int(c) for c in rng.integers(1, n, size=rng.integers(1, 4)))})


def merged_by_blocks(volume, level, mapping, adjacency, spacing, origin, rng):
    shape = volume.shape
    cz, cy, cx = (cuts(rng, n) for n in shape)
    fragments = []
    for z0, z1 in zip(cz, cz[1:]):
        for y0, y1 in zip(cy, cy[1:]):
            for x0, x1 in zip(cx, cx[1:]):
                lo, hi = [z0, y0, x0], [z1, y1, x1]
                top = [min(h + 1, n) for h, n in zip(hi, shape)]  # the one-voxel apron on the high sides
                box = np.ascontiguousarray(volume[z0:top[0], y0:top[1], x0:top[2]])
                fragments.append(_surftrack.scan_threshold_block(box, lo, list(shape), lo, hi, float(level),
                                                                 adjacency, mapping, 1e-3))
    rng.shuffle(fragments)
    out = _surftrack.merge_threshold_fragments(fragments, list(shape), float(level), list(spacing), list(origin),
                                               np.eye(3).tolist(), adjacency, mapping, 1e-3, True)
    return surftrack.Surface(**out)


@pytest.mark.parametrize("dtype", [np.float32, np.uint8])
@pytest.mark.parametrize("mapping", ["midpoint", "linear"])
def test_merged_blocks_are_the_single_pass(rng, dtype, mapping):
    for trial in range(12):
        shape = tuple(int(n) for n in rng.integers(3, 11, size=3))
        volume = (rng.random(shape) * 200).astype(dtype)
        level = 120.5 if dtype == np.uint8 else 120.0
        adjacency = ["26-6", "18-6", "6-18", "6-26"][trial % 4]
        spacing = tuple(float(s) for s in rng.uniform(0.3, 2.0, size=3))
        origin = tuple(float(o) for o in rng.uniform(-5, 5, size=3))
        single = surftrack.extract(volume, level=level, mode="all", mapping=mapping, adjacency=adjacency,
                                   spacing=spacing, origin=origin, threads=1)
        merged = merged_by_blocks(volume, level, mapping, adjacency, spacing, origin, rng)
        assert len(merged.vertices) == direct_surfels(volume > level)
        assert merged.vertices.tobytes() == single.vertices.tobytes()
        assert np.array_equal(merged.faces, single.faces)
        assert np.array_equal(merged.surfels, single.surfels)
        assert merged.euler == single.euler and merged.boundaries_in_image == single.boundaries_in_image
        assert merged.components == single.components


def test_bad_fragments_are_refused():
    volume = np.zeros((4, 5, 6), np.float32)
    volume[1, 2, 3] = 5
    whole = _surftrack.scan_threshold_block(volume, [0, 0, 0], [4, 5, 6], [0, 0, 0], [4, 5, 6], 1.0, "26-6",
                                            "midpoint", 1e-3)
    with pytest.raises(ValueError, match="linear mapping"):  # scanned for the midpoint, merged as linear
        _surftrack.merge_threshold_fragments([whole], [4, 5, 6], 1.0, [1, 1, 1], [0, 0, 0], np.eye(3).tolist(),
                                             "26-6", "linear", 1e-3, True)
    with pytest.raises(ValueError, match="apron"):  # a box without its high apron
        _surftrack.scan_threshold_block(volume[:, :, :3], [0, 0, 0], [4, 5, 6], [0, 0, 0], [4, 5, 3], 1.0,
                                        "26-6", "midpoint", 1e-3)
    with pytest.raises(ValueError, match="empty selection"):
        high = _surftrack.scan_threshold_block(volume, [0, 0, 0], [4, 5, 6], [0, 0, 0], [4, 5, 6], 9.0, "26-6",
                                               "midpoint", 1e-3)
        _surftrack.merge_threshold_fragments([high], [4, 5, 6], 9.0, [1, 1, 1], [0, 0, 0], np.eye(3).tolist(),
                                             "26-6", "midpoint", 1e-3, True)
