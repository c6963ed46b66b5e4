"""Chunked stores written by an independent writer (zarr-python 2.13, Debian's python3-zarr and
python3-numcodecs; N5 blocks also by hand, as the N5 specification lays them out) decoded chunk
by chunk by io/ChunkedStore.h's providers through tests/chunk_dump, and compared byte for byte
with the arrays numpy holds: every codec and shuffle, the ten voxel types in both byte orders,
C and F order, both dimension separators, missing chunks, shapes that chunks do not divide,
leading time and channel axes, OME-Zarr levels and their composed transformations; what
cannot be read refused with one line and exit status 1. Run by ctest (tests/CMakeLists.txt)
with SURFTRACK_CHUNK_DUMP set to the tool, and SURFTRACK_EXE to the command-line tool, which reads
a store whole (its meshes are those of the same voxels in a raw file)."""
import gzip
import json
import os
import struct
import subprocess
import zlib

import numpy as np
import pytest

zarr = pytest.importorskip("zarr")
numcodecs = pytest.importorskip("numcodecs")

EXE = os.environ.get("SURFTRACK_CHUNK_DUMP", "build/tests/chunk_dump")
# zarr-python warns that other N5 libraries may not read blosc; surftrack's does.
pytestmark = pytest.mark.filterwarnings("ignore:Not all N5 implementations support blosc")

SHAPE, CHUNKS = (37, 29, 23), (8, 7, 5)  # numpy's (z, y, x); no chunk size divides its axis
KINDS = ["u1", "i1", "u2", "i2", "u4", "i4", "u8", "i8", "f4", "f8"]
DTYPES = [o + k for k in KINDS for o in "<>"]
CODECS = ([("blosc", c, s) for c in ["lz4", "lz4hc", "zstd", "zlib", "blosclz"] for s in (0, 1, 2)] +
          [("zstd",), ("zlib",), ("gzip",), (None,)])


def compressor(spec):
    if spec[0] == "blosc":
        return numcodecs.Blosc(cname=spec[1], clevel=5, shuffle=spec[2])
    return {"zstd": numcodecs.Zstd(level=3), "zlib": numcodecs.Zlib(level=5),
            "gzip": numcodecs.GZip(level=5), None: None}[spec[0]]


def random_array(dtype, shape, seed):
    """Values spread over the whole range of integer types; floats with NaN and infinities."""
    rng = np.random.default_rng(seed)
    dtype = np.dtype(dtype)
    if dtype.kind in "ui":
        info = np.iinfo(dtype)
        a = rng.integers(info.min, info.max, size=shape, dtype=dtype.newbyteorder("="), endpoint=True)
    else:
        a = (rng.standard_normal(shape) * 1e3).astype(dtype.newbyteorder("="))
        a.flat[:: 97] = np.nan
        a.flat[1:: 101] = np.inf
        a.flat[2:: 103] = -np.inf
    return a.astype(dtype)


def run(path, tmp_path, *args):
    out = tmp_path / "volume.raw"
    r = subprocess.run([EXE, str(path), str(out), *map(str, args)], capture_output=True, text=True, timeout=120)
    return r, out


def dump(path, tmp_path, *args):
    r, out = run(path, tmp_path, *args)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    return json.loads(r.stdout), out.read_bytes()


def expect_voxels(report, raw, expected):
    """The dump is `expected` (numpy's axes, the engine's x the last), x fastest, native order."""
    if expected.ndim == 2:
        expected = expected[None]
    assert report["dims"] == [expected.shape[2], expected.shape[1], expected.shape[0]]
    native = np.ascontiguousarray(expected.astype(expected.dtype.newbyteorder("=")))
    assert raw == native.tobytes()


def expect_refused(path, tmp_path, *args, says=()):
    r, _ = run(path, tmp_path, *args)
    assert r.returncode == 1, (r.stdout, r.stderr)
    assert r.stderr.count("\n") == 1 and r.stderr.startswith("chunk_dump: error: cannot read "), r.stderr
    for part in says:
        assert part in r.stderr, r.stderr
    return r.stderr


def write_zarr(path, data, codec=(None,), order="C", separator=".", chunks=CHUNKS, fill_value=0, **kw):
    z = zarr.open_array(str(path), mode="w", shape=data.shape, chunks=chunks, dtype=data.dtype,
                        compressor=compressor(codec), order=order, dimension_separator=separator,
                        fill_value=fill_value, **kw)
    z[...] = data
    return z


def chunk_files(path):
    return sorted(os.path.relpath(os.path.join(d, f), path) for d, _, fs in os.walk(path)
                  for f in fs if not f.startswith("."))


