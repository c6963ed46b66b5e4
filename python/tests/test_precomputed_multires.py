"""Neuroglancer's multi-resolution precomputed meshes (surftrack.write_precomputed(lods=N),
`surftrack labels|mesh --format precomputed-multires`), read back by multires_reader.py, written
from the format's description (neuroglancer's meshes.md and sharded.md: info, the binary .index
manifest, fragments concatenated in manifest order, the shard index, gzip'd minishard indices,
murmurhash3_x86_128), and every fragment decoded by Debian's `draco_decoder`, not by the writer's
library calls. Checked against independent computations with numpy:
  - manifest sizes add up to the data; nodes in Z-order; every node's parent present;
  - every triangle of a level k > 0 fragment lies in the octant Neuroglancer's own rule (the
    partition point 2^(bits-1) of the quantized coordinates) puts it in;
  - each level glued from its fragments (shared vertices by their quantized point on the
    level's lattice) is closed, oriented, with the Euler characteristic and the components of
    the label's mesh (counted here from label_surfaces' faces), facing out (positive volume);
  - level 0 is the label's mesh cut on the grid: the same area and volume, every label vertex
    among its vertices up to the quantization step, every other vertex on a label edge;
  - the transform puts level 0 where the legacy format puts the same mesh (nanometres);
  - sharded and unsharded layouts hold the same manifests and fragments;
  - bad input refused with one line and nothing written."""
import json
import os
import shutil
import struct
import subprocess

import numpy as np
import pytest
from scipy.spatial import cKDTree

import surftrack
from conftest import closed_oriented_manifold
from multires_reader import fragment_ranges, murmurhash3_x86_128_low64, parse_manifest, read_sharded, zorder

CLI = os.environ.get("SURFTRACK_CLI")
DRACO = shutil.which("draco_decoder")
NODE_DIR = os.path.join(os.path.dirname(__file__), "node")
NODE = shutil.which("node") if os.path.isdir(os.path.join(NODE_DIR, "node_modules", "draco3d")) else None
pytestmark = pytest.mark.skipif(DRACO is None, reason="draco_decoder (Debian package draco) not installed")


# --- the format's reader (multires_reader.py) ----------------------------------------------------

def test_murmurhash_against_a_reference_implementation():
    # MurmurHash3_x86_128 (h1 h2 h3 h4 in hex) of the 8 little-endian bytes of each key, as the
    # npm package murmurhash3js 3.0.1 (x86.hash128) computes it: an implementation independent
    # of this repository's C++ and of the Python above.
    reference = {0: "e028ae414772b0844772b0844772b084", 1: "16d4ce9ae8bd67d6e8bd67d6e8bd67d6",
                 77: "a37a11fc168163421681634216816342",
                 2**64 - 1: "212b5d1a574f66bdbcbc1d09bcbc1d09",
                 2**53 + 1: "58396398dfde6c79dfa89e26dfa89e26"}
    for key, h in reference.items():
        assert murmurhash3_x86_128_low64(key) == int(h[0:8], 16) | (int(h[8:16], 16) << 32)


