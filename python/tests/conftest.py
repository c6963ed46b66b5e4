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


@pytest.fixture
def rng():
    return np.random.default_rng(20261201)
