#!/usr/bin/python3
"""One object's surface out of a huge, sparse chunked store, and out of a dense one.

Writes (once, kept in --dir) with zarr-python, not with our code:
  - a sparse uint16 OME-Zarr image of SIDE^3 voxels (default 8192^3 = 0.55 T voxels), chunks
    128^3, blosc-zstd with byte shuffle, fill value 0: a ball of radius R (default 230: about a
    million surfels) and three small balls far from it; only the chunks holding an object are
    written, every other chunk is missing (= the fill value);
  - a dense zarr array of the ball's bounding region (every chunk present, same codec), and
    the same region as a raw file (the in-memory peer).
Then, in the same run:
  - `surftrack mesh SPARSE --seed ... --iso 500` (this build's CLI, one process per run, its
    wall time, its peak resident set via wait4, its chunk counters from --json), cache 512 MiB;
  - the same with a cache of 64 MiB (16 chunks: chunks evicted and decoded again);
  - the same from the dense store, and from the raw file (in memory: the region, page-cached);
  - the decoding alone: zarr-python reading the dense region whole (every chunk decoded once);
  - what a user does today (a separate process): zarr-python reads the bounding box,
    skimage.measure.marching_cubes on it, the ball's component picked by a connected-component
    pass over the mesh (scipy.sparse.csgraph).
Refuses to time a wrong answer: every surftrack run must give one closed surface whose vertex
count equals the surfel count numpy computes from the ball's voxels, and the chunks the sparse
run decodes are compared with those the surface crosses, computed here from the voxels (a chunk
is crossed when it holds a voxel of a surfel: an inside voxel with an outside 6-neighbour or
the reverse).

    /usr/bin/python3 bench/bench_chunked.py [--build build] [--dir /tmp/surftrack-chunked]
        [--side 8192] [--radius 230] [--reps 3] [--no-peers]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

CHUNK = 128
ISO = 500
INSIDE = 1000

USER_TODAY = r'''
import sys, time, json
import numpy as np, zarr
from skimage.measure import marching_cubes
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
path, z0, z1, y0, y1, x0, x1 = sys.argv[1], *map(int, sys.argv[2:8])
t0 = time.perf_counter()
a = zarr.open(path, mode="r")
region = a[z0:z1, y0:y1, x0:x1]
t1 = time.perf_counter()
verts, faces, _, _ = marching_cubes(region.astype(np.float32), 500.0)
t2 = time.perf_counter()
n = len(verts)
e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]]])
g = coo_matrix((np.ones(len(e), np.int8), (e[:, 0], e[:, 1])), shape=(n, n))
count, comp = connected_components(g, directed=False)
biggest = np.bincount(comp).argmax()
keep = comp[faces[:, 0]] == biggest
t3 = time.perf_counter()
print(json.dumps({"read": t1 - t0, "marching_cubes": t2 - t1, "components": t3 - t2,
                  "total": t3 - t0, "vertices": int((comp == biggest).sum()),
                  "faces": int(keep.sum())}))
'''


def ball_values(zs, ys, xs, centre, radius):
    """uint16 block: INSIDE where the voxel centre is within radius of centre, else 0."""
    z, y, x = np.meshgrid(zs - centre[0], ys - centre[1], xs - centre[2], indexing="ij")
    return np.where(z * z + y * y + x * x <= radius * radius, INSIDE, 0).astype(np.uint16)


def write_objects(array, balls):
    """Writes each ball chunk by chunk; chunks holding nothing are not written (missing)."""
    written = 0
    for centre, radius in balls:
        lo = [max(0, (c - radius - 1) // CHUNK) for c in centre]
        hi = [min(array.shape[d] // CHUNK, (centre[d] + radius + 1) // CHUNK + 1) for d in range(3)]
        for cz in range(lo[0], hi[0]):
            for cy in range(lo[1], hi[1]):
                for cx in range(lo[2], hi[2]):
                    s = [slice(c * CHUNK, (c + 1) * CHUNK) for c in (cz, cy, cx)]
                    block = ball_values(*(np.arange(q.start, q.stop) for q in s), centre, radius)
                    if block.any():
                        array[s[0], s[1], s[2]] = block
                        written += 1
    return written


def make_inputs(d, side, radius):
    import zarr
    from numcodecs import Blosc
    stamp = os.path.join(d, f"stamp-{side}-{radius}")
    centre = (side // 2 + 37, side // 2 - 53, side // 2 + 101)
    lo = [c - radius - 2 for c in centre]
    hi = [c + radius + 3 for c in centre]
    if os.path.exists(stamp):
        return centre, lo, hi
    os.makedirs(d, exist_ok=True)
    codec = Blosc(cname="zstd", clevel=5, shuffle=Blosc.SHUFFLE)
    sparse = os.path.join(d, "sparse.ome.zarr")
    root = zarr.open_group(zarr.DirectoryStore(sparse, dimension_separator="/"), mode="w")
    image = root.create_dataset("0", shape=(side,) * 3, chunks=(CHUNK,) * 3, dtype="<u2",
                                compressor=codec, fill_value=0, dimension_separator="/")
    root.attrs["multiscales"] = [{
        "version": "0.4", "name": "ball",
        "axes": [{"name": a, "type": "space", "unit": "micrometer"} for a in "zyx"],
        "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1]}]}]}]
    far = [((300, 400, 500), 20), ((side - 300, 600, side - 700), 20), ((900, side - 500, 4000), 20)]
    written = write_objects(image, [(centre, radius)] + far)
    print(f"wrote {sparse}: {side}^3, {written} chunks present of {(side // CHUNK) ** 3}", flush=True)
    shape = tuple(h - l for l, h in zip(lo, hi))
    region = ball_values(*(np.arange(l, h) for l, h in zip(lo, hi)), centre, radius)
    dense = zarr.open(os.path.join(d, "dense.zarr"), mode="w", shape=shape, chunks=(CHUNK,) * 3,
                      dtype="<u2", compressor=codec, fill_value=0)
    dense[...] = region
    region.tofile(os.path.join(d, "region.raw"))
    open(stamp, "w").close()
    return centre, lo, hi


def truth(centre, radius, lo, hi):
    """Surfel count of the ball and the chunks (of the sparse store) its surfels touch."""
    inside = ball_values(*(np.arange(l, h) for l, h in zip(lo, hi)), centre, radius) > ISO
    surfels = 0
    touched = np.zeros(inside.shape, bool)
    for axis in range(3):
        a = [slice(None)] * 3
        b = [slice(None)] * 3
        a[axis] = slice(0, -1)
        b[axis] = slice(1, None)
        cut = inside[tuple(a)] != inside[tuple(b)]
        surfels += int(cut.sum())
        touched[tuple(a)] |= cut
        touched[tuple(b)] |= cut
    idx = np.nonzero(touched)
    keys = set(zip(*((idx[d] + lo[d]) // CHUNK for d in range(3))))
    return surfels, len(keys)


def run_cli(cmd, rss_file):
    """Wall time, peak RSS (MiB) and the --json report of one run. The peak is GNU time's (a
    child forked from this large process would start from this process's resident set)."""
    t0 = time.perf_counter()
    p = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", rss_file] + cmd, capture_output=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"bench_chunked: {' '.join(cmd)} failed: {p.stderr.decode().strip()}")
    return wall, int(open(rss_file).read().split()[-1]) / 1024, json.loads(p.stdout)


