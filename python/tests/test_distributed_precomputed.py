"""surftrack.distributed.write_label_meshes in Neuroglancer's formats, and the CLI's `labels
--dask ... --format precomputed*`: the directory written by blocks on a Dask LocalCluster is the
single pass' directory (surftrack.write_precomputed on surftrack.label_surfaces, or the CLI
without --dask) file for file and byte for byte, for the legacy format, the multi-resolution
format unsharded and sharded (one shard and many), on random label images of every unsigned
width (ids near 2^64 included) cut into blocks the shape does not divide; bad input refused
before the run, and nothing left at the output path by an error."""
import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pytest

import surftrack

if "asan" in os.environ.get("LD_PRELOAD", ""):
    pytest.skip("Dask's worker processes are not run under the sanitizers", allow_module_level=True)
distributed = pytest.importorskip("dask.distributed")

from surftrack import distributed as blocks  # noqa: E402
from test_distributed import run_cli  # noqa: E402  (the CLI built beside the package)


@pytest.fixture(scope="module")
def client():
    # Threads, not processes, for speed: the tasks and what they exchange are the same (one
    # test below runs on processes).
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def tree(path):
    """{relative path: sha256} of every file under `path` (directories by their files)."""
    path = Path(path)
    return {str(p.relative_to(path)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(path.rglob("*")) if p.is_file()}


def random_labels(rng, shape, dtype):
    """Boxes of random ids of `dtype` (its largest values included) on background 0."""
    top = np.iinfo(dtype).max
    ids = sorted({int(top), int(top) - 1, *(int(v) for v in rng.integers(1, min(top, 2**62), size=4))})
    labels = np.zeros(shape, dtype)
    for _ in range(int(rng.integers(3, 9))):
        lo = rng.integers(-2, shape, size=3).clip(0)
        hi = lo + rng.integers(1, 7, size=3)
        labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = ids[int(rng.integers(len(ids)))]
    labels[tuple(rng.integers(0, shape, size=3))] = top  # a single voxel somewhere
    return labels


FORMATS = [  # (format, write_label_meshes' options)
    ("precomputed", {}),
    ("precomputed-multires", {"lods": 2}),
    ("precomputed-multires", {"lods": 3, "sharded": True}),
    ("precomputed-multires", {"lods": 1, "sharded": "identity", "quantization_bits": 10}),
]


@pytest.mark.parametrize("case", range(len(FORMATS)))
def test_blocks_write_the_single_pass_directory(client, tmp_path, case):
    fmt, options = FORMATS[case]
    rng = np.random.default_rng(100 + case)
    for run, dtype in enumerate([np.uint8, np.uint16, np.uint32, np.uint64] * 2):
        shape = tuple(int(n) for n in rng.integers(8, 13, size=3))
        labels = random_labels(rng, shape, dtype)
        block = [(4, 5, 3), (1, 7, 20), (6, 6, 6), (20, 20, 20), (3, 3, 3), (5, 12, 2), (7, 1, 9), (9, 4, 11)][run]
        spacing = tuple(float(v) for v in rng.choice([0.5, 1.0, 4.0], size=3))
        axes, unit = ["zyx", "xyz"][run % 2], ["nm", "um", "mm"][run % 3]
        present = [int(L) for L in np.unique(labels) if L]
        names = {L: f"cell {i}" for i, L in enumerate(present) if i % 2} if run % 2 else None
        surfaces = surftrack.label_surfaces(labels, spacing=spacing, origin=(1, -2, 3), walls="independent")
        want = tmp_path / f"single{run}"
        lods = options.get("lods") if fmt == "precomputed-multires" else None
        surftrack.write_precomputed(surfaces, want, axes=axes, unit=unit, spacing=spacing, names=names, lods=lods,
                                    sharded=options.get("sharded", False),
                                    quantization_bits=options.get("quantization_bits", 16))
        got = tmp_path / f"dask{run}"
        stages = set()
        figures = blocks.write_label_meshes(labels, got, block=block, spacing=spacing, origin=(1, -2, 3),
                                            client=client, format=fmt, axes=axes, unit=unit, names=names,
                                            work_dir=tmp_path / f"work{run}",
                                            progress=lambda stage, done, total: stages.add(stage), **options)
        assert tree(got) == tree(want) and len(tree(want)) > 1, (fmt, options, dtype)
        assert sorted(figures) == sorted(surfaces)
        for L, s in surfaces.items():
            assert figures[L]["vertices"] == len(s.vertices) and figures[L]["triangles"] == len(s.faces)
        assert stages == ({"blocks", "labels", "shards"} if options.get("sharded") else {"blocks", "labels"})
        assert not list((tmp_path / f"work{run}").glob("ng_*"))  # the shards' blobs removed once written
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []  # no staging left


def test_many_shards(client, tmp_path):
    """More segments than one shard holds (shardingFor: 2^14 keys a shard before shards
    multiply): one task per shard, each file the single pass' own."""
    shape = (34, 34, 34)
    count = 2**14 + 300
    labels = np.zeros(shape, np.uint32)
    cells = np.argwhere(np.indices(shape).sum(0) % 2 == 0)[:count]  # single voxels, none touching by a face
    labels[tuple(cells.T)] = np.arange(1, len(cells) + 1, dtype=np.uint32) * 7
    assert len(cells) == count
    surfaces = surftrack.label_surfaces(labels, walls="independent")
    want, got = tmp_path / "single", tmp_path / "dask"
    surftrack.write_precomputed(surfaces, want, axes="zyx", spacing=(1, 1, 1), lods=1, sharded=True)
    blocks.write_label_meshes(labels, got, block=(17, 34, 12), client=client, format="precomputed-multires",
                              axes="zyx", lods=1, sharded=True)
    files = tree(want)
    assert tree(got) == files and sum(f.endswith(".shard") for f in files) > 1


def test_on_worker_processes(tmp_path):
    rng = np.random.default_rng(7)
    labels = random_labels(rng, (11, 9, 10), np.uint64)
    surfaces = surftrack.label_surfaces(labels, walls="independent")
    surftrack.write_precomputed(surfaces, tmp_path / "single", axes="zyx", spacing=(1, 1, 1), lods=2, sharded=True)
    blocks.write_label_meshes(labels, tmp_path / "dask", block=(5, 4, 7), workers=2, format="precomputed-multires",
                              axes="zyx", lods=2, sharded=True)
    assert tree(tmp_path / "dask") == tree(tmp_path / "single")


def test_bad_input_writes_nothing(client, tmp_path):
    labels = np.zeros((6, 6, 6), np.int8)
    labels[1:3, 1:3, 1:3] = 5
    cases = [({"format": "obj"}, "unknown format"),
             ({"format": "precomputed", "axes": "zyx", "lods": 2}, "precomputed-multires"),
             ({"format": "precomputed", "axes": "zyx", "sharded": True}, "precomputed-multires"),
             ({"axes": "zyx"}, "for format="),
             ({"format": "precomputed"}, "axes"),
             ({"format": "precomputed-multires", "axes": "zyx", "lods": 11}, "lods"),
             ({"format": "precomputed-multires", "axes": "zyx", "quantization_bits": 12}, "quantization_bits"),
             ({"format": "precomputed", "axes": "zyx", "unit": "furlong"}, "unit"),
             ({"format": "precomputed-multires", "axes": "zyx", "merge_budget": 1}, "merge_budget is for")]
    for options, says in cases:
        with pytest.raises(ValueError, match=says):
            blocks.write_label_meshes(labels, tmp_path / "out", client=client, **options)
    labels[4, 4, 4] = -3  # found by the blocks: the run stops, nothing is left
    with pytest.raises(ValueError, match="segment id -3"):
        blocks.write_label_meshes(labels, tmp_path / "out", block=(3, 3, 3), client=client, format="precomputed",
                                  axes="zyx", work_dir=tmp_path / "work")
    # A reduce task fails after others wrote their labels' files (vertices beyond float32
    # nanometres far from the origin only): the staging directory goes, nothing is left.
    far = np.zeros((12, 6, 6), np.uint16)
    far[0:2, 0:2, 0:2], far[9:11, 3:5, 3:5] = 1, 2
    with pytest.raises(ValueError, match="beyond a float32"):
        surftrack.write_precomputed(surftrack.label_surfaces(far, spacing=(1e29, 1, 1), walls="independent"), tmp_path / "single",
                                    axes="zyx", unit="m", spacing=(1e29, 1, 1))
    with pytest.raises(ValueError, match="beyond a float32"):
        blocks.write_label_meshes(far, tmp_path / "out", block=(6, 6, 6), spacing=(1e29, 1, 1), client=client,
                                  shards=2, format="precomputed", axes="zyx", unit="m", work_dir=tmp_path / "work")
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("x")
    with pytest.raises(ValueError, match="not an empty directory"):
        blocks.write_label_meshes(labels, tmp_path / "full", client=client, format="precomputed", axes="zyx")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full", "work"]


def test_cli_labels_on_dask_writes_the_single_pass_directory(tmp_path):
    """`surftrack labels STORE -o DIR/ --dask local:2 --format ...` against the CLI's single
    pass on the same OME-Zarr store (micrometres or --unit nm, anisotropic, label names, a frame
    and an origin given): every file, and the table."""
    zarr = pytest.importorskip("zarr")
    rng = np.random.default_rng(41)
    shape = (21, 17, 23)
    seeds = rng.integers(0, shape, size=(9, 3))
    grid = np.stack(np.indices(shape), axis=-1).reshape(-1, 1, 3)
    cells = np.argmin(((grid - seeds[None]) ** 2).sum(-1), axis=1).reshape(shape).astype(np.uint64)
    cells = np.where(cells == 3, 0, cells + np.uint64(2**64 - 20))
    store = tmp_path / "seg.ome.zarr"
    root = zarr.open_group(str(store), mode="w")
    root.create_dataset("s0", data=cells, chunks=(8, 9, 7))
    root.attrs["multiscales"] = [{"version": "0.4", "axes": [{"name": a, "type": "space", "unit": "micrometer"}
                                                              for a in "zyx"],
                                  "datasets": [{"path": "s0", "coordinateTransformations": [
                                      {"type": "scale", "scale": [2.0, 1.5, 1.0]}]}]}]
    names = tmp_path / "names.txt"
    names.write_text(f"{2**64 - 19} first\n{2**64 - 15} second one\n")
    for i, fmt in enumerate([["precomputed", "--unit", "nm"],
                             ["precomputed-multires", "--lods", "2", "--sharded", "--frame", "ras", "--origin", "5,-3,2"],
                             ["precomputed-multires", "--lods", "1", "--sharded", "--shard-hash", "identity"]]):
        single, dask = tmp_path / f"single-{i}", tmp_path / f"dask-{i}"
        common = ["--label-names", names, "--format", *fmt]
        a = run_cli("labels", store, "--walls", "independent", "-o", f"{single}/", *common, "--table", tmp_path / "a.csv")
        assert a.returncode == 0, a.stderr
        b = run_cli("labels", store, "-o", f"{dask}/", *common, "--table", tmp_path / "b.csv", "--dask", "local:2",
                    "--block", "10,6,8")
        assert b.returncode == 0, b.stderr
        assert tree(dask) == tree(single) and "info" in tree(single)
        if "--shard-hash" in fmt:
            assert json.loads((dask / "info").read_text())["sharding"]["hash"] == "identity"
        assert (tmp_path / "a.csv").read_text().replace(str(single), "D") == \
            (tmp_path / "b.csv").read_text().replace(str(dask), "D")
    r = run_cli("labels", store, "-o", f"{tmp_path}/bad/", "--format", "precomputed", "--lods", "2", "--dask", "local:2")
    assert r.returncode != 0 and "precomputed-multires" in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert not (tmp_path / "bad").exists() and not list(tmp_path.glob(".bad*"))
