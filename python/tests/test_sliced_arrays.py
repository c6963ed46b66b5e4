"""surftrack.extract on arrays only Python can read — dask arrays, h5py datasets, zarr arrays
in memory, any object with .shape, .dtype, .chunks and numpy slicing — read slice by slice
through the engine's chunk cache (python/src/ArrayChunkProvider.h): a seeded extraction gives,
array for array, the surface of numpy's copy of the same voxels, slices only boxes near the
surface (recorded, and far boxes made to raise), and a slice that fails or comes back wrong is
one ValueError. Other modes read the array whole, as before."""
import zlib

import numpy as np
import pytest

import surftrack

da = pytest.importorskip("dask.array")
h5py = pytest.importorskip("h5py")
zarr = pytest.importorskip("zarr")
# (Some random balls hold a one-voxel cavity nearest their centre: a speck, the same both ways.)
pytestmark = pytest.mark.filterwarnings("ignore:the surface found is a speck")


def noisy_ball(seed, shape, dtype):
    """A noisy ball (values 60..110 inside, the distance outside) and a voxel inside it."""
    rng = np.random.default_rng(seed)
    z, y, x = np.indices(shape)
    c = np.array(shape) / 2 + rng.uniform(-2, 2, 3)
    f = np.sqrt((z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2) + rng.uniform(-0.8, 0.8, shape)
    volume = np.where(f < min(shape) / 3, 60 + (f * 3) % 50, f)  # (60..110: int8 too)
    return volume.astype(dtype), tuple(int(v) for v in c)


def same(a, b):
    assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(a.faces, b.faces)
    assert a.surfels.tolist() == b.surfels.tolist()


class Recorder:
    """An array-like over numpy: records every box sliced; boxes beyond `far` voxels from
    `centre` along any axis raise (they must never be read)."""

    def __init__(self, volume, chunks, centre=None, far=None):
        self.volume, self.chunks, self.centre, self.far = volume, chunks, centre, far
        self.shape, self.dtype = volume.shape, volume.dtype
        self.boxes = []

    def __getitem__(self, box):
        self.boxes.append(tuple((s.start, s.stop) for s in box))
        if self.far is not None:
            for (lo, hi), c in zip(self.boxes[-1], self.centre):
                if hi <= c - self.far or lo >= c + self.far:
                    raise RuntimeError(f"box {box} is far from the surface: never to be read")
        return self.volume[box]


DTYPES = ["<u2", ">f4", "<i8", "|u1", ">u8", "<f8", "|i1", ">i2"]


@pytest.mark.parametrize("dtype", DTYPES)
def test_arrays_of_every_type_and_chunk_shape_give_the_arrays_surface(dtype):
    # Random shapes and chunk shapes (1-voxel chunks once), read through a plain array-like and
    # once through dask (whose every slice is a graph computed: slower, fewer chunks).
    for trial in range(5):
        seed = zlib.crc32(f"{dtype}/{trial}".encode())
        rng = np.random.default_rng(seed)
        shape = tuple(int(n) for n in rng.integers(12, 26, 3))
        volume, centre = noisy_ball(seed, shape, np.dtype(dtype))
        chunks = (1, 1, 1) if trial == 0 else tuple(int(c) for c in rng.integers(2, 12, 3))
        if trial == 4:
            chunks = tuple(max(c, 6) for c in chunks)
        array = (lambda: da.from_array(volume, chunks=chunks)) if trial == 4 else (lambda: Recorder(volume, chunks))
        level = 50.5
        expected = surftrack.extract(volume, level=level, seed=centre)
        got = surftrack.extract(array(), level=level, seed=centre)
        same(got, expected)
        # Every decode is a slice of the array: at most the chunks there are; a one-chunk cache
        # (every access evicts) decodes again and gives the same surface.
        assert 0 < got.chunks["chunks_decoded"] <= got.chunks["chunks"]
        small = surftrack.extract(array(), level=level, seed=centre, cache_mib=0)
        same(small, expected)
        assert small.chunks["chunks_decoded"] >= got.chunks["chunks_decoded"]


def test_irregular_dask_chunks_labels_and_bools():
    rng = np.random.default_rng(7)
    labels = rng.integers(0, 3, (20, 18, 22)).astype(np.uint32)
    labels[5:15, 4:14, 6:16] = 7
    irregular = da.from_array(labels, chunks=((3, 9, 8), (18,), (5, 5, 5, 7)))
    same(surftrack.extract(irregular, label=7, seed=(10, 9, 11)), surftrack.extract(labels, label=7, seed=(10, 9, 11)))
    mask = labels == 7
    same(surftrack.extract(da.from_array(mask, chunks=4), level=0.5, seed=(10, 9, 11)),
         surftrack.extract(mask, level=0.5, seed=(10, 9, 11)))


def test_h5py_datasets_chunked_contiguous_and_big_endian(tmp_path):
    volume, centre = noisy_ball(11, (30, 26, 28), np.dtype("<u2"))
    expected = surftrack.extract(volume, level=50.5, seed=centre)
    with h5py.File(tmp_path / "v.h5", "w") as f:
        f.create_dataset("chunked", data=volume.astype(">u2"), chunks=(5, 7, 3), compression="gzip")
        f.create_dataset("contiguous", data=volume)
    with h5py.File(tmp_path / "v.h5", "r") as f:
        for name in ("chunked", "contiguous"):
            same(surftrack.extract(f[name], level=50.5, seed=centre), expected)


def test_zarr_arrays_in_memory():
    volume, centre = noisy_ball(13, (24, 20, 22), np.dtype("<f4"))
    z = zarr.array(volume, chunks=(6, 5, 7))  # a dict store: not a directory the engine reads
    got = surftrack.extract(z, level=50.5, seed=centre, spacing=(2.0, 0.5, 1.0), origin=(1, 2, 3))
    same(got, surftrack.extract(volume, level=50.5, seed=centre, spacing=(2.0, 0.5, 1.0), origin=(1, 2, 3)))


def test_far_boxes_are_never_sliced():
    # A ball of radius 6 in a 64 x 40 x 200 array of 8^3 chunks: the seeded extraction slices
    # only boxes within a chunk and the tracker's apron of the ball; the rest raise if sliced.
    shape = (64, 40, 200)
    z, y, x = np.indices(shape)
    centre = (30, 20, 100)
    volume = (((z - 30) ** 2 + (y - 20) ** 2 + (x - 100) ** 2) <= 36).astype(np.uint8)
    rec = Recorder(volume, (8, 8, 8), centre=centre, far=6 + 8 + 8)
    got = surftrack.extract(rec, level=0.5, seed=centre)
    same(got, surftrack.extract(volume, level=0.5, seed=centre))
    assert len(rec.boxes) == got.chunks["chunks_decoded"] < got.chunks["chunks"] // 10
    assert len(set(rec.boxes)) == len(rec.boxes)  # each box sliced once (the cache holds them all)


def test_failing_or_wrong_slices_are_one_value_error():
    volume, centre = noisy_ball(17, (16, 16, 16), np.dtype("<u2"))

    class Wrong(Recorder):
        def __getitem__(self, box):
            return np.zeros((2, 2, 2), self.dtype)

    class Failing(Recorder):
        def __getitem__(self, box):
            raise OSError("the disk is gone\nsecond line")

    with pytest.raises(ValueError, match=r"chunk \[.*came back with shape \(2, 2, 2\)"):
        surftrack.extract(Wrong(volume, (4, 4, 4)), level=50.5, seed=centre)
    with pytest.raises(ValueError, match=r"reading the array's chunk \[.*OSError: the disk is gone$"):
        surftrack.extract(Failing(volume, (4, 4, 4)), level=50.5, seed=centre)
    with pytest.raises(ValueError, match="3-D"):
        surftrack.extract(Recorder(volume[0], (4, 4)), level=50.5, seed=(1, 1))
    with pytest.raises(TypeError, match="dtype"):
        surftrack.extract(Recorder(volume.astype(np.complex64), (4, 4, 4)), level=50.5, seed=centre)


def test_other_modes_read_the_array_whole():
    volume, centre = noisy_ball(19, (18, 20, 16), np.dtype("<u2"))
    whole = surftrack.extract(da.from_array(volume, chunks=4), level=50.5, mode="largest")
    same(whole, surftrack.extract(volume, level=50.5, mode="largest"))
    assert getattr(whole, "chunks", None) is None  # (read as one array, not chunk by chunk)
