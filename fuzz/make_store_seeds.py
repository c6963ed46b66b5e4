"""Writes the seed corpus of fuzz/fuzz_chunked_store.cpp with an independent writer: zarr v2
arrays, N5 datasets and OME-Zarr images written by zarr-python 2.13 and numcodecs (Debian's
python3-zarr and python3-numcodecs), N5 blocks also by hand as the N5 specification lays them out
(clipped at the far edges, the old "compressionType"), and chunks compressed by numcodecs and by
Python's gzip and zlib modules. Each store is packed into one input as fuzz/ChunkedStoreFuzz.h
describes (the format's metadata file first, then "\\n@@@@ <name>\\n" and the bytes of each other
file); each chunk is 4 bytes of its decoded size (little-endian; for gzip, bit 31 set: a zlib
stream) and its bytes. Run by fuzz/CMakeLists.txt with Debian's /usr/bin/python3:
    make_store_seeds.py <dir>      # writes <dir>/{zarr,n5,omezarr,blosc,zstd,gzip}/
and by tests/CMakeLists.txt for tests/test_chunked_fuzz_replay.cpp (with --optional: no seeds,
and status 0, without zarr or numcodecs).
"""
import gzip
import io
import json
import os
import struct
import sys
import tempfile
import warnings
import zlib

import numpy as np

try:
    import numcodecs
    import zarr
except ImportError as e:  # (the test build asks for the seeds --optional: its test then says so)
    if "--optional" in sys.argv:
        print(f"make_store_seeds.py: no seeds written: {e}", file=sys.stderr)
        sys.exit(0)
    raise

MARKER = b"\n@@@@ "
warnings.filterwarnings("ignore", message="Not all N5 implementations support blosc")


def put(root, fmt, name, data):
    os.makedirs(os.path.join(root, fmt), exist_ok=True)
    with open(os.path.join(root, fmt, name), "wb") as f:
        f.write(data)


def pack(directory, first, options=None):
    """The store in `directory` as one input: `first` (its metadata), then every other file."""
    with open(os.path.join(directory, first), "rb") as f:
        out = f.read()
    assert MARKER not in out
    names = []
    for base, _, files in os.walk(directory):
        for name in files:
            names.append(os.path.relpath(os.path.join(base, name), directory))
    for name in sorted(names):
        if name == first:
            continue
        with open(os.path.join(directory, name), "rb") as f:
            data = f.read()
        assert MARKER not in data, name
        out += MARKER + name.encode() + b"\n" + data
    if options:
        out += MARKER + b"!options\n" + options.encode()
    return out


def array(shape, dtype, seed):
    """Ramps and noise: compressible, not constant; floats with a NaN and an infinity."""
    rng = np.random.default_rng(seed)
    dtype = np.dtype(dtype)
    n = int(np.prod(shape))
    ramp = np.arange(n) % 37
    if dtype.kind == "f":
        a = (ramp + rng.standard_normal(n)).astype(dtype)
        a[::11] = np.nan
        a[5::13] = np.inf
    else:
        a = (ramp * 3 + rng.integers(0, 3, n)).astype(dtype)
        if dtype.kind == "i":
            a[::7] = -a[::7]
    return a.reshape(shape)


def compressor(spec):
    if spec is None:
        return None
    kind, *args = spec
    if kind == "blosc":
        return numcodecs.Blosc(cname=args[0], clevel=5, shuffle=args[1])
    return {"zstd": numcodecs.Zstd(level=3), "zlib": numcodecs.Zlib(level=5), "gzip": numcodecs.GZip(level=5)}[kind]


def zarr_seeds(root):
    cases = [  # shape, chunks, dtype, codec, order, separator, fill, what is written, options
        ((5, 6, 7), (3, 4, 3), "u1", ("blosc", "lz4", 1), "C", ".", 0, "all", None),
        ((5, 6, 7), (3, 4, 3), "<i2", ("blosc", "zstd", 2), "F", ".", 0, "all", None),
        ((5, 6, 7), (3, 4, 3), ">u2", ("zstd",), "C", "/", 7, "all", None),
        ((5, 6, 7), (3, 4, 3), "<f4", ("zlib",), "C", ".", "NaN", "part", None),
        ((4, 5, 6), (3, 3, 4), ">f8", ("gzip",), "C", ".", -1.5, "all", None),
        ((4, 5, 6), (2, 3, 4), "<i8", None, "C", ".", 0, "all", None),
        ((4, 5, 6), (2, 3, 4), "|i1", ("blosc", "blosclz", 0), "F", "/", -3, "part", None),
        ((6, 7), (4, 4), "<u4", ("blosc", "lz4hc", 1), "C", ".", 0, "all", None),
        ((2, 3, 4, 5), (1, 2, 3, 3), "u1", ("zstd",), "C", ".", 0, "all", "channel=1"),
        ((2, 2, 3, 4, 5), (1, 2, 2, 3, 3), "<u2", ("blosc", "zlib", 1), "C", ".", 0, "all", "time=1 channel=0"),
        ((4, 4, 4), (4, 4, 4), "<u2", ("blosc", "lz4", 1), "C", ".", 0, "all", None),  # decoded in place
        ((3, 3, 3), (4, 4, 4), ">i4", ("blosc", "lz4", 1), "F", ".", -5, "all", None),
        ((5, 6, 7), (3, 4, 3), "<f8", ("zstd",), "C", ".", "Infinity", "part", None),
    ]
    for k, (shape, chunks, dtype, codec, order, separator, fill, written, options) in enumerate(cases):
        with tempfile.TemporaryDirectory() as tmp:
            store = zarr.DirectoryStore(tmp, dimension_separator=separator)
            z = zarr.create(shape=shape, chunks=chunks, dtype=dtype, compressor=compressor(codec), order=order,
                            fill_value=np.nan if fill == "NaN" else np.inf if fill == "Infinity" else fill, store=store)
            data = array(shape, dtype, k)
            if written == "all":
                z[...] = data
            else:  # the first chunks along the first axis only: the others are missing
                z[: chunks[0]] = data[: chunks[0]]
            put(root, "zarr", f"{k:02d}-{dtype.strip('<>|')}-{codec[0] if codec else 'none'}.zarr", pack(tmp, ".zarray", options))


