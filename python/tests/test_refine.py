"""smooth=, max_error=, reduce= of surftrack.extract (docs/python.md): the Python layer passes
them through and reports the figures; the geometry itself is checked by tests/test_refine.cpp
with CGAL."""
import numpy as np
import pytest

import surftrack


def _ball(n=36, r=12.0):
    z, y, x = np.mgrid[:n, :n, :n]
    return (((x - n / 2) ** 2 + (y - n / 2 + 3) ** 2 + (z - n / 2) ** 2) < r * r).astype(np.uint8)


def test_smoothing_keeps_vertices_on_their_segments_and_the_topology():
    volume = _ball()
    before = surftrack.extract(volume, label=1, mode="largest", spacing=(1.0, 0.5, 2.0))
    after = surftrack.extract(volume, label=1, mode="largest", spacing=(1.0, 0.5, 2.0), smooth=10)
    assert after.euler == before.euler == 2
    assert np.array_equal(after.faces, before.faces)
    assert after.refine["smooth_iterations"] == 10
    assert after.refine["max_vertex_displacement"] > 0
    # Each vertex on the segment between its two voxel centres, strictly inside (array axes).
    c, d = after.surfels[:, 0].astype(float), after.surfels[:, 1].astype(float)
    index = after.vertices / np.array([1.0, 0.5, 2.0])
    axis = np.argmax(np.abs(d - c), axis=1)
    rows = np.arange(len(axis))
    t = (index[rows, axis] - c[rows, axis]) / (d[rows, axis] - c[rows, axis])
    assert np.all((t >= 1e-3 - 1e-9) & (t <= 1 - 1e-3 + 1e-9))
    other = np.ones_like(index, dtype=bool)
    other[rows, axis] = False
    assert np.allclose(index[other], c[other])
    assert not np.allclose(after.vertices, before.vertices)


def test_decimation_meets_its_target_and_keeps_the_genus():
    volume = _ball()
    volume[:, 16:20, 16:20] = 0  # a tunnel: genus 1
    s = surftrack.extract(volume, label=1, mode="largest", smooth=5, reduce=0.75)
    target = 0.25 * s.refine["triangles_before"]
    assert abs(len(s.faces) - target) <= 0.05 * target
    assert s.refine["triangles_after"] == len(s.faces)
    assert s.genus == 1
    assert abs(s.refine["volume_after"] - s.refine["volume_before"]) < 0.02 * s.refine["volume_before"]


def test_bad_refine_arguments_raise_value_error():
    volume = _ball(16, 5)
    with pytest.raises(ValueError, match="reduction"):
        surftrack.extract(volume, label=1, mode="largest", reduce=1.0)
    with pytest.raises(ValueError, match="max error"):
        surftrack.extract(volume, label=1, mode="largest", max_error=-1.0)
    with pytest.raises(ValueError, match="iterations"):
        surftrack.extract(volume, label=1, mode="largest", smooth=-2)
