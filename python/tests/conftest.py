import numpy as np
import pytest
from scipy import ndimage


def smooth_volume(rng, shape, sigma=2.0):
    """A random smooth float volume: white noise blurred by a Gaussian."""
    return ndimage.gaussian_filter(rng.random(shape), sigma, mode="nearest")


def ball(shape, centre, radius, dtype=np.uint8, value=100):
    grid = np.indices(shape).astype(float)
    d2 = sum((g - c) ** 2 for g, c in zip(grid, centre))
    return np.where(d2 <= radius * radius, value, 0).astype(dtype)


def closed_oriented_manifold(faces, n_vertices):
    """Every directed edge once and its reverse once: closed, oriented, no complex edge; and
    each vertex's faces form one fan (no complex vertex)."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    keys = edges[:, 0].astype(np.int64) * n_vertices + edges[:, 1]
    rev = edges[:, 1].astype(np.int64) * n_vertices + edges[:, 0]
    if len(np.unique(keys)) != len(keys):
        return False
    if not np.array_equal(np.sort(keys), np.sort(rev)):
        return False
    # One fan per vertex: following next-edge around a vertex visits all its faces.
    succ = {}
    for a, b, c in faces:
        for u, v, w in ((a, b, c), (b, c, a), (c, a, b)):
            succ.setdefault(u, {})[v] = w  # around u: from edge (u, v) to edge (u, w)
    for u, ring in succ.items():
        start = next(iter(ring))
        v, seen = start, 0
        while True:
            v = ring[v]
            seen += 1
            if v == start or seen > len(ring):
                break
        if seen != len(ring):
            return False
    return len(succ) == n_vertices


@pytest.fixture
def rng():
    return np.random.default_rng(20261201)
