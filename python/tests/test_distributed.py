"""surftrack.distributed: every label by blocks on a Dask LocalCluster of two worker processes,
against surftrack.label_surfaces on the whole array (the single pass): the same arrays for every
label and pair on random label images cut into blocks the shape does not divide (1-voxel-thick
blocks and a single block included), byte-identical PLY files from a zarr store, uint64 ids
around 2^53 and 2^64 - 1 exact, a resumed run that recomputes no finished block, a worker killed
mid-run that changes nothing, bad input refused before the run, and labels over a merge budget
given the single pass's figures by the tree of groups of blocks."""
import os
import zlib
from pathlib import Path

import numpy as np
import pytest

import surftrack

if "asan" in os.environ.get("LD_PRELOAD", ""):
    # The sanitized suite preloads the sanitizer runtimes into Python; Dask's worker processes
    # would inherit them. The engine calls they make are those of the tests run there directly.
    pytest.skip("Dask's worker processes are not run under the sanitizers", allow_module_level=True)
distributed = pytest.importorskip("dask.distributed")
zarr = pytest.importorskip("zarr")

from surftrack import distributed as blocks  # noqa: E402

IDS = [2**64 - 1, 2**53 + 1, 2**53, 2**53 - 1, 3]


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       memory_limit="1GiB", dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def random_labels(rng, shape):
    labels = np.zeros(shape, np.uint64)
    for _ in range(int(rng.integers(3, 12))):
        lo = rng.integers(-2, shape, size=3).clip(0)
        hi = lo + rng.integers(1, 7, size=3)
        labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = IDS[int(rng.integers(len(IDS)))]
    labels[tuple(rng.integers(0, shape, size=3))] = IDS[0]  # a single voxel somewhere
    labels[0, 0, 0] = IDS[1]  # and one in a corner
    return labels


def expect_same(got, want):
    assert sorted(got) == sorted(want)
    for label, w in want.items():
        g = got[label]
        assert np.array_equal(g.vertices, w.vertices) and np.array_equal(g.faces, w.faces), label
        assert np.array_equal(g.surfels, w.surfels)
        assert g.voxels == w.voxels and g.euler == w.euler and g.components == w.components


@pytest.mark.parametrize("adjacency", ["26-6", "18-6", "6-18", "6-26"])
def test_blocks_merge_to_the_single_pass(client, adjacency):
    rng = np.random.default_rng({"26-6": 1, "18-6": 2, "6-18": 3, "6-26": 4}[adjacency])
    for block in [(4, 3, 5), (1, 6, 2), (20, 20, 20), (5, 1, 7)]:
        labels = random_labels(rng, tuple(rng.integers(7, 12, size=3)))
        spacing = tuple(float(v) for v in rng.choice([0.5, 1.0, 4.0], size=3))
        want = surftrack.label_surfaces(labels, spacing=spacing, origin=(1, -2, 3), adjacency=adjacency, walls="independent")
        got = blocks.label_surfaces(labels, block=block, spacing=spacing, origin=(1, -2, 3),
                                    adjacency=adjacency, client=client)
        expect_same(got, want)


def test_zarr_store_gives_byte_identical_files_and_resumes(client, tmp_path):
    rng = np.random.default_rng(9)
    shape = (61, 47, 53)
    # Voronoi cells of 40 seeds: walls everywhere, labels touching the array's faces.
    seeds = rng.integers(0, shape, size=(40, 3))
    grid = np.stack(np.indices(shape), axis=-1).reshape(-1, 1, 3)
    cells = np.argmin(((grid - seeds[None]) ** 2).sum(-1), axis=1).reshape(shape)
    labels = (np.uint64(2**64 - 41) + cells.astype(np.uint64))
    labels[labels == np.uint64(2**64 - 41)] = 0  # one cell is background
    store = zarr.open(str(tmp_path / "seg.zarr"), mode="w", shape=shape, chunks=(17, 13, 11), dtype=np.uint64)
    store[:] = labels
    source = zarr.open(str(tmp_path / "seg.zarr"), mode="r")

    seen = []
    out = tmp_path / "meshes"
    work = tmp_path / "fragments"
    figures = blocks.write_label_meshes(source, out, block=(34, 26, 22), spacing=(2.0, 1.5, 1.0),
                                        client=client, work_dir=work,
                                        progress=lambda stage, done, total: seen.append((stage, done, total)))
    want = surftrack.label_surfaces(labels, spacing=(2.0, 1.5, 1.0), walls="independent")
    assert sorted(figures) == sorted(want) and len(want) == 39
    reference = tmp_path / "reference"
    reference.mkdir()
    for label, surface in want.items():
        surface.write(str(reference / f"label_{label}.ply"))
        assert (out / f"label_{label}.ply").read_bytes() == (reference / f"label_{label}.ply").read_bytes()
        assert figures[label]["voxels"] == surface.voxels and figures[label]["euler"] == surface.euler
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in reference.iterdir())
    assert ("blocks", 12, 12) in seen and seen[-1][0] == "labels" and seen[-1][1] == seen[-1][2] == 39

    # Resumed: every block's fragment file is there, so none is computed again.
    stamps = {p.name: p.stat().st_mtime_ns for p in work.iterdir()}
    assert len(stamps) == 12
    again = tmp_path / "again"
    blocks.write_label_meshes(source, again, block=(34, 26, 22), spacing=(2.0, 1.5, 1.0), client=client,
                              work_dir=work)
    assert {p.name: p.stat().st_mtime_ns for p in work.iterdir()} == stamps
    for f in out.iterdir():
        assert (again / f.name).read_bytes() == f.read_bytes()


