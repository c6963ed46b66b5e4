#!/usr/bin/python3
"""Label maps as one conforming complex: the figures of docs/theory.md §12 against per-label
meshing, in one run (docs/performance.md, "Label maps as one conforming complex").

1. Stress table. For walls="independent" (each label meshed against the rest, §11) and
   walls="shared" (the complex, §12), 26-6, on inputs made with fixed seeds: a Voronoi volume
   (96³, 300 cells, no background), random labels 0..3 and 0..20 (24³; 0 is the background), a
   12³ volume split by the plane i + 2j + 3k = 30 into labels 1 / 2, two labels crossing
   diagonally on a face (13 and 14 in a 16 × 32 × 32 background) and the AAL atlas. Columns:
   - twins: the triangles that need a twin (not on the background's wall: some vertex's surfel
     has both voxels inside the domain and off the background) whose reversed twin (the same
     three vertex positions in reverse order, compared exactly) is in another label, in %;
   - points: random points, uniform in 2 × 2 × 2 voxel cells (the cube between 8 voxel centres)
     whose corners hold two labels or more besides the background, a few thousand per input;
     each is tested against every label with a voxel in the 4 × 4 × 4 voxels around its cell (a
     label farther away cannot reach the cell: the analogs are built cube by cube from the
     corners, Definition 9) by its generalised winding number (signed solid angles, Van
     Oosterom and Strackee). A point is right when it is inside exactly one label, or at most
     one where a corner of its cell is background (the background has no mesh). Overlaps (in
     two or more) and gaps (in none where one is required) are counted apart. For AAL only the
     cells among the labels of the picture and the background are sampled, and a third of
     the points, for time;
   - defects: per label, edges of more than two triangles, boundary edges (one triangle) and
     vertices at the same coordinates as another vertex of the label; the count of labels with
     each and the sum.
2. Shared walls after decimation, at reduce 0.5, 0.8, 0.9 (2×, 5×, 10×), on AAL and the Voronoi
   volume: the complex's decimation (label_surfaces(walls="shared", reduce=F)) against each label
   of the undecimated complex decimated alone by vtkQuadricDecimation (SetTargetReduction(F)).
   The fraction is that of the triangles, over all labels, whose reversed twin is in another
   label; the triangles reached against the target (1 - F) × before, summed over the labels.
   surftrack has no decimation of a mesh it did not extract (Surface has no method for it,
   extract(reduce=) decimates the surface it extracts, the CLI reads volumes only): that column
   is left out.
3. Accuracy against analytic shapes: binary spheres of radius 10, 20, 40 (voxel centres inside,
   centre off the grid by (0.31, 0.17, 0.43)), a tube of radius 2 and 40 voxels along the first
   axis, closed by flat caps: its voxels are i = 4 … 43, so the capped cylinder compared with is
   the one from i = 3.5 to 43.5 (where the midpoint mesh's caps lie), area 2πrL + 2πr², volume
   πr²L; its normals are measured only on the triangles at least 4 voxels from both caps; and a
   torus R = 12, r = 4 about the first axis. Area and enclosed volume (relative errors, %) and
   the mean angle between each triangle's normal and the shape's normal at the point closest to
   the triangle's centroid, for: the midpoint mesh (walls="shared", no smoothing), the complex
   smoothed (smooth=10 and 50, 50 being the CLI's default), and vtkWindowedSincPolyDataFilter on
   the midpoint mesh (10 and 50 iterations, pass band 0.1, NormalizeCoordinatesOn, as
   bench_refine_vtk.py).
4. The whole AAL atlas, shared walls + smooth 10 + reduce 0.9: one label_surfaces call, and the CLI
   (`surftrack labels aal.nii.gz -o X.ply --walls shared --smooth 10 --reduce 0.9 --json`, its
   per-stage seconds), against VTK per label on the same threads (--threads; vtkSMPTools): each
   label's independent midpoint mesh (label_surfaces(walls="independent")) through
   vtkWindowedSincPolyDataFilter (10 iterations) and vtkQuadricDecimation (0.9), summed. Wall
   seconds (time.perf_counter) and CPU seconds (time.process_time, all threads; the CLI's from
   getrusage of the child). No time is printed unless the complex's walls are all shared (every
   triangle that needs a twin has one) and the CLI's triangle counts are the binding's.
5. A picture: AAL regions that touch each other (--picture-labels, default the left caudate,
   putamen, pallidum and thalamus; else 5 labels: the pair with the largest contact, then the
   label with the most contact with the group, and so on), cut by a plane through their centre
   across their thinnest axis so the walls between them show, before (the midpoint complex) and
   after (smooth 10, reduce 0.9), rendered with matplotlib (Agg), to --picture. The atlas is
   cropped to the group's box with a 12-voxel margin for it (the walls near the group are the
   whole atlas's).

--quick: small sizes (a smoke run: Voronoi 32³ of 30 cells, random 12³, 600 points, spheres of
radius 5 and 10, a tube of 20 voxels, a 48³ crop of AAL around the picture's labels for tables 1, 2
and 4). --skip-aal leaves the atlas out. The script checks what it measures: the
complex must have every twin and every point right, else it stops with an error.

Needs Debian's /usr/bin/python3 with numpy, python3-vtk9, matplotlib; scipy (Voronoi) and nibabel
(AAL) are used when present (else a brute-force Voronoi and a minimal NIfTI-1 reader).
PYTHONPATH=build/python; the CLI at --cli (default build/cli/surftrack).
"""
import argparse
import gzip
import itertools
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

import surftrack

