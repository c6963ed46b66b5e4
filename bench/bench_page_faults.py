#!/usr/bin/env python3
"""Counts per call, not times: what extract(mode="all") and label_surfaces cost in page faults
and CPU, on one thread and on all cores (docs/performance.md, "Threads and fresh memory").

Counts survive a loaded machine where wall-clock times do not. For each image and thread count,
after one warm-up call, the medians over --repeat calls of:
  - minor page faults (ru_minflt): first writes to fresh memory, one per 4 KiB page (one per
    2 MiB where huge pages back it, lib/HugePages.h);
  - CPU seconds of the process, all threads (ru_utime + ru_stime): work, not waiting; threads=0
    should cost about what threads=1 does;
  - involuntary context switches (ru_nivcsw): how often a thread was preempted (a parallel
    call waits at each join for its slowest thread, so on a busy machine these become wall time);
  - the wall time, printed for reference only.
The first call's faults are printed too (a fresh process: the arrays land on never-used pages).

Images: the Figure 9 sphere (bench_python.make_noisy_sphere, clean) at the sizes of --sizes,
iso-value 127.5; the MRI ch2better of mricron-data at 100 if present; for label_surfaces a
--cells-cell near-Voronoi label image of --label-size^3 voxels (a jittered grid of centres, each
voxel labelled by the nearest centre of the 27 grid cells around it; numpy only).

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_page_faults.py
    PYTHONPATH=build/python /usr/bin/python3 bench/bench_page_faults.py --sizes 256 --no-labels
"""
from __future__ import annotations

import argparse
import gc
import os
import resource
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_python import MRI_ISO, MRI_PATH, SPHERE_ISO, make_noisy_sphere  # noqa: E402


def near_voronoi(n: int, cells: int, seed: int = 20261201) -> np.ndarray:
    g = max(1, round(cells ** (1 / 3)))
    side = n / g
    rng = np.random.default_rng(seed)
    centres = ((np.stack(np.meshgrid(*[np.arange(g)] * 3, indexing="ij"), -1) + rng.random((g, g, g, 3))) * side)
    centres = centres.reshape(-1, 3)
    out = np.empty((n, n, n), np.uint32)
    j, k = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    for i in range(n):
        p = np.stack([np.full(j.shape, i), j, k], -1).astype(float) + 0.5
        b = np.minimum((p / side).astype(int), g - 1)
        best = np.full(j.shape, np.inf)
        label = np.zeros(j.shape, np.int64)
        for d in np.ndindex(3, 3, 3):
            c = b + np.array(d) - 1
            inside = np.all((c >= 0) & (c < g), -1)
            c = np.clip(c, 0, g - 1)
            index = (c[..., 0] * g + c[..., 1]) * g + c[..., 2]
            dist = np.where(inside, np.sum((p - centres[index]) ** 2, -1), np.inf)
            better = dist < best
            best[better] = dist[better]
            label[better] = index[better]
        out[i] = label + 1
    return out


def counts(call, repeat: int):
    def usage():
        r = resource.getrusage(resource.RUSAGE_SELF)
        return np.array([r.ru_minflt, r.ru_utime + r.ru_stime, r.ru_nivcsw, time.perf_counter()])

    u0 = usage()
    call()
    first = usage() - u0
    gc.collect()
    rows = []
    for _ in range(repeat):
        u0 = usage()
        result = call()
        rows.append(usage() - u0)
        del result
        gc.collect()
    med = [statistics.median(r[i] for r in rows) for i in range(4)]
    return first[0], med


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="256,512", help="sphere sides (default 256,512)")
    parser.add_argument("--threads", default="1,0", help="thread counts (default 1,0)")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--mri", default=MRI_PATH)
    parser.add_argument("--no-labels", action="store_true")
    parser.add_argument("--label-size", type=int, default=256)
    parser.add_argument("--cells", type=int, default=20000)
    args = parser.parse_args(argv)
    import surftrack

    cases = []
    for q in (int(s) for s in args.sizes.split(",") if s):
        volume, _ = make_noisy_sphere(q, 0.0)
        cases.append((f"sphere {q}^3", lambda t, v=volume: surftrack.extract(v, level=SPHERE_ISO, mode="all", threads=t)))
    if os.path.exists(args.mri):
        import nibabel
        mri = np.ascontiguousarray(np.asanyarray(nibabel.load(args.mri).dataobj))
        cases.append(("MRI ch2better", lambda t: surftrack.extract(mri, level=MRI_ISO, mode="all", threads=t)))
    if not args.no_labels:
        labels = near_voronoi(args.label_size, args.cells)
        cases.append((f"labels {args.label_size}^3, {len(np.unique(labels))} cells",
                      lambda t: surftrack.label_surfaces(labels, threads=t, walls="independent")))
    print(f"{'image':34} {'threads':>7} {'1st faults':>10} {'faults':>9} {'CPU s':>8} {'nivcsw':>7} {'wall s':>8}")
    for name, call in cases:
        for t in (int(s) for s in args.threads.split(",")):
            first, (faults, cpu, nivcsw, wall) = counts(lambda: call(t), args.repeat)
            print(f"{name:34} {t:7d} {first:10.0f} {faults:9.0f} {cpu:8.3f} {nivcsw:7.0f} {wall:8.3f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
