"""Every label of a volume larger than one machine, by blocks on Dask (docs/python.md, "Every
label by blocks, on Dask"; the proof of exactness is docs/theory.md, "Label maps by blocks"),
and every boundary of a threshold the same way (docs/theory.md, "Thresholds by blocks").

A block owns the cubes whose minimum corner lies in its core and reads one more voxel on its
high sides; each of its labels' fragments holds global surfel keys and the triangles of the cubes
it owns. A label's fragments from every block, merged (keys made unique, triangles in the single
pass' order, vertices placed by the single pass' expression), are exactly that label's surface
from ``label_surfaces`` on the whole array: same arrays, same bytes written. No welding, no
tolerance, no repair.

The graph: one task per block (reads its box from the array — a zarr array, or anything indexed
as numpy is — and writes one fragment file; a block whose file exists is not computed again, so
a stopped run resumes), one plan task, one task per shard of labels (reads its labels' fragments
from the files, merges, writes or returns). Fragments go through the file system, never through
the scheduler: ``work_dir`` must be shared by every worker. A block's file is the engine's flat
fragment file (core/include/surftrack/LabelBlockFiles.h), written and read in C++. A label whose
fragments exceed ``merge_budget`` gets its exact figures from a tree of groups of blocks and its
mesh file streamed from the fragment files, never whole in memory (docs/theory.md, "A label
larger than one merge").

In Neuroglancer's formats (docs/python.md, "Neuroglancer output on Dask"), the reduce tasks
encode each label with the single pass' C++ encoders (write_precomputed's), then, sharded, one
task per Neuroglancer shard assembles its file, and a final task writes ``info`` and moves the
staging directory into place.
"""
from __future__ import annotations

import itertools
import os
import shutil
import tempfile
import uuid
import zlib
from pathlib import Path
from types import SimpleNamespace
from typing import NamedTuple

import numpy as np

from . import _surftrack
from .precomputed import _frame, _stored

_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def block_grid(shape, block):
    """The blocks of an array of `shape` cut every `block` voxels: a list of (lo, hi) triples
    (the last block of an axis is shorter where `block` does not divide it)."""
    shape = tuple(int(n) for n in shape)
    block = tuple(int(b) for b in block)
    if len(shape) != 3 or len(block) != 3 or min(block) < 1:
        raise ValueError(f"block must be three positive sizes for a 3-D array, not {block!r}")
    axes = [[(lo, min(lo + b, n)) for lo in range(0, n, b)] for n, b in zip(shape, block)]
    return [(tuple(a[0] for a in c), tuple(a[1] for a in c)) for c in itertools.product(*axes)]


def _fragment_path(work_dir, lo, run, suffix=".frag"):
    """The fragment file of the block at `lo` in a run: `run` names what the fragments depend on
    (the kind of run, the array's shape and type, the block size, the selection, the pair), so
    that a work_dir reused with other arguments recomputes rather than reuses. Label maps' files
    are the engine's fragment files (.frag); thresholds' are still numpy's .npz."""
    return Path(work_dir) / f"block_{lo[0]}_{lo[1]}_{lo[2]}_{run}{suffix}"


def _run_name(*what):
    return f"{zlib.crc32(repr(what).encode()):08x}"


def _summary(path):
    """{label: (vertices, triangles)} of a fragment file (its index, checked: a damaged file is
    a ValueError naming it)."""
    return {L: (k, t) for L, k, t in _surftrack.fragment_file_summary(str(path))}


def _mesh_block(source, lo, hi, shape, background, adjacency, work_dir, run):
    """Task: the fragments of one block, written to its file (atomically: a retried or repeated
    task writes the same bytes; an existing file is kept, so a resumed run skips the block)."""
    path = _fragment_path(work_dir, lo, run)
    if path.exists():
        return str(path), _summary(path)
    top = [min(h + 1, n) for h, n in zip(hi, shape)]  # the one-voxel apron on the high sides
    box = np.ascontiguousarray(source[lo[0]:top[0], lo[1]:top[1], lo[2]:top[2]])
    if box.dtype.kind not in "biu":
        raise ValueError(f"a label image needs integer voxels, not {box.dtype}")
    # Scanned and written in C++ (core/include/surftrack/LabelBlockFiles.h: a flat file, written
    # under a temporary name and renamed, the same bytes on a retry).
    counts = _surftrack.scan_label_block_file(box, list(lo), list(shape), list(lo), list(hi), background, adjacency,
                                              str(path))
    return str(path), {L: (k, t) for L, k, t in counts}