def n5_block(block, compress):
    """A mode-0 N5 block: its own size (x first), big-endian voxels x fastest, compressed."""
    header = struct.pack(">HH", 0, block.ndim) + b"".join(struct.pack(">I", n) for n in block.shape[::-1])
    return header + compress(block.astype(block.dtype.newbyteorder(">")).tobytes())


def n5_seeds(root):
    codecs = [None, numcodecs.GZip(level=5), numcodecs.Zlib(level=5), numcodecs.Zstd(level=3),
              numcodecs.Blosc(cname="lz4", shuffle=1)]
    dtypes = ["u1", "<u2", "<f4", "<i8", "<f8"]
    for k, codec in enumerate(codecs):
        with tempfile.TemporaryDirectory() as tmp:
            shape, chunks = ((2, 5, 6, 7), (1, 3, 4, 3)) if k == 4 else ((5, 6, 7), (3, 4, 3))
            z = zarr.create(shape=shape, chunks=chunks, dtype=dtypes[k], compressor=codec,
                            store=zarr.N5Store(tmp), path="v")
            z[...] = array(shape, dtypes[k], 100 + k)
            options = "channel=1" if k == 4 else None
            put(root, "n5", f"{k:02d}-zarr-{type(codec).__name__ if codec else 'raw'}.n5",
                pack(os.path.join(tmp, "v"), "attributes.json", options))
    # By hand: blocks clipped at the far edges, the compression before N5 1.0, a missing block.
    shape, chunks = (5, 6, 7), (3, 4, 3)  # numpy's order; N5's is the reverse
    for k, (dtype, compression, compress) in enumerate([
            ("int16", {"type": "gzip"}, gzip.compress),
            ("uint32", {"type": "gzip", "useZlib": True}, zlib.compress),
            ("float32", None, lambda b: b)]):
        with tempfile.TemporaryDirectory() as tmp:
            attributes = {"dimensions": list(shape[::-1]), "blockSize": list(chunks[::-1]), "dataType": dtype}
            if compression:
                attributes["compression"] = compression
            else:
                attributes["compressionType"] = "raw"
            with open(os.path.join(tmp, "attributes.json"), "w") as f:
                json.dump(attributes, f)
            data = array(shape, dtype, 200 + k)
            for iz in range(2):
                for iy in range(2):
                    for ix in range(3):
                        if (ix, iy, iz) == (1, 1, 0):
                            continue  # missing: zeros
                        region = data[iz * 3:(iz + 1) * 3, iy * 4:(iy + 1) * 4, ix * 3:(ix + 1) * 3]
                        path = os.path.join(tmp, str(ix), str(iy), str(iz))
                        os.makedirs(os.path.dirname(path), exist_ok=True)
                        with open(path, "wb") as f:
                            f.write(n5_block(region, compress))
            put(root, "n5", f"{k:02d}-by-hand-{dtype}.n5", pack(tmp, "attributes.json"))


