#!/usr/bin/env python3
"""Neuroglancer output (docs/performance.md, "Neuroglancer output"): the write time and the size
on disk of every label's mesh in each format, from the same surfaces in one process.

Inputs: the AAL atlas (mricron-data's aal.nii.gz, 116 labels, read with nibabel, axes "xyz",
its voxel size) and the 512^3 uint32 volume of 2,500 Voronoi cells of bench/bench_labels.py
(cached in --cache; axes "zyx", unit voxels of 1 nm). Each input's surfaces come from one
``surftrack.label_surfaces`` call (timed apart); then, on those surfaces, one after the other:
  - one binary PLY file per label (``Surface.write``),
  - ``write_precomputed`` legacy (one float32 fragment per label),
  - ``write_precomputed(lods=L)`` multi-resolution, Draco, unsharded, L = --lods (default 3),
    its bytes split by level of detail with the .index manifests.
Before a figure is printed the output is checked by the independent reader of
python/tests/test_precomputed_multires.py (written from the format's description, fragments
decoded by Debian's draco_decoder): for --check labels spread over the input, every level is a
closed oriented manifold with the label's Euler characteristic and components
(``check_segment``); the legacy files' vertex counts are the surfaces'. A wrong output stops the
run before its time is shown.

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_precomputed.py
    PYTHONPATH=build/python /usr/bin/python3 bench/bench_precomputed.py --no-voronoi --lods 2
"""
from __future__ import annotations

import argparse
import os
import shutil
import struct
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "python", "tests"))
from bench_labels import AAL, load_labels, voronoi_volume  # noqa: E402
from bench_python import cpu_model  # noqa: E402


def tree_bytes(path: Path) -> int:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())