def test_a_worker_killed_mid_run_changes_nothing(tmp_path):
    # A cluster of its own: the shared one would carry the lost worker's aftermath (tasks the
    # scheduler still reschedules or cancels) into the tests after this one.
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       memory_limit="1GiB", dashboard_address=None)
    with distributed.Client(cluster) as client:
        _killed_mid_run(client, tmp_path)
    cluster.close()


def _killed_mid_run(client, tmp_path):
    labels = random_labels(np.random.default_rng(17), (12, 11, 10))
    marker = tmp_path / "killed-once"

    class KillsItsWorkerOnce:
        """Reads as the array does, but the first read of the block at the origin ends the
        worker process (defined here, so that it is pickled by value)."""

        def __init__(self, array, marker):
            self.array, self.marker = array, str(marker)
            self.shape, self.dtype = array.shape, array.dtype

        def __getitem__(self, index):
            if index[0].start == 0 and index[1].start == 0 and index[2].start == 0 and not os.path.exists(self.marker):
                Path(self.marker).write_text("x")
                os._exit(1)
            return self.array[index]

    got = blocks.label_surfaces(KillsItsWorkerOnce(labels, marker), block=(5, 4, 6), client=client)
    assert marker.exists()
    expect_same(got, surftrack.label_surfaces(labels, walls="independent"))
    client.wait_for_workers(2)


def test_bad_input_is_refused_before_the_run(client, tmp_path):
    labels = np.zeros((8, 8, 8), np.uint16)
    labels[2:5, 2:5, 2:5] = 1
    with pytest.raises(ValueError, match=r"use block=\("):
        blocks.label_surfaces(labels, block=(1200, 1200, 1200), client=client)
    with pytest.raises(ValueError, match="integer voxels"):
        blocks.label_surfaces(labels.astype(np.float32), client=client)
    with pytest.raises(ValueError, match="block"):
        blocks.label_surfaces(labels, block=(0, 4, 4), client=client)
    full = tmp_path / "full"
    full.mkdir()
    (full / "x").write_text("x")
    with pytest.raises(ValueError, match="not an empty directory"):
        blocks.write_label_meshes(labels, full, client=client)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full"]


def test_a_work_dir_reused_with_other_arguments_recomputes(client, tmp_path):
    # The fragments depend on the background (and the pair, the block, the array): a second run
    # in the same work_dir with another background must not merge the first run's fragments.
    labels = random_labels(np.random.default_rng(23), (10, 9, 11))
    work = tmp_path / "fragments"
    blocks.label_surfaces(labels, block=(5, 5, 5), client=client, work_dir=work)
    other = blocks.label_surfaces(labels, block=(5, 5, 5), client=client, work_dir=work, background=int(IDS[1]))
    expect_same(other, surftrack.label_surfaces(labels, background=int(IDS[1]), walls="independent"))
    assert len(list(work.iterdir())) == 2 * len(blocks.block_grid(labels.shape, (5, 5, 5)))


