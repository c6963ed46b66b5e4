#!/usr/bin/python3
"""Every label of a 1024^3 segmentation by blocks on Dask, against the single pass.

Input (written once, kept): a uint32 OME-Zarr image of N^3 voxels (default 1024^3, 4 GiB raw)
of C Voronoi cells (default 2,500; uniform random centres, fixed seed, labels 1..C), chunks
128^3, blosc-zstd, written by zarr-python; the same voxels as a raw file.
Runs, in the same run:
  - the single pass in memory: `surftrack labels RAW -o DIR/label_{label}.ply` (the raw file
    page-cached; all cores), and the same from the store (decoded whole first);
  - the single pass in Python, the reference of the Dask runs: surftrack.label_surfaces on the
    raw file memory-mapped (all cores), each label written as label_<L>.ply (Python's vertices
    are in the array's axes z, y, x, the CLI's in x, y, z: the two sets of files differ);
  - surftrack.distributed.write_label_meshes(zarr array, DIR) on a LocalCluster of W worker
    processes (one thread each, memory limit --worker-gib each), W = 1 and 2, blocks --block;
    the fragment files in a fresh work directory each time; the workers' peak resident sets
    (getrusage in each worker) and the stages' times (blocks, labels) from the progress calls.
Refuses to report a wrong answer: every Dask output directory must hold the same files as
Python's single pass, byte for byte; the CLI's from the store those of the raw file; the label
count must be C.

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_distributed.py [--build build]
        [--dir /tmp/surftrack-dask] [--size 1024] [--cells 2500] [--block 256] [--workers 1,2]
        [--worker-gib 3] [--generate-only] [--calibration bench/dask-calibration.json]
"""
import argparse
import filecmp
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

SEED = 20261203
CHUNK = 128