def check(report, surfels, what):
    """The ball's surface: one closed 2-manifold sphere with a vertex per surfel numpy counts."""
    got = (report["vertices"], report["components"], report["closed"], report["manifold"], report["genus"])
    if got != (surfels, 1, True, True, 0):
        sys.exit(f"bench_chunked: {what}: (vertices, components, closed, manifold, genus) = {got}, "
                 f"expected ({surfels}, 1, True, True, 0): not timed")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--dir", default="/tmp/surftrack-chunked")
    ap.add_argument("--side", type=int, default=8192)
    ap.add_argument("--radius", type=int, default=230)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--no-peers", action="store_true")
    args = ap.parse_args()
    cli = os.path.join(args.build, "cli", "surftrack")
    print("load:", open("/proc/loadavg").read().split()[:3], flush=True)
    centre, lo, hi = make_inputs(args.dir, args.side, args.radius)
    surfels, crossed = truth(centre, args.radius, lo, hi)
    # A boundary voxel on the +x axis of the ball (the engine's x is the last axis): the seed
    # surfel is its own +x face, so the seed search reads nothing but that voxel's chunk.
    z, y = centre[0], centre[1]
    x = centre[2] + args.radius
    seed = f"{x},{y},{z},+x"
    shape = [h - l for l, h in zip(lo, hi)]
    seed_local = f"{x - lo[2]},{y - lo[1]},{z - lo[0]},+x"
    out = os.path.join(args.dir, "out.ply")
    rss_file = os.path.join(args.dir, "rss.txt")
    runs = {
        "sparse store (lazy)": [cli, "mesh", os.path.join(args.dir, "sparse.ome.zarr"), "--seed", seed,
                                "--iso", str(ISO), "-o", out, "--json"],
        "sparse store (lazy), cache 64 MiB": [cli, "mesh", os.path.join(args.dir, "sparse.ome.zarr"),
                                              "--seed", seed, "--iso", str(ISO), "-o", out, "--json",
                                              "--cache", "64"],
        "dense region store (lazy)": [cli, "mesh", os.path.join(args.dir, "dense.zarr"), "--seed",
                                      seed_local, "--iso", str(ISO), "-o", out, "--json"],
        "raw region (in memory)": [cli, "mesh", os.path.join(args.dir, "region.raw"), "--raw-dims",
                                   ",".join(map(str, shape[::-1])), "--raw-type", "uint16", "--seed",
                                   seed_local, "--iso", str(ISO), "-o", out, "--json"],
    }
    print(f"ball radius {args.radius}: {surfels} surfels (numpy), its surface crosses {crossed} chunks",
          flush=True)
    results = {}
    for name, cmd in runs.items():
        walls, rss = [], []
        for _ in range(args.reps):
            wall, peak, report = run_cli(cmd, rss_file)
            check(report, surfels, name)
            walls.append(wall)
            rss.append(peak)
        results[name] = (statistics.median(walls), max(rss), report)
        st = report["input_storage"]
        extra = ""
        if "chunks_decoded" in st:
            extra = (f", chunks decoded {st['chunks_decoded']} of {st['chunks']}, "
                     f"{st['bytes_read'] / 2**20:.1f} MiB read")
            if name.startswith("sparse"):  # (the chunk grid that "crossed" counts in)
                extra += f" ({st['chunks_decoded'] / crossed:.2f} x those crossed)"
        stages = ", ".join(f"{k} {v:.3f}" for k, v in report["timings_s"].items())
        print(f"{name}: {statistics.median(walls):.3f} s (runs {', '.join(f'{w:.3f}' for w in walls)}), "
              f"peak RSS {max(rss):.0f} MiB{extra}; stages: {stages}", flush=True)
    import zarr
    t0 = time.perf_counter()
    zarr.open(os.path.join(args.dir, "dense.zarr"), mode="r")[...]
    decode = time.perf_counter() - t0
    print(f"zarr-python decoding the dense region whole: {decode:.3f} s", flush=True)
    dense = results["dense region store (lazy)"][0]
    memory = results["raw region (in memory)"][0]
    print(f"dense store / (in memory + decoding) = {dense / (memory + decode):.2f}"
          f" (target <= 1.5); sparse 8192^3 end to end {results['sparse store (lazy)'][0]:.3f} s (target <= 1.5 s)")
    if not args.no_peers:
        cmd = ["/usr/bin/python3", "-c", USER_TODAY, os.path.join(args.dir, "dense.zarr"),
               "0", str(shape[0]), "0", str(shape[1]), "0", str(shape[2])]
        wall, peak, report = run_cli(cmd, rss_file)
        print(f"today (zarr-python box read, skimage marching_cubes, mesh components): {wall:.3f} s, "
              f"peak RSS {peak:.0f} MiB; stages: " + ", ".join(f"{k} {v:.3f}" for k, v in report.items()
                                                                 if k not in ("vertices", "faces")))
    print("load:", open("/proc/loadavg").read().split()[:3])


if __name__ == "__main__":
    main()
