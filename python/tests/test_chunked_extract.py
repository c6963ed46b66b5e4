"""surftrack.extract on chunked stores written by zarr-python (a zarr array, its path, an
OME-Zarr image): read lazily by the engine's own readers, the surface is array for array the one
numpy's copy of the same voxels gives, for several codecs, types and chunk shapes (1-voxel
chunks included); chunks far from the surface are never read; what would read every chunk is
refused with a ValueError."""
import json
import os
import zlib

import numpy as np
import pytest

import surftrack
from surftrack import _surftrack

zarr = pytest.importorskip("zarr")
numcodecs = pytest.importorskip("numcodecs")


def blob(rng, shape):
    z, y, x = np.indices(shape)
    c = np.array(shape) / 2 + rng.uniform(-2, 2, 3)
    r = min(shape) / 3
    f = np.sqrt((z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2) + rng.uniform(-0.8, 0.8, shape)
    return f, c


CASES = [("<u2", (8, 8, 8), numcodecs.Blosc("lz4", 5, numcodecs.Blosc.SHUFFLE)),
         (">f4", (7, 5, 9), numcodecs.Blosc("zstd", 3, numcodecs.Blosc.BITSHUFFLE)),
         ("<i8", (1, 1, 1), None),
         ("|u1", (16, 3, 11), numcodecs.Zlib(level=1)),
         ("<f8", (5, 13, 2), numcodecs.GZip(level=1)),
         ("<u8", (9, 9, 9), numcodecs.Zstd(level=1))]


@pytest.mark.parametrize("dtype,chunks,compressor", CASES)
def test_a_seeded_extraction_from_a_store_is_the_arrays(tmp_path, dtype, chunks, compressor):
    rng = np.random.default_rng(zlib.crc32(repr((dtype, chunks)).encode()))  # (fixed: not hash())
    shape = (23, 19, 21)
    f, centre = blob(rng, shape)
    volume = np.where(f < min(shape) / 3, 100 + (f * 3) % 50, f).astype(np.dtype(dtype))
    store = zarr.open(str(tmp_path / "v.zarr"), mode="w", shape=shape, chunks=chunks, dtype=dtype,
                      compressor=compressor, fill_value=0)
    store[:] = volume
    seed = tuple(int(v) for v in centre)
    for source in (zarr.open(str(tmp_path / "v.zarr"), mode="r"), tmp_path / "v.zarr", str(tmp_path / "v.zarr")):
        for kwargs in ({"level": 60.0}, {"level": 60.0, "mapping": "midpoint", "spacing": (2.0, 1.0, 0.5),
                                         "origin": (1.0, -2.0, 3.0)}):
            lazy = surftrack.extract(source, seed=seed, **kwargs)
            whole = surftrack.extract(volume, seed=seed, **kwargs)
            assert np.array_equal(lazy.vertices, whole.vertices) and np.array_equal(lazy.faces, whole.faces)
            assert np.array_equal(lazy.surfels, whole.surfels) and lazy.components == whole.components
            assert 0 < lazy.chunks["chunks_decoded"] <= lazy.chunks["chunks"]


def test_labels_and_ome_zarr_levels(tmp_path):
    labels = np.zeros((30, 28, 26), np.uint64)
    labels[5:20, 6:18, 4:22] = 2**64 - 1
    labels[20:25, 6:18, 4:22] = 2**53 + 1
    root = zarr.open_group(str(tmp_path / "img.ome.zarr"), mode="w")
    root.create_dataset("0", data=labels, chunks=(8, 8, 8))
    root.create_dataset("1", data=labels[::2, ::2, ::2], chunks=(8, 8, 8))
    root.attrs["multiscales"] = [{
        "version": "0.4", "axes": [{"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"],
        "datasets": [{"path": str(i), "coordinateTransformations": [
            {"type": "scale", "scale": [4.0 * 2 ** i, 2.0 * 2 ** i, 1.0 * 2 ** i]},
            {"type": "translation", "translation": [10.0, 20.0, 30.0]}]} for i in (0, 1)]}]
    for level in (0, 1):
        data = labels[:: 2 ** level, :: 2 ** level, :: 2 ** level]
        f = 2 ** level
        for label in (2**64 - 1, 2**53 + 1):
            seed = tuple(int(v) for v in np.argwhere(data == np.uint64(label))[0])
            lazy = surftrack.extract(tmp_path / "img.ome.zarr", label=label, seed=seed, store_level=level)
            whole = surftrack.extract(data, label=label, seed=seed, spacing=(4.0 * f, 2.0 * f, 1.0 * f),
                                      origin=(10.0, 20.0, 30.0))
            assert np.array_equal(lazy.vertices, whole.vertices) and np.array_equal(lazy.faces, whole.faces)


def test_far_chunks_are_never_read_and_full_reads_refused(tmp_path):
    shape = (96, 96, 96)
    z, y, x = np.ogrid[:96, :96, :96]
    volume = (((z - 20) ** 2 + (y - 24) ** 2 + (x - 30) ** 2) < 100).astype(np.uint8) * 9
    path = tmp_path / "s.zarr"
    zarr.open(str(path), mode="w", shape=shape, chunks=(16, 16, 16), dtype="|u1")[:] = volume
    for name in os.listdir(path):
        if name.startswith("."):
            continue
        if max(int(v) for v in name.split(".")) >= 4:  # chunks from voxel 64 on: far from the ball
            (path / name).write_bytes(b"garbage")
    lazy = surftrack.extract(path, label=9, seed=(20, 24, 30))
    whole = surftrack.extract(volume, label=9, seed=(20, 24, 30))
    assert np.array_equal(lazy.faces, whole.faces) and lazy.chunks["chunks_decoded"] < 64
    with pytest.raises(ValueError, match="reads every voxel"):
        surftrack.extract(path, label=9, mode="largest")
    with pytest.raises(ValueError, match="needs level= or label="):
        surftrack.extract(path, seed=(20, 24, 30))
    with pytest.raises(ValueError, match="not a directory"):
        surftrack.extract(str(tmp_path / "nothing.zarr"), label=9, seed=(1, 1, 1))
    with pytest.raises(ValueError, match="zarr|store|N5"):
        surftrack.extract(tmp_path, label=9, seed=(1, 1, 1))  # a directory that is no store


@pytest.mark.parametrize("dtype,chunks,compressor", CASES)
def test_boxes_read_from_a_store_are_zarr_pythons(tmp_path, dtype, chunks, compressor):
    # read_store_box (core copyBox over the store's chunk cache): what a block task of
    # `labels --dask` reads, against zarr-python's slicing of the same store, on 120 random
    # boxes (single voxels, whole axes, boxes across chunk edges and the partial far chunks).
    rng = np.random.default_rng(zlib.crc32(repr(("box", dtype, chunks)).encode()))
    shape = (23, 19, 21)
    data = (rng.random(shape) * 100).astype(np.dtype(dtype))
    store = zarr.open(str(tmp_path / "v.zarr"), mode="w", shape=shape, chunks=chunks, dtype=dtype,
                      compressor=compressor, fill_value=7)
    store[:, :, :10] = data[:, :, :10]  # the rest of the array: missing chunks, the fill value
    expected = zarr.open(str(tmp_path / "v.zarr"), mode="r")
    assert _surftrack.store_layout(str(tmp_path / "v.zarr"), 0, None, None) == (shape, np.dtype(dtype).newbyteorder("=").name)
    for _ in range(120):
        lo = [int(rng.integers(0, n)) for n in shape]
        hi = [int(rng.integers(a + 1, n + 1)) for a, n in zip(lo, shape)]
        got = _surftrack.read_store_box(str(tmp_path / "v.zarr"), 0, None, None, lo, hi)
        assert got.dtype.isnative and np.array_equal(got, expected[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]])
    with pytest.raises(ValueError, match="not inside the array"):
        _surftrack.read_store_box(str(tmp_path / "v.zarr"), 0, None, None, [0, 0, 0], [24, 1, 1])