AAL = "/usr/share/mricron/templates/aal.nii.gz"
WINDING_TOLERANCE = 1e-6
TAB10 = ("blue", "orange", "green", "red", "purple", "brown", "pink", "grey", "olive", "cyan")  # matplotlib's


# ----------------------------------------------------------------------------------------- inputs

def voronoi(n, cells, seed):
    """An n³ volume of `cells` Voronoi cells (labels 1 … cells, no background)."""
    rng = np.random.default_rng(seed)
    sites = rng.uniform(0, n, size=(cells, 3))
    grid = np.indices((n, n, n)).reshape(3, -1).T.astype(float)
    try:
        from scipy.spatial import cKDTree
        nearest = cKDTree(sites).query(grid)[1]
    except ImportError:
        nearest = np.concatenate([np.argmin(((g[:, None, :] - sites[None]) ** 2).sum(-1), axis=1)
                                  for g in np.array_split(grid, max(1, len(grid) // 4096))])
    return (nearest + 1).astype(np.uint16).reshape(n, n, n)


def random_labels(n, top, seed):
    return np.random.default_rng(seed).integers(0, top + 1, size=(n, n, n)).astype(np.uint8)


def plane_split(n):
    i, j, k = np.indices((n, n, n))
    return np.where(i + 2 * j + 3 * k < 30, 1, 2).astype(np.uint8)


def diagonal_contact():
    a = np.zeros((16, 32, 32), np.uint8)
    a[8, 24, 24] = a[8, 25, 25] = 13
    a[8, 24, 25] = a[8, 25, 24] = 14
    return a


def read_nifti(path):
    """The voxels of a NIfTI-1 file in the file's order, indexed [z, y, x] (C order, x fastest),
    so that the engine's x is the file's x as the CLI reads it."""
    try:
        import nibabel
        data = np.asanyarray(nibabel.load(path).dataobj)
        return np.ascontiguousarray(data.T)
    except ImportError:
        pass
    raw = gzip.open(path).read() if path.endswith(".gz") else open(path, "rb").read()
    endian = "<" if int.from_bytes(raw[0:4], "little") == 348 else ">"
    dim = np.frombuffer(raw[40:56], endian + "i2")
    code = int(np.frombuffer(raw[70:72], endian + "i2")[0])
    offset = int(np.frombuffer(raw[108:112], endian + "f4")[0])
    types = {2: "u1", 4: "i2", 8: "i4", 256: "i1", 512: "u2", 768: "u4"}
    if dim[0] != 3 or code not in types:
        sys.exit(f"bench_complex: {path}: not a 3-D integer NIfTI-1 image (dims {dim[0]}, type {code})")
    x, y, z = (int(d) for d in dim[1:4])
    return np.frombuffer(raw, endian + types[code], count=x * y * z, offset=offset).reshape(z, y, x).astype(
        np.dtype(types[code]).newbyteorder("="))


# ------------------------------------------------------------------------------------ mesh figures

def meshes(labels, walls, threads, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pinch copies are announced as warnings (theory.md §12)
        return surftrack.label_surfaces(labels, walls=walls, threads=threads, **kwargs)


def twin_flags(vertex_sets, face_sets):
    """For each label's triangles, whether its reversed twin (the same three points, exactly, in
    the reverse order) is a triangle of another label: one array of bools per label."""
    counts = [len(v) for v in vertex_sets]
    points, ids = np.unique(np.concatenate(vertex_sets), axis=0, return_inverse=True)
    ids = ids.reshape(-1)
    starts = np.concatenate([[0], np.cumsum(counts)])
    tri = np.concatenate([ids[starts[n] + f.astype(np.int64)] for n, f in enumerate(face_sets)]).reshape(-1, 3)
    owner = np.repeat(np.arange(len(face_sets)), [len(f) for f in face_sets])

    def canonical(t):  # the rotation starting at the smallest point id: the same triangle, one row
        r = np.argmin(t, axis=1)
        return np.take_along_axis(t, (r[:, None] + np.arange(3)[None]) % 3, axis=1)
    fwd, rev = canonical(tri), canonical(tri[:, [0, 2, 1]])
    keys, inverse = np.unique(np.concatenate([fwd, rev]), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    fwd_id, rev_id = inverse[:len(tri)], inverse[len(tri):]
    # Triangles of the twin's key, all labels, then those of the triangle's own label.
    order = np.sort(fwd_id)
    everywhere = np.searchsorted(order, rev_id, "right") - np.searchsorted(order, rev_id, "left")
    pair = np.sort(fwd_id * len(face_sets) + owner)
    own_key = rev_id * len(face_sets) + owner
    own = np.searchsorted(pair, own_key, "right") - np.searchsorted(pair, own_key, "left")
    flags = everywhere - own > 0
    return np.split(flags, np.cumsum([len(f) for f in face_sets])[:-1])


def needs_twin(surface, labels, background):
    """The triangles not on the background's wall: some vertex's surfel has both voxels in the
    domain and neither of them background (every vertex of a wall with the background or the
    outside of the domain has one of its voxels there: a wall's edges are cut at every level it
    bounds, theory.md §12)."""
    s = surface.surfels.astype(np.int64)  # (N, 2, 3)
    inside = np.all((s >= 0) & (s < np.array(labels.shape)), axis=2)
    value = np.full(s.shape[:2], background, dtype=np.int64)
    value[inside] = labels[tuple(s[inside].T)]
    labelled = np.all(inside & (value != background), axis=1)
    return labelled[surface.faces.astype(np.int64)].any(axis=1)


class Surfaceless:
    """vertices and faces, as defects() reads them from a Surface."""

    def __init__(self, vertices, faces):
        self.vertices, self.faces = vertices, faces


def defects(surface):
    f = surface.faces.astype(np.int64)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    coincident = len(surface.vertices) - len(np.unique(surface.vertices, axis=0))
    return int((counts > 2).sum()), int((counts == 1).sum()), int(coincident)


def winding_numbers(vertices, faces, points, budget=300_000):
    """Generalised winding numbers of a closed mesh at points: the signed solid angles of its
    triangles over 4π (Van Oosterom and Strackee), in chunks of about `budget` point-triangle
    pairs."""
    a, b, c = (vertices[faces[:, n].astype(np.int64)] for n in range(3))
    out = np.empty(len(points))
    step = max(1, budget // max(1, len(faces)))
    for s in range(0, len(points), step):
        p = points[s:s + step, None, :]
        x, y, z = a[None] - p, b[None] - p, c[None] - p
        lx, ly, lz = (np.sqrt(np.einsum("pfi,pfi->pf", v, v)) for v in (x, y, z))
        det = np.einsum("pfi,pfi->pf", x, np.cross(y, z))
        den = (lx * ly * lz + np.einsum("pfi,pfi->pf", x, y) * lz + np.einsum("pfi,pfi->pf", x, z) * ly
               + np.einsum("pfi,pfi->pf", y, z) * lx)
        out[s:s + step] = (2 * np.arctan2(det, den)).sum(axis=1) / (4 * np.pi)
    return out


def cell_corners(labels):
    n = [m - 1 for m in labels.shape]
    return [labels[a:a + n[0], b:b + n[1], c:c + n[2]] for a, b, c in itertools.product((0, 1), repeat=3)]


def sample_points(labels, background, count, seed, subset=None):
    """`count` points uniform in random cells whose corners hold two labels or more besides the
    background; with `subset`, only cells whose 4³ neighbourhood holds no label outside it.
    Returns the points, whether each cell has a background corner, and the labels near each (in
    the 4³ voxels around its cell)."""
    big = np.iinfo(np.int64).max
    low = high = background_corner = None
    for corner in cell_corners(labels):  # one corner at a time: AAL's cells are 7 M
        c = corner.astype(np.int64)
        is_background = c == background
        lo, hi = np.where(is_background, big, c), np.where(is_background, -big, c)
        if low is None:
            low, high, background_corner = lo, hi, is_background
        else:
            np.minimum(low, lo, out=low)
            np.maximum(high, hi, out=high)
            background_corner |= is_background
    allowed = low < high
    del low, high
    if subset is not None:
        # No voxel outside subset ∪ {background} among voxels c - 1 … c + 2 of cell c: a box sum.
        bad = np.pad(~np.isin(labels, list(subset) + [background]), 1).astype(np.int64)
        total = np.pad(bad.cumsum(0).cumsum(1).cumsum(2), ((1, 0), (1, 0), (1, 0)))
        n = allowed.shape
        box = np.zeros(n, np.int64)
        for corner in itertools.product((0, 1), repeat=3):
            sign = (-1) ** (3 - sum(corner))
            i, j, k = (4 * c for c in corner)
            box += sign * total[i:i + n[0], j:j + n[1], k:k + n[2]]
        allowed &= box == 0
    cells = np.argwhere(allowed)
    if len(cells) == 0:
        return np.zeros((0, 3)), np.zeros(0, bool), []
    rng = np.random.default_rng(seed)
    chosen = cells[rng.integers(0, len(cells), size=count)]
    points = chosen + rng.uniform(0, 1, size=(count, 3))

    def near(cell):
        lo = np.maximum(cell - 1, 0)
        hi = np.minimum(cell + 3, labels.shape)
        found = np.unique(labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]])
        return found[found != background]
    return points, background_corner[tuple(chosen.T)], [near(c) for c in chosen]


def point_figures(surfaces, points, has_background, candidates):
    """(right, overlaps, gaps, not integer) over the points (see the docstring, table 1)."""
    inside = np.zeros(len(points), np.int64)
    fractional = 0
    for label in sorted({int(l) for c in candidates for l in c}):
        which = np.array([label in c for c in candidates])
        s = surfaces.get(label)
        if s is None or not which.any():
            continue
        w = winding_numbers(s.vertices, s.faces, points[which])
        fractional += int((np.abs(w - np.round(w)) > WINDING_TOLERANCE).sum())
        inside[which] += (np.round(w) != 0).astype(np.int64)
    overlaps = int((inside > 1).sum())
    gaps = int(((inside == 0) & ~has_background).sum())
    return len(points) - overlaps - gaps, overlaps, gaps, fractional


def stress_row(name, labels, walls, background, threads, points):
    surfaces = meshes(labels, walls, threads, background=background)
    keys = sorted(surfaces)
    flags = twin_flags([surfaces[k].vertices for k in keys], [surfaces[k].faces for k in keys])
    need = [needs_twin(surfaces[k], labels, background) for k in keys]
    needed = int(sum(n.sum() for n in need))
    twinned = int(sum((f & n).sum() for f, n in zip(flags, need)))
    p, bg, near = points
    right, overlaps, gaps, fractional = point_figures(surfaces, p, bg, near)
    d = np.array([defects(surfaces[k]) for k in keys]).reshape(-1, 3)
    row = {"input": name, "walls": walls, "labels": len(keys),
           "triangles": int(sum(len(surfaces[k].faces) for k in keys)), "need_twin": needed,
           "twinned": twinned, "twin_pct": 100.0 * twinned / needed if needed else 100.0,
           "points": len(p), "points_right_pct": 100.0 * right / len(p) if len(p) else float("nan"),
           "overlaps": overlaps, "gaps": gaps, "non_integer_windings": fractional,
           "labels_multi_edges": int((d[:, 0] > 0).sum()), "multi_edges": int(d[:, 0].sum()),
           "labels_boundary_edges": int((d[:, 1] > 0).sum()), "boundary_edges": int(d[:, 1].sum()),
           "labels_coincident": int((d[:, 2] > 0).sum()), "coincident_vertices": int(d[:, 2].sum())}
    if walls == "shared" and (twinned != needed or right != len(p) or fractional):
        sys.exit(f"bench_complex: the complex is wrong on {name}: {needed - twinned} triangles without their "
                 f"twin, {overlaps} overlaps, {gaps} gaps, {fractional} non-integer winding numbers")
    return row


# ---------------------------------------------------------------------------------------------- VTK

def to_vtk(vertices, faces):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    poly = vtk.vtkPolyData()
    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(vertices, dtype=np.float64), deep=True))
    poly.SetPoints(points)
    cells = np.hstack([np.full((len(faces), 1), 3, np.int64), faces.astype(np.int64)]).reshape(-1)
    array = vtk.vtkCellArray()
    array.SetCells(len(faces), numpy_to_vtkIdTypeArray(cells, deep=True))
    poly.SetPolys(array)
    return poly


def from_vtk(poly):
    from vtk.util.numpy_support import vtk_to_numpy
    if poly.GetNumberOfPolys() == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    v = vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float64)
    cells = vtk_to_numpy(poly.GetPolys().GetData()).reshape(-1, 4)
    if not np.all(cells[:, 0] == 3):
        sys.exit("bench_complex: VTK returned a polygon that is not a triangle")
    return v, cells[:, 1:].astype(np.int64)


def vtk_sinc(vertices, faces, iterations):
    import vtk
    sinc = vtk.vtkWindowedSincPolyDataFilter()  # configured as bench_refine_vtk.py
    sinc.SetInputData(to_vtk(vertices, faces))
    sinc.SetNumberOfIterations(iterations)
    sinc.SetPassBand(0.1)
    sinc.BoundarySmoothingOff()
    sinc.FeatureEdgeSmoothingOff()
    sinc.NonManifoldSmoothingOn()
    sinc.NormalizeCoordinatesOn()
    sinc.Update()
    return from_vtk(sinc.GetOutput())


def vtk_quadric(vertices, faces, reduce):
    import vtk
    q = vtk.vtkQuadricDecimation()
    q.SetInputData(to_vtk(vertices, faces))
    q.SetTargetReduction(reduce)
    q.Update()
    return from_vtk(q.GetOutput())


# ------------------------------------------------------------------------------------ 2. decimation

def decimation_rows(name, labels, threads, reductions):
    base = meshes(labels, "shared", threads)
    keys = sorted(base)
    before = sum(len(base[k].faces) for k in keys)
    flags = twin_flags([base[k].vertices for k in keys], [base[k].faces for k in keys])
    base_pct = 100.0 * sum(f.sum() for f in flags) / before
    rows = []
    for f in reductions:
        target = sum(round((1 - f) * len(base[k].faces)) for k in keys)
        ours = meshes(labels, "shared", threads, reduce=f)
        flags = twin_flags([ours[k].vertices for k in keys], [ours[k].faces for k in keys])
        need = [needs_twin(ours[k], labels, 0) for k in keys]
        if any((n & ~t).any() for n, t in zip(need, flags)):
            sys.exit(f"bench_complex: the decimated complex of {name} lost a twin (reduce {f})")
        ours_tri = sum(len(ours[k].faces) for k in keys)
        ours_pct = 100.0 * sum(t.sum() for t in flags) / ours_tri
        decimated = [vtk_quadric(base[k].vertices, base[k].faces, f) for k in keys]
        vtk_tri = sum(len(t) for _, t in decimated)
        flags = twin_flags([v for v, _ in decimated], [t for _, t in decimated])
        vtk_pct = 100.0 * sum(t.sum() for t in flags) / vtk_tri if vtk_tri else 0.0
        rows.append({"input": name, "reduce": f, "triangles_before": before, "target": target,
                     "shared_pct_before": base_pct, "complex_triangles": ours_tri, "complex_shared_pct": ours_pct,
                     "vtk_triangles": vtk_tri, "vtk_shared_pct": vtk_pct})
    return rows


# -------------------------------------------------------------------------------------- 3. accuracy

def shapes(quick):
    """(name, mask, area, volume, normal(points) -> unit normals, measured(points) -> bool)."""
    offset = np.array([0.31, 0.17, 0.43])
    out = []
    for r in ((5, 10) if quick else (10, 20, 40)):
        n = 2 * r + 6
        c = np.full(3, n / 2) + offset
        x = np.indices((n, n, n)).reshape(3, -1).T
        mask = (np.linalg.norm(x - c, axis=1) <= r).reshape(n, n, n)
        out.append((f"sphere r={r}", mask, 4 * np.pi * r * r, 4 / 3 * np.pi * r ** 3,
                    lambda p, c=c: (p - c) / np.linalg.norm(p - c, axis=1)[:, None], lambda p: np.ones(len(p), bool)))
    r, length = 2, (20 if quick else 40)
    shape = (length + 8, 12, 12)
    c = np.array([0.0, 6.17, 6.43])
    i, j, k = np.indices(shape)
    mask = ((j - c[1]) ** 2 + (k - c[2]) ** 2 <= r * r) & (i >= 4) & (i < 4 + length)

    def radial(p, c=c):
        d = p - c
        d[:, 0] = 0
        return d / np.linalg.norm(d, axis=1)[:, None]
    out.append((f"tube r={r} L={length} (capped)", mask, 2 * np.pi * r * length + 2 * np.pi * r * r,
                np.pi * r * r * length, radial, lambda p: (p[:, 0] > 3.5 + 4) & (p[:, 0] < 3.5 + length - 4)))
    big, small = 12, 4
    shape = (2 * small + 6, 2 * (big + small) + 6, 2 * (big + small) + 6)
    c = np.array(shape) / 2 + offset
    i, j, k = np.indices(shape)
    rho = np.sqrt((j - c[1]) ** 2 + (k - c[2]) ** 2)
    mask = (rho - big) ** 2 + (i - c[0]) ** 2 <= small * small

    def torus_normal(p, c=c):
        d = p - c
        ring = d.copy()
        ring[:, 0] = 0
        ring *= (big / np.linalg.norm(ring, axis=1))[:, None]
        n = d - ring
        return n / np.linalg.norm(n, axis=1)[:, None]
    out.append((f"torus R={big} r={small}", mask, 4 * np.pi ** 2 * big * small, 2 * np.pi ** 2 * big * small ** 2,
                torus_normal, lambda p: np.ones(len(p), bool)))
    return out


def area_volume_normals(vertices, faces):
    a, b, c = (vertices[faces[:, n].astype(np.int64)] for n in range(3))
    cross = np.cross(b - a, c - a)
    twice = np.linalg.norm(cross, axis=1)
    return 0.5 * twice.sum(), np.einsum("fi,fi->f", a, np.cross(b, c)).sum() / 6, cross / twice[:, None], (a + b + c) / 3


def accuracy_rows(quick, threads):
    rows = []
    for name, mask, area, volume, normal, measured in shapes(quick):
        labels = mask.astype(np.uint8)
        midpoint = meshes(labels, "shared", threads)[1]
        results = [("midpoint", midpoint.vertices, midpoint.faces)]
        for n in (10, 50):
            s = meshes(labels, "shared", threads, smooth=n)[1]
            results.append((f"surftrack smooth {n}", s.vertices, s.faces))
        for n in (10, 50):
            results.append((f"VTK windowed sinc {n}",) + vtk_sinc(midpoint.vertices, midpoint.faces, n))
        for method, v, f in results:
            closed = Surfaceless(v, f)
            if len(f) != len(midpoint.faces) or defects(closed)[:2] != (0, 0):
                sys.exit(f"bench_complex: {method} on the {name} is not the midpoint mesh's closed 2-manifold "
                         f"connectivity ({len(f)} triangles, {defects(closed)[:2]} edges of 3+ / 1 triangle)")
            a, vol, normals, centroids = area_volume_normals(v, f)
            keep = measured(centroids)
            cosine = np.clip(np.einsum("fi,fi->f", normals[keep], normal(centroids[keep])), -1, 1)
            rows.append({"shape": name, "method": method, "triangles": len(f),
                         "area_error_pct": 100 * (a - area) / area, "volume_error_pct": 100 * (vol - volume) / volume,
                         "normal_error_deg": float(np.degrees(np.arccos(cosine)).mean())})
    return rows


# --------------------------------------------------------------------------------------- 4. timing

def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def aal_timing(labels, cli, nifti, threads, workdir):
    t0, c0 = time.perf_counter(), time.process_time()
    ours = meshes(labels, "shared", threads, smooth=10, reduce=0.9)
    ours_s, ours_cpu = time.perf_counter() - t0, time.process_time() - c0
    keys = sorted(ours)
    flags = twin_flags([ours[k].vertices for k in keys], [ours[k].faces for k in keys])
    need = [needs_twin(ours[k], labels, 0) for k in keys]
    if any((n & ~t).any() for n, t in zip(need, flags)):
        sys.exit("bench_complex: the complex of AAL (smooth 10, reduce 0.9) lost a twin: no time printed")
    if nifti is None:  # the quick run's crop: a raw file, the array's last axis as the CLI's x
        nifti = os.path.join(workdir, "aal.raw")
        labels.tofile(nifti)
        source = [nifti, "--raw-dims", ",".join(str(n) for n in labels.shape[::-1]), "--raw-type", str(labels.dtype)]
    else:
        source = [nifti]
    command = [cli, "labels", *source, "-o", os.path.join(workdir, "aal.ply"), "--walls", "shared", "--smooth", "10",
               "--reduce", "0.9", "--json", "--threads", str(threads)]
    t0, c0 = time.perf_counter(), children_cpu()
    run = subprocess.run(command, capture_output=True, text=True)
    cli_s, cli_cpu = time.perf_counter() - t0, children_cpu() - c0
    if run.returncode != 0:
        sys.exit(f"bench_complex: {' '.join(command)} failed: {run.stderr.strip()}")
    report = json.loads(run.stdout)
    cli_rows = {row["label"]: row["triangles"] for row in report["labels"]}
    if cli_rows != {k: len(ours[k].faces) for k in keys}:
        sys.exit("bench_complex: the CLI's triangle counts are not the binding's: no time printed")
    import vtk
    if threads > 0:
        vtk.vtkSMPTools.Initialize(threads)
    t0, c0 = time.perf_counter(), time.process_time()
    independent = meshes(labels, "independent", threads)
    extract_s, extract_cpu = time.perf_counter() - t0, time.process_time() - c0
    sinc_s = sinc_cpu = quadric_s = quadric_cpu = 0.0
    vtk_tri = 0
    for k in sorted(independent):
        t0, c0 = time.perf_counter(), time.process_time()
        v, f = vtk_sinc(independent[k].vertices, independent[k].faces, 10)
        sinc_s, sinc_cpu = sinc_s + time.perf_counter() - t0, sinc_cpu + time.process_time() - c0
        t0, c0 = time.perf_counter(), time.process_time()
        v, f = vtk_quadric(v, f, 0.9)
        quadric_s, quadric_cpu = quadric_s + time.perf_counter() - t0, quadric_cpu + time.process_time() - c0
        if len(f) == 0:
            sys.exit(f"bench_complex: VTK left label {k} without a triangle: no time printed")
        vtk_tri += len(f)
    ours_tri = sum(len(ours[k].faces) for k in keys)
    before = sum(s.refine.get("triangles_before", 0) for s in ours.values())
    target = sum(s.refine.get("target_triangles", 0) for s in ours.values())
    return {"labels": len(keys), "threads": threads,
            "python": {"wall_s": ours_s, "cpu_s": ours_cpu, "triangles": ours_tri, "triangles_before": before,
                       "target": target},
            "cli": {"wall_s": cli_s, "cpu_s": cli_cpu, "stages_s": report["seconds"],
                    "triangles": sum(cli_rows.values())},
            "vtk": {"extract_wall_s": extract_s, "extract_cpu_s": extract_cpu, "sinc_wall_s": sinc_s,
                    "sinc_cpu_s": sinc_cpu, "quadric_wall_s": quadric_s, "quadric_cpu_s": quadric_cpu,
                    "wall_s": extract_s + sinc_s + quadric_s, "cpu_s": extract_cpu + sinc_cpu + quadric_cpu,
                    "triangles_before": int(sum(len(s.faces) for s in independent.values())),
                    "triangles": vtk_tri}}


# -------------------------------------------------------------------------------------- 5. picture

def touching_group(labels, size=5):
    """`size` labels that touch each other: the pair with the largest contact, then each time the
    label with the largest contact with the group (face-adjacent voxel pairs, background left
    out)."""
    pairs = []
    for axis in range(3):
        a = np.moveaxis(labels, axis, 0)
        x, y = a[:-1].reshape(-1), a[1:].reshape(-1)
        keep = (x != y) & (x != 0) & (y != 0)
        pairs.append(np.sort(np.stack([x[keep], y[keep]], axis=1), axis=1))
    pairs, counts = np.unique(np.concatenate(pairs), axis=0, return_counts=True)
    contact = {(int(a), int(b)): int(n) for (a, b), n in zip(pairs, counts)}
    if not contact:
        return []
    group = list(max(contact, key=contact.get))
    while len(group) < size:
        score = {}
        for (a, b), n in contact.items():
            if (a in group) != (b in group):
                other = b if a in group else a
                score[other] = score.get(other, 0) + n
        if not score:
            break
        group.append(max(score, key=score.get))
    return sorted(group)


def group_box(labels, group, margin):
    """The slices of the box around the group's voxels, `margin` voxels wider (clamped)."""
    where = np.argwhere(np.isin(labels, group))
    lo = np.maximum(where.min(axis=0) - margin, 0)
    hi = np.minimum(where.max(axis=0) + 1 + margin, labels.shape)
    return tuple(slice(a, b) for a, b in zip(lo, hi))


def render(panels, titles, path, caption=""):
    """The panels side by side (matplotlib, Agg): each label's triangles on the near side of the
    plane through the group's centre across its longest axis, lit, one colour per label, drawn as
    one collection so that the depth order is over all the labels."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    colours = np.array(plt.get_cmap("tab10").colors)
    everything = np.concatenate([v for panel in panels for v, f in panel])
    centre = (everything.max(axis=0) + everything.min(axis=0)) / 2
    extent = everything.max(axis=0) - everything.min(axis=0)
    cut = int(np.argmin(extent))  # the cut shows the walls across the group's thinnest axis
    view = np.zeros(3)
    view[cut] = 1
    fig = plt.figure(figsize=(11, 5.6), dpi=90)
    for n, (panel, title) in enumerate(zip(panels, titles)):
        ax = fig.add_subplot(1, len(panels), n + 1, projection="3d")
        tris, shades = [], []
        for index, (v, f) in enumerate(panel):
            tri = v[f.astype(np.int64)]
            tri = tri[tri.mean(axis=1)[:, cut] <= centre[cut]]
            normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            normal /= np.linalg.norm(normal, axis=1)[:, None]
            light = 0.35 + 0.65 * np.abs(normal @ (0.8 * view + 0.35))
            tris.append(tri)
            shades.append(colours[index % len(colours)][None, :] * light[:, None])
        ax.add_collection3d(Poly3DCollection(np.concatenate(tris), facecolors=np.clip(np.concatenate(shades), 0, 1),
                                             edgecolors=(0, 0, 0, 0.3), linewidths=0.06))
        span = extent.max() / 2
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
            setter(c - span, c + span)
        # Look at the cut face from the kept side, slightly from above.
        ax.view_init(*{0: (20, 20), 1: (20, 70), 2: (70, -60)}[cut])
        try:
            ax.set_box_aspect(None, zoom=1.5)
        except TypeError:  # matplotlib before 3.6: no zoom
            pass
        ax.set_axis_off()
        fig.text((n + 0.5) / len(panels), 0.95, title, ha="center", fontsize=12)
    fig.text(0.5, 0.02, caption, ha="center")
    fig.subplots_adjust(left=0, right=1, bottom=0.05, top=0.92, wspace=0)
    fig.savefig(path)
    plt.close(fig)
    try:  # 256 colours: a third of the bytes, for a picture kept in the repository
        from PIL import Image
        Image.open(path).convert("RGB").quantize(256).save(path, optimize=True)
    except ImportError:
        pass


def picture(labels, group, threads, path):
    """The group's labels in the atlas cropped to their box with a 12-voxel margin (the walls near
    the group are those of the whole atlas; the smoothing and the decimation near the crop's border
    differ, far from the group), before and after."""
    box = labels[group_box(labels, group, 12)]
    box = np.ascontiguousarray(box)
    before = meshes(box, "shared", threads, only=group)
    after = meshes(box, "shared", threads, only=group, smooth=10, reduce=0.9)
    render([[(before[k].vertices, before[k].faces) for k in group], [(after[k].vertices, after[k].faces) for k in group]],
           [f"midpoint complex ({sum(len(before[k].faces) for k in group):,} triangles)",
            f"smooth 10, reduce 0.9 ({sum(len(after[k].faces) for k in group):,} triangles)"], path,
           "labels " + ", ".join(f"{k} ({c})" for k, c in zip(group, itertools.cycle(TAB10)))
           + ", cut by a plane through their centre")
    return os.path.getsize(path)


# ------------------------------------------------------------------------------------------ output

def table(rows, columns):
    """A markdown table of `rows` (dicts): columns as (header, key, format)."""
    lines = ["| " + " | ".join(h for h, _, _ in columns) + " |",
             "|" + "|".join("---" if f is None else "---:" for _, _, f in columns) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(str(r[k]) if f is None else format(r[k], f) for _, k, f in columns) + " |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="small sizes: a smoke run")
    ap.add_argument("--skip-aal", action="store_true", help="leave the AAL atlas out")
    ap.add_argument("--aal", default=AAL, help=f"the AAL atlas (default {AAL})")
    ap.add_argument("--json", help="also write every figure to this JSON file")
    ap.add_argument("--threads", type=int, default=2, help="threads of surftrack and VTK (default 2; 0: all cores)")
    ap.add_argument("--cli", default=os.path.join("build", "cli", "surftrack"), help="the surftrack CLI")
    ap.add_argument("--picture", default=os.path.join("docs", "complex-before-after.png"),
                    help="the PNG of the AAL regions before and after (default docs/complex-before-after.png)")
    ap.add_argument("--picture-labels", default="71,73,75,77",
                    help="the atlas labels of the picture (default 71,73,75,77: AAL's left caudate, putamen, "
                         "pallidum, thalamus; when one is missing, 5 touching labels are chosen)")
    ap.add_argument("--points", type=int, default=3000, help="random points per input (default 3000)")
    ap.add_argument("--tables", default="1,2,3,4",
                    help="which tables to make (default 1,2,3,4; 4 brings the picture, 5)")
    a = ap.parse_args()
    tables = {int(n) for n in a.tables.split(",") if n.strip()}
    started = time.perf_counter()
    print(f"# bench_complex: surftrack {surftrack.__version__}, threads {a.threads}, "
          f"load average at start {os.getloadavg()[0]:.2f}{' (quick run)' if a.quick else ''}\n")
    out = {"quick": a.quick, "threads": a.threads, "load_start": os.getloadavg()[0]}
    points = 600 if a.quick else a.points

    aal = None
    if not a.skip_aal:
        if not os.path.exists(a.aal):
            print(f"(no {a.aal}: the AAL atlas is left out)\n")
        else:
            aal = read_nifti(a.aal)
    group = []
    if aal is not None:
        group = [int(v) for v in a.picture_labels.split(",")] if a.picture_labels else []
        if not group or not np.isin(group, aal).all():
            group = touching_group(aal)
    whole = aal
    if aal is not None and a.quick:  # a 48³ crop around the picture's labels
        centre = np.argwhere(np.isin(aal, group)).mean(axis=0).astype(int)
        lo = [min(max(c - 24, 0), n - 48) for c, n in zip(centre, aal.shape)]
        aal = np.ascontiguousarray(aal[lo[0]:lo[0] + 48, lo[1]:lo[1] + 48, lo[2]:lo[2] + 48])

    # 1. The stress table.
    inputs = [("Voronoi 32³, 30 cells" if a.quick else "Voronoi 96³, 300 cells",
               voronoi(32, 30, 1) if a.quick else voronoi(96, 300, 1), None),
              (f"random 0..3, {12 if a.quick else 24}³", random_labels(12 if a.quick else 24, 3, 2), None),
              (f"random 0..20, {12 if a.quick else 24}³", random_labels(12 if a.quick else 24, 20, 3), None),
              ("plane i+2j+3k=30, 12³", plane_split(12), None),
              ("diagonal contact 13/14", diagonal_contact(), None)]
    if aal is not None:
        inputs.append((f"AAL{' (48³ crop)' if a.quick else ''}, points near labels {group}", aal, group))
    rows = []
    for seed, (name, labels, subset) in enumerate(inputs if 1 in tables else []):
        # AAL's labels are large (about 12,000 triangles each): a third of the points, for time.
        p = sample_points(labels, 0, points if subset is None else points // 3, 100 + seed, subset)
        for walls in ("independent", "shared"):
            rows.append(stress_row(name, labels, walls, 0, a.threads, p))
    out["stress"] = rows
    if 1 in tables:
        print("## 1. Stress inputs: walls shared between labels, space partitioned, defects (26-6)\n")
        print(table(rows, [("input", "input", None), ("walls", "walls", None), ("labels", "labels", "d"),
                           ("triangles", "triangles", ",d"), ("twins %", "twin_pct", ".2f"),
                           ("points", "points", "d"), ("right %", "points_right_pct", ".2f"),
                           ("overlaps", "overlaps", "d"), ("gaps", "gaps", "d"),
                           ("labels with edges of >2 triangles", "labels_multi_edges", "d"),
                           ("such edges", "multi_edges", "d"), ("boundary edges", "boundary_edges", "d"),
                           ("labels with coincident vertices", "labels_coincident", "d"),
                           ("coincident vertices", "coincident_vertices", "d")]))
        print("\ntwins %: of the triangles not on the background's wall, those whose reversed twin is in another "
              "label. right %: random points in cells of 2+ labels inside exactly one label (at most one where the "
              "cell has a background corner); overlaps: inside 2+; gaps: inside none where one is required.\n")

    # 2. Shared walls after decimation.
    if 2 in tables:
        print("## 2. Shared wall triangles after decimation: the complex against each label alone (VTK)\n")
        drows = []
        reductions = (0.5, 0.8, 0.9)
        if aal is not None:
            drows += decimation_rows("AAL" + (" (48³ crop)" if a.quick else ""), aal, a.threads, reductions)
        drows += decimation_rows(inputs[0][0], inputs[0][1], a.threads, reductions)
        out["decimation"] = drows
        print(table(drows, [("input", "input", None), ("reduce", "reduce", ".1f"),
                            ("triangles before", "triangles_before", ",d"), ("shared % before", "shared_pct_before", ".1f"),
                            ("target", "target", ",d"), ("complex: triangles", "complex_triangles", ",d"),
                            ("complex: shared %", "complex_shared_pct", ".1f"), ("VTK quadric per label: triangles",
                                                                                  "vtk_triangles", ",d"),
                            ("VTK: shared %", "vtk_shared_pct", ".1f")]))
        print("\nshared %: triangles whose reversed twin is in another label, over all the labels' triangles (the rest "
              "face the background or the domain's border). surftrack's own decimation of one label alone is not "
              "shown: surftrack has no decimation of a mesh it did not extract (no Surface method; extract(reduce=) "
              "and `surftrack mesh --reduce` decimate the surface they extract, the CLI reads volumes only).\n")

    # 3. Accuracy.
    if 3 in tables:
        print("## 3. Accuracy against the analytic shapes (relative errors; normal error: mean angle, degrees)\n")
        arows = accuracy_rows(a.quick, a.threads)
        out["accuracy"] = arows
        print(table(arows, [("shape", "shape", None), ("mesh", "method", None), ("triangles", "triangles", ",d"),
                            ("area %", "area_error_pct", "+.2f"), ("volume %", "volume_error_pct", "+.2f"),
                            ("normal error °", "normal_error_deg", ".2f")]))
        print("\nThe tube's normals are measured on the triangles at least 4 voxels from its caps.\n")

    # 4. The whole atlas, timed; 5. the picture.
    if aal is not None and 4 in tables:
        with tempfile.TemporaryDirectory(prefix="bench_complex.") as work:
            t = aal_timing(aal, a.cli, None if a.quick else a.aal, a.threads, work)
        out["aal_time"] = t
        print(f"## 4. The AAL atlas{' (48³ crop)' if a.quick else ''}, {t['labels']} labels: shared walls + smooth 10 "
              f"+ reduce 0.9 against VTK per label, {a.threads} threads\n")
        py, cl, vt = t["python"], t["cli"], t["vtk"]
        trows = [{"run": "label_surfaces(walls='shared', smooth=10, reduce=0.9)", "wall": py["wall_s"],
                  "cpu": py["cpu_s"], "triangles": py["triangles"]},
                 {"run": "surftrack labels --walls shared --smooth 10 --reduce 0.9 (stages: " +
                  ", ".join(f"{k} {v:.2f} s" for k, v in cl["stages_s"].items()) + ")",
                  "wall": cl["wall_s"], "cpu": cl["cpu_s"], "triangles": cl["triangles"]},
                 {"run": "VTK per label: independent meshes (label_surfaces)", "wall": vt["extract_wall_s"],
                  "cpu": vt["extract_cpu_s"], "triangles": vt["triangles_before"]},
                 {"run": "  + vtkWindowedSincPolyDataFilter (10)", "wall": vt["sinc_wall_s"], "cpu": vt["sinc_cpu_s"],
                  "triangles": vt["triangles_before"]},
                 {"run": "  + vtkQuadricDecimation (0.9)", "wall": vt["quadric_wall_s"], "cpu": vt["quadric_cpu_s"],
                  "triangles": vt["triangles"]},
                 {"run": "VTK per label, total", "wall": vt["wall_s"], "cpu": vt["cpu_s"], "triangles": vt["triangles"]}]
        print(table(trows, [("run", "run", None), ("wall s", "wall", ".2f"), ("CPU s", "cpu", ".2f"),
                            ("triangles", "triangles", ",d")]))
        print(f"\nThe complex: {py['triangles_before']:,} triangles before decimation, target {py['target']:,}; "
              "every wall shared (checked before timing was printed).\n")
        if group:
            size = picture(whole, group, a.threads, a.picture)
            out["picture"] = {"path": a.picture, "labels": group, "bytes": size}
            print(f"## 5. Picture: labels {group} -> {a.picture} ({size / 1024:.0f} KB"
                  f"{'; larger than 300 KB: do not commit it' if size > 300 * 1024 else ''})\n")
    out["load_end"] = os.getloadavg()[0]
    out["seconds"] = time.perf_counter() - started
    print(f"# load average at end {out['load_end']:.2f}; the run took {out['seconds']:.0f} s")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