def generate(d, n, cells):
    import zarr
    from numcodecs import Blosc
    from scipy.spatial import cKDTree
    store = os.path.join(d, f"voronoi-{n}-{cells}.ome.zarr")
    raw = os.path.join(d, f"voronoi-{n}-{cells}.raw")
    stamp = raw + ".done"
    if os.path.exists(stamp):
        return store, raw
    os.makedirs(d, exist_ok=True)
    t0 = time.perf_counter()
    rng = np.random.default_rng(SEED)
    tree = cKDTree(rng.random((cells, 3)) * n)
    root = zarr.open_group(zarr.DirectoryStore(store, dimension_separator="/"), mode="w")
    image = root.create_dataset("0", shape=(n,) * 3, chunks=(CHUNK,) * 3, dtype="<u4",
                                compressor=Blosc(cname="zstd", clevel=3, shuffle=Blosc.SHUFFLE),
                                fill_value=0, dimension_separator="/")
    root.attrs["multiscales"] = [{
        "version": "0.4", "name": "voronoi",
        "axes": [{"name": a, "type": "space", "unit": "nanometer"} for a in "zyx"],
        "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1]}]}]}]
    j, k = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    with open(raw, "wb") as out:
        for z0 in range(0, n, CHUNK):
            slab = np.empty((min(CHUNK, n - z0), n, n), np.uint32)
            for i in range(slab.shape[0]):
                points = np.stack([np.full(j.size, z0 + i), j.reshape(-1), k.reshape(-1)], axis=1).astype(float)
                _, index = tree.query(points, workers=-1)
                slab[i] = (index + 1).reshape(n, n)
            image[z0:z0 + slab.shape[0]] = slab
            slab.tofile(out)
            print(f"  slab {z0 // CHUNK + 1} of {(n + CHUNK - 1) // CHUNK}", flush=True)
    open(stamp, "w").close()
    print(f"generated {store} and {raw} in {time.perf_counter() - t0:.0f} s", flush=True)
    return store, raw


def timed(cmd):
    t0 = time.perf_counter()
    r = subprocess.run(["/usr/bin/time", "-f", "%M"] + cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"bench_distributed: {' '.join(cmd)} failed: {r.stderr.strip()[-500:]}")
    return wall, int(r.stderr.split()[-1]) / 1024


def same_files(a, b):
    names = sorted(os.listdir(a))
    if names != sorted(os.listdir(b)):
        return False
    _, mismatch, errors = filecmp.cmpfiles(a, b, names, shallow=False)
    return not mismatch and not errors


PYTHON_SINGLE = r'''
import sys, numpy as np, surftrack
raw, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
labels = np.memmap(raw, dtype="<u4", mode="r", shape=(n, n, n))
for label, surface in surftrack.label_surfaces(labels, threads=0, walls="independent").items():
    surface.write(f"{out}/label_{label}.ply")
'''


def peak_rss_mib():
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--dir", default="/tmp/surftrack-dask")
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--cells", type=int, default=2500)
    ap.add_argument("--block", type=int, default=256)
    ap.add_argument("--workers", default="1,2")
    ap.add_argument("--worker-gib", type=float, default=3.0)
    ap.add_argument("--generate-only", action="store_true")
    ap.add_argument("--calibration", help="write the 1-worker run's costs here, for bench/model_distributed.py")
    args = ap.parse_args()
    store, raw = generate(args.dir, args.size, args.cells)
    if args.generate_only:
        return
    import zarr
    from dask.distributed import Client, LocalCluster
    import surftrack.distributed as sd
    cli = os.path.join(args.build, "cli", "surftrack")
    n = args.size
    print("load:", open("/proc/loadavg").read().split()[:3], flush=True)
    single = os.path.join(args.dir, "single")
    shutil.rmtree(single, ignore_errors=True)
    os.makedirs(single)
    subprocess.run(["cat", raw], stdout=subprocess.DEVNULL, check=True)  # page-cached
    wall, rss = timed([cli, "labels", "--walls", "independent", raw, "--raw-dims", f"{n},{n},{n}", "--raw-type", "uint32",
                       "-o", os.path.join(single, "label_{label}.ply"), "-q"])
    count = len(os.listdir(single))
    if count != args.cells:
        sys.exit(f"bench_distributed: the single pass wrote {count} files, not {args.cells}")
    print(f"single pass, raw file in memory, 2 threads: {wall:.1f} s, peak RSS {rss:.0f} MiB, {count} labels",
          flush=True)
    base = wall
    other = os.path.join(args.dir, "single-store")
    shutil.rmtree(other, ignore_errors=True)
    os.makedirs(other)
    wall, rss = timed([cli, "labels", "--walls", "independent", store, "-o", os.path.join(other, "label_{label}.ply"), "-q"])
    if not same_files(single, other):
        sys.exit("bench_distributed: the single pass from the store differs from the raw file's")
    print(f"single pass, store decoded whole, 2 threads: {wall:.1f} s, peak RSS {rss:.0f} MiB", flush=True)
    reference = os.path.join(args.dir, "python-single")
    shutil.rmtree(reference, ignore_errors=True)
    os.makedirs(reference)
    wall, rss = timed(["/usr/bin/python3", "-c", PYTHON_SINGLE, raw, str(n), reference])
    if len(os.listdir(reference)) != args.cells:
        sys.exit("bench_distributed: Python's single pass wrote another number of labels")
    print(f"single pass in Python (label_surfaces + write), 2 threads: {wall:.1f} s, peak RSS {rss:.0f} MiB",
          flush=True)
    array = zarr.open(os.path.join(store, "0"), mode="r")
    for workers in [int(w) for w in args.workers.split(",")]:
        out = os.path.join(args.dir, f"dask-{workers}")
        work = os.path.join(args.dir, f"work-{workers}")
        shutil.rmtree(out, ignore_errors=True)
        shutil.rmtree(work, ignore_errors=True)
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               memory_limit=f"{args.worker_gib}GiB", dashboard_address=None)
        stages = {}
        t0 = time.perf_counter()

        def progress(stage, done, total):
            stages[stage] = time.perf_counter() - t0

        with Client(cluster) as client:
            t0 = time.perf_counter()
            sd.write_label_meshes(array, out, block=(args.block,) * 3, client=client, work_dir=work,
                                  progress=progress)
            wall = time.perf_counter() - t0
            peaks = client.run(peak_rss_mib)
        cluster.close()
        print(f"  ({workers} worker(s): {wall:.1f} s; comparing with Python's single pass)", flush=True)
        if not same_files(reference, out):
            sys.exit(f"bench_distributed: {workers} workers: the output differs from the single pass")
        fragments = sum(os.path.getsize(os.path.join(work, f)) for f in os.listdir(work))
        if workers == 1 and args.calibration:
            def size(d):
                return sum(os.path.getsize(os.path.join(r, f)) for r, _, fs in os.walk(d) for f in fs)
            with open(args.calibration, "w") as f:
                json.dump({"source": f"bench/bench_distributed.py, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
                                     f"load {open('/proc/loadavg').read().split()[0]}: {n}^3 uint32 Voronoi of "
                                     f"{args.cells} cells, 1 worker process",
                           "voxels": n ** 3, "dtype": "uint32", "itemsize": 4, "block": args.block,
                           "map_seconds": stages["blocks"], "reduce_seconds": wall - stages["blocks"],
                           "fragment_bytes": fragments, "store_bytes": size(store), "output_bytes": size(out)},
                          f, indent=2)
        print(f"Dask, {workers} worker(s) x 1 thread, {args.worker_gib:g} GiB each, blocks {args.block}^3: "
              f"{wall:.1f} s ({wall / base:.2f} x the single pass), blocks done at {stages.get('blocks', 0):.1f} s, "
              f"worker peak RSS {', '.join(f'{p:.0f}' for p in peaks.values())} MiB, fragments "
              f"{fragments / 2**20:.0f} MiB; output byte-identical", flush=True)
    print("load:", open("/proc/loadavg").read().split()[:3])


if __name__ == "__main__":
    main()