def test_the_same_array_run_back_to_back_on_one_client(client):
    # Each run scatters the array once. Under a key derived from the content, the next run reused
    # that key while the previous run's release of it was still in flight: the scheduler then
    # forgot the array beneath the new run's blocks, cancelling them (about 3 runs in 100) or
    # leaving the run waiting forever. Sixty runs back to back, each the single pass's surfaces.
    labels = random_labels(np.random.default_rng(23), (10, 9, 11))
    want = surftrack.label_surfaces(labels, walls="independent")
    for _ in range(60):
        expect_same(blocks.label_surfaces(labels, block=(5, 5, 5), client=client), want)


def test_labels_over_the_merge_budget_get_exact_figures_and_streamed_files(client, tmp_path):
    """write_label_meshes with a merge_budget some labels exceed: those get the single pass's
    figures (counts exactly, area and volume within 1e-9 relative: summed by groups of blocks,
    docs/theory.md "A label larger than one merge") and their file streamed; every file is the
    single pass's, byte for byte."""
    rng = np.random.default_rng(41)
    shape = (23, 19, 21)
    seeds = rng.integers(0, shape, size=(6, 3))
    grid = np.stack(np.indices(shape), axis=-1).reshape(-1, 1, 3)
    labels = np.argmin(((grid - seeds[None]) ** 2).sum(-1), axis=1).reshape(shape).astype(np.int32) - 2
    labels[rng.random(shape) < 0.05] = 7  # specks: many components
    want = surftrack.label_surfaces(labels, spacing=(2.0, 1.0, 0.5), walls="independent")
    # A first run writes the fragment files, whose sizes set a budget half the labels exceed.
    work = tmp_path / "work"
    blocks.write_label_meshes(labels, tmp_path / "first", block=(4, 5, 3), client=client, work_dir=work)
    weight = {}
    for path in work.iterdir():
        for label, keys, triangles in surftrack._surftrack.fragment_file_summary(str(path)):
            weight[label] = weight.get(label, 0) + 8 * keys + 12 * triangles
    sizes = sorted(weight.values())
    budget = (sizes[len(sizes) // 2 - 1] + sizes[len(sizes) // 2]) // 2
    figures = blocks.write_label_meshes(labels, tmp_path / "out", block=(4, 5, 3), spacing=(2.0, 1.0, 0.5),
                                        client=client, work_dir=work, merge_budget=budget)
    assert sorted(figures) == sorted(want)
    by_tree = [L for L, f in figures.items() if "levels" in f]
    assert sorted(by_tree) == sorted(L for L in weight if weight[L] > budget) and 0 < len(by_tree) < len(want)
    assert all(figures[L]["levels"] >= 1 for L in by_tree)
    for label, w in want.items():
        f = figures[label]
        assert (f["voxels"], f["vertices"], f["triangles"], f["euler"], f["boundaries"]) == \
            (w.voxels, len(w.vertices), len(w.faces), w.euler, len(w.components))
        assert f["area"] == pytest.approx(sum(c["area"] for c in w.components), rel=1e-9)
        assert f["volume"] == pytest.approx(sum(c["volume"] for c in w.components), rel=1e-9)
        # Merged whole, or streamed (over the budget): the same bytes.
        w.write(str(tmp_path / "want.ply"))
        assert f["file"] == f"label_{label}.ply"
        assert (tmp_path / "out" / f["file"]).read_bytes() == (tmp_path / "want.ply").read_bytes()
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(f"label_{L}.ply" for L in want)
    with pytest.raises(ValueError, match="merge_budget"):
        blocks.write_label_meshes(labels, tmp_path / "bad", client=client, merge_budget=-1)


THRESHOLD_CASES = [(np.float32, "linear"), (np.uint8, "midpoint"), (">f8", "linear"), (np.int16, "linear"),
                   (bool, "midpoint")]


@pytest.mark.parametrize("dtype,mapping", THRESHOLD_CASES)
def test_threshold_blocks_merge_to_the_single_pass(client, dtype, mapping):
    rng = np.random.default_rng(zlib.crc32(repr((dtype, mapping)).encode()))
    for trial, block in enumerate([(4, 3, 5), (1, 6, 2), (30, 30, 30), (5, 1, 7)]):
        shape = tuple(int(n) for n in rng.integers(6, 12, size=3))
        volume = (rng.random(shape) * 200).astype(dtype) if dtype is not bool else rng.random(shape) > 0.6
        level = 0.5 if dtype is bool else 120.5
        adjacency = ["26-6", "18-6", "6-18", "6-26"][trial]
        spacing = tuple(float(s) for s in rng.uniform(0.5, 2.0, size=3))
        want = surftrack.extract(volume, level=level, mode="all", mapping=mapping, adjacency=adjacency,
                                 spacing=spacing, origin=(1, -2, 3), threads=1)
        got = blocks.threshold_surface(volume, level, block=block, mapping=mapping, adjacency=adjacency,
                                       spacing=spacing, origin=(1, -2, 3), client=client)
        assert got.vertices.tobytes() == want.vertices.tobytes()
        assert np.array_equal(got.faces, want.faces) and np.array_equal(got.surfels, want.surfels)
        assert got.euler == want.euler and got.components == want.components


def test_threshold_mesh_from_a_zarr_store_is_byte_identical_and_resumes(client, tmp_path):
    rng = np.random.default_rng(29)
    shape = (41, 37, 33)
    z, y, x = np.indices(shape)
    volume = (np.sin(x / 4.0) + np.cos(y / 5.0) * np.sin(z / 3.0) + rng.normal(0, 0.05, shape)).astype(np.float32)
    zarr.open(str(tmp_path / "v.zarr"), mode="w", shape=shape, chunks=(9, 10, 11), dtype="<f4")[:] = volume
    source = zarr.open(str(tmp_path / "v.zarr"), mode="r")
    seen = []
    work = tmp_path / "fragments"
    figures = blocks.write_threshold_mesh(source, tmp_path / "a.ply", 0.25, block=(16, 20, 12), spacing=(3, 2, 1),
                                          client=client, work_dir=work,
                                          progress=lambda stage, done, total: seen.append((stage, done, total)))
    want = surftrack.extract(volume, level=0.25, mode="all", spacing=(3, 2, 1), threads=1)
    want.write(str(tmp_path / "b.ply"))
    assert (tmp_path / "a.ply").read_bytes() == (tmp_path / "b.ply").read_bytes()
    assert figures["vertices"] == len(want.vertices) and figures["euler"] == want.euler
    assert figures["boundaries"] == len(want.components) == 3  # (two of genus 4 and a speck)
    assert ("blocks", 18, 18) in seen and seen[-1] == ("merge", 1, 1)
    stamps = {p.name: p.stat().st_mtime_ns for p in work.iterdir()}
    blocks.write_threshold_mesh(source, tmp_path / "c.ply", 0.25, block=(16, 20, 12), spacing=(3, 2, 1),
                                client=client, work_dir=work)
    assert {p.name: p.stat().st_mtime_ns for p in work.iterdir()} == stamps
    assert (tmp_path / "c.ply").read_bytes() == (tmp_path / "b.ply").read_bytes()
    # Another level in the same work_dir: recomputed, not the first level's fragments.
    blocks.write_threshold_mesh(source, tmp_path / "d.ply", 0.5, block=(16, 20, 12), spacing=(3, 2, 1),
                                client=client, work_dir=work)
    surftrack.extract(volume, level=0.5, mode="all", spacing=(3, 2, 1), threads=1).write(str(tmp_path / "e.ply"))
    assert (tmp_path / "d.ply").read_bytes() == (tmp_path / "e.ply").read_bytes()


def test_threshold_bad_input(client):
    volume = np.zeros((6, 6, 6), np.float32)
    with pytest.raises(ValueError, match="mapping"):
        blocks.threshold_surface(volume, 0.5, mapping="cubic", client=client)
    with pytest.raises(ValueError, match="finite"):
        blocks.threshold_surface(volume, float("nan"), client=client)
    with pytest.raises(ValueError, match="3-D"):
        blocks.threshold_surface(volume[0], 0.5, client=client)
    with pytest.raises(ValueError, match="adjacency"):
        blocks.threshold_surface(volume, 0.5, adjacency="8-4", client=client)


def cli():
    path = os.environ.get("SURFTRACK_CLI") or str(Path(__file__).resolve().parents[2] / "build" / "cli" / "surftrack")
    if not os.access(path, os.X_OK):
        pytest.skip(f"the surftrack CLI is not built at {path}")
    return path


def run_cli(*args):
    import subprocess
    return subprocess.run([cli(), *map(str, args)], capture_output=True, text=True, timeout=300)


def test_cli_labels_on_dask_writes_the_single_pass_files_and_table(tmp_path):
    """`surftrack labels STORE -o DIR/ --dask local:2` against the CLI's own single pass on the
    same store: every mesh file byte for byte, labels.csv and --table equal (but for the
    directory in the file column), with label names ('/' made '_'), a geometry override,
    an OME-Zarr level and --ascii."""
    rng = np.random.default_rng(31)
    shape = (37, 29, 41)
    seeds = rng.integers(0, shape, size=(15, 3))
    grid = np.stack(np.indices(shape), axis=-1).reshape(-1, 1, 3)
    cells = np.argmin(((grid - seeds[None]) ** 2).sum(-1), axis=1).reshape(shape).astype(np.uint16)
    cells[cells == 4] = 0  # one cell is background
    store = tmp_path / "seg.ome.zarr"
    root = zarr.open_group(str(store), mode="w")
    for level, data in enumerate([cells, cells[::2, ::2, ::2]]):
        root.create_dataset(f"s{level}", data=data, chunks=(8, 9, 7))
    root.attrs["multiscales"] = [{"version": "0.4", "axes": [{"name": a, "type": "space", "unit": "micrometer"}
                                                              for a in "zyx"],
                                  "datasets": [{"path": f"s{k}", "coordinateTransformations": [
                                      {"type": "scale", "scale": [2.0 * 2**k, 1.5 * 2**k, 1.0 * 2**k]}]}
                                      for k in range(2)]}]
    names = tmp_path / "names.txt"
    names.write_text("".join(f"{L} region/{L}\n" for L in range(1, 15, 2)))  # ('/' made '_' in file names)
    for extra in [[], ["--level", 1, "--ascii", "--spacing", "1,2,3", "--adjacency", "6-26"]]:
        single, dask = tmp_path / f"single{len(extra)}", tmp_path / f"dask{len(extra)}"
        common = ["--label-names", names, *extra]
        a = run_cli("labels", store, "--walls", "independent", "-o", f"{single}/", *common, "--table", tmp_path / "a.json")
        assert a.returncode == 0, a.stderr
        b = run_cli("labels", store, "-o", f"{dask}/", *common, "--table", tmp_path / "b.json", "--dask", "local:2",
                    "--block", "16,10,12", "--work-dir", tmp_path / f"work{len(extra)}")
        assert b.returncode == 0, b.stderr
        assert "blocks meshed" in b.stderr and "labels merged" in b.stderr
        files = sorted(p.name for p in single.iterdir())
        assert files == sorted(p.name for p in dask.iterdir()) and len(files) == 14  # 13 labels + labels.csv
        assert "1_region_1.ply" in files and "2_label2.ply" in files
        for f in files:
            left, right = (single / f).read_bytes(), (dask / f).read_bytes()
            if f == "labels.csv":
                left, right = left.replace(str(single).encode(), b"D"), right.replace(str(dask).encode(), b"D")
            assert left == right, f
        assert (tmp_path / "a.json").read_text().replace(str(single), "D") == \
            (tmp_path / "b.json").read_text().replace(str(dask), "D")


def test_cli_labels_on_dask_bad_input(tmp_path):
    zarr.open(str(tmp_path / "s.zarr"), mode="w", shape=(6, 6, 6), chunks=(3, 3, 3), dtype="<u2")[:] = 1
    (tmp_path / "v.raw").write_bytes(bytes(216))
    cases = [(["labels", tmp_path / "v.raw", "--raw-dims", "6,6,6", "--raw-type", "uint8", "-o", f"{tmp_path}/a/",
               "--dask", "local:2"], "chunked store"),
             (["labels", tmp_path / "s.zarr", "-o", tmp_path / "all.ply", "--dask", "local:2"], "-o DIR/"),
             (["labels", tmp_path / "s.zarr", "-o", f"{tmp_path}/b/", "--dask", "local:2", "--labels", "1"], "not with"),
             (["labels", tmp_path / "s.zarr", "-o", f"{tmp_path}/c/", "--block", "4,4,4"], "for --dask"),
             (["labels", tmp_path / "s.zarr", "-o", f"{tmp_path}/d/", "--dask", "local:0"], "local:N")]
    for args, says in cases:
        r = run_cli(*args)
        assert r.returncode != 0 and says in r.stderr and r.stderr.count("\n") == 1, (args, r.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr", "v.raw"]  # nothing written, no temporary left


def test_cli_mesh_all_on_dask_writes_the_single_pass_file(tmp_path):
    """`surftrack mesh STORE --all --iso S -o FILE --dask local:2` against the CLI's single pass
    on the same store: the same bytes, in PLY and OBJ, both mappings, a geometry override; the
    figures it prints are the single pass's."""
    rng = np.random.default_rng(37)
    shape = (27, 22, 31)
    volume = (rng.random(shape) * 200).astype(">f4")
    zarr.open(str(tmp_path / "v.zarr"), mode="w", shape=shape, chunks=(7, 9, 5), dtype=">f4")[:] = volume
    for out, extra in [("a.ply", ["--spacing", "1,2,3"]), ("b.obj", ["--mapping", "midpoint", "--adjacency", "6-18"])]:
        single, dask = tmp_path / f"single-{out}", tmp_path / f"dask-{out}"
        a = run_cli("mesh", tmp_path / "v.zarr", "--all", "--iso", 120, "-o", single, *extra, "--json")
        assert a.returncode == 0, a.stderr
        b = run_cli("mesh", tmp_path / "v.zarr", "--all", "--iso", 120, "-o", dask, *extra, "--json",
                    "--dask", "local:2", "--block", "8,12,10")
        assert b.returncode == 0, b.stderr
        assert single.read_bytes() == dask.read_bytes()
        import json
        want, got = json.loads(a.stdout), json.loads(b.stdout)
        assert (got["vertices"], got["triangles"], got["boundaries"], got["euler_characteristic"]) == \
            (want["vertices"], want["triangles"], want["components"], want["euler_characteristic"])
    for args, says in [(["--seed", "3,3,3"], "--all"), (["--all"], "--iso"), (["--all", "--iso", 1, "--smooth"], "--smooth")]:
        r = run_cli("mesh", tmp_path / "v.zarr", *args, "-o", tmp_path / "c.ply", "--dask", "local:2")
        assert r.returncode != 0 and says in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert not (tmp_path / "c.ply").exists()


def test_cli_labels_on_dask_with_a_merge_budget(tmp_path):
    """`surftrack labels STORE -o DIR/ --dask local:2 --merge-budget B` against the CLI's single
    pass on the same store: every file byte for byte (those of the labels over the budget
    streamed; the fragment files' bytes, counted here from their indices, decide which), the
    single pass's counts exactly, area and volume within 1e-9, merge_levels in the table; with
    --ascii (not streamed) the rows of the labels over the budget say that no file was written
    (never a file missing without a word)."""
    import csv
    import json
    rng = np.random.default_rng(43)
    shape = (26, 21, 23)
    seeds = rng.integers(0, shape, size=(7, 3))
    grid = np.stack(np.indices(shape), axis=-1).reshape(-1, 1, 3)
    cells = np.argmin(((grid - seeds[None]) ** 2).sum(-1), axis=1).reshape(shape).astype(np.uint16) + 1
    cells[rng.random(shape) < 0.04] = 9  # specks: a label of many components
    zarr.open(str(tmp_path / "s.zarr"), mode="w", shape=shape, chunks=(9, 8, 7), dtype="<u2")[:] = cells
    single = tmp_path / "single"
    a = run_cli("labels", tmp_path / "s.zarr", "--walls", "independent", "-o", f"{single}/", "--table", tmp_path / "a.json")
    assert a.returncode == 0, a.stderr
    work = tmp_path / "work"
    first = run_cli("labels", tmp_path / "s.zarr", "-o", f"{tmp_path}/first/", "--dask", "local:2", "--block",
                    "9,8,12", "--work-dir", work)
    assert first.returncode == 0, first.stderr
    weight = {}
    for path in work.iterdir():
        for label, keys, triangles in surftrack._surftrack.fragment_file_summary(str(path)):
            weight[label] = weight.get(label, 0) + 8 * keys + 12 * triangles
    sizes = sorted(w // 1024 for w in weight.values())
    kib = sizes[len(sizes) // 2]  # a budget in K that about half the labels exceed
    over = sorted(L for L, w in weight.items() if w > kib * 1024)
    assert 0 < len(over) < len(weight)
    dask = tmp_path / "dask"
    b = run_cli("labels", tmp_path / "s.zarr", "-o", f"{dask}/", "--table", tmp_path / "b.json", "--dask", "local:2",
                "--block", "9,8,12", "--work-dir", work, "--merge-budget", f"{kib}K")
    assert b.returncode == 0, b.stderr
    want = {r["label"]: r for r in json.loads((tmp_path / "a.json").read_text())}
    got = {r["label"]: r for r in json.loads((tmp_path / "b.json").read_text())}
    assert sorted(got) == sorted(want) == sorted(weight)
    for label, w in want.items():
        g = got[label]
        for column in ("voxels", "surfels", "triangles", "boundaries", "euler", "genus", "name"):
            assert g[column] == w[column], (label, column)
        assert g["area"] == pytest.approx(w["area"], rel=1e-9) and g["volume"] == pytest.approx(w["volume"], rel=1e-9)
        name = Path(w["file"]).name
        assert g["file"] == str(dask / name) and "no_file" not in g
        assert (g.get("merge_levels", 0) >= 1) == (label in over)
        assert (dask / name).read_bytes() == (single / name).read_bytes(), label  # merged whole or streamed
    rows = list(csv.DictReader(open(dask / "labels.csv")))
    assert [int(r["label"]) for r in rows] == sorted(weight) and "no_file" not in rows[0]
    assert all((r["merge_levels"] != "") == (int(r["label"]) in over) for r in rows)
    assert "no mesh file" not in b.stderr

    # Text PLY is not streamed: the labels over the budget get no file, and their rows say so.
    text = tmp_path / "text"
    c = run_cli("labels", tmp_path / "s.zarr", "-o", f"{text}/", "--table", tmp_path / "c.json", "--dask", "local:2",
                "--block", "9,8,12", "--work-dir", work, "--merge-budget", f"{kib}K", "--ascii")
    assert c.returncode == 0, c.stderr
    got = {r["label"]: r for r in json.loads((tmp_path / "c.json").read_text())}
    for label, w in want.items():
        g, name = got[label], Path(w["file"]).name
        assert g["surfels"] == w["surfels"] and g["euler"] == w["euler"]
        if label in over:
            assert g["file"] is None and "--ascii" in g["no_file"] and not (text / name).exists()
        else:
            assert "no_file" not in g and (text / name).exists()
    rows = list(csv.DictReader(open(text / "labels.csv")))
    assert all((r["no_file"] != "") == (int(r["label"]) in over) for r in rows)
    assert f"{len(over)} label" in c.stderr and "no mesh file" in c.stderr


def test_cli_merge_budget_bad_input(tmp_path):
    zarr.open(str(tmp_path / "s.zarr"), mode="w", shape=(6, 6, 6), chunks=(3, 3, 3), dtype="<u2")[:] = 1
    cases = [(["--merge-budget", "1M"], "is for --dask"),
             (["--dask", "local:2", "--merge-budget", "12X"], "not a number of bytes"),
             (["--dask", "local:2", "--merge-budget", "-5"], "not a number of bytes"),
             (["--dask", "local:2", "--merge-budget", "99999999999G"], "not a number of bytes"),
             (["--dask", "local:2", "--merge-budget", "1G", "--format", "precomputed"], "not with --format")]
    for args, says in cases:
        r = run_cli("labels", tmp_path / "s.zarr", "--walls", "independent", "-o", f"{tmp_path}/out/", *args)
        assert r.returncode != 0 and says in r.stderr and r.stderr.count("\n") == 1, (args, r.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr"]


def read_binary_ply(path):
    """(vertices (N, 3) float32, faces (M, 3) int) of a binary PLY of this tool's layout, by numpy."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().split("\n")
    n = int(next(line for line in header if line.startswith("element vertex")).split()[-1])
    m = int(next(line for line in header if line.startswith("element face")).split()[-1])
    vertices = np.frombuffer(data, dtype="<f4", count=3 * n, offset=end).reshape(n, 3)
    faces = np.frombuffer(data, dtype=np.dtype([("k", "u1"), ("v", "<i4", 3)]), count=m, offset=end + 12 * n)
    assert (faces["k"] == 3).all() and end + 12 * n + 13 * m == len(data)
    return vertices, faces["v"].astype(np.int64)


def split_by_numpy(vertices, faces):
    """The connected components of a mesh, by scipy's graph components: each (vertices, faces) in
    the mesh's order renumbered, by decreasing vertex count, ties by smallest vertex."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    n = len(vertices)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]]])
    _, label = connected_components(coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n)),
                                    directed=False)
    first = {c: int(np.flatnonzero(label == c)[0]) for c in np.unique(label)}
    order = sorted(first, key=lambda c: (-int((label == c).sum()), first[c]))
    parts = []
    for c in order:
        keep = np.flatnonzero(label == c)
        index = np.full(n, -1)
        index[keep] = np.arange(len(keep))
        mine = faces[label[faces[:, 0]] == c]
        parts.append((vertices[keep], index[mine]))
    return parts


def test_threshold_meshes_one_file_per_boundary(client, tmp_path):
    """write_threshold_meshes: a file per boundary, each byte-identical to the single pass's
    Surface.write_components, and equal to the single pass's whole mesh split by scipy's graph
    components (vertices to the float, faces exactly); the figures per boundary are the single
    pass's."""
    rng = np.random.default_rng(47)
    shape = (19, 23, 17)
    volume = rng.random(shape).astype(np.float32)
    want = surftrack.extract(volume, level=0.8, mode="all", spacing=(1.5, 1.0, 2.0), threads=1)
    assert len(want.components) > 10
    figures = blocks.write_threshold_meshes(volume, tmp_path / "out", 0.8, block=(7, 9, 5), spacing=(1.5, 1.0, 2.0),
                                            client=client)
    names = [f"boundary_{k}.ply" for k in range(1, len(want.components) + 1)]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(names)
    (tmp_path / "want").mkdir()
    want.write_components([tmp_path / "want" / n for n in names])
    parts = split_by_numpy(want.vertices.astype(np.float32), want.faces.astype(np.int64))
    for n, row, w, (v, f) in zip(names, figures["components"], want.components, parts):
        assert (tmp_path / "out" / n).read_bytes() == (tmp_path / "want" / n).read_bytes(), n
        got_v, got_f = read_binary_ply(tmp_path / "out" / n)
        assert np.array_equal(got_v, v) and np.array_equal(got_f, f), n
        assert row["file"] == n and {k: row[k] for k in w} == w
    with pytest.raises(ValueError, match="not an empty directory"):
        blocks.write_threshold_meshes(volume, tmp_path / "out", 0.8, client=client)


def test_cli_mesh_all_on_dask_one_file_per_boundary(tmp_path):
    """`surftrack mesh STORE --all --iso S -o DIR/ --dask local:2` against the CLI's single pass
    `-o DIR/`: the same files byte for byte (boundary_<k>.ply and boundaries.csv, but for the
    directory in its file column), both equal to the single pass's one-file mesh split by
    scipy's graph components; text PLY too; -o DIR/ without --all refused."""
    rng = np.random.default_rng(53)
    shape = (21, 18, 25)
    volume = (rng.random(shape) * 100).astype("<f4")
    zarr.open(str(tmp_path / "v.zarr"), mode="w", shape=shape, chunks=(8, 7, 9), dtype="<f4")[:] = volume
    for extra in [["--spacing", "1,2,3"], ["--mapping", "midpoint", "--adjacency", "6-18", "--ascii"]]:
        tag = len(extra)
        single, dask, whole = tmp_path / f"single{tag}", tmp_path / f"dask{tag}", tmp_path / f"whole{tag}.ply"
        args = ["mesh", tmp_path / "v.zarr", "--all", "--iso", 85, *extra]
        a = run_cli(*args, "-o", f"{single}/")
        assert a.returncode == 0, a.stderr
        b = run_cli(*args, "-o", f"{dask}/", "--dask", "local:2", "--block", "8,10,6")
        assert b.returncode == 0, b.stderr
        files = sorted(p.name for p in single.iterdir())
        assert files == sorted(p.name for p in dask.iterdir()) and len(files) > 10
        for f in files:
            left, right = (single / f).read_bytes(), (dask / f).read_bytes()
            if f == "boundaries.csv":
                left, right = left.replace(str(single).encode(), b"D"), right.replace(str(dask).encode(), b"D")
            assert left == right, f
        if "--ascii" in extra:
            continue
        c = run_cli(*args, "-o", whole)
        assert c.returncode == 0, c.stderr
        parts = split_by_numpy(*read_binary_ply(whole))
        assert len(files) == len(parts) + 1
        import csv
        rows = list(csv.DictReader(open(single / "boundaries.csv")))
        for k, (v, f) in enumerate(parts, 1):
            got_v, got_f = read_binary_ply(single / f"boundary_{k}.ply")
            assert np.array_equal(got_v, v) and np.array_equal(got_f, f), k
            assert rows[k - 1]["boundary"] == str(k) and int(rows[k - 1]["vertices"]) == len(v)
            assert int(rows[k - 1]["triangles"]) == len(f)
            assert Path(rows[k - 1]["file"]).name == f"boundary_{k}.ply"
    r = run_cli("mesh", tmp_path / "v.zarr", "--iso", 85, "-o", f"{tmp_path}/e/")
    assert r.returncode != 0 and "--all" in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert not (tmp_path / "e").exists()