#: Fragment bytes a reduce task holds at most (about): the plan makes more shards than asked
#: for when the fragments would exceed it.
_SHARD_BYTES = 512 << 20


def _plan(results, shards):
    """Task: the labels cut into shards, each a list of (label, its blocks' files, its fragments'
    bytes). Labels in the order of their first block (neighbours together, so that a shard reads
    few files), cut into runs of about equal fragment bytes: at least `shards` runs, and enough that none holds much
    more than _SHARD_BYTES (a keys entry is 8 bytes, a triangle 12)."""
    where, weight = {}, {}
    for order, (path, summary) in enumerate(results):
        for label, (keys, triangles) in summary.items():
            where.setdefault(label, []).append((order, path))
            weight[label] = weight.get(label, 0) + 8 * keys + 12 * triangles
    labels = sorted(where, key=lambda L: (where[L][0][0], L))
    total = sum(weight.values())
    count = max(1, min(len(labels), max(shards, -(-total // _SHARD_BYTES))))
    plan, run, filled = [], [], 0
    for label in labels:
        run.append((label, [path for _, path in where[label]], weight[label]))
        filled += weight[label]
        if filled * count >= total * (len(plan) + 1) and len(plan) < count - 1:
            plan.append(run)
            run = []
    if run:
        plan.append(run)
    return plan


def _merge_label(label, paths, geometry, background, adjacency, figures, out_path="", binary=True):
    """A label's fragments read from its blocks' files and merged, all in C++ (no Python array
    between the files and the mesh), and written to `out_path` when given (the bytes of
    Surface.write, from the engine's arrays)."""
    spacing, origin, direction = geometry
    return _surftrack.merge_label_files(label, list(paths), spacing, origin, direction, background, adjacency,
                                        figures, out_path, binary)


def _tree_figures(label, paths, geometry, adjacency, grid, budget):
    """The figures of a label whose fragments exceed `budget` bytes, without its mesh: merged by
    cells of blocks of at most `budget` bytes, combined up an octree (docs/theory.md, "A label
    larger than one merge"); counts exact, area and volume summed in another order."""
    spacing, origin, direction = geometry
    shape, block = grid
    f = _surftrack.label_figures_by_tree(label, list(paths), list(shape), list(block), spacing, origin, direction,
                                         adjacency, int(budget))
    boundaries, area, volume = _component_sums(f["components"])
    return {"voxels": f["voxels"], "vertices": f["vertices"], "triangles": f["triangles"], "euler": f["euler"],
            "boundaries": boundaries, "area": area, "volume": volume, "file": None, "levels": f["levels"]}


def _component_sums(components):
    """The number of components of a (K, 7) figures table (as Surface holds it) and their area
    and volume, summed in the order the command line's table sums them."""
    table = np.asarray(components).reshape(-1, 7)
    area = volume = 0.0
    for row in table:
        area += float(row[5])
        volume += float(row[6])
    return len(table), area, volume


def _file_name(label, naming):
    """A label's file: label_<L>.ply, or the command line's names (cli/LabelsCommand.cpp:
    <L>_<name>.ply when the volume has label names, '/', '\\' and ' ' made '_')."""
    if not naming or not naming["names"]:
        return f"label_{label}.ply"
    name = naming["names"].get(str(label), f"label{label}")
    return f"{label}_{name.replace('/', '_').replace(' ', '_').replace(chr(92), '_')}.ply"


def _reduce_shard(shard, geometry, background, adjacency, figures, out_dir, naming=None, encoding=None, budget=None,
                  grid=None):
    """Task: every label of a shard merged; written into `out_dir` (named by _file_name) when it
    is given (the files only, returned as figures), else the surfaces' fields returned. With
    `encoding` (_Encoding), each label encoded in Neuroglancer's format instead (_EncodedLabels).
    A label whose fragments exceed `budget` bytes gets its figures from the tree (_tree_figures)
    and, into `out_dir`, its mesh streamed with bounded memory (binary PLY only: with text PLY,
    "file" None and "no_file" saying why; write_label_meshes refuses a budget for Neuroglancer's
    formats)."""
    out = {}
    encoded = _EncodedLabels(encoding) if encoding else None
    for label, paths, weight in shard:
        if budget is not None and weight > budget:
            out[label] = tree = _tree_figures(label, paths, geometry, adjacency, grid, budget)
            if out_dir is not None and encoding is None:
                if naming is not None and not naming["binary"]:  # (the streamed writer writes binary PLY)
                    tree["no_file"] = ("over --merge-budget and --ascii: a label's mesh is streamed as binary "
                                           "PLY only, no text")
                else:
                    file = _file_name(label, naming)
                    counts = _surftrack.write_label_mesh_streamed(label, list(paths), *geometry,
                                                                  str(Path(out_dir) / file), int(budget))
                    if tuple(counts) != (tree["vertices"], tree["triangles"]):
                        raise RuntimeError(f"label {label}: the streamed mesh's counts {tuple(counts)} are not the "
                                           "tree's")
                    tree["file"] = file
            continue
        if out_dir is None and encoding is None:  # plain arrays through the scheduler (the C++ result does not pickle)
            fields = _merge_label(label, paths, geometry, background, adjacency, figures)
            result = fields.pop("result")
            fields["surfels"], fields["normals"] = result.surfels(), result.normals()
            out[label] = fields
            continue
        if encoding is not None:
            fields = _merge_label(label, paths, geometry, background, adjacency, figures)
            fields.pop("result", None)
            file = encoded.add(label, SimpleNamespace(vertices=fields["vertices"], faces=fields["faces"]))
        else:
            file = _file_name(label, naming)
            fields = _merge_label(label, paths, geometry, background, adjacency, figures, str(Path(out_dir) / file),
                                  naming["binary"] if naming else True)
        boundaries, area, volume = _component_sums(fields["components"])
        out[label] = {"voxels": fields["voxels"], "vertices": len(fields["vertices"]),
                      "triangles": len(fields["faces"]), "euler": fields["euler"],
                      "boundaries": boundaries, "area": area, "volume": volume, "file": file}
    if encoded is not None:
        return {"labels": out, "blobs": encoded.close()}
    return out


class _Encoding(NamedTuple):
    """What a reduce task needs to encode its labels as write_precomputed does: the frame
    (precomputed._frame: the map to nanometres, the vertices' divisor, the format), the command
    line's geometry (its multi-resolution format stores voxel indices, converter/PrecomputedFrame.h;
    None from Python), the labels' count (the sharded layout depends on it), the staging
    directory (unsharded: the files go there) and the work directory (sharded: the blobs)."""
    frame: object
    cli_geometry: object
    count: int
    staging: str
    work_dir: str
    run: str


class _EncodedLabels:
    """A reduce task's labels encoded by the single pass' C++ encoder (one label at a time, the
    surface dropped after): unsharded, each label's two files written into the staging
    directory; sharded, the encoded bytes gathered by Neuroglancer shard into one blob file per
    shard and task in the work directory, which the shard's task reads (_write_shard)."""

    def __init__(self, encoding):
        self.e = encoding
        self.shards = {}  # shard -> [(label, manifest, data)]

    def add(self, label, surface):
        f = self.e.frame
        vertices, faces = _stored(surface, f)
        manifest, data = _surftrack.encode_precomputed_segment(label, vertices, faces, f.linear, f.offset, f.lods,
                                                               f.quantization_bits, self.e.cli_geometry)
        if f.hashing:
            shard = _surftrack.precomputed_shards([label], f.hashing, self.e.count)[0]
            self.shards.setdefault(shard, []).append((label, manifest, data))
            return ""
        staging = Path(self.e.staging)
        names = (f"{label}:0", f"{label}.mesh") if f.lods == 0 else (f"{label}.index", f"{label}")
        (staging / names[0]).write_bytes(manifest)
        (staging / names[1]).write_bytes(data)
        return names[0]

    def close(self):
        """{shard: blob file} of what this task encoded (sharded; {} unsharded)."""
        out = {}
        for shard, items in self.shards.items():
            path = Path(self.e.work_dir) / f"ng_{self.e.run}_{shard}_{uuid.uuid4().hex}.npz"
            temporary = path.with_name(f".{path.name}.npz")
            np.savez(temporary, labels=np.array([str(L) for L, _, _ in items]),
                     manifests=np.array([len(m) for _, m, _ in items], dtype=np.int64),
                     datas=np.array([len(d) for _, _, d in items], dtype=np.int64),
                     bytes=np.frombuffer(b"".join(m + d for _, m, d in items), dtype=np.uint8))
            os.replace(temporary, path)
            out[shard] = str(path)
        return out


def _write_shard(paths, hashing, count, staging):
    """Task: one Neuroglancer shard file assembled by the single pass' shard writer from the
    blobs of the labels hashed to it (every reduce task's blob file of that shard)."""
    items = []
    for path in paths:
        with np.load(path) as f:
            labels, manifests, datas, raw = f["labels"], f["manifests"], f["datas"], f["bytes"].tobytes()
        at = 0
        for L, m, d in zip(labels, manifests, datas):
            items.append((int(L), raw[at:at + m], raw[at + m:at + m + d]))
            at += int(m) + int(d)
    files = _surftrack.build_precomputed_shard(items, hashing, count)
    for name, data in files:
        (Path(staging) / name).write_bytes(data)
    return [name for name, _ in files]


def _finish_precomputed(_done, frame, labels, names, staging, target):
    """Task: `info` and `segment_properties/info` written (after every label's and shard's file,
    which `_done` holds back the task for), then the staging directory moved into place when
    `target` is given (the command line moves it itself, cli/DaskLabels.cpp)."""
    named = any(names.get(L, "") for L in labels)
    info = _surftrack.precomputed_info(frame.linear, frame.offset, frame.lods, frame.quantization_bits,
                                       frame.hashing, len(labels), named)
    Path(staging, "info").write_bytes(info)
    if named:
        Path(staging, "segment_properties").mkdir()
        Path(staging, "segment_properties", "info").write_bytes(
            _surftrack.segment_properties([(L, str(names.get(L, ""))) for L in labels]))
    if target is not None:
        os.replace(staging, target)  # replaces an empty directory
    return True


class _Cluster:
    """The client given, or a LocalCluster of `workers` processes for the call."""

    def __init__(self, client, workers):
        self.client, self.workers, self.own = client, workers, None

    def __enter__(self):
        if self.client is None:
            from dask.distributed import Client, LocalCluster
            self.own = LocalCluster(n_workers=self.workers or min(os.cpu_count() or 1, 4), threads_per_worker=1,
                                    processes=True, dashboard_address=None)
            self.client = Client(self.own)
        return self.client

    def __exit__(self, *exc):
        if self.own is not None:
            self.client.close()
            self.own.close()


def _check_volume(source, adjacency, integers):
    shape = tuple(int(n) for n in source.shape)
    if len(shape) != 3:
        raise ValueError(f"the volume must be 3-D, not of shape {shape}")
    if integers and np.dtype(source.dtype).kind not in "biu":
        raise ValueError(f"a label image needs integer voxels: this one has {source.dtype} voxels")
    if not integers and np.dtype(source.dtype).kind not in "biuf":
        raise ValueError(f"unsupported volume dtype '{source.dtype}'")
    if adjacency not in ("26-6", "18-6", "6-18", "6-26"):
        raise ValueError(f"unsupported adjacency pair '{adjacency}'")
    return shape


def _map_blocks(client, task, source, blocks, args, progress):
    """Every block's task (task(source, lo, hi, *args)), waited for with progress("blocks", ...);
    the futures in block order."""
    from dask.distributed import as_completed
    if isinstance(source, np.ndarray):  # sent to the workers once, not with every task
        # Under a key of its own (hash=False): under the content's hash, a second run on the same
        # array reuses the key while the first run's release of it is still on its way to the
        # scheduler, which then forgets the array under the new run's blocks and cancels them.
        source = client.scatter(source, broadcast=False, hash=False)
    futures = [client.submit(task, source, lo, hi, *args,
                             key=f"surftrack-block-{lo[0]}-{lo[1]}-{lo[2]}-{uuid.uuid4().hex[:8]}", pure=False)
               for lo, hi in blocks]
    done = 0
    for _ in as_completed(futures):
        done += 1
        if progress:
            progress("blocks", done, len(blocks))
    return futures


def _run(source, *, block, spacing, origin, direction, background, adjacency, figures, client, workers,
         work_dir, out_dir, shards, progress, naming=None, precomputed=None, merge_budget=None):
    from dask.distributed import as_completed
    from . import _geometry

    shape = _check_volume(source, adjacency, integers=True)
    blocks = block_grid(shape, block)
    spacing, origin, direction = _geometry(spacing, origin, direction)
    geometry = (list(spacing), list(origin), direction.tolist())
    run = _run_name("labels", shape, str(np.dtype(source.dtype)), tuple(block), int(background), adjacency)
    with _Cluster(client, workers) as client:
        _require_memory(client, block, np.dtype(source.dtype).itemsize)
        futures = _map_blocks(client, _mesh_block, source, blocks, (shape, background, adjacency, work_dir, run),
                              progress)
        plan = client.submit(_plan, futures, shards or max(1, 2 * len(client.scheduler_info()["workers"])), pure=False)
        shard_list = plan.result()
        encoding = None
        if precomputed is not None:
            labels = sorted(L for s in shard_list for L, *_ in s)
            for L in labels:  # as the single pass' writer refuses them, before the merge
                if L <= 0:
                    raise ValueError(f"segment id {L} cannot be written: Neuroglancer's segment ids are positive "
                                     "uint64 values")
            encoding = _Encoding(precomputed["frame"], precomputed.get("cli_geometry"), len(labels),
                                 precomputed["staging"], work_dir, run)
        reduced = [client.submit(_reduce_shard, s, geometry, background, adjacency, figures, out_dir, naming,
                                 encoding, merge_budget, (shape, tuple(block)), pure=False) for s in shard_list]
        out, merged, total, blobs = {}, 0, sum(len(s) for s in shard_list), {}
        for future in as_completed(reduced):
            part = future.result()
            if encoding is not None:
                for shard, path in part["blobs"].items():
                    blobs.setdefault(shard, []).append(path)
                part = part["labels"]
            out.update(part)
            merged += len(part)
            if progress:
                progress("labels", merged, total)
        if encoding is not None:
            _write_precomputed_files(client, encoding, blobs, labels, precomputed, progress)
        return out


def _write_precomputed_files(client, encoding, blobs, labels, precomputed, progress):
    """The sharded layout's shard files (one task per Neuroglancer shard, from the reduce tasks'
    blobs), then the final task (info, segment properties, the move into place)."""
    from dask.distributed import as_completed
    frame = encoding.frame
    written = [client.submit(_write_shard, sorted(paths), frame.hashing, encoding.count, encoding.staging,
                             pure=False) for shard, paths in sorted(blobs.items())]
    for done, _ in enumerate(as_completed(written), 1):
        if progress:
            progress("shards", done, len(written))
    final = client.submit(_finish_precomputed, written, frame, labels, precomputed.get("names") or {},
                          encoding.staging, precomputed.get("target"), pure=False)
    final.result()
    for path in (p for paths in blobs.values() for p in paths):  # the shards are written: the blobs are spent
        Path(path).unlink(missing_ok=True)


def _require_memory(client, block, itemsize):
    """A block task holds its box with the apron, a copy of it, and about 8 bytes a voxel of
    fragments: refused before the run when that exceeds a worker's memory limit."""
    voxels = np.prod([b + 1 for b in block], dtype=np.float64)
    need = voxels * (2 * itemsize + 8)
    limits = [w.get("memory_limit") or 0 for w in client.scheduler_info()["workers"].values()]
    limit = min((m for m in limits if m), default=0)
    if limit and need > 0.6 * limit:
        side = int(((0.6 * limit) / (2 * itemsize + 8)) ** (1 / 3)) - 1
        raise ValueError(f"a block of {block} needs about {need / 2**20:.0f} MiB, more than 60% of a "
                         f"worker's {limit / 2**20:.0f} MiB: use block=({side}, {side}, {side}) or smaller")


def label_surfaces(labels, *, block=(256, 256, 256), spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0),
                   direction=None, background=0, adjacency="26-6", figures=True, client=None, workers=None,
                   work_dir=None, shards=None, progress=None) -> dict:
    """``surftrack.label_surfaces(labels, walls="independent", ...)`` computed by blocks on Dask
    (shared walls are not made by blocks): the same dict of
    label -> Surface, array for array. ``labels`` is a 3-D integer array read by slicing (a zarr
    array, a numpy array, a memory map). ``client``: a ``dask.distributed.Client`` (any cluster);
    None starts a LocalCluster of ``workers`` processes for the call. ``work_dir`` holds the
    fragment files (shared by the workers; a temporary directory by default; given again, the
    blocks already there are not recomputed). ``progress(stage, done, total)`` with stage
    "blocks" then "labels". The surfaces come back through the scheduler: for labels too large
    for that, ``write_label_meshes``."""
    from . import Surface
    with _work_dir(work_dir) as work:
        fields = _run(labels, block=block, spacing=spacing, origin=origin, direction=direction,
                      background=background, adjacency=adjacency, figures=figures, client=client,
                      workers=workers, work_dir=work, out_dir=None, shards=shards, progress=progress)
    return {label: Surface(**fields[label]) for label in sorted(fields)}


def write_label_meshes(labels, out_dir, *, block=(256, 256, 256), spacing=(1.0, 1.0, 1.0),
                       origin=(0.0, 0.0, 0.0), direction=None, background=0, adjacency="26-6", client=None,
                       workers=None, work_dir=None, shards=None, progress=None, format="ply", axes=None,
                       unit="nm", names=None, lods=None, sharded=False, quantization_bits=16,
                       merge_budget=None) -> dict:
    """Every label's surface written into ``out_dir`` by the reduce tasks. ``format="ply"``: one
    file ``label_<L>.ply`` a label, each byte-identical to ``surftrack.label_surfaces(labels,
    walls="independent", ...)[L].write(...)`` on the whole array. ``format="precomputed"`` or
    ``"precomputed-multires"``: Neuroglancer's directory, every file byte-identical to
    ``surftrack.write_precomputed(surftrack.label_surfaces(labels, walls="independent", ...), out_dir, axes=axes,
    unit=unit, spacing=spacing, names=names, lods=lods, sharded=sharded,
    quantization_bits=quantization_bits)`` (``lods`` 3 by default for the multi-resolution
    format; ``axes`` required). ``out_dir`` (shared by the workers) must not exist or be empty;
    it appears whole at the end or not at all. Returns label -> figures (voxels, vertices,
    triangles, euler, boundaries, area, volume, file). ``progress`` stages: "blocks", "labels",
    and "shards" for a sharded layout. ``merge_budget`` (bytes, None: no limit; PLY only): a label
    whose fragments take more is not merged whole: its figures are computed over a tree of groups
    of blocks of at most that many bytes each (docs/theory.md, "A label larger than one merge";
    counts exact, area and volume up to rounding; "levels" the tree's), and its file, still
    byte-identical, is written by streaming the fragments (docs/theory.md, "Its mesh, streamed")."""
    if merge_budget is not None and (isinstance(merge_budget, bool) or int(merge_budget) < 0):
        raise ValueError(f"merge_budget must be a number of bytes (>= 0) or None, not {merge_budget!r}")
    if merge_budget is not None and format != "ply":
        raise ValueError("merge_budget is for format='ply': Neuroglancer's formats encode every label whole")
    precomputed = _precomputed_job(format, axes=axes, unit=unit, spacing=spacing, names=names, lods=lods,
                                   sharded=sharded, quantization_bits=quantization_bits)
    target, staging = _staging_for(out_dir)
    try:
        with _work_dir(work_dir) as work:
            if precomputed is not None:
                precomputed.update(staging=str(staging), target=str(target))
            figures = _run(labels, block=block, spacing=spacing, origin=origin, direction=direction,
                           background=background, adjacency=adjacency, figures=True, client=client,
                           workers=workers, work_dir=work, out_dir=None if precomputed else str(staging),
                           shards=shards, progress=progress, precomputed=precomputed, merge_budget=merge_budget)
        if precomputed is None:
            os.replace(staging, target)  # replaces an empty directory
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return dict(sorted(figures.items()))


_FORMATS = ("ply", "precomputed", "precomputed-multires")


def _precomputed_job(format, *, axes, unit, spacing, names, lods, sharded, quantization_bits):
    """write_label_meshes' format arguments checked before any work: None for PLY files, else
    what _run's `precomputed` takes (the frame, the names)."""
    if format not in _FORMATS:
        raise ValueError(f"unknown format {format!r}: expected " + ", ".join(repr(f) for f in _FORMATS))
    multires = format == "precomputed-multires"
    if format == "ply":
        if (axes, names, lods, sharded, quantization_bits, unit) != (None, None, None, False, 16, "nm"):
            raise ValueError("axes, unit, names, lods, sharded and quantization_bits are for format='precomputed' "
                             "or 'precomputed-multires'")
        return None
    if not multires and (lods is not None or sharded or quantization_bits != 16):
        raise ValueError("lods, sharded and quantization_bits are for format='precomputed-multires'")
    if axes is None:
        raise ValueError("Neuroglancer output needs axes='zyx' (an array indexed [z, y, x]) or 'xyz'")
    frame = _frame(axes=axes, unit=unit, spacing=spacing, lods=(3 if lods is None else lods) if multires else None,
                   sharded=sharded, quantization_bits=quantization_bits)
    return {"frame": frame, "names": {int(L): str(n) for L, n in (names or {}).items()}}


def _threshold_block(source, lo, hi, shape, level, adjacency, mapping, epsilon, work_dir, run):
    """Task: the fragment of one block of a threshold's every boundary (docs/theory.md,
    "Thresholds by blocks"), written to its file atomically as _mesh_block writes its own."""
    path = _fragment_path(work_dir, lo, run, ".npz")
    if not path.exists():
        top = [min(h + 1, n) for h, n in zip(hi, shape)]  # the one-voxel apron on the high sides
        box = np.asarray(source[lo[0]:top[0], lo[1]:top[1], lo[2]:top[2]])
        box = np.ascontiguousarray(box.view(np.uint8) if box.dtype.kind == "b" else box,
                                   dtype=None if box.dtype.kind == "b" else box.dtype.newbyteorder("="))
        voxels, keys, values, triangles = _surftrack.scan_threshold_block(
            box, list(lo), list(shape), list(lo), list(hi), float(level), adjacency, mapping, float(epsilon))
        temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}.npz")
        np.savez(temporary, voxels=np.uint64(voxels), keys=keys, values=values, triangles=triangles)
        os.replace(temporary, path)
    return str(path)


def _reduce_threshold(paths, shape, level, geometry, adjacency, mapping, epsilon, figures, out_path, binary,
                      out_dir=None):
    """Task: every block's fragment merged into the one surface of every boundary (all in this
    worker's memory); written to `out_path` (figures returned), or one file per boundary into
    `out_dir` (boundary_<k>.ply, Surface.write_components; figures with a row per boundary
    returned), or returned as fields."""
    from . import Surface
    fragments = []
    for path in paths:
        with np.load(path) as f:
            fragments.append((int(f["voxels"]), f["keys"], f["values"], f["triangles"]))
    spacing, origin, direction = geometry
    fields = _surftrack.merge_threshold_fragments(fragments, list(shape), float(level), spacing, origin, direction,
                                                  adjacency, mapping, float(epsilon), figures)
    if out_path is None and out_dir is None:  # plain arrays through the scheduler (the C++ result does not pickle)
        result = fields.pop("result")
        fields["surfels"], fields["normals"] = result.surfels(), result.normals()
        return fields
    surface = Surface(**fields)
    out = {"vertices": len(surface.vertices), "triangles": len(surface.faces), "euler": int(fields["euler"]),
           "boundaries": len(surface.components)}
    if out_dir is not None:
        names = [f"boundary_{k}.ply" for k in range(1, len(surface.components) + 1)]
        surface.write_components([str(Path(out_dir) / n) for n in names], binary=binary)
        out["components"] = [{**c, "file": n} for c, n in zip(surface.components, names)]
        return out
    surface.write(out_path, binary=binary)
    return out


def _run_threshold(source, level, *, block, mapping, adjacency, spacing, origin, direction, epsilon, figures,
                   client, workers, work_dir, out_path, binary, progress, out_dir=None):
    from . import _MAPPINGS, _geometry

    shape = _check_volume(source, adjacency, integers=False)
    level = float(level)
    if not np.isfinite(level):
        raise ValueError(f"level must be a finite number, not {level!r}")
    mapping = {"default": "linear"}.get(mapping, mapping)
    if mapping not in _MAPPINGS or mapping == "default":
        raise ValueError(f"unknown mapping '{mapping}': expected linear or midpoint")
    blocks = block_grid(shape, block)
    spacing, origin, direction = _geometry(spacing, origin, direction)
    geometry = (list(spacing), list(origin), direction.tolist())
    run = _run_name("threshold", shape, str(np.dtype(source.dtype)), tuple(block), level.hex(), adjacency, mapping,
                    float(epsilon))
    with _Cluster(client, workers) as client:
        _require_memory(client, block, np.dtype(source.dtype).itemsize)
        futures = _map_blocks(client, _threshold_block, source, blocks,
                              (shape, level, adjacency, mapping, epsilon, work_dir, run), progress)
        merged = client.submit(_reduce_threshold, futures, shape, level, geometry, adjacency, mapping, epsilon,
                               figures, out_path, binary, out_dir, pure=False)
        out = merged.result()
        if progress:
            progress("merge", 1, 1)
        return out


def threshold_surface(volume, level, *, block=(256, 256, 256), mapping="linear", adjacency="26-6",
                      spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None, epsilon=1e-3,
                      figures=True, client=None, workers=None, work_dir=None, progress=None):
    """``surftrack.extract(volume, level=level, mode="all", ...)`` computed by blocks on Dask:
    every boundary of ``volume > level`` as one Surface, array for array. ``volume`` is a 3-D
    array read by slicing (a zarr array, a numpy array, a memory map). One task per block
    (fragment files in ``work_dir``, resumable), one merge task, which holds the whole surface:
    for surfaces larger than one worker's memory, not yet. ``progress(stage, done, total)``
    with stage "blocks", then "merge". Other arguments as ``label_surfaces``."""
    from . import Surface
    with _work_dir(work_dir) as work:
        fields = _run_threshold(volume, level, block=block, mapping=mapping, adjacency=adjacency, spacing=spacing,
                                origin=origin, direction=direction, epsilon=epsilon, figures=figures,
                                client=client, workers=workers, work_dir=work, out_path=None, binary=True,
                                progress=progress)
    return Surface(**fields)


def write_threshold_mesh(volume, path, level, *, block=(256, 256, 256), mapping="linear", adjacency="26-6",
                         spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None, epsilon=1e-3,
                         binary=True, client=None, workers=None, work_dir=None, progress=None) -> dict:
    """Every boundary of ``volume > level`` written to ``path`` (.ply, .obj, .off, .stl) by the
    merge task, byte-identical to ``surftrack.extract(volume, level=level, mode="all",
    ...).write(path)`` (atomic, as Surface.write). ``path`` must be on storage the workers see.
    Returns figures (vertices, triangles, euler, boundaries)."""
    with _work_dir(work_dir) as work:
        return _run_threshold(volume, level, block=block, mapping=mapping, adjacency=adjacency, spacing=spacing,
                              origin=origin, direction=direction, epsilon=epsilon, figures=True, client=client,
                              workers=workers, work_dir=work, out_path=os.path.abspath(os.fspath(path)),
                              binary=binary, progress=progress)


def write_threshold_meshes(volume, out_dir, level, *, block=(256, 256, 256), mapping="linear", adjacency="26-6",
                           spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None, epsilon=1e-3,
                           binary=True, client=None, workers=None, work_dir=None, progress=None) -> dict:
    """Every boundary of ``volume > level``, each in its own file ``out_dir/boundary_<k>.ply``
    (k from 1, in the order of the surface's ``components``: by decreasing vertex count), each
    byte-identical to ``surftrack.extract(volume, level=level, mode="all",
    ...).write_components(...)``, written by the merge task. ``out_dir`` (shared by the workers)
    must not exist or be empty; it appears whole at the end or not at all. Returns the figures of
    write_threshold_mesh and ``"components"``: a row per boundary (its figures and file)."""
    target, staging = _staging_for(out_dir)
    try:
        with _work_dir(work_dir) as work:
            out = _run_threshold(volume, level, block=block, mapping=mapping, adjacency=adjacency, spacing=spacing,
                                 origin=origin, direction=direction, epsilon=epsilon, figures=True, client=client,
                                 workers=workers, work_dir=work, out_path=None, binary=binary, progress=progress,
                                 out_dir=str(staging.resolve()))
        os.replace(staging, target)  # replaces an empty directory
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return out


def _staging_for(out_dir):
    """(out_dir, its staging directory, made): `out_dir` must not exist or be empty; the outputs
    are written into the staging directory, which is renamed to `out_dir` at the end, so that
    it appears whole or not at all."""
    target = Path(out_dir)
    if target.exists() and (not target.is_dir() or any(target.iterdir())):
        raise ValueError(f"cannot write into '{out_dir}': it exists and is not an empty directory")
    staging = target.parent / f".{target.name}.tmp-{uuid.uuid4().hex}"
    staging.mkdir(parents=True)
    return target, staging


class _work_dir:
    """`path` (created if need be, kept), or a temporary directory removed at the end."""

    def __init__(self, path):
        self.path, self.temporary = path, None

    def __enter__(self):
        if self.path is None:
            self.temporary = tempfile.TemporaryDirectory(prefix="surftrack-blocks-")
            return self.temporary.name
        Path(self.path).mkdir(parents=True, exist_ok=True)
        return str(self.path)

    def __exit__(self, *exc):
        if self.temporary is not None:
            self.temporary.cleanup()
