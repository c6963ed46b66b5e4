"""An independent reader of Neuroglancer's multi-resolution precomputed meshes, written from the
format's description (neuroglancer's meshes.md and sharded.md: the binary .index manifest,
fragments concatenated in manifest order just before the manifest in a shard, the shard index,
gzip'd minishard indices, murmurhash3_x86_128), not from the writer's code: shared by
test_precomputed_multires.py and the browser test (tests/browser/test_neuroglancer.py), which
checks the byte ranges Neuroglancer requests against it."""
import gzip
import os
import struct

import numpy as np


def murmurhash3_x86_128_low64(key):
    """MurmurHash3_x86_128 (seed 0) of the 8 little-endian bytes of key: the low 64 bits."""
    m = 0xFFFFFFFF

    def rotl(x, r):
        return ((x << r) | (x >> (32 - r))) & m

    def fmix(h):
        h ^= h >> 16
        h = (h * 0x85EBCA6B) & m
        h ^= h >> 13
        h = (h * 0xC2B2AE35) & m
        return h ^ (h >> 16)

    data = struct.pack("<Q", key)
    c1, c2, c3 = 0x239B961B, 0xAB0E9789, 0x38B34AE5
    h = [0, 0, 0, 0]
    k1 = int.from_bytes(data[0:4], "little")
    k2 = int.from_bytes(data[4:8], "little")
    k2 = (rotl((k2 * c2) & m, 16) * c3) & m
    h[1] ^= k2
    k1 = (rotl((k1 * c1) & m, 15) * c2) & m
    h[0] ^= k1
    h = [x ^ 8 for x in h]
    h[0] = (h[0] + h[1] + h[2] + h[3]) & m
    h[1] = (h[1] + h[0]) & m
    h[2] = (h[2] + h[0]) & m
    h[3] = (h[3] + h[0]) & m
    h = [fmix(x) for x in h]
    h[0] = (h[0] + h[1] + h[2] + h[3]) & m
    h[1] = (h[1] + h[0]) & m
    return h[0] | (h[1] << 32)


def decode(data, encoding):
    return gzip.decompress(data) if encoding == "gzip" else data


def locate_sharded(path, info, segid):
    """Where segid lies in the shard files: (the shard's file name, the shard's bytes, the
    manifest's first byte, its stored length); the fragment data ends where the manifest
    starts."""
    s = info["sharding"]
    assert s["@type"] == "neuroglancer_uint64_sharded_v1"
    key = segid >> s["preshift_bits"]
    assert s["hash"] in ("identity", "murmurhash3_x86_128")
    hashed = murmurhash3_x86_128_low64(key) if s["hash"] == "murmurhash3_x86_128" else key
    minishard = hashed & ((1 << s["minishard_bits"]) - 1)
    shard = (hashed >> s["minishard_bits"]) & ((1 << s["shard_bits"]) - 1)
    width = max(1, -(-s["shard_bits"] // 4))
    name = f"{shard:0{width}x}.shard"
    with open(os.path.join(path, name), "rb") as f:
        data = f.read()
    index_end = 16 << s["minishard_bits"]
    start, end = struct.unpack_from("<QQ", data, 16 * minishard)
    assert index_end + end <= len(data)
    index = np.frombuffer(decode(data[index_end + start:index_end + end], s["minishard_index_encoding"]), "<u8")
    assert len(index) % 3 == 0
    ids, starts, sizes = index.reshape(3, -1).astype(object)
    ids = np.cumsum(ids)
    position = index_end
    for i, chunk in enumerate(ids):
        position += starts[i]
        if chunk == segid:
            return name, data, position, sizes[i]
        position += sizes[i]
    raise KeyError(segid)


def read_sharded(path, info, segid):
    """(manifest bytes, fragment data bytes) of segid from the shard files."""
    _, data, position, size = locate_sharded(path, info, segid)
    manifest = decode(data[position:position + size], info["sharding"]["data_encoding"])
    total = sum(parse_manifest(manifest)["sizes"])
    assert total <= position
    return manifest, data[position - total:position]


def fragment_ranges(path, info, segid):
    """Where each fragment of segid lies in the served files: per level of detail, a list of
    (file name, first byte, last byte) of its nonempty fragments, in manifest order; the file
    is "<id>" unsharded, the shard file sharded."""
    if "sharding" in info:
        name, data, position, size = locate_sharded(path, info, segid)
        m = parse_manifest(decode(data[position:position + size], info["sharding"]["data_encoding"]))
        at = position - sum(m["sizes"])
    else:
        name = str(segid)
        with open(os.path.join(path, f"{segid}.index"), "rb") as f:
            m = parse_manifest(f.read())
        at = 0
    levels, n = [], 0
    for positions in m["positions"]:
        level = []
        for size in m["sizes"][n:n + len(positions)]:
            if size:
                level.append((name, at, at + size - 1))
            at += size
        n += len(positions)
        levels.append(level)
    return levels


def parse_manifest(m):
    """The fields of a manifest, its length checked against them."""
    chunk = np.frombuffer(m, "<f4", 3, 0)
    origin = np.frombuffer(m, "<f4", 3, 12)
    (lods,) = struct.unpack_from("<I", m, 24)
    scales = np.frombuffer(m, "<f4", lods, 28)
    offsets = np.frombuffer(m, "<f4", 3 * lods, 28 + 4 * lods).reshape(lods, 3)
    counts = np.frombuffer(m, "<u4", lods, 28 + 16 * lods)
    at = 28 + 20 * lods
    positions, sizes = [], []
    for n in counts:
        positions.append(np.frombuffer(m, "<u4", 3 * n, at).reshape(3, n).T.astype(np.int64))
        at += 12 * n
        sizes.extend(np.frombuffer(m, "<u4", n, at).tolist())
        at += 4 * n
    assert at == len(m), "the manifest's length does not match its fields"
    return dict(chunk=chunk.astype(float), origin=origin.astype(float), lods=lods, scales=scales,
                vertex_offsets=offsets, positions=positions, sizes=sizes)


def zorder(p):
    key = 0
    for bit in range(21):
        for axis in range(3):
            key |= ((int(p[axis]) >> bit) & 1) << (3 * bit + axis)
    return key
