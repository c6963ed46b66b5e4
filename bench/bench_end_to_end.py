#!/usr/bin/python3
"""The whole path a user runs, from file to mesh file, each tool a separate process.

Writes the inputs with bench_write_inputs (the Figure 9 noisy spheres as .mha, a sparse
4.4 G-voxel raw file holding one ball), then runs on the same files, in the same run:
  - surftrack mesh (this build's CLI): one component from the protocol's seed surfel; the
    largest boundary on 1 and on all threads (the same file on both); the big raw file from a seed voxel at the ball's
    centre (its pages evicted from the page cache first, so what is resident afterwards is
    what the run read); the demo's MRI cortex (ch2better.nii.gz, --largest, 1 and all threads);
  - VTK (python3-vtk9, when installed): vtkMetaImageReader -> vtkFlyingEdges3D ->
    vtkPolyDataConnectivityFilter (closest-point region, the seed surfel's midpoint) ->
    vtkPLYWriter, on 1 and on all threads;
  - scikit-image (python3-skimage, when installed): the .mha read with numpy,
    skimage.measure.marching_cubes (Lewiner) on the whole volume, a binary PLY written.
Prints wall time (median of --reps), the CLI's own stages, peak memory (the process's maximum
resident set), voxel bytes read, and the ratios to VTK. Refuses to time a wrong answer: every
surftrack run must give one closed 2-manifold component of the same surfel count in every
repetition, and each peer a non-empty mesh.

    /usr/bin/python3 bench/bench_end_to_end.py [--build build] [--dir /tmp/surftrack-e2e]
        [--sizes 256,512] [--reps 3] [--no-big] [--no-peers] [--keep]
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

VTK_SCRIPT = r'''
import sys
# Only the modules used (import vtk would load them all: seconds of start-up).
from vtkmodules.vtkCommonCore import vtkSMPTools
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D, vtkPolyDataConnectivityFilter
from vtkmodules.vtkIOImage import vtkImageReader2, vtkMetaImageReader
from vtkmodules.vtkIOPLY import vtkPLYWriter
path, iso, px, py, pz, threads, out = sys.argv[1:8]
vtkSMPTools.Initialize(int(threads))
if path.endswith(".raw"):
    nx, ny, nz = map(int, sys.argv[8].split(","))
    reader = vtkImageReader2()
    reader.SetFileName(path)
    reader.SetDataScalarTypeToUnsignedChar()
    reader.SetFileDimensionality(3)
    reader.SetDataExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
else:
    reader = vtkMetaImageReader()
    reader.SetFileName(path)
fe = vtkFlyingEdges3D()
fe.SetInputConnection(reader.GetOutputPort())
fe.SetValue(0, float(iso))
fe.ComputeNormalsOff(); fe.ComputeGradientsOff(); fe.ComputeScalarsOff()
conn = vtkPolyDataConnectivityFilter()
conn.SetInputConnection(fe.GetOutputPort())
conn.SetExtractionModeToClosestPointRegion()
conn.SetClosestPoint(float(px), float(py), float(pz))
writer = vtkPLYWriter()  # (the region's triangles, with every point of the input, as VTK does)
writer.SetInputConnection(conn.GetOutputPort())
writer.SetFileName(out)
writer.SetFileTypeToBinary()
writer.Write()
print(conn.GetOutput().GetNumberOfPolys())
'''

SKIMAGE_SCRIPT = r'''
import sys, numpy as np
from skimage import measure
path, iso, out = sys.argv[1:4]
with open(path, "rb") as f:
    head = f.read(4096)
end = head.index(b"ElementDataFile = LOCAL") + len(b"ElementDataFile = LOCAL")
end = head.index(b"\n", end) + 1
fields = dict(l.split(" = ", 1) for l in head[:end].decode().splitlines() if " = " in l)
nx, ny, nz = map(int, fields["DimSize"].split())
assert fields["ElementType"] == "MET_UCHAR"
volume = np.fromfile(path, dtype=np.uint8, offset=end).reshape(nz, ny, nx)
verts, faces, _, _ = measure.marching_cubes(volume, level=float(iso))
verts = verts[:, ::-1].astype(np.float32)
with open(out, "wb") as f:
    f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
             "property float y\nproperty float z\nelement face %d\nproperty list uchar int vertex_indices\n"
             "end_header\n" % (len(verts), len(faces))).encode())
    f.write(verts.tobytes())
    rec = np.empty(len(faces), dtype=[("n", "u1"), ("v", "<i4", 3)])
    rec["n"] = 3
    rec["v"] = faces
    f.write(rec.tobytes())
print(len(faces))
'''


def run_measured(cmd):
    """(seconds, peak RSS MB, stdout) of one process, its peak from its own wait4 rusage."""
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out = proc.stdout.read()
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd), proc.returncode, err.decode().strip()))
    return seconds, usage.ru_maxrss / 1024.0, out.decode()


def evict(path):
    """Drops the file's clean pages from the page cache, so that the next run reads them."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.posix_fadvise(fd, 0, 0, os.POSIX_FADV_DONTNEED)
    finally:
        os.close(fd)