@pytest.mark.parametrize("codec", CODECS, ids=lambda c: "-".join(map(str, c)))
def test_every_codec(tmp_path, codec):
    i = CODECS.index(codec)
    data = random_array(DTYPES[(3 * i) % len(DTYPES)], SHAPE, seed=i)
    path = tmp_path / "a.zarr"
    write_zarr(path, data, codec, order="CF"[i % 2], separator="./"[i // 2 % 2])
    report, raw = dump(path, tmp_path)
    expect_voxels(report, raw, data)
    assert report["format"] == "zarr" and report["missing_chunks"] == 0
    assert report["chunk"] == [5, 7, 8] and report["chunks"] == 5 * 5 * 5
    assert report["bytes_read"] == sum(os.path.getsize(path / f) for f in chunk_files(path))


@pytest.mark.parametrize("dtype", DTYPES)
def test_every_type_both_orders(tmp_path, dtype):
    i = DTYPES.index(dtype)
    data = random_array(dtype, SHAPE, seed=100 + i)
    for order in "CF":
        path = tmp_path / f"{order}.zarr"
        write_zarr(path, data, CODECS[i % len(CODECS)], order=order, separator="./"[i % 2])
        report, raw = dump(path, tmp_path)
        expect_voxels(report, raw, data)
        assert report["type"] == {"u1": "uint8", "i1": "int8", "u2": "uint16", "i2": "int16", "u4": "uint32",
                                  "i4": "int32", "u8": "uint64", "i8": "int64", "f4": "float",
                                  "f8": "double"}[dtype[1:]]


def test_one_byte_types_in_any_byte_order(tmp_path):
    # zarr-python writes "|u1"; '<' and '>' are the same bytes and are read too.
    data = random_array("u1", SHAPE, seed=5)
    path = tmp_path / "a.zarr"
    write_zarr(path, data)
    for order in "<>|":
        meta = json.loads((path / ".zarray").read_text())
        meta["dtype"] = order + "u1"
        (path / ".zarray").write_text(json.dumps(meta))
        expect_voxels(*dump(path, tmp_path), data)


@pytest.mark.parametrize("separator", "./")
@pytest.mark.parametrize("order", "CF")
def test_missing_chunks_hold_the_fill_value(tmp_path, separator, order):
    rng = np.random.default_rng(ord(separator) + ord(order))
    for dtype, fill in [("<i2", -7), (">u4", 4000000000), ("<f4", "NaN"), (">f8", -np.inf), ("<u8", 2**64 - 1),
                        ("<i8", -2**63), ("|u1", None)]:
        data = random_array(dtype, SHAPE, seed=int(rng.integers(1 << 30)))
        path = tmp_path / f"{dtype[1:]}.zarr"
        value = {"NaN": np.nan, None: 0}.get(fill, fill) if not isinstance(fill, float) else fill
        write_zarr(path, data, ("blosc", "zstd", 1), order=order, separator=separator, fill_value=value)
        if fill is None:  # a null fill value reads as 0
            meta = json.loads((path / ".zarray").read_text())
            meta["fill_value"] = None
            (path / ".zarray").write_text(json.dumps(meta))
        expected = data.copy()
        files = chunk_files(path)
        removed = rng.choice(len(files), size=len(files) // 3, replace=False)
        for k in removed:
            os.remove(path / files[k])
            iz, iy, ix = map(int, files[k].replace("/", ".").split("."))
            expected[iz * 8:(iz + 1) * 8, iy * 7:(iy + 1) * 7, ix * 5:(ix + 1) * 5] = (
                np.nan if fill == "NaN" else 0 if fill is None else fill)
        report, raw = dump(path, tmp_path)
        expect_voxels(report, raw, expected)
        assert report["missing_chunks"] == len(removed)


@pytest.mark.parametrize("seed", range(6))
def test_random_shapes_and_chunks(tmp_path, seed):
    """Shapes, chunks (larger than the array too) and codecs drawn at random, fixed seeds."""
    rng = np.random.default_rng(1000 + seed)
    for k in range(4):
        shape = tuple(int(n) for n in rng.integers(1, 30, size=3))
        chunks = tuple(int(c) for c in rng.integers(1, 12, size=3))
        dtype = DTYPES[int(rng.integers(len(DTYPES)))]
        codec = CODECS[int(rng.integers(len(CODECS)))]
        data = random_array(dtype, shape, seed=int(rng.integers(1 << 30)))
        path = tmp_path / f"{k}.zarr"
        write_zarr(path, data, codec, order="CF"[k % 2], separator="./"[seed % 2], chunks=chunks)
        expect_voxels(*dump(path, tmp_path), data)


def test_two_dimensional_array_is_one_slice(tmp_path):
    data = random_array("<u2", (29, 23), seed=3)
    path = tmp_path / "a.zarr"
    write_zarr(path, data, ("zstd",), chunks=(8, 5))
    report, raw = dump(path, tmp_path)
    expect_voxels(report, raw, data)
    assert report["dims"] == [23, 29, 1]


@pytest.mark.parametrize("order", "CF")
def test_leading_time_and_channel_axes_chosen_by_index(tmp_path, order):
    data = random_array("<i2", (2, 3, 13, 11, 9), seed=11)
    path = tmp_path / "tczyx.zarr"
    # Chunks of 2 channels: the volume starts inside a chunk for channel 1.
    write_zarr(path, data, ("blosc", "lz4", 1), order=order, chunks=(1, 2, 4, 5, 3))
    for t in range(2):
        for c in range(3):
            report, raw = dump(path, tmp_path, "--time", t, "--channel", c)
            expect_voxels(report, raw, data[t, c])
            assert report["chosen"] == [{"name": "t", "index": t, "size": 2}, {"name": "c", "index": c, "size": 3}]
    report, raw = dump(path, tmp_path)  # index 0 by default
    expect_voxels(report, raw, data[0, 0])
    assert report["choice"] == "t 0 of 2, c 0 of 3"
    expect_refused(path, tmp_path, "--channel", 3, says=["channel 3 is outside", "of 3"])
    expect_refused(path, tmp_path, "--time", -1, says=["time -1 is outside"])
    expect_refused(path, tmp_path, "--level", 1, says=["level 1"])
    czyx = tmp_path / "czyx.zarr"
    write_zarr(czyx, data[1], ("zlib",), order=order, chunks=(3, 4, 5, 3))
    expect_voxels(*dump(czyx, tmp_path, "--channel", 2), data[1, 2])
    expect_refused(czyx, tmp_path, "--time", 0, says=["no time axis"])
    zyx = tmp_path / "zyx.zarr"
    write_zarr(zyx, data[1, 1], chunks=(4, 5, 3))
    expect_refused(zyx, tmp_path, "--channel", 0, says=["no channel axis"])


# --- N5 ----------------------------------------------------------------------------------------

N5_CODECS = [None, numcodecs.GZip(level=5), numcodecs.Zlib(level=5), numcodecs.Zstd(level=3),
             numcodecs.Blosc("lz4", shuffle=1), numcodecs.Blosc("zstd", shuffle=2)]


@pytest.mark.parametrize("k", range(len(N5_CODECS)))
def test_n5_written_by_zarr(tmp_path, k):
    store = zarr.N5Store(str(tmp_path / "c.n5"))
    for j, dtype in enumerate(["u1", "i2", "u4", "i8", "f4", "f8"][k % 2::2]):
        data = random_array(dtype, SHAPE, seed=10 * k + j)
        z = zarr.create(store=store, path=f"g/v{j}", shape=SHAPE, chunks=CHUNKS, dtype=dtype,
                        compressor=N5_CODECS[k], overwrite=True)
        z[...] = data
        report, raw = dump(tmp_path / "c.n5" / "g" / f"v{j}", tmp_path)
        expect_voxels(report, raw, data)
        assert report["format"] == "n5" and report["missing_chunks"] == 0
    # The group and the container name their datasets.
    expect_refused(tmp_path / "c.n5" / "g", tmp_path, says=["an N5 group", "/g/v0'"])


def n5_block(block, compress):
    """An N5 block as the specification lays it out: mode 0, the block's own size (x first),
    big-endian voxels x fastest, compressed whole."""
    header = struct.pack(">HH", 0, block.ndim) + b"".join(struct.pack(">I", n) for n in block.shape[::-1])
    return header + compress(np.ascontiguousarray(block.astype(block.dtype.newbyteorder(">"))).tobytes())


@pytest.mark.parametrize("compression", ["raw", "gzip", "zlib"])
def test_n5_written_by_hand_clipped_edge_blocks(tmp_path, compression):
    data = random_array("<u2", SHAPE, seed=42)
    path = tmp_path / "d"
    path.mkdir()
    attrs = {"dimensions": list(SHAPE[::-1]), "blockSize": list(CHUNKS[::-1]), "dataType": "uint16",
             "compression": {"type": "gzip", "useZlib": compression == "zlib"} if compression != "raw" else {"type": "raw"}}
    (path / "attributes.json").write_text(json.dumps(attrs))
    compress = {"raw": bytes, "gzip": gzip.compress, "zlib": zlib.compress}[compression]
    expected = data.copy()
    rng = np.random.default_rng(4)
    for iz in range(5):
        for iy in range(5):
            for ix in range(5):
                region = np.s_[iz * 8:(iz + 1) * 8, iy * 7:(iy + 1) * 7, ix * 5:(ix + 1) * 5]
                if rng.random() < 0.2:  # not written: 0
                    expected[region] = 0
                    continue
                (path / str(ix) / str(iy)).mkdir(parents=True, exist_ok=True)
                (path / str(ix) / str(iy) / str(iz)).write_bytes(n5_block(data[region], compress))
    expect_voxels(*dump(path, tmp_path), expected)


def test_n5_bad_blocks(tmp_path):
    data = random_array("<u2", (8, 7, 5), seed=1)
    path = tmp_path / "d"
    (path / "0" / "0").mkdir(parents=True)
    (path / "attributes.json").write_text(json.dumps(
        {"dimensions": [5, 7, 8], "blockSize": [5, 7, 8], "dataType": "uint16", "compression": {"type": "raw"}}))
    block = path / "0" / "0" / "0"
    good = n5_block(data, bytes)
    block.write_bytes(struct.pack(">HH", 1, 3) + good[4:16] + struct.pack(">I", data.size) + good[16:])
    expect_refused(path, tmp_path, says=["block mode 1 (varlength)", "/0/0/0'"])
    block.write_bytes(good[:-1])
    expect_refused(path, tmp_path, says=["holds 559 bytes where the chunk holds 560"])
    block.write_bytes(good[:10])
    expect_refused(path, tmp_path, says=["shorter than its block header"])
    block.write_bytes(good[:4] + struct.pack(">I", 6) + good[8:])
    expect_refused(path, tmp_path, says=["6 voxels along axis 0 where the dataset's blocks have 5"])
    block.write_bytes(good)
    expect_voxels(*dump(path, tmp_path), data)
    for attrs, says in [({"dataType": "object"}, "unsupported dataType \"object\""),
                        ({"compression": {"type": "xz"}}, "unsupported compression 'xz'"),
                        ({"compression": {"type": "lz4"}}, "unsupported compression 'lz4'")]:
        meta = {"dimensions": [5, 7, 8], "blockSize": [5, 7, 8], "dataType": "uint16", "compression": {"type": "raw"}}
        meta.update(attrs)
        (path / "attributes.json").write_text(json.dumps(meta))
        expect_refused(path, tmp_path, says=[says, "attributes.json'"])
    # A useZlib that is not a boolean is not true: gzip, which the raw block is not.
    meta["compression"] = {"type": "gzip", "useZlib": {"x": 1}}
    (path / "attributes.json").write_text(json.dumps(meta))
    expect_refused(path, tmp_path, says=["corrupt or truncated gzip data", "/0/0/0'"])


# --- OME-Zarr ----------------------------------------------------------------------------------

def affine(transforms, rank):
    """The (rank+1)^2 matrix of OME-Zarr transformations applied in order."""
    m = np.eye(rank + 1)
    for t in transforms:
        step = np.eye(rank + 1)
        if t["type"] == "scale":
            step[:rank, :rank] = np.diag(t["scale"])
        elif t["type"] == "translation":
            step[:rank, rank] = t["translation"]
        m = step @ m
    return m


def write_ome(path, levels, axes, dataset_transforms, global_transforms, codec=("blosc", "zstd", 2)):
    root = zarr.open_group(str(path), mode="w")
    datasets = []
    for k, data in enumerate(levels):
        z = root.create_dataset(f"s{k}", shape=data.shape, chunks=(1,) * (data.ndim - 3) + (6, 5, 4),
                                dtype=data.dtype, compressor=compressor(codec))
        z[...] = data
        datasets.append({"path": f"s{k}", "coordinateTransformations": dataset_transforms[k]})
    multiscale = {"version": "0.4", "name": "test", "axes": axes, "datasets": datasets}
    if global_transforms is not None:
        multiscale["coordinateTransformations"] = global_transforms
    root.attrs["multiscales"] = [multiscale]


def test_ome_zarr_levels_and_composed_transforms(tmp_path):
    rng = np.random.default_rng(9)
    full = random_array("<u2", (2, 37, 29, 23), seed=8)
    levels = [full, full[:, ::2, ::2, ::2], full[:, ::4, ::4, ::4]]
    axes = [{"name": "c", "type": "channel"}] + [{"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"]
    dataset_transforms = []
    for k in range(3):
        scale = [1.0] + [float(s) * 2 ** k for s in (0.5, 0.25, 0.2)]
        shift = [0.0] + [float(v) for v in rng.uniform(-3, 3, size=3)]
        dataset_transforms.append([{"type": "scale", "scale": scale}, {"type": "translation", "translation": shift}])
    global_transforms = [{"type": "scale", "scale": [1.0, 2.0, 3.0, 0.5]},
                         {"type": "translation", "translation": [0.0, 10.0, -20.0, 30.0]}]
    path = tmp_path / "image.ome.zarr"
    write_ome(path, levels, axes, dataset_transforms, global_transforms)
    for k in range(3):
        for c in range(2):
            report, raw = dump(path, tmp_path, "--level", k, "--channel", c)
            expect_voxels(report, raw, levels[k][c])
            m = affine(dataset_transforms[k] + global_transforms, 4)
            # The engine's axes are the array's reversed: x the last.
            assert report["spacing"] == pytest.approx(np.diag(m)[1:4][::-1].tolist(), rel=1e-14)
            assert report["origin"] == pytest.approx(m[1:4, 4][::-1].tolist(), rel=1e-14, abs=1e-14)
            assert report["direction"] == np.eye(3).tolist()
            assert report["unit"] == "micrometer" and report["format"] == "ome-zarr"
            assert report["level"] == k and report["levels"] == 3
            assert report["choice"] == f"level {k} of 3, c {c} of 2"
            assert report["channel"] == c and report["channels"] == 2
            assert report["array"].endswith(f"image.ome.zarr/s{k}")
    expect_refused(path, tmp_path, "--level", 3, says=["level 3 is outside its 3 levels (0 to 2)"])
    expect_refused(path, tmp_path, "--channel", 2, says=["channel 2 is outside its axis 'c' of 2"])
    expect_refused(path, tmp_path, "--time", 0, says=["no time axis"])


def test_ome_zarr_without_global_transform_and_without_translation(tmp_path):
    data = random_array(">f4", (17, 13, 11), seed=2)
    axes = [{"name": n, "type": "space"} for n in "zyx"]
    path = tmp_path / "image.zarr"
    write_ome(path, [data], axes, [[{"type": "scale", "scale": [3.0, 2.0, 0.5]}]], None, codec=("gzip",))
    report, raw = dump(path, tmp_path)
    expect_voxels(report, raw, data)
    assert report["spacing"] == [0.5, 2.0, 3.0] and report["origin"] == [0.0, 0.0, 0.0]
    assert report["unit"] == "" and report["choice"] == ""


def test_ome_zarr_bad_metadata(tmp_path):
    data = random_array("<u1", (6, 5, 4), seed=2)
    axes = [{"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"]
    scale = [{"type": "scale", "scale": [1.0, 1.0, 1.0]}]
    path = tmp_path / "image.zarr"
    cases = [
        (dict(version="0.3"), "OME-Zarr version \"0.3\": surftrack reads version 0.4"),
        (dict(axes=axes[:2] + [{"name": "x", "type": "space", "unit": "nanometer"}]), "different units"),
        (dict(axes=[{"name": "z", "type": "space"}, {"name": "c", "type": "channel"}, {"name": "x", "type": "space"}]),
         "are not 2 or 3 trailing space axes"),
        (dict(datasets=[]), "\"datasets\" must list the levels"),
        (dict(datasets=[{"path": "s0", "coordinateTransformations": [{"type": "scale", "scale": [1, 0, 1]}]}]),
         "must be positive"),
        (dict(datasets=[{"path": "s0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1]}]}]),
         "does not have one value for each of the 3 axes"),
        (dict(datasets=[{"path": "s0", "coordinateTransformations": [{"type": "affine", "affine": []}]}]),
         "unsupported coordinateTransformation"),
        (dict(datasets=[{"path": "../s0", "coordinateTransformations": scale}]), "leaves the group"),
        (dict(datasets=[{"path": "s1", "coordinateTransformations": scale}]), "not a zarr array (no .zarray)"),
    ]
    for change, says in cases:
        write_ome(path, [data], axes, [scale], None)
        ms = dict(zarr.open_group(str(path)).attrs["multiscales"][0])
        ms.update(change)
        zarr.open_group(str(path)).attrs["multiscales"] = [ms]
        expect_refused(path, tmp_path, says=[says])
    # A 4D level under three axes.
    write_ome(path, [data], axes, [scale], None)
    zarr.open_array(str(path / "s0"), mode="w", shape=(1, 6, 5, 4), chunks=(1, 6, 5, 4), dtype="u1")
    expect_refused(path, tmp_path, says=["the array has 4 dimensions where the OME-Zarr image names 3 axes"])


# --- What cannot be read: one line, exit status 1 ------------------------------------------------

def small_store(tmp_path, codec=("blosc", "lz4", 1), name="a.zarr", dtype="<u2"):
    data = random_array(dtype, (12, 10, 9), seed=3)
    path = tmp_path / name
    write_zarr(path, data, codec, chunks=(6, 5, 9))
    return path, data


def edit_zarray(path, **fields):
    meta = json.loads((path / ".zarray").read_text())
    meta.update(fields)
    (path / ".zarray").write_text(json.dumps(meta))


def test_bad_metadata(tmp_path):
    path, _ = small_store(tmp_path)
    (path / ".zarray").write_text('{"zarr_format": 2, "shape": [12, 10,')
    expect_refused(path, tmp_path, says=["/.zarray': not valid JSON"])
    cases = [
        (dict(zarr_format=3), "zarr_format 3: surftrack reads zarr format 2"),
        (dict(dtype="<c8"), "unsupported dtype \"<c8\": surftrack reads u1, i1, u2, i2, u4, i4, u8, i8, f4 or f8"),
        (dict(dtype="|b1"), "unsupported dtype \"|b1\""),
        (dict(dtype="<f2"), "unsupported dtype \"<f2\""),
        (dict(dtype="|u2"), "unsupported dtype \"|u2\""),
        (dict(dtype=[["a", "<u2"]]), "unsupported dtype"),
        (dict(order="K"), "the order \"K\" is neither"),
        (dict(dimension_separator="-"), "dimension_separator \"-\""),
        (dict(shape=[12, 10]), "the chunks [6, 5, 9] do not have one size for each of the 2 axes"),
        (dict(shape=[12, 0, 9]), "has an empty axis"),
        (dict(shape=[12, -1, 9]), "'shape' must be a list of integers >= 0"),
        (dict(chunks=[6, 0, 9]), "'chunks' must be a list of integers >= 1"),
        (dict(chunks=[6, "5", 9]), "'chunks' must be a list of integers >= 1"),
        (dict(shape=[12, 10, 3000000000]), "more than 2147483647 voxels along a spatial axis"),
        (dict(chunks=[2000, 2000, 2000]), "take more than the 2 GiB a chunk may"),
        (dict(shape=[1, 1, 1, 1, 12, 10, 9], chunks=[1, 1, 1, 1, 6, 5, 9]), "the array has 7 dimensions"),
        (dict(shape=[12], chunks=[6]), "the array has 1 dimensions"),
        (dict(fill_value=70000), "the fill_value 70000 is not a uint16 value"),
        (dict(fill_value=-1), "the fill_value -1 is not a uint16 value"),
        (dict(fill_value=1.5), "the fill_value 1.5 is not a uint16 value"),
        (dict(fill_value="NaN"), "the fill_value \"NaN\" is not a uint16 value"),
        (dict(compressor={"id": "lz4", "acceleration": 1}), "unsupported compressor 'lz4': surftrack reads blosc, zstd, zlib, gzip or none"),
        (dict(compressor={"id": "bz2", "level": 1}), "unsupported compressor 'bz2'"),
        (dict(filters=[{"id": "delta", "dtype": "<u2"}]), "filters [{\"dtype\":\"<u2\",\"id\":\"delta\"}] are not supported"),
    ]
    for fields, says in cases:
        path, _ = small_store(tmp_path)
        edit_zarray(path, **fields)
        expect_refused(path, tmp_path, says=[says])
    path, _ = small_store(tmp_path)
    (path / ".zarray").write_text("[1, 2]")
    expect_refused(path, tmp_path, says=["not a JSON object"])


def test_not_a_store(tmp_path):
    expect_refused(tmp_path / "nothing", tmp_path, says=["no such directory"])
    (tmp_path / "file.zarr").write_text("x")
    expect_refused(tmp_path / "file.zarr", tmp_path, says=["a file; a chunked store is a directory"])
    (tmp_path / "empty").mkdir()
    expect_refused(tmp_path / "empty", tmp_path, says=["not a zarr array (.zarray), an OME-Zarr image"])
    group = zarr.open_group(str(tmp_path / "g.zarr"), mode="w")
    group.create_dataset("b", shape=(4, 4, 4), dtype="u1")
    group.create_dataset("a", shape=(4, 4, 4), dtype="u1")
    expect_refused(tmp_path / "g.zarr", tmp_path, says=["a zarr group without OME-Zarr multiscales",
                                                       "g.zarr/a', '", "g.zarr/b'"])


@pytest.mark.parametrize("codec", [("blosc", "lz4", 1), ("blosc", "zstd", 2), ("blosc", "blosclz", 0),
                                   ("zstd",), ("zlib",), ("gzip",), (None,)], ids=lambda c: "-".join(map(str, c)))
def test_bad_chunks(tmp_path, codec):
    path, data = small_store(tmp_path, codec)
    chunk = path / "0.0.0"
    good = chunk.read_bytes()
    # Truncated.
    for keep in sorted({0, 1, 10, len(good) // 2, len(good) - 1}):
        chunk.write_bytes(good[:keep])
        expect_refused(path, tmp_path, says=["cannot read chunk '", "/0.0.0'"])
    # Another size of voxels, compressed correctly.
    for wrong in (data[:6, :5, :8], np.concatenate([data[:6, :5, :], data[:1, :5, :]])):
        c = compressor(codec)
        raw = np.ascontiguousarray(wrong).tobytes()
        chunk.write_bytes(c.encode(raw) if c else raw)
        says = "bytes where the chunk holds 540" if wrong.nbytes < 540 or codec[0] in (None, "blosc") else "more than the 540 bytes"
        expect_refused(path, tmp_path, says=[says, "/0.0.0'"])
    # Random bytes and bit flips: refused or decoded, never a crash.
    rng = np.random.default_rng(len(good))
    for trial in range(40):
        if trial < 10:
            bad = rng.integers(0, 256, size=int(rng.integers(1, 2 * len(good) + 20)), dtype=np.uint8).tobytes()
        else:
            b = bytearray(good)
            for _ in range(int(rng.integers(1, 4))):
                b[int(rng.integers(len(b)))] ^= 1 << int(rng.integers(8))
            bad = bytes(b)
        chunk.write_bytes(bad)
        r, _ = run(path, tmp_path)
        assert r.returncode in (0, 1), r.stderr
        if r.returncode == 1:
            assert r.stderr.count("\n") == 1 and "/0.0.0'" in r.stderr, r.stderr
    chunk.write_bytes(good)
    expect_voxels(*dump(path, tmp_path), data)


def test_chunk_that_is_a_directory(tmp_path):
    path, _ = small_store(tmp_path)
    os.remove(path / "1.0.0")
    (path / "1.0.0").mkdir()
    expect_refused(path, tmp_path, says=["cannot read chunk '", "/1.0.0': it is not a regular file"])


def probe(path):
    r = subprocess.run([EXE, "--probe", str(path)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    return json.loads(r.stdout)


def test_recognised_stores(tmp_path):
    """isChunkedStore: the three kinds of store (a trailing slash too) and their groups, nothing else."""
    zarr_array, data = small_store(tmp_path)
    write_ome(tmp_path / "ome", [data], [{"name": n, "type": "space"} for n in "zyx"],
              [[{"type": "scale", "scale": [1.0, 1.0, 1.0]}]], None)
    z = zarr.create(store=zarr.N5Store(str(tmp_path / "c.n5")), path="v", shape=(4, 4, 4), dtype="u1")
    z[...] = 1
    zarr.open_group(str(tmp_path / "g.zarr"), mode="w")
    for path in [zarr_array, tmp_path / "ome", tmp_path / "c.n5" / "v", tmp_path / "c.n5", tmp_path / "g.zarr"]:
        assert probe(path) and probe(str(path) + "/")
    expect_voxels(*dump(str(zarr_array) + "/", tmp_path), data)
    (tmp_path / "empty").mkdir()
    for path in [tmp_path / "empty", tmp_path / "nothing",
                 zarr_array / "0.0.0", tmp_path / "ome" / "s0" / "0.0.0"]:
        assert not probe(path)
    # Damaged metadata is still a store: opening it says what is wrong.
    (zarr_array / ".zarray").write_text("{")
    assert probe(zarr_array)


def test_ome_zarr_time_series_of_slices(tmp_path):
    data = random_array("<f8", (3, 10, 9), seed=6)
    axes = [{"name": "t", "type": "time", "unit": "second"},
            {"name": "y", "type": "space", "unit": "nanometer"}, {"name": "x", "type": "space", "unit": "nanometer"}]
    root = zarr.open_group(str(tmp_path / "ts.zarr"), mode="w")
    root.create_dataset("0", data=data, chunks=(2, 4, 4), compressor=compressor(("zstd",)))
    root.attrs["multiscales"] = [{"version": "0.4", "axes": axes, "datasets": [
        {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [60.0, 4.0, 2.5]},
                                                    {"type": "translation", "translation": [0.0, 1.0, -1.0]}]}]}]
    for t in range(3):
        report, raw = dump(tmp_path / "ts.zarr", tmp_path, "--time", t)
        expect_voxels(report, raw, data[t])
        assert report["dims"] == [9, 10, 1] and report["unit"] == "nanometer"
        assert report["spacing"] == [2.5, 4.0, 1.0] and report["origin"] == [-1.0, 1.0, 0.0]
        assert report["chosen"] == [{"name": "t", "index": t, "size": 3}]


# --- The command-line tool reads stores whole ----------------------------------------------------

CLI = os.environ.get("SURFTRACK_EXE", "build/cli/surftrack")


def surftrack(*args):
    if not os.path.exists(CLI):
        pytest.skip("the command-line tool is not built")
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, timeout=120)


def test_cli_meshes_a_store_as_the_same_voxels_in_a_raw_file(tmp_path):
    z, y, x = np.mgrid[:40, :36, :32]
    ball = np.where((x - 15.3) ** 2 + (y - 17.6) ** 2 / 1.5 + (z - 19.2) ** 2 < 12 ** 2, 200, 10).astype("<u2")
    channels = np.stack([ball // 2, ball])  # c, z, y, x
    axes = [{"name": "c", "type": "channel"}] + [{"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"]
    store = tmp_path / "ball.ome.zarr"
    write_ome(store, [channels, channels[:, ::2, ::2, ::2]], axes,
              [[{"type": "scale", "scale": [1.0, 2.0 * f, 1.0 * f, 0.5 * f]},
                {"type": "translation", "translation": [0.0, 3.0, -4.0, 5.0]}] for f in (1, 2)], None)
    for level, channel in [(0, 1), (1, 1), (1, 0)]:
        data = channels[channel][:: 2 ** level, :: 2 ** level, :: 2 ** level]
        data.tofile(tmp_path / "ball.raw")
        f = 2 ** level
        r = surftrack("mesh", store, "--level", level, "--channel", channel, "-o", tmp_path / "a.ply", "--iso", 60, "--json")
        assert r.returncode == 0, r.stderr
        raw = surftrack("mesh", tmp_path / "ball.raw", "--raw-dims", "{},{},{}".format(*data.shape[::-1]), "--raw-type",
                        "uint16", "--spacing", "{},{},{}".format(0.5 * f, 1.0 * f, 2.0 * f), "--origin", "5,-4,3",
                        "-o", tmp_path / "b.ply", "--iso", 60)
        assert raw.returncode == 0, raw.stderr
        assert (tmp_path / "a.ply").read_bytes() == (tmp_path / "b.ply").read_bytes()
    r = surftrack("info", store, "--json", "--channel", 1)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert info["dims"] == [32, 36, 40] and info["unit"] == "micrometer" and info["channel"] == 1
    assert info["spacing"] == [0.5, 1.0, 2.0] and info["origin"] == [5.0, -4.0, 3.0]
    # The store's chunks as zarr-python states them (its axes reversed: the engine's x first).
    level0 = zarr.open(str(store / "s0"), mode="r")
    chunked = info["chunked"]
    assert chunked["chunk"] == list(level0.chunks[1:][::-1]) and chunked["levels"] == 2 and chunked["level"] == 0
    assert chunked["chunks"] == [-(-n // c) for n, c in zip(level0.shape[1:][::-1], level0.chunks[1:][::-1])]
    assert chunked["dtype"] == level0.dtype.str and chunked["format"] == "ome-zarr"
    assert info["storage"]["mapped"] is False and "min" in info  # (small: its values read)
    for args, says in [((store, "--level", 2), "level 2 is outside its 2 levels"),
                       ((store, "--time", 0), "no time axis"),
                       ((tmp_path / "ball.raw", "--raw-dims", "1,1,1", "--raw-type", "uint8", "--level", 1), "--level and --time")]:
        r = surftrack("info", *args)
        assert r.returncode == 1 and r.stderr.count("\n") == 1 and says in r.stderr, r.stderr


def test_cli_seeded_mesh_reads_a_store_lazily(tmp_path):
    """`surftrack mesh STORE --iso S --seed ...` decodes only the chunks around the surface (the
    chunk cache, core/include/surftrack/ChunkedSource.h), with the same PLY bytes as the same
    voxels in a raw file; --largest reads the store whole, as before, with the same bytes; a
    one-chunk cache (--cache 1) gives them too."""
    n = 160
    z, y, x = np.ogrid[:n, :n, :n]
    ball = np.where((x - 80.5) ** 2 + (y - 70.2) ** 2 + (z - 90.7) ** 2 < 20 ** 2, 200, 10).astype("<u2")
    store = tmp_path / "ball.zarr"
    zarr.open(str(store), mode="w", shape=ball.shape, chunks=(16, 16, 16), dtype="<u2",
              compressor=numcodecs.Blosc("zstd", 3, numcodecs.Blosc.SHUFFLE))[:] = ball
    ball.tofile(tmp_path / "ball.raw")
    inside = ball > 100
    outside_neighbour = np.zeros_like(inside)
    for axis in range(3):
        for step in (1, -1):
            outside_neighbour |= ~np.roll(inside, step, axis=axis)
    surface_chunks = len(np.unique(np.argwhere(inside & outside_neighbour) // 16, axis=0))
    box = np.argwhere(inside)
    lo, hi = (box.min(axis=0) - 9) // 16, (box.max(axis=0) + 9) // 16
    near_chunks = int(np.prod(hi - lo + 1))
    assert near_chunks < 150
    raw = surftrack("mesh", tmp_path / "ball.raw", "--raw-dims", f"{n},{n},{n}", "--raw-type", "uint16",
                    "--spacing", "0.5,1,2", "--iso", 100, "--seed", "80,70,90", "-o", tmp_path / "raw.ply")
    assert raw.returncode == 0, raw.stderr
    for extra in [(), ("--cache", 1)]:
        r = surftrack("mesh", store, "--spacing", "0.5,1,2", "--iso", 100, "--seed", "80,70,90",
                      "-o", tmp_path / "lazy.ply", "--json", *extra)
        assert r.returncode == 0, r.stderr
        storage = json.loads(r.stdout)["input_storage"]
        assert storage["storage"].endswith("read lazily") and storage["chunks"] == 1000
        # At least every chunk holding a voxel of the surface, at most those within one tracker
        # brick and its apron (9 voxels) of the ball's box: about a tenth of the 1,000.
        assert surface_chunks <= storage["chunks_decoded"] <= (near_chunks if not extra else 1000), storage
        assert (tmp_path / "lazy.ply").read_bytes() == (tmp_path / "raw.ply").read_bytes()
    whole = surftrack("mesh", store, "--spacing", "0.5,1,2", "--iso", 100, "--largest", "-o", tmp_path / "whole.ply",
                      "--json")
    assert whole.returncode == 0, whole.stderr
    assert "chunks_decoded" not in json.loads(whole.stdout)["input_storage"]
    assert (tmp_path / "whole.ply").read_bytes() == (tmp_path / "raw.ply").read_bytes()
    # Every chunk farther than a brick from the ball made garbage: the lazy extraction never
    # reads one (same bytes), the whole read stops at the first.
    for name in os.listdir(store):
        if name.startswith("."):
            continue
        index = np.array([int(v) for v in name.split(".")])
        if np.any(index < lo) or np.any(index > hi):
            (store / name).write_bytes(b"not a blosc chunk")
    r = surftrack("mesh", store, "--spacing", "0.5,1,2", "--iso", 100, "--seed", "80,70,90", "-o", tmp_path / "lazy.ply")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "lazy.ply").read_bytes() == (tmp_path / "raw.ply").read_bytes()
    r = surftrack("mesh", store, "--iso", 100, "--largest", "-o", tmp_path / "whole.ply")
    assert r.returncode == 1 and r.stderr.count("\n") == 1 and "chunk" in r.stderr, r.stderr
    far = surftrack("mesh", store, "--iso", 100, "--seed", "2,2,2", "--max-seed-distance", 4, "-o", tmp_path / "x.ply")
    assert far.returncode == 1 and far.stderr.count("\n") == 1, far.stderr


def test_a_store_larger_than_memory_is_read_lazily_or_refused(tmp_path):
    """A 4000^3 uint8 store (60 GiB of voxels, one chunk written): a seeded mesh decodes one
    chunk; --largest, which would decode it whole, is refused naming what reads it in parts."""
    store = tmp_path / "huge.zarr"
    z = zarr.open(str(store), mode="w", shape=(4000, 4000, 4000), chunks=(64, 64, 64), dtype="|u1")
    z[100:110, 100:110, 100:110] = 5
    r = surftrack("mesh", store, "--iso", 1, "--seed", "105,105,105", "-o", tmp_path / "a.ply", "--json")
    assert r.returncode == 0, r.stderr
    storage = json.loads(r.stdout)["input_storage"]
    assert storage["chunks_decoded"] == 1 and storage["chunks"] == 63 ** 3
    r = surftrack("mesh", store, "--iso", 1, "--largest", "-o", tmp_path / "b.ply")
    assert r.returncode == 1 and r.stderr.count("\n") == 1, r.stderr
    assert "whole" in r.stderr and "seed rule" in r.stderr and "surftrack.distributed" in r.stderr
    assert not (tmp_path / "b.ply").exists()
    # `info` describes it from its metadata, decoding nothing: a chunk made garbage is not read.
    for chunk in store.glob("1.*"):
        chunk.write_bytes(b"garbage")
    r = surftrack("info", store, "--json")
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert info["dims"] == [4000, 4000, 4000] and info["type"] == "uint8" and "min" not in info
    assert info["storage"]["values_read"] is False and "memory" in info["storage"]["not_read_because"]
    assert info["chunked"]["chunk"] == [64, 64, 64] and info["chunked"]["chunks"] == [63, 63, 63]
    assert info["chunked"]["compressor"].startswith("blosc")  # zarr-python's default compressor
    r = surftrack("info", store, "--spacing", "2,3,4")
    assert r.returncode == 0 and "its values not read" in r.stdout and "63 x 63 x 63 = 250047 chunks" in r.stdout
    assert "voxel centres from (0, 0, 0) to (7998, 11997, 15996)" in r.stdout, r.stdout


MUTANTS = [None, 0, -1, 1, 3, 2 ** 31, 2 ** 63, -2 ** 63, 2 ** 64 - 1, 1.5, 1e300, "NaN", "", "x", [], [1], [0, 0, 0],
           [2 ** 40, 1, 1], {}, {"id": "blosc"}, {"type": "gzip"}, True, "<u2", "|u1", ">f8", "F", "/", [[1]], "0.4",
           {"type": "scale", "scale": [1, 1, 1]}]


def mutate(obj, rng, depth=0):
    """Replaces, deletes or appends one value somewhere in a JSON document."""
    keys = list(obj) if isinstance(obj, dict) else list(range(len(obj)))
    if not keys:
        return
    k = keys[int(rng.integers(len(keys)))]
    r = rng.random()
    if r < 0.15:
        del obj[k]
    elif r < 0.5 and isinstance(obj[k], (dict, list)) and obj[k] and depth < 4:
        mutate(obj[k], rng, depth + 1)
    elif r < 0.6 and isinstance(obj, list):
        obj.append(json.loads(json.dumps(MUTANTS[int(rng.integers(len(MUTANTS)))])))
    else:
        obj[k] = json.loads(json.dumps(MUTANTS[int(rng.integers(len(MUTANTS)))]))


def test_random_metadata_mutations(tmp_path):
    """Metadata of each kind of store mutated at random (fixed seed): read, or refused with one
    line, never a crash."""
    rng = np.random.default_rng(2024)
    data = np.arange(2 * 6 * 5 * 4, dtype="<u2").reshape(2, 6, 5, 4)
    for trial in range(90):
        path = tmp_path / f"m{trial}"
        kind = trial % 3
        if kind == 0:
            write_zarr(path, data, ("blosc", "lz4", 1), chunks=(1, 3, 2, 4))
            meta, store = path / ".zarray", path
        elif kind == 1:
            axes = [{"name": "c", "type": "channel"}] + [{"name": n, "type": "space", "unit": "um"} for n in "zyx"]
            write_ome(path, [data], axes, [[{"type": "scale", "scale": [1, 2, 3, 4]},
                                            {"type": "translation", "translation": [0, 1, 2, 3]}]],
                      [{"type": "scale", "scale": [1, 1, 1, 1]}])
            meta, store = path / ".zattrs", path
        else:
            z = zarr.create(store=zarr.N5Store(str(path)), path="d", shape=data.shape, chunks=(1, 3, 2, 4),
                            dtype="<u2", compressor=numcodecs.GZip())
            z[...] = data
            meta, store = path / "d" / "attributes.json", path / "d"
        doc = json.loads(meta.read_text())
        for _ in range(int(rng.integers(1, 4))):
            mutate(doc, rng)
        meta.write_text(json.dumps(doc))
        args = [[], ["--channel", 1], ["--level", 1], ["--time", 0]][trial // 3 % 4]
        r, _ = run(store, tmp_path, *args)
        assert r.returncode in (0, 1), (doc, r.stderr)
        if r.returncode == 1:
            assert r.stderr.count("\n") == 1 and r.stderr.startswith("chunk_dump: error: cannot read "), (doc, r.stderr)
