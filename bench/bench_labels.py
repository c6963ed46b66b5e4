#!/usr/bin/env python3
"""Label maps (docs/performance.md, "Label maps"): every label of a label image in one call.

(a) Every label of the AAL atlas (mricron-data's aal.nii.gz, 116 labels, background 0), all
    boundaries: surftrack.label_surfaces(labels, threads=N, walls="independent") against VTK's
    vtkDiscreteFlyingEdges3D with the 116 label values (SetValue(i, L); no normals, gradients
    or scalars computed), VTK on the same N threads (SMP backend Sequential for N = 1, else its
    default backend initialised with N). Both in this process, one after the other, medians of
    --repeat runs; the ratio is that of the two medians of this run.
(b) A synthetic 512^3 uint32 volume of 2,500 Voronoi cells (uniform random centres, fixed seed;
    label = 1 + index of the nearest centre as scipy's cKDTree answers it (ties as it breaks them);
    cached in --cache): every label, all boundaries, on N threads, in a fresh
    process so that its peak resident memory (ru_maxrss) is that of loading the volume and
    extracting, compared with 2 x the volume + the output (the C++ surfaces: 24 bytes a vertex,
    16 a surfel (sizeof(Surfel)), 12 a triangle). Then, in another fresh process of the same run,
    vtkDiscreteFlyingEdges3D on the same threads with the first --vtk-labels label values only
    (it makes one pass over the volume per value: all 2,500 would take hours); its time for all
    the labels is that time x cells / --vtk-labels, an extrapolation, printed as such.
(c) --interfaces: on every atlas present, what two touching labels share: the fraction of
    each label's vertices that lie on another label's surface (interface surfels, shared by
    construction) and the fraction of its triangles whose three vertices are also a triangle of
    another label (shared triangles; the rest lie in cubes holding three labels or in
    configurations the two labels triangulate differently).

Every answer is checked before its time is reported (one surface per label, vertex count = the
label's (label, not label) voxel pairs on the AAL, VTK's output non-empty).

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_labels.py                 # (a) and (b)
    PYTHONPATH=build/python /usr/bin/python3 bench/bench_labels.py --threads 1 --no-voronoi
    PYTHONPATH=build/python /usr/bin/python3 bench/bench_labels.py --interfaces --no-voronoi --no-aal
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_python import cpu_model, timed  # noqa: E402

ATLASES = "/usr/share/mricron/templates"
AAL = os.path.join(ATLASES, "aal.nii.gz")
ATLAS_FILES = ["aal.nii.gz", "AICHAmc.nii.gz", "JHU-WhiteMatter-labels-1mm.nii.gz",
               "JHU-WhiteMatter-labels-2mm.nii.gz", "brodmann.nii.gz",
               "HarvardOxford-cort-maxprob-thr0-1mm.nii.gz", "jhu189.nii.gz"]
VORONOI_SEED = 20261201


def load_labels(path: str) -> np.ndarray:
    import nibabel
    image = nibabel.load(path)
    data = np.asanyarray(image.dataobj)
    if data.dtype.kind not in "iu":
        data = np.rint(data).astype(np.int32)
    return np.ascontiguousarray(data)


def direct_surfels(labels: np.ndarray, label: int) -> int:
    inside = np.pad(labels == label, 1)
    return int(sum(np.count_nonzero(inside & ~np.roll(inside, s, axis=a)) for a in range(3) for s in (1, -1)))


class DiscreteFlyingEdges:
    """vtkDiscreteFlyingEdges3D on a numpy label array, thread count fixed for the run."""

    def __init__(self, threads: int):
        from vtkmodules.vtkCommonCore import vtkSMPTools, vtkVersion
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkFiltersGeneral import vtkDiscreteFlyingEdges3D
        from vtkmodules.util import numpy_support
        self.vtkImageData, self.filter, self.ns = vtkImageData, vtkDiscreteFlyingEdges3D, numpy_support
        if threads == 1 and vtkSMPTools.SetBackend("Sequential"):
            how = "SMP backend Sequential"
        else:
            vtkSMPTools.Initialize(threads)
            how = f"SMP backend {vtkSMPTools.GetBackend()}, Initialize({threads})"
        self.description = (f"VTK {vtkVersion.GetVTKVersion()} vtkDiscreteFlyingEdges3D, {how}, "
                            f"estimated threads {vtkSMPTools.GetEstimatedNumberOfThreads()}")

    def __call__(self, volume: np.ndarray, values):
        image = self.vtkImageData()
        image.SetDimensions(volume.shape[2], volume.shape[1], volume.shape[0])
        scalars = self.ns.numpy_to_vtk(volume.reshape(-1), deep=0)
        image.GetPointData().SetScalars(scalars)
        fe = self.filter()
        fe.SetInputData(image)
        fe.ComputeNormalsOff()
        fe.ComputeGradientsOff()
        fe.ComputeScalarsOff()
        for i, v in enumerate(values):
            fe.SetValue(i, float(v))
        fe.Update()
        poly = fe.GetOutput()
        return poly.GetNumberOfPoints(), poly.GetNumberOfPolys(), (fe, poly, image, scalars)


def part_aal(args) -> None:
    import surftrack
    labels = load_labels(args.aal)
    values = [int(v) for v in np.unique(labels) if v != 0]
    print(f"\n== (a) AAL {labels.shape} {labels.dtype}, {len(values)} labels, threads {args.threads}, "
          f"load {os.getloadavg()[0]:.2f}", flush=True)
    vtk = DiscreteFlyingEdges(args.threads)
    print(vtk.description)
    # Check once, untimed.
    surfaces = surftrack.label_surfaces(labels, threads=args.threads, walls="independent")
    assert sorted(surfaces) == values, "one surface per label"
    for L in values[::10]:
        assert len(surfaces[L].vertices) == direct_surfels(labels, L), L
    points, polys, _ = vtk(labels, values)
    assert points > 0 and polys > 0
    ours = sum(len(s.vertices) for s in surfaces.values())
    ours_tri = sum(len(s.faces) for s in surfaces.values())
    del surfaces
    t_ours, _ = timed(lambda: surftrack.label_surfaces(labels, threads=args.threads, walls="independent"), args.repeat)
    load_mid = os.getloadavg()[0]
    t_vtk, _ = timed(lambda: vtk(labels, values), args.repeat)
    a, b = statistics.median(t_ours), statistics.median(t_vtk)
    print(f"surftrack.label_surfaces   {a:.3f} s  (runs {', '.join(f'{t:.3f}' for t in t_ours)}; "
          f"{ours} vertices, {ours_tri} triangles)")
    print(f"vtkDiscreteFlyingEdges3D   {b:.3f} s  (runs {', '.join(f'{t:.3f}' for t in t_vtk)}; "
          f"{points} points, {polys} triangles)")
    print(f"ratio surftrack / VTK      {a / b:.2f}  (target <= 0.5: {'met' if a / b <= 0.5 else 'MISSED'}); "
          f"load {load_mid:.2f} between, {os.getloadavg()[0]:.2f} after")


def voronoi_volume(path: str, n: int, cells: int) -> np.ndarray:
    if os.path.exists(path):
        return np.load(path, mmap_mode="r")
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(VORONOI_SEED)
    centres = rng.random((cells, 3)) * n
    tree = cKDTree(centres)
    out = np.empty((n, n, n), dtype=np.uint32)
    j, k = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    t0 = time.perf_counter()
    for i in range(n):
        points = np.stack([np.full(j.size, i), j.reshape(-1), k.reshape(-1)], axis=1).astype(float)
        _, index = tree.query(points, workers=-1)
        out[i] = (index + 1).reshape(n, n)
    np.save(path, out)
    print(f"generated {path} in {time.perf_counter() - t0:.1f} s", flush=True)
    return out


def voronoi_worker(path: str, threads: int, repeat: int) -> None:
    """In a fresh process: load, extract `repeat` times, report times and peak memory."""
    import surftrack
    volume = np.load(path)
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    times, vertices, faces, labels = [], 0, 0, 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        surfaces = surftrack.label_surfaces(volume, threads=threads, walls="independent")
        times.append(time.perf_counter() - t0)
        vertices = sum(len(s.vertices) for s in surfaces.values())
        faces = sum(len(s.faces) for s in surfaces.values())
        labels = len(surfaces)
        del surfaces
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print(json.dumps({"times": times, "labels": labels, "vertices": vertices, "faces": faces,
                      "volume_bytes": volume.nbytes, "rss_after_load": base, "peak_rss": peak}))


def vtk_voronoi_worker(path: str, threads: int, repeat: int, count: int) -> None:
    """In a fresh process: vtkDiscreteFlyingEdges3D with label values 1..count, `repeat` times."""
    volume = np.load(path)
    vtk = DiscreteFlyingEdges(threads)
    times, points, polys = [], 0, 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        points, polys, keep = vtk(volume, list(range(1, count + 1)))
        times.append(time.perf_counter() - t0)
        del keep
    print(json.dumps({"times": times, "points": points, "polys": polys, "description": vtk.description}))


def part_voronoi(args) -> None:
    print(f"\n== (b) Voronoi {args.size}^3 uint32, {args.cells} cells, threads {args.threads}, "
          f"load {os.getloadavg()[0]:.2f}", flush=True)
    volume = voronoi_volume(args.cache, args.size, args.cells)
    assert volume.shape == (args.size,) * 3 and volume.dtype == np.uint32
    del volume
    run = subprocess.run([sys.executable, os.path.abspath(__file__), "--voronoi-worker", args.cache,
                          "--threads", str(args.threads), "--repeat", str(args.repeat)],
                         capture_output=True, text=True, check=True, env=os.environ)
    r = json.loads(run.stdout.strip().splitlines()[-1])
    assert r["labels"] == args.cells, r
    output = 24 * r["vertices"] + 16 * r["vertices"] + 12 * r["faces"]
    t = statistics.median(r["times"])
    limit = 2 * r["volume_bytes"] + output
    mib = 1 << 20
    print(f"label_surfaces             {t:.3f} s  (runs {', '.join(f'{x:.3f}' for x in r['times'])}; "
          f"{r['labels']} labels, {r['vertices']} vertices, {r['faces']} triangles)")
    print(f"time target <= 2 s on 2 threads: {'met' if t <= 2 and args.threads <= 2 else 'MISSED'}")
    print(f"peak RSS {r['peak_rss'] / mib:.0f} MiB (after loading the volume {r['rss_after_load'] / mib:.0f} MiB); "
          f"volume {r['volume_bytes'] / mib:.0f} MiB, output {output / mib:.0f} MiB, "
          f"limit 2 x volume + output = {limit / mib:.0f} MiB: {'met' if r['peak_rss'] <= limit else 'MISSED'}; "
          f"load {os.getloadavg()[0]:.2f} after")
    if args.vtk_labels <= 0:
        return
    count = min(args.vtk_labels, args.cells)
    run = subprocess.run([sys.executable, os.path.abspath(__file__), "--vtk-voronoi-worker", args.cache,
                          "--threads", str(args.threads), "--repeat", str(args.vtk_repeat),
                          "--vtk-labels", str(count)],
                         capture_output=True, text=True, check=True, env=os.environ)
    v = json.loads(run.stdout.strip().splitlines()[-1])
    assert v["points"] > 0 and v["polys"] > 0, v
    tv = statistics.median(v["times"])
    estimate = tv * args.cells / count
    print(v["description"])
    print(f"vtkDiscreteFlyingEdges3D, {count} of the {args.cells} labels: {tv:.3f} s  "
          f"(runs {', '.join(f'{x:.3f}' for x in v['times'])}; {v['points']} points, {v['polys']} triangles)")
    print(f"  all {args.cells} labels extrapolated: {estimate:.1f} s; ratio surftrack (all labels) / VTK "
          f"(extrapolated) {t / estimate:.3f}; surftrack all labels / VTK {count} labels {t / tv:.2f}; "
          f"load {os.getloadavg()[0]:.2f} after")


def part_interfaces(args) -> None:
    import surftrack
    print(f"\n== (c) shared vertices and triangles, load {os.getloadavg()[0]:.2f}")
    print(f"{'atlas':45s} {'labels':>6s} {'vertices on interfaces':>24s} {'triangles shared':>18s}")
    for name in ATLAS_FILES:
        path = os.path.join(ATLASES, name)
        if not os.path.exists(path):
            continue
        labels = load_labels(path)
        surfaces = surftrack.label_surfaces(labels, threads=args.threads, walls="independent")
        # Vertices by surfel midpoint (exact: the midpoint mapping, no geometry), a global id each.
        allv = np.concatenate([s.vertices for s in surfaces.values()])
        _, ids = np.unique(allv, axis=0, return_inverse=True)
        ids = ids.reshape(-1)
        counts = np.bincount(ids)
        tri_keys, owner, offset = [], [], 0
        shared_vertices = 0
        for L, s in surfaces.items():
            vid = ids[offset:offset + len(s.vertices)]
            shared_vertices += int(np.count_nonzero(counts[vid] > 1))
            t = np.sort(vid[s.faces.astype(np.int64)], axis=1)
            tri_keys.append(t)
            owner.append(np.full(len(t), L))
            offset += len(s.vertices)
        t = np.concatenate(tri_keys)
        _, tid, tcount = np.unique(t, axis=0, return_inverse=True, return_counts=True)
        shared_tri = int(np.count_nonzero(tcount[tid.reshape(-1)] > 1))
        # Of the triangles whose three vertices are all on interfaces, how many are shared.
        on_interface = np.all(counts[t] > 1, axis=1)
        print(f"{name:45s} {len(surfaces):6d} {shared_vertices / len(allv):23.1%} {shared_tri / len(t):17.1%}"
              f"   (of the triangles with 3 interface vertices: "
              f"{shared_tri / max(1, int(np.count_nonzero(on_interface))):.1%})", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--threads", type=int, default=2, help="threads for surftrack and VTK (default 2)")
    parser.add_argument("--repeat", type=int, default=5, help="runs per tool; medians (default 5)")
    parser.add_argument("--aal", default=AAL, help=f"the AAL atlas (default {AAL})")
    parser.add_argument("--no-aal", action="store_true", help="skip (a)")
    parser.add_argument("--no-voronoi", action="store_true", help="skip (b)")
    parser.add_argument("--interfaces", action="store_true", help="run (c)")
    parser.add_argument("--size", type=int, default=512, help="Voronoi volume side (default 512)")
    parser.add_argument("--cells", type=int, default=2500, help="Voronoi cells (default 2500)")
    parser.add_argument("--cache", default="/tmp/surftrack-voronoi-512-2500.npy",
                        help="where the Voronoi volume is cached (default /tmp/surftrack-voronoi-512-2500.npy)")
    parser.add_argument("--vtk-labels", type=int, default=50,
                        help="(b): VTK on this many of the Voronoi labels, 0 for none (default 50)")
    parser.add_argument("--vtk-repeat", type=int, default=3, help="(b): VTK runs; median (default 3)")
    parser.add_argument("--voronoi-worker", metavar="NPY", help=argparse.SUPPRESS)
    parser.add_argument("--vtk-voronoi-worker", metavar="NPY", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.voronoi_worker:
        voronoi_worker(args.voronoi_worker, args.threads, args.repeat)
        return 0
    if args.vtk_voronoi_worker:
        vtk_voronoi_worker(args.vtk_voronoi_worker, args.threads, args.repeat, args.vtk_labels)
        return 0
    import surftrack
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, surftrack from "
          f"{os.path.dirname(surftrack.__file__)}; nproc {os.cpu_count()}, CPU {cpu_model()}, "
          f"load average {os.getloadavg()[0]:.2f} at start")
    if not args.no_aal:
        part_aal(args)
    if not args.no_voronoi:
        part_voronoi(args)
    if args.interfaces:
        part_interfaces(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