class Result:
    def __init__(self, case, tool, times, peaks, extra=""):
        self.case, self.tool, self.extra = case, tool, extra
        self.seconds = statistics.median(times)
        self.peak = statistics.median(peaks)


def surftrack_runs(exe, args, reps, before=None):
    """reps runs of `surftrack mesh ... --json`; checks the answer; returns times, peaks, JSON."""
    times, peaks, reports = [], [], []
    for _ in range(reps):
        if before:
            before()
        seconds, peak, out = run_measured([exe, "mesh"] + args + ["--json", "--quiet"])
        j = json.loads(out)
        if not (j["closed"] and j["manifold"]):
            raise RuntimeError("surftrack %s: not a closed manifold" % " ".join(args))
        if reports and j["surfels"] != reports[0]["surfels"]:
            raise RuntimeError("surftrack %s: surfel counts differ between runs" % " ".join(args))
        times.append(seconds)
        peaks.append(peak)
        reports.append(j)
    return times, peaks, reports


def largest_on_threads(exe, case, args, out, reps, cores, show):
    """`--largest` on 1 and on all threads: the same file each time (refused otherwise), and the
    speed-up."""
    largest, files = {}, {}
    for threads in (1, cores):
        path = out("lg%d.ply" % threads)
        times, peaks, js = surftrack_runs(exe, args + ["-o", path, "--largest", "--threads", str(threads)], reps)
        largest[threads] = Result(case, "surftrack --largest, %d thr" % threads, times, peaks,
                                  stage_text(js[len(js) // 2]))
        show(largest[threads])
        with open(path, "rb") as f:
            files[threads] = f.read()
    if files[1] != files[cores]:
        raise RuntimeError("%s: --largest wrote different files on 1 and %d threads" % (case, cores))
    print("%-24s %-34s %9.2fx" % (case, "--largest speed-up %d thr / 1" % cores,
                                  largest[1].seconds / largest[cores].seconds))


def stage_text(j):
    t = j["timings_s"]
    total = sum(v for k, v in t.items() if k != "total")
    core = t.get("track", 0) + t.get("convert", 0)
    parts = ", ".join("%s %.0f" % (k, 1000 * v) for k, v in t.items() if k != "total")
    return "%s ms; track+convert %.0f %% of in-process" % (parts, 100 * core / total if total else 0)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--build", default=os.path.join(here, "..", "build"), help="the CMake build directory")
    ap.add_argument("--dir", default=os.path.join(tempfile.gettempdir(), "surftrack-e2e"),
                    help="where the inputs and outputs are written")
    ap.add_argument("--sizes", default="256,512", help="sphere sides (default 256,512)")
    ap.add_argument("--reps", type=int, default=3, help="runs per measurement (median; default 3)")
    ap.add_argument("--no-big", action="store_true", help="skip the 4.4 G-voxel raw file")
    ap.add_argument("--no-peers", action="store_true", help="skip VTK and scikit-image")
    ap.add_argument("--keep", action="store_true", help="keep the inputs and outputs")
    a = ap.parse_args()

    exe = os.path.join(a.build, "cli", "surftrack")
    writer = os.path.join(a.build, "bench", "bench_write_inputs")
    for f in (exe, writer):
        if not os.access(f, os.X_OK):
            sys.exit("bench_end_to_end: %s is not built (cmake --build %s)" % (f, a.build))
    os.makedirs(a.dir, exist_ok=True)
    cmd = [writer, a.dir, "--sizes", a.sizes] + (["--no-big"] if a.no_big else [])
    manifest = json.loads(subprocess.run(cmd, check=True, stdout=subprocess.PIPE).stdout)
    cores = os.cpu_count()
    have_vtk = have_skimage = False
    if not a.no_peers:
        have_vtk = subprocess.run([sys.executable, "-c", "import vtkmodules.vtkFiltersCore"], capture_output=True).returncode == 0
        have_skimage = subprocess.run([sys.executable, "-c", "import skimage"], capture_output=True).returncode == 0
    vtk_py = os.path.join(a.dir, "vtk_extract.py")
    sk_py = os.path.join(a.dir, "skimage_extract.py")
    open(vtk_py, "w").write(VTK_SCRIPT)
    open(sk_py, "w").write(SKIMAGE_SCRIPT)
    out = lambda name: os.path.join(a.dir, name)

    print("end-to-end, %d cores, load average %s, median of %d runs, python %s"
          % (cores, " ".join("%.1f" % x for x in os.getloadavg()), a.reps, sys.executable))
    print("%-24s %-34s %9s %9s %12s  %s" % ("case", "tool", "wall s", "peak MB", "voxels read", "notes"))
    ratios = []

    def show(r):
        print("%-24s %-34s %9.3f %9.0f %12s  %s" % (r.case, r.tool, r.seconds, r.peak,
                                                   getattr(r, "read", ""), r.extra))
        sys.stdout.flush()

    for s in manifest["spheres"]:
        case = "sphere %d, %g %%" % (s["q"], 100 * s["noise"])
        f = s["file"]
        times, peaks, js = surftrack_runs(exe, [f, "-o", out("st.ply"), "--iso", str(s["iso"]),
                                                "--seed", s["seed"]], a.reps)
        j = js[len(js) // 2]
        st = Result(case, "surftrack --seed (one component)", times, peaks,
                    "%d surfels; %s" % (j["surfels"], stage_text(j)))
        st.read = "%.1f %%" % (100.0 * j["input_storage"]["voxel_bytes_read"] / j["input_storage"]["voxel_bytes"])
        show(st)
        vtk2 = None
        if have_vtk:
            p = s["seed_point"]
            for threads in (1, cores):
                vt, vp = [], []
                for _ in range(a.reps):
                    seconds, peak, o = run_measured([sys.executable, vtk_py, f, str(s["iso"]), str(p[0]), str(p[1]),
                                                     str(p[2]), str(threads), out("vtk.ply")])
                    if int(o.split()[-1]) <= 0:
                        raise RuntimeError("VTK found no triangle on " + f)
                    vt.append(seconds)
                    vp.append(peak)
                r = Result(case, "VTK flying edges + connectivity, %d thr" % threads, vt, vp,
                           "%s triangles" % o.split()[-1])
                show(r)
                if threads == cores:
                    vtk2 = r
            print("%-24s %-34s %9.2fx" % (case, "ratio surftrack / VTK %d thr" % cores, st.seconds / vtk2.seconds))
            ratios.append((case, st.seconds / vtk2.seconds))
        if have_skimage:
            kt, kp = [], []
            for _ in range(a.reps):
                seconds, peak, o = run_measured([sys.executable, sk_py, f, str(s["iso"]), out("sk.ply")])
                kt.append(seconds)
                kp.append(peak)
            r = Result(case, "skimage marching_cubes (whole)", kt, kp, "%s triangles" % o.split()[-1])
            show(r)
            print("%-24s %-34s %9.2fx" % (case, "ratio surftrack / skimage", st.seconds / r.seconds))
        if s["q"] == max(x["q"] for x in manifest["spheres"]) and s["noise"] >= 0.05:
            largest_on_threads(exe, case, [f, "--iso", str(s["iso"])], out, a.reps, cores, show)

    if "big" in manifest:
        b = manifest["big"]
        d = b["dims"]
        c = b["centre"]
        size = d[0] * d[1] * d[2]
        times, peaks, js = surftrack_runs(
            exe, [b["file"], "-o", out("big.ply"), "--raw-dims", "%d,%d,%d" % tuple(d), "--raw-type", "uint8",
                  "--iso", str(b["iso"]), "--seed", "%d,%d,%d" % tuple(c)], a.reps, before=lambda: evict(b["file"]))
        j = js[len(js) // 2]
        r = Result("big raw %dx%dx%d" % tuple(d), "surftrack --seed (pages evicted)", times, peaks,
                   "%d surfels; %s" % (j["surfels"], stage_text(j)))
        resident = j["input_storage"].get("voxel_bytes_resident", size)
        r.read = "%.2f %%" % (100.0 * resident / size)
        show(r)

    mri = "/usr/share/mricron/templates/ch2better.nii.gz"
    if os.path.exists(mri):
        largest_on_threads(exe, "MRI cortex (nii.gz)", [mri, "--iso", "100"], out, a.reps, cores, show)
    print("load average at the end: %s" % " ".join("%.1f" % x for x in os.getloadavg()))
    if not a.keep:
        shutil.rmtree(a.dir, ignore_errors=True)


if __name__ == "__main__":
    main()