def ome_seeds(root):
    cases = [  # axes, level-0 shape, chunks, options
        ([("z", "space"), ("y", "space"), ("x", "space")], (4, 6, 5), (2, 3, 3), None),
        ([("z", "space"), ("y", "space"), ("x", "space")], (4, 6, 5), (2, 3, 3), "level=1"),
        ([("c", "channel"), ("z", "space"), ("y", "space"), ("x", "space")], (2, 4, 6, 5), (1, 2, 3, 3), "channel=1"),
        ([("t", "time"), ("c", "channel"), ("y", "space"), ("x", "space")], (2, 2, 6, 5), (1, 1, 3, 3), "time=1 level=1"),
    ]
    for k, (axes, shape, chunks, options) in enumerate(cases):
        with tempfile.TemporaryDirectory() as tmp:
            group = zarr.open_group(zarr.DirectoryStore(tmp), mode="w")
            data = array(shape, "<u2", 300 + k)
            spatial = sum(1 for _, t in axes if t == "space")
            datasets = []
            for level in range(2):
                step = tuple([1] * (len(shape) - spatial) + [2 ** level] * spatial)
                level_data = data[tuple(slice(None, None, s) for s in step)]
                group.create_dataset(str(level), data=level_data, chunks=chunks,
                                     compressor=numcodecs.Blosc(cname="zstd", shuffle=2) if level == 0 else numcodecs.Zlib())
                datasets.append({"path": str(level), "coordinateTransformations": [
                    {"type": "scale", "scale": [float(s) * 0.5 for s in step]},
                    {"type": "translation", "translation": [0.25 * level] * len(shape)}]})
            group.attrs["multiscales"] = [{
                "version": "0.4", "name": "seed",
                "axes": [{"name": n, "type": t, **({"unit": "micrometer"} if t == "space" else {})} for n, t in axes],
                "datasets": datasets,
                "coordinateTransformations": [{"type": "scale", "scale": [1.0] * (len(shape) - 1) + [2.0]}]}]
            put(root, "omezarr", f"{k:02d}-ome-{len(shape)}d.zarr", pack(tmp, ".zattrs", options))


def chunk_seed(decoded_size, data, flag=0):
    return struct.pack("<I", decoded_size | flag) + data


def codec_seeds(root):
    sources = [array((8, 16, 16), "u1", 400).tobytes(), array((4, 8, 16), "<u2", 401).tobytes(),
               array((3, 7, 11), "<f4", 402).tobytes(), array((2, 4, 8), "<f8", 403).tobytes(),
               np.random.default_rng(404).integers(0, 256, 1500, dtype=np.uint8).tobytes(),  # incompressible
               b"", b"\x00" * 4096]
    k = 0
    for raw in sources:
        for cname, shuffle, typesize, blocksize in [("lz4", 1, 2, 0), ("zstd", 2, 4, 256), ("zlib", 0, 1, 0),
                                                    ("blosclz", 1, 8, 128), ("lz4hc", 2, 2, 0)]:
            if len(raw) % typesize:
                continue
            codec = numcodecs.Blosc(cname=cname, clevel=5, shuffle=shuffle, blocksize=blocksize)
            encoded = codec.encode(np.frombuffer(raw, dtype=f"u{typesize}") if raw else np.zeros(0, f"u{typesize}"))
            put(root, "blosc", f"{k:02d}-{cname}-{shuffle}-{typesize}.blosc", chunk_seed(len(raw), bytes(encoded)))
            k += 1
    for k, raw in enumerate(sources):
        encoded = numcodecs.Zstd(level=1 + k % 5).encode(raw)
        put(root, "zstd", f"{k:02d}.zst", chunk_seed(len(raw), bytes(encoded)))
    # Two frames, and a skippable frame before one.
    a, b = sources[0][:1000], sources[1][:500]
    put(root, "zstd", "frames.zst", chunk_seed(1500, bytes(numcodecs.Zstd().encode(a)) + bytes(numcodecs.Zstd().encode(b))))
    skippable = struct.pack("<II", 0x184D2A50, 5) + b"skip!"
    put(root, "zstd", "skippable.zst", chunk_seed(1000, skippable + bytes(numcodecs.Zstd().encode(a))))
    for k, raw in enumerate(sources):
        put(root, "gzip", f"{k:02d}.gz", chunk_seed(len(raw), gzip.compress(raw, compresslevel=1 + k % 9, mtime=0)))
        put(root, "gzip", f"{k:02d}.zlib", chunk_seed(len(raw), zlib.compress(raw, 1 + k % 9), flag=1 << 31))
    put(root, "gzip", "numcodecs.gz", chunk_seed(len(sources[1]), bytes(numcodecs.GZip(level=5).encode(sources[1]))))
    # Two members, and a member with a file name, a comment, extra field and header CRC
    # (FNAME, FCOMMENT, FEXTRA, FHCRC) written by hand.
    put(root, "gzip", "members.gz", chunk_seed(1500, gzip.compress(a, mtime=0) + gzip.compress(b, mtime=0)))
    body = zlib.compressobj(6, zlib.DEFLATED, -15)
    deflated = body.compress(a) + body.flush()
    header = b"\x1f\x8b\x08" + bytes([0x02 | 0x04 | 0x08 | 0x10]) + b"\0\0\0\0\0\xff" + struct.pack("<H", 4) + b"abcd" + b"name\0" + b"comment\0"
    header += struct.pack("<H", zlib.crc32(header) & 0xffff)
    put(root, "gzip", "flags.gz", chunk_seed(len(a), header + deflated + struct.pack("<II", zlib.crc32(a), len(a))))


def main():
    args = [a for a in sys.argv[1:] if a != "--optional"]
    if len(args) != 1:
        sys.exit("usage: make_store_seeds.py [--optional] <dir>")
    root = args[0]
    zarr_seeds(root)
    n5_seeds(root)
    ome_seeds(root)
    codec_seeds(root)


if __name__ == "__main__":
    main()
