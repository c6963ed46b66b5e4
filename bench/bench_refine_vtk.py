#!/usr/bin/python3
"""Smoothing and decimation, surftrack against VTK, in one run (docs/performance.md,
"Smoothing and decimation").

Runs bench_refine (the binary clean sphere of Figure 9, R = 0.4 q: its midpoint mesh, smooth()
and decimate(); or, with --input FILE --iso V, the largest boundary of a volume file), then VTK
on the same mesh: vtkWindowedSincPolyDataFilter with the same number of iterations (none with
--iterations 0: both decimate the extracted mesh), and vtkQuadricDecimation with the same
reduction. Reports for each result the RMS of |x - c| - R over the vertices (the sphere only),
the enclosed volume against the extracted mesh's, the times, and, from surftrack_mesh_check
(CGAL, tests/mesh_check.cpp; --skip-checks leaves it out), closedness, genus and
self-intersecting triangle pairs. With --floor it also runs bench_decimation_floor on the mesh
both tools decimate: OpenMesh's DecimaterT with the quadric module alone, the checked decimater
with the quadric, normal-flip and link-condition modules, then decimateSafely (which adds the
embedding and distance guards), each to the same triangle count (what the guards cost, against
VTK's figure of the same run). Times are wall and CPU seconds of the calls alone (the
process's CPU time, all threads, for surftrack's smoothing and for VTK; the thread's for
surftrack's decimation, which runs on one). Both smoothings get the same thread count (--threads,
default 2: surftrack's SmoothOptions::threads, VTK's vtkSMPTools, whose backend is TBB in
Debian's VTK); decimation is serial in both. Renders a before/after PNG with gnuplot.

Needs Debian's /usr/bin/python3 with numpy and vtk 9 (python3-vtk9).
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def read_ply(path):
    r = vtk.vtkPLYReader()
    r.SetFileName(path)
    r.Update()
    out = vtk.vtkPolyData()
    out.DeepCopy(r.GetOutput())
    return out


def write_ply(poly, path):
    w = vtk.vtkPLYWriter()
    w.SetFileName(path)
    w.SetInputData(poly)
    w.SetFileTypeToBinary()
    w.Write()


def figures(poly, centre, radius):
    p = vtk_to_numpy(poly.GetPoints().GetData()).astype(float)
    r = np.linalg.norm(p - centre, axis=1)
    mass = vtk.vtkMassProperties()
    mass.SetInputData(poly)
    mass.Update()
    return {"triangles": poly.GetNumberOfPolys(), "rms": float(np.sqrt(np.mean((r - radius) ** 2))),
            "volume": mass.GetVolume()}


def check(tool, path):
    return json.loads(subprocess.run([tool, path], check=True, capture_output=True, text=True).stdout)


def render(meshes, titles, path, centre, radius):
    """Side-by-side close-ups (gnuplot, pngcairo) of the cap x > c + 0.8 R of each mesh: its
    triangles as lit polygons, so the terraces of the midpoint mesh show."""
    data = []
    for i, poly in enumerate(meshes):
        p = vtk_to_numpy(poly.GetPoints().GetData()).astype(float) - centre
        cells = vtk_to_numpy(poly.GetPolys().GetData()).reshape(-1, 4)[:, 1:]
        keep = (p[cells][:, :, 0] > 0.8 * radius).all(axis=1)
        name = f"{path}.{i}.dat"
        with open(name, "w") as f:
            for t in cells[keep]:
                for v in t:
                    f.write(f"{p[v][1]:.5f} {p[v][2]:.5f} {p[v][0]:.5f}\n")
                f.write("\n")
        data.append(name)
    script = [f"set terminal pngcairo size {420 * len(meshes)},460", f"set output '{path}'",
              f"set multiplot layout 1,{len(meshes)}", "unset key", "unset tics", "unset border",
              "set view 20,20,1.3", "set pm3d depthorder lighting primary 0.6 specular 0.2",
              "set style fill solid 1.0 border lc rgb '#555555'", "set view equal xyz"]
    for name, title in zip(data, titles):
        script += [f"set title '{title}'", f"splot '{name}' with polygons fc rgb '#d9c09a'"]
    script.append("unset multiplot")
    subprocess.run(["gnuplot"], input="\n".join(script), text=True, check=True)
    for name in data:
        os.remove(name)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build", help="the CMake build directory (default: build)")
    ap.add_argument("--size", type=int, default=128, help="the sphere's image side q (default 128)")
    ap.add_argument("--iterations", type=int, default=50, help="smoothing iterations, both tools (default 50)")
    ap.add_argument("--max-error", type=float, default=0.5, help="surftrack's decimation bound, voxels (default 0.5)")
    ap.add_argument("--reduce", type=float, default=0.9, help="fraction of triangles removed, both tools (default 0.9)")
    ap.add_argument("--lambda", dest="lam", type=float, help="surftrack's Taubin lambda (default: SmoothOptions')")
    ap.add_argument("--mu", type=float, help="surftrack's Taubin mu (default: SmoothOptions')")
    ap.add_argument("--threads", type=int, default=2,
                    help="threads of both smoothings (default 2; surftrack's 0 is all cores)")
    ap.add_argument("--passband", type=float, default=0.1, help="vtkWindowedSincPolyDataFilter pass band (default 0.1)")
    ap.add_argument("--out", default="bench-refine", help="directory for the meshes (default bench-refine)")
    ap.add_argument("--png", help="write the before/after picture here")
    ap.add_argument("--input", help="a volume file instead of the sphere (its largest boundary)")
    ap.add_argument("--iso", type=float, default=0.0, help="the iso-value (threshold) for --input")
    ap.add_argument("--skip-checks", action="store_true", help="no CGAL checks (large meshes)")
    ap.add_argument("--floor", action="store_true",
                    help="also time OpenMesh's decimation without the guards on the same mesh (bench_decimation_floor)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    bench = os.path.join(a.build, "bench", "bench_refine")
    tool = os.path.join(a.build, "tests", "surftrack_mesh_check")
    needed = [bench] + ([] if a.skip_checks else [tool]) + ([os.path.join(a.build, "bench", "bench_decimation_floor")] if a.floor else [])
    for binary in needed:
        if not os.path.exists(binary):
            sys.exit(f"bench_refine_vtk: no {binary}: configure the build with -DSURFTRACK_BUILD_BENCH=ON "
                     f"and build the benchmarks")
    command = [bench, "--size", str(a.size), "--iterations", str(a.iterations), "--max-error", str(a.max_error),
               "--reduce", str(a.reduce), "--threads", str(a.threads), "--out", a.out]
    if a.input:
        command += ["--input", a.input, "--iso", str(a.iso)]
    if a.lam is not None:
        command += ["--lambda", str(a.lam)]
    if a.mu is not None:
        command += ["--mu", str(a.mu)]
    ours = json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
    centre, radius = np.full(3, ours["centre"]), ours["radius"]
    midpoint = read_ply(os.path.join(a.out, "sphere-midpoint.ply"))

    smoothing = a.iterations > 0
    if a.threads > 0:
        vtk.vtkSMPTools.Initialize(a.threads)
    sinc = vtk.vtkWindowedSincPolyDataFilter()
    sinc.SetInputData(midpoint)
    sinc.SetNumberOfIterations(a.iterations)
    sinc.SetPassBand(a.passband)
    sinc.BoundarySmoothingOff()
    sinc.FeatureEdgeSmoothingOff()
    sinc.NonManifoldSmoothingOn()
    sinc.NormalizeCoordinatesOn()
    sinc_s = sinc_cpu = None
    smoothed = midpoint
    if smoothing:
        t0, c0 = time.perf_counter(), time.process_time()
        sinc.Update()
        sinc_s, sinc_cpu = time.perf_counter() - t0, time.process_time() - c0
        smoothed = sinc.GetOutput()
        write_ply(smoothed, os.path.join(a.out, "vtk-sinc.ply"))

    decimation = vtk.vtkQuadricDecimation()
    decimation.SetInputData(smoothed)
    decimation.SetTargetReduction(a.reduce)
    t0, c0 = time.perf_counter(), time.process_time()
    decimation.Update()
    quadric_s, quadric_cpu = time.perf_counter() - t0, time.process_time() - c0
    decimated = decimation.GetOutput()
    write_ply(decimated, os.path.join(a.out, "vtk-quadric.ply"))

    base = figures(midpoint, centre, radius)
    rows = []
    results = [("extracted mesh" if a.input else "midpoint mesh", "sphere-midpoint.ply", None, None)]
    if smoothing:
        results += [("surftrack smooth()", "sphere-smoothed.ply", ours["smooth_s"]["wall"], ours["smooth_s"]["cpu"]),
                    ("VTK windowed sinc", "vtk-sinc.ply", sinc_s, sinc_cpu)]
    results += [("surftrack decimate()", "sphere-decimated.ply", ours["decimate_s"]["wall"], ours["decimate_s"]["cpu"]),
                ("VTK quadric decimation", "vtk-quadric.ply", quadric_s, quadric_cpu)]
    for name, path, secs, cpu in results:
        poly = read_ply(os.path.join(a.out, path))
        f = figures(poly, centre, radius)
        c = ({"genus": None, "closed_oriented": None, "manifold": None, "self_intersecting_pairs": -1}
             if a.skip_checks else check(tool, os.path.join(a.out, path)))
        rows.append({"result": name, "triangles": f["triangles"], "rms": f["rms"],
                     "rms_drop": base["rms"] / f["rms"] if f["rms"] > 0 else None,
                     "volume_change_pct": 100 * (f["volume"] - base["volume"]) / base["volume"],
                     "seconds": secs, "cpu": cpu, "genus": c["genus"], "closed_manifold": c["closed_oriented"] and c["manifold"],
                     "self_intersecting_pairs": c["self_intersecting_pairs"]})
    what = f"{a.input} at {a.iso:g}" if a.input else f"binary clean sphere q = {a.size}, R = {radius:g}"
    taubin = "" if a.lam is None and a.mu is None else f" (surftrack lambda {a.lam}, mu {a.mu})"
    print(f"{what}; {a.iterations} iterations{taubin}; {a.threads} smoothing threads "
          f"(VTK SMP {vtk.vtkSMPTools.GetBackend()}, {vtk.vtkSMPTools.GetEstimatedNumberOfThreads()}); reduce {a.reduce}; "
          f"surftrack max error {a.max_error}; load average {os.getloadavg()[0]:.2f}")
    print(f"{'result':24s} {'triangles':>9s} {'RMS':>8s} {'drop':>6s} {'volume':>9s} {'time s':>7s} {'cpu s':>7s} "
          f"{'genus':>6s} {'manifold':>8s} {'self-int':>8s}")
    for r in rows:
        secs = "" if r["seconds"] is None else f"{r['seconds']:.3f}"
        cpu = "" if r["cpu"] is None else f"{r['cpu']:.3f}"
        drop = "" if r["rms_drop"] is None else f"{r['rms_drop']:.2f}x"
        if a.input:
            drop = ""
        print(f"{r['result']:24s} {r['triangles']:9d} {r['rms'] if not a.input else float('nan'):8.4f} {drop:>6s} "
              f"{r['volume_change_pct']:+8.3f}% "
              f"{secs:>7s} {cpu:>7s} {str(r['genus']):>6s} {str(r['closed_manifold']):>8s} {r['self_intersecting_pairs']:8d}")
    if a.png and smoothing and not a.input:
        render([read_ply(os.path.join(a.out, p)) for p in ("sphere-midpoint.ply", "sphere-smoothed.ply",
                                                            "vtk-sinc.ply", "sphere-decimated.ply")],
               ["midpoint (terraced)", "surftrack smooth()", "VTK windowed sinc", "surftrack decimate()"], a.png,
               centre, radius)
        print("picture:", a.png)
    if a.floor:
        floor = json.loads(subprocess.run(
            [os.path.join(a.build, "bench", "bench_decimation_floor"), "--input",
             os.path.join(a.out, "sphere-smoothed.ply" if smoothing else "sphere-midpoint.ply"),
             "--reduce", str(a.reduce), "--max-error", str(a.max_error)],
            check=True, capture_output=True, text=True).stdout)
        print(f"decimation of the same mesh to {floor['target']} triangles, CPU s (median of 3): "
              f"OpenMesh quadric alone {floor['openmesh']['cpu']:.3f}, with the link condition "
              f"{floor['link']['cpu']:.3f}, decimateSafely {floor['safe']['cpu']:.3f}; "
              f"VTK quadric {quadric_cpu:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