def draco_decode(data, tmp):
    """(positions (N, 3) int64, faces (M, 3)) of a Draco mesh, decoded by Debian's draco_decoder
    into an OBJ file."""
    src, dst = tmp / "f.drc", tmp / "f.obj"
    src.write_bytes(data)
    run = subprocess.run([DRACO, "-i", str(src), "-o", str(dst)], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    vertices, faces = [], []
    for line in dst.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            faces.append([int(x.split("/")[0]) - 1 for x in parts[1:4]])
    v = np.array(vertices).reshape(-1, 3)
    assert np.array_equal(v, np.round(v)), "positions must be the quantized integers"
    return v.astype(np.int64), np.array(faces, np.int64).reshape(-1, 3)


def read_info(path):
    info = json.loads((path / "info").read_text())
    assert info["@type"] == "neuroglancer_multilod_draco"
    assert info["vertex_quantization_bits"] in (10, 16) and len(info["transform"]) == 12
    assert info["lod_scale_multiplier"] > 0
    return info


def load_segment(path, info, segid, tmp, decode=True):
    if "sharding" in info:
        manifest, data = read_sharded(str(path), info, segid)
    else:
        manifest, data = (path / f"{segid}.index").read_bytes(), (path / str(segid)).read_bytes()
    m = parse_manifest(manifest)
    assert sum(m["sizes"]) == len(data), "the fragments' sizes do not add up to the data"
    assert np.all(m["scales"] > 0) and np.all(np.diff(m["scales"]) >= 0)
    assert np.all(m["vertex_offsets"] == 0)
    at, fragments = 0, []
    for lod in range(m["lods"]):
        keys = [zorder(p) for p in m["positions"][lod]]
        assert keys == sorted(keys) and len(set(keys)) == len(keys), "nodes not in Z-order"
        if lod > 0:  # Neuroglancer reaches a node only through its parent
            parents = {tuple(p) for p in m["positions"][lod]}
            assert all(tuple(p >> 1) in parents for p in m["positions"][lod - 1])
        level = []
        for i in range(len(m["positions"][lod])):
            size = m["sizes"][sum(len(p) for p in m["positions"][:lod]) + i]
            level.append(draco_decode(data[at:at + size], tmp) if size and decode else None)
            if size and decode and NODE:
                (tmp / f"n{lod}_{i}.drc").write_bytes(data[at:at + size])
            at += size
        fragments.append(level)
    if NODE and decode:
        check_second_decoder(fragments, tmp)
    m["fragments"] = fragments
    m["manifest_bytes"], m["data_bytes"] = manifest, data
    return m


def triangles_by_position(positions, faces):
    """The triangles as sorted rows of their corners' points, each rotated to start at its
    smallest corner (orientation kept): independent of how a decoder numbers the points."""
    t = positions[faces]  # (M, 3, 3)
    keys = [tuple(map(tuple, tri)) for tri in t.tolist()]
    rotated = []
    for a, b, c in keys:
        r = min([(a, b, c), (b, c, a), (c, a, b)])
        rotated.append(r)
    return sorted(rotated)


def check_second_decoder(fragments, tmp):
    """Every fragment decoded again by npm's draco3d under node: the same triangles, the same
    orientation, as Debian's draco_decoder gives."""
    names = [(lod, i) for lod, level in enumerate(fragments) for i, f in enumerate(level) if f is not None]
    run = subprocess.run([NODE, os.path.join(NODE_DIR, "draco3d_decode.js"),
                          *[str(tmp / f"n{lod}_{i}.drc") for lod, i in names]],
                         capture_output=True, text=True, cwd=NODE_DIR)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert len(lines) == len(names)
    for (lod, i), line in zip(names, lines):
        d = json.loads(line)
        p = np.asarray(d["positions"], np.int64).reshape(-1, 3)
        f = np.asarray(d["faces"], np.int64).reshape(-1, 3)
        q, g = fragments[lod][i]
        assert triangles_by_position(p, f) == triangles_by_position(q, g), (lod, i)


# --- checks of one level -------------------------------------------------------------------------

def glue(m, lod, bits):
    """The level's mesh from its fragments: each vertex keyed by its point on the level's
    lattice (node * (2^bits - 1) + q), so shared vertices of neighbouring fragments are one."""
    top = (1 << bits) - 1
    keys, faces = [], []
    base = 0
    for pos, frag in zip(m["positions"][lod], m["fragments"][lod]):
        if frag is None:
            continue
        q, f = frag
        assert q.min() >= 0 and q.max() <= top
        if lod > 0:
            check_octants(q, f, bits)
        keys.append(q + pos * top)
        faces.append(f + base)
        base += len(q)
    keys = np.concatenate(keys)
    unique, ids = np.unique(keys, axis=0, return_inverse=True)
    faces = ids.reshape(-1)[np.concatenate(faces)]
    scale = m["chunk"] * 2.0**lod / top
    return unique * scale + m["origin"], faces


def check_octants(q, faces, bits):
    """Neuroglancer splits a level k > 0 fragment in octants at 2^(bits-1): a vertex below is in
    the lower half, above in the upper, at it in both; a triangle goes to the first octant all
    three vertices allow. That octant must hold the triangle's (dequantized) vertices."""
    mid = 1 << (bits - 1)
    tri = q[faces]  # (M, 3 vertices, 3 axes)
    low_ok = (tri <= mid).all(axis=1)   # (M, 3 axes): the lower half allowed
    high_ok = (tri >= mid).all(axis=1)
    assert np.all(low_ok | high_ok), "a triangle crosses the middle of its fragment"
    # The chosen octant is the lower half where allowed: its vertices must be at or below mid.
    chosen_low = low_ok
    assert np.all(np.where(chosen_low[:, None, :], tri <= mid, tri >= mid))
    # A triangle put in the lower half while it lies in the upper one would have all three at mid.
    flat = (tri == mid).all(axis=1)
    assert not np.any(flat & ~low_ok)


def topology(vertices, faces):
    """(closed and oriented, Euler characteristic, components) counted with numpy."""
    assert np.all((faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2]))
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    d = np.unique(directed, axis=0)
    oriented = len(d) == len(directed)  # no directed edge twice
    reverse = {tuple(e) for e in d[:, ::-1].tolist()}
    closed = oriented and all(tuple(e) in reverse for e in d.tolist())
    edges = len(d) // 2
    used = np.unique(faces)
    euler = len(used) - edges + len(faces)
    parent = list(range(len(vertices)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    for a, b in directed.tolist():
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[ra] = rb
    components = len({find(v) for v in used.tolist()})
    return closed, euler, components


def volume(vertices, faces):
    t = vertices[faces]
    return np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6


def area(vertices, faces):
    t = vertices[faces]
    return np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum() / 2


def check_segment(m, info, vertices, faces):
    """The segment's levels against its mesh (vertices, faces in the stored coordinates, facing
    out of the segment there): when the transform mirrors, the fragments' triangles are
    reversed, so that they face out in Neuroglancer's space."""
    bits = info["vertex_quantization_bits"]
    mirror = np.sign(np.linalg.det(np.reshape(info["transform"], (3, 4))[:, :3]))
    closed, euler, components = topology(vertices, faces)
    assert closed
    for lod in range(m["lods"]):
        v, f = glue(m, lod, bits)
        c, e, k = topology(v, f)
        assert c and e == euler and k == components, (lod, c, e, euler, k, components)
        assert closed_oriented_manifold(f, len(v)), lod
        assert mirror * volume(v, f) > 0, lod
    step = m["chunk"] / ((1 << bits) - 1)  # level 0's quantization step, per axis
    v0, f0 = glue(m, 0, bits)
    # The same surface, refined, moved by at most 1.5 steps: its volume within that layer of its
    # area, its area within the relative tilt such moves give edges of half a voxel or more.
    a = area(vertices, faces)
    assert area(v0, f0) == pytest.approx(a, rel=1e-3 + 6 * step.max())
    assert mirror * volume(v0, f0) == pytest.approx(volume(vertices, faces), abs=1.5 * step.max() * a + 1e-9)
    # Every vertex of the mesh is a vertex of level 0, up to half a step (one more if the cut
    # snapped it onto a plane, GridCut.h); the others lie on its triangles (the cut's points).
    tree = cKDTree(v0 / step)
    d, _ = tree.query(vertices / step, p=np.inf)
    assert d.max() <= 1.5 + 1e-6
    hit = np.zeros(len(v0), bool)
    for near in tree.query_ball_point(vertices / step, 1.5 + 1e-6, p=np.inf):
        hit[near] = True
    others = v0[~hit]
    for start in range(0, len(others), 256):  # in pieces: (points, triangles) arrays stay small
        assert distance_to_triangles(others[start:start + 256], vertices[faces]).max() <= 2 * step.max()


def distance_to_triangles(points, triangles):
    """Each point's distance to the nearest of the triangles (P, 3) x (T, 3, 3) -> (P,):
    the plane's distance where the projection falls inside, else the nearest edge's."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    n = np.cross(b - a, c - a)
    n2 = np.einsum("tj,tj->t", n, n)
    rel = points[:, None, :] - a[None]                                # (P, T, 3)
    h = np.einsum("ptj,tj->pt", rel, n) / np.sqrt(n2)                 # signed height
    proj = points[:, None, :] - h[..., None] * (n / np.sqrt(n2)[:, None])[None]
    # Barycentric coordinates of the projection.
    u = np.einsum("ptj,tj->pt", np.cross(c - b, proj - b[None]), n) / n2
    v = np.einsum("ptj,tj->pt", np.cross(a - c, proj - c[None]), n) / n2
    w = 1 - u - v
    inside = (u >= 0) & (v >= 0) & (w >= 0)
    best = np.where(inside, np.abs(h), np.inf)
    for p, q in ((a, b), (b, c), (c, a)):
        e = q - p
        t = np.clip(np.einsum("ptj,tj->pt", points[:, None, :] - p[None], e) / np.einsum("tj,tj->t", e, e), 0, 1)
        closest = p[None] + t[..., None] * e[None]
        best = np.minimum(best, np.linalg.norm(points[:, None, :] - closest, axis=2))
    return best.min(axis=1)


# --- the tests -----------------------------------------------------------------------------------

def boxes_volume(rng, shape, ids):
    labels = np.zeros(shape, np.uint64)
    for _ in range(5):
        lo = rng.integers(0, shape, size=3)
        hi = lo + rng.integers(2, 9, size=3)
        labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = ids[int(rng.integers(len(ids)))]
    return labels


def torus(shape, centre, big, small, value):
    z, y, x = np.indices(shape).astype(float)
    z, y, x = z - centre[0], y - centre[1], x - centre[2]
    ring = (np.hypot(x, y) - big) ** 2 + z ** 2 <= small ** 2
    return np.where(ring, value, 0).astype(np.uint64)


@pytest.mark.parametrize("bits,lods,sharded", [(16, 3, False), (10, 2, False), (16, 3, True), (16, 1, False)])
def test_levels_are_closed_oriented_and_match_the_label(tmp_path, bits, lods, sharded):
    rng = np.random.default_rng(23 + bits + lods)
    ids = [2**64 - 1, 2**53 + 1, 5, 77]
    for case in range(2):
        labels = boxes_volume(rng, (20, 18, 16), ids)
        labels = np.maximum(labels, torus(labels.shape, (9, 9, 8), 5, 2, 9))
        spacing = tuple(float(v) for v in rng.choice([0.004, 0.04], size=3))
        surfaces = surftrack.label_surfaces(labels, spacing=spacing, walls="independent")
        out = tmp_path / f"case{case}"
        surftrack.write_precomputed(surfaces, out, axes="zyx", unit="um", spacing=spacing,
                                    lods=lods, sharded=sharded, quantization_bits=bits,
                                    names={9: "torus"})
        info = read_info(out)
        assert info["vertex_quantization_bits"] == bits and ("sharding" in info) == sharded
        if not sharded:
            assert sorted(int(n[:-6]) for n in os.listdir(out) if n.endswith(".index")) == sorted(surfaces)
        props = json.loads((out / info["segment_properties"] / "info").read_text())
        assert props["inline"]["properties"][0]["values"][props["inline"]["ids"].index("9")] == "torus"
        for segid, s in surfaces.items():
            m = load_segment(out, info, segid, tmp_path)
            assert m["lods"] == lods
            # The stored coordinates are voxel units: the vertices divided by the spacing.
            vertices = np.asarray(s.vertices, float) / np.asarray(spacing)
            check_segment(m, info, vertices, np.asarray(s.faces))


def test_smoothed_surface_of_genus_two(tmp_path):
    # Smoothed vertices lie anywhere on their segments, near the grid's planes too.
    volume = np.maximum(torus((18, 30, 30), (9, 15, 9), 5, 2.2, 200), torus((18, 30, 30), (9, 15, 20), 5, 2.2, 200))
    s = surftrack.extract(volume.astype(np.uint8), level=100, mode="largest", smooth=20)
    closed, euler, components = topology(np.asarray(s.vertices, float), np.asarray(s.faces))
    assert closed and components == 1 and euler == -2  # genus 2
    # (16 bits: smoothed vertices can come closer than the coarse levels' 10-bit steps, where
    # the quantization would merge them, which the glue here cannot tell from a defect.)
    out = tmp_path / "m"
    surftrack.write_precomputed({1: s}, out, axes="zyx", lods=3)
    info = read_info(out)
    m = load_segment(out, info, 1, tmp_path)
    check_segment(m, info, np.asarray(s.vertices, float), np.asarray(s.faces))


def transform_of(info):
    t = np.asarray(info["transform"], float).reshape(3, 4)
    return lambda p: p @ t[:, :3].T + t[:, 3]


def read_legacy_vertices(path, segid):
    data = (path / f"{segid}.mesh").read_bytes()
    n = struct.unpack_from("<I", data)[0]
    return np.frombuffer(data, "<f4", 3 * n, 4).reshape(n, 3).astype(float)


def test_transform_puts_level_zero_where_the_legacy_format_puts_the_mesh(tmp_path):
    labels = torus((16, 20, 22), (8, 10, 11), 6, 2.5, 3)
    spacing = (0.5, 0.25, 0.125)
    surfaces = surftrack.label_surfaces(labels, spacing=spacing, walls="independent")
    surftrack.write_precomputed(surfaces, tmp_path / "legacy", axes="zyx", unit="um", spacing=spacing)
    surftrack.write_precomputed(surfaces, tmp_path / "multi", axes="zyx", unit="um", spacing=spacing, lods=2)
    info = read_info(tmp_path / "multi")
    m = load_segment(tmp_path / "multi", info, 3, tmp_path)
    v0, _ = glue(m, 0, 16)
    nm = transform_of(info)(v0)
    legacy = read_legacy_vertices(tmp_path / "legacy", 3)
    # Every legacy vertex is a level-0 vertex, in nanometres, up to the quantization step.
    step = np.abs(transform_of(info)(m["chunk"][None] / 65535) - transform_of(info)(np.zeros((1, 3)))).max()
    d = np.abs(legacy[:, None, :] - nm[None, :, :]).max(axis=2).min(axis=1)
    assert d.max() <= step + 1e-3 * legacy.std()


def test_sharded_and_unsharded_hold_the_same_segments(tmp_path):
    rng = np.random.default_rng(4)
    labels = boxes_volume(rng, (14, 14, 14), list(range(1, 40)))
    labels[labels > 0] += np.uint64(2**40)
    surfaces = surftrack.label_surfaces(labels, walls="independent")
    surftrack.write_precomputed(surfaces, tmp_path / "u", axes="zyx", lods=2)
    read_info(tmp_path / "u")
    for hashing in (True, "identity"):
        out = tmp_path / f"s-{hashing}"
        surftrack.write_precomputed(surfaces, out, axes="zyx", lods=2, sharded=hashing)
        info = read_info(out)
        assert info["sharding"]["hash"] == ("identity" if hashing == "identity" else "murmurhash3_x86_128")
        assert not any(n.endswith(".index") for n in os.listdir(out))
        assert all(n.endswith(".shard") or n == "info" for n in os.listdir(out))
        for segid in surfaces:
            manifest, data = read_sharded(str(out), info, segid)
            assert manifest == (tmp_path / "u" / f"{segid}.index").read_bytes()
            assert data == (tmp_path / "u" / str(segid)).read_bytes()
            # The byte ranges the browser test expects Neuroglancer to request: the same
            # fragments in the shard file as in the unsharded data file.
            sharded_ranges = fragment_ranges(str(out), info, segid)
            plain_ranges = fragment_ranges(str(tmp_path / "u"), read_info(tmp_path / "u"), segid)
            assert [len(level) for level in sharded_ranges] == [len(level) for level in plain_ranges]
            for (name, a, b), (plain, c, d) in zip(sum(sharded_ranges, []), sum(plain_ranges, [])):
                assert plain == str(segid) and b - a == d - c
                assert (out / name).read_bytes()[a:b + 1] == (tmp_path / "u" / plain).read_bytes()[c:d + 1]
    with pytest.raises(ValueError, match="sharded"):
        surftrack.write_precomputed(surfaces, tmp_path / "x", axes="zyx", lods=2, sharded="md5")


def test_many_labels_spread_over_minishards_by_the_hash(tmp_path):
    # 343 labels: more than one minishard, so the reader finds each only through the hash.
    labels = np.zeros((21, 21, 21), np.uint64)
    ids = np.unique(np.random.default_rng(9).integers(1, 2**63 - 1, size=400, dtype=np.int64))[:343].astype(np.uint64)
    assert len(ids) == 343
    for n, (z, y, x) in enumerate(np.ndindex(7, 7, 7)):
        labels[3 * z:3 * z + 2, 3 * y:3 * y + 2, 3 * x:3 * x + 2] = ids[n]
    surfaces = surftrack.label_surfaces(labels, walls="independent")
    surftrack.write_precomputed(surfaces, tmp_path / "s", axes="zyx", lods=1, sharded=True)
    info = read_info(tmp_path / "s")
    assert info["sharding"]["minishard_bits"] + info["sharding"]["shard_bits"] >= 1
    for n, (segid, surface) in enumerate(sorted(surfaces.items())):
        m = load_segment(tmp_path / "s", info, segid, tmp_path, decode=n % 25 == 0)  # every 25th decoded
        assert m["lods"] == 1 and len(m["positions"][0]) == 1
        if n % 25 == 0:
            v, f = glue(m, 0, 16)
            assert topology(v, f) == (True, 2, 1) and len(f) == len(surface.faces)


def test_bad_input_is_refused_and_nothing_written(tmp_path):
    labels = np.zeros((6, 6, 6), np.uint8)
    labels[1:4, 1:4, 1:4] = 3
    surfaces = surftrack.label_surfaces(labels, walls="independent")
    with pytest.raises(ValueError, match="positive uint64"):
        surftrack.write_precomputed({0: surfaces[3]}, tmp_path / "p", axes="zyx", lods=2)
    with pytest.raises(ValueError, match="lods"):
        surftrack.write_precomputed(surfaces, tmp_path / "p", axes="zyx", lods=11)
    with pytest.raises(ValueError, match="quantization_bits"):
        surftrack.write_precomputed(surfaces, tmp_path / "p", axes="zyx", lods=2, quantization_bits=12)
    with pytest.raises(ValueError, match="multi-resolution"):
        surftrack.write_precomputed(surfaces, tmp_path / "p", axes="zyx", sharded=True)
    s = surfaces[3]
    open_mesh = type("M", (), {"vertices": np.asarray(s.vertices), "faces": np.asarray(s.faces)[1:]})
    with pytest.raises(ValueError, match="closed"):
        surftrack.write_precomputed({3: open_mesh}, tmp_path / "p", axes="zyx", lods=2)
    (tmp_path / "file").write_text("x")
    with pytest.raises(OSError, match="not a directory"):
        surftrack.write_precomputed(surfaces, tmp_path / "file", axes="zyx", lods=2)
    # A directory nobody may create entries in (/proc, even for root).
    with pytest.raises(OSError, match="cannot write"):
        surftrack.write_precomputed(surfaces, "/proc/surftrack-multires-test", axes="zyx", lods=2)
    assert not os.path.exists("/proc/surftrack-multires-test")
    assert sorted(os.listdir(tmp_path)) == ["file"]


@pytest.mark.skipif(not CLI, reason="SURFTRACK_CLI not set")
def test_cli_labels_and_mesh(tmp_path):
    labels = np.maximum(torus((14, 16, 18), (7, 8, 9), 5, 2, 4), 0)
    labels[1:4, 1:5, 2:6] = 2**63
    raw = tmp_path / "seg.raw"
    labels.astype(np.uint64).tofile(raw)
    base = ["--raw-dims", "18,16,14", "--raw-type", "uint64", "--spacing", "4,5,40", "--unit", "nm", "--quiet"]
    for extra in ([], ["--sharded"], ["--sharded", "--shard-hash", "identity"],
                  ["--sharded", "--shard-hash", "murmurhash3_x86_128"]):
        out = tmp_path / ("cli" + "".join(extra))
        run = subprocess.run([CLI, "labels", str(raw), *base, "--format", "precomputed-multires", "--lods", "2",
                              *extra, "-o", str(out) + "/"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        info = read_info(out)
        hashing = extra[2] if len(extra) > 2 else "murmurhash3_x86_128"
        assert info.get("sharding", {}).get("hash", hashing) == hashing and ("sharding" in info) == bool(extra)
        t = np.asarray(info["transform"]).reshape(3, 4)
        # Voxel indices to nanometres: the spacing, and half a voxel (voxel i over [i, i + 1)).
        assert np.allclose(t[:, :3], np.diag([4, 5, 40])) and np.allclose(t[:, 3], [2, 2.5, 20])
        surfaces = surftrack.label_surfaces(labels, walls="independent")  # index space, columns z, y, x
        for segid, s in surfaces.items():
            m = load_segment(out, info, segid, tmp_path)
            check_segment(m, info, np.asarray(s.vertices, float)[:, ::-1], np.asarray(s.faces)[:, ::-1])
    out = tmp_path / "one"
    run = subprocess.run([CLI, "mesh", str(raw), *base, "--label", "4", "--format", "precomputed-multires",
                          "--id", "12", "-o", str(out) + "/"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    info = read_info(out)
    assert sorted(os.listdir(out)) == ["12", "12.index", "info"]
    run = subprocess.run([CLI, "mesh", str(raw), *base, "--label", "4", "--format", "precomputed-multires",
                          "--id", "12", "--sharded", "--shard-hash", "identity", "-o", str(tmp_path / "one-s") + "/"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    info = read_info(tmp_path / "one-s")
    assert info["sharding"]["hash"] == "identity"
    manifest, data = read_sharded(str(tmp_path / "one-s"), info, 12)
    assert manifest == (out / "12.index").read_bytes() and data == (out / "12").read_bytes()
    run = subprocess.run([CLI, "mesh", str(raw), *base, "--label", "4", "--format", "precomputed",
                          "-o", str(tmp_path / "legacy") + "/"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert sorted(os.listdir(tmp_path / "legacy")) == ["1.mesh", "1:0", "info"]

    def refused(args, says):
        before = sorted(os.listdir(tmp_path))
        run = subprocess.run([CLI, *args], capture_output=True, text=True)
        assert run.returncode != 0 and run.stderr.count("\n") == 1 and says in run.stderr, run.stderr
        assert sorted(os.listdir(tmp_path)) == before

    refused(["mesh", str(raw), *base, "--label", "4", "--format", "precomputed-multires", "--id", "0",
             "-o", str(tmp_path / "z") + "/"], "positive uint64")
    refused(["labels", str(raw), *base, "--format", "precomputed-multires", "--lods", "0",
             "-o", str(tmp_path / "z") + "/"], "--lods")
    refused(["labels", str(raw), *base, "--lods", "2", "-o", str(tmp_path / "z") + "/"], "precomputed-multires")
    refused(["labels", str(raw), *base, "--format", "precomputed-multires", "-o", str(raw)], "directory")
    refused(["labels", str(raw), *base, "--format", "precomputed-multires", "--shard-hash", "identity",
             "-o", str(tmp_path / "z") + "/"], "--sharded")
    refused(["mesh", str(raw), *base, "--label", "4", "--format", "precomputed", "--shard-hash", "identity",
             "-o", str(tmp_path / "z") + "/"], "precomputed-multires")
    refused(["labels", str(raw), *base, "--format", "precomputed-multires", "--sharded", "--shard-hash", "md5",
             "-o", str(tmp_path / "z") + "/"], "murmurhash3_x86_128 or identity")