def timed_once(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def level_bytes(out: Path, labels) -> list[int]:
    """The bytes of each level of detail over every label, from the .index manifests."""
    from multires_reader import parse_manifest
    per_level = None
    for label in labels:
        m = parse_manifest((out / f"{label}.index").read_bytes())
        counts = [len(p) for p in m["positions"]]
        sizes, at = [], 0
        for n in counts:
            sizes.append(sum(m["sizes"][at:at + n]))
            at += n
        per_level = sizes if per_level is None else [a + b for a, b in zip(per_level, sizes)]
    return per_level


def check(out_legacy: Path, out_multi: Path, surfaces, spacing, count: int) -> int:
    """The independent reader's checks on `count` labels spread over the input; returns how many."""
    import test_precomputed_multires as reader
    info = reader.read_info(out_multi)
    labels = sorted(surfaces)
    chosen = labels[:: max(1, len(labels) // count)][:count]
    with tempfile.TemporaryDirectory() as tmp:
        for label in chosen:
            s = surfaces[label]
            m = reader.load_segment(out_multi, info, label, Path(tmp))
            vertices = np.asarray(s.vertices, float) / np.asarray(spacing)
            reader.check_segment(m, info, vertices, np.asarray(s.faces))
            fragment = (out_legacy / f"{label}:0").read_text()
            data = (out_legacy / __import__("json").loads(fragment)["fragments"][0]).read_bytes()
            (n,) = struct.unpack_from("<I", data, 0)
            assert n == len(s.vertices), (label, n, len(s.vertices))
    return len(chosen)


def run(name, labels, axes, spacing, args) -> None:
    import surftrack
    print(f"\n== {name}: {labels.shape} {labels.dtype}, load {os.getloadavg()[0]:.2f}", flush=True)
    t0 = time.perf_counter()
    surfaces = surftrack.label_surfaces(labels, spacing=spacing, threads=args.threads, walls="independent")
    t_scan = time.perf_counter() - t0
    triangles = sum(len(s.faces) for s in surfaces.values())
    print(f"label_surfaces: {len(surfaces)} labels, {triangles} triangles, {t_scan:.2f} s", flush=True)
    root = Path(tempfile.mkdtemp(prefix="bench-precomputed-", dir=args.tmp))
    try:
        ply = root / "ply"
        ply.mkdir()
        t_ply = timed_once(lambda: [s.write(str(ply / f"{L}.ply")) for L, s in surfaces.items()])
        legacy, multi = root / "legacy", root / "multires"
        t_legacy = timed_once(lambda: surftrack.write_precomputed(surfaces, legacy, axes=axes,
                                                                  spacing=spacing))
        load_before = os.getloadavg()[0]
        # --multires-labels N: the multi-resolution write on N labels spread over the input only
        # (its time for all of them extrapolated by triangles, and printed as such).
        part = surfaces
        if args.multires_labels and args.multires_labels < len(surfaces):
            keys = sorted(surfaces)
            part = {L: surfaces[L] for L in keys[:: len(keys) // args.multires_labels][:args.multires_labels]}
        t_multi = timed_once(lambda: surftrack.write_precomputed(part, multi, axes=axes,
                                                                 spacing=spacing, lods=args.lods))
        checked = check(legacy, multi, part, spacing, args.check)
        levels = level_bytes(multi, sorted(part))
        part_triangles = sum(len(s.faces) for s in part.values())
        print(f"checked {checked} labels at every level (closed, oriented, Euler characteristic and "
              f"components of the label) by the independent reader")
        print(f"| output | write (s) | bytes on disk | bytes per level |")
        print(f"|---|---|---|---|")
        print(f"| one PLY per label | {t_ply:.2f} | {tree_bytes(ply)} | |")
        print(f"| legacy precomputed | {t_legacy:.2f} | {tree_bytes(legacy)} | |")
        if part is surfaces:
            print(f"| multi-resolution, lods {args.lods} | {t_multi:.2f} | {tree_bytes(multi)} | "
                  f"{', '.join(str(b) for b in levels)} |")
        else:
            scale = triangles / part_triangles
            print(f"| multi-resolution, lods {args.lods}, {len(part)} labels ({part_triangles} triangles) | "
                  f"{t_multi:.2f} | {tree_bytes(multi)} | {', '.join(str(b) for b in levels)} |")
            print(f"| multi-resolution, lods {args.lods}, all labels: EXTRAPOLATED x{scale:.1f} by triangles | "
                  f"~{t_multi * scale:.0f} | ~{tree_bytes(multi) * scale:.3g} | |")
        print(f"load {load_before:.2f} before the multi-resolution write, {os.getloadavg()[0]:.2f} after",
              flush=True)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lods", type=int, default=3)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--check", type=int, default=8, help="labels checked per input (default 8)")
    parser.add_argument("--multires-labels", type=int, default=0,
                        help="write the multi-resolution format for this many labels only (0: all)")
    parser.add_argument("--no-aal", action="store_true")
    parser.add_argument("--no-voronoi", action="store_true")
    parser.add_argument("--size", type=int, default=512, help="Voronoi volume side (default 512)")
    parser.add_argument("--cells", type=int, default=2500, help="Voronoi cells (default 2500)")
    parser.add_argument("--cache", default=None,
                        help="the Voronoi volume's cache (default /tmp/surftrack-voronoi-SIZE-CELLS.npy)")
    parser.add_argument("--tmp", default=None, help="where the outputs are written (default $TMPDIR)")
    args = parser.parse_args(argv)
    if shutil.which("draco_decoder") is None:
        sys.exit("bench_precomputed: draco_decoder (Debian package draco) is needed to check the output")
    print(f"CPU: {cpu_model()}, {os.cpu_count()} cores; load {os.getloadavg()}")
    if not args.no_aal:
        import nibabel
        spacing = tuple(float(v) for v in nibabel.load(AAL).header.get_zooms()[:3])
        run("AAL", load_labels(AAL), "xyz", spacing, args)
    if not args.no_voronoi:
        cache = args.cache or f"/tmp/surftrack-voronoi-{args.size}-{args.cells}.npy"
        run(f"Voronoi {args.size}^3, {args.cells} cells",
            np.ascontiguousarray(voronoi_volume(cache, args.size, args.cells)), "zyx", (1.0, 1.0, 1.0), args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
