"""Label maps by blocks through fragment files (core/include/surftrack/LabelBlockFiles.h; docs/theory.md,
"Label maps by blocks" and "A label larger than one merge"), through the bindings scan_label_block_file,
merge_label_files and label_figures_by_tree, without Dask:

- a label merged from the files is label_surfaces' surface of the whole volume, array for array;
- a block written twice gives the same bytes and leaves no temporary file;
- truncations and single-bit flips at every byte of a file's header and index and throughout
  its data, a byte appended, another version,
  another kind of file: a ValueError naming the file, never a crash or a wrong mesh;
- the figures by the tree of groups of blocks, with budgets forcing 1, 2 and 3 levels (and
  random budgets), against the single pass on random label images: vertex, triangle, edge counts,
  Euler characteristics, genus, component count and order exactly; area and volume within 1e-9
  relative (the same per-triangle terms, summed per group then per tree node rather than in the
  single pass's triangle order, so rounding differs)."""
import numpy as np
import pytest

import surftrack
from surftrack import _surftrack
from surftrack.distributed import block_grid

IDENTITY = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
MIRROR = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]  # a reflection: volumes keep their sign


def random_labels(rng, shape, ids=(1, 2, 7, 2**64 - 1)):
    """Boxes, hollow boxes (cavities: negative volumes), handles (genus) and specks of a few labels."""
    labels = np.zeros(shape, np.uint64)
    for _ in range(int(rng.integers(4, 10))):
        lo = rng.integers(0, np.array(shape) - 2)
        hi = np.minimum(lo + rng.integers(2, 12, size=3), shape)
        L = np.uint64(ids[int(rng.integers(len(ids)))])
        labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = L
        if min(hi - lo) >= 3 and rng.random() < 0.5:  # a hole through it, or a cavity
            through = int(rng.integers(0, 2))
            mid = (lo + hi) // 2
            z0, z1 = (lo[0], hi[0]) if through else (mid[0], mid[0] + 1)
            labels[z0:z1, mid[1], mid[2]] = 0
    specks = rng.integers(0, shape, size=(int(rng.integers(5, 30)), 3))
    labels[tuple(specks.T)] = np.uint64(ids[int(rng.integers(len(ids)))])
    return labels


def write_blocks(labels, block, tmp_path, adjacency="26-6", background=0):
    paths = []
    for lo, hi in block_grid(labels.shape, block):
        top = [min(h + 1, n) for h, n in zip(hi, labels.shape)]
        box = np.ascontiguousarray(labels[lo[0]:top[0], lo[1]:top[1], lo[2]:top[2]])
        path = str(tmp_path / f"b_{lo[0]}_{lo[1]}_{lo[2]}.frag")
        _surftrack.scan_label_block_file(box, list(lo), list(labels.shape), list(lo), list(hi), background,
                                         adjacency, path)
        paths.append(path)
    return paths


def test_merged_from_files_is_the_single_pass(tmp_path):
    rng = np.random.default_rng(5)
    for trial, adjacency in enumerate(["26-6", "18-6", "6-18", "6-26"]):
        labels = random_labels(rng, tuple(int(n) for n in rng.integers(8, 15, size=3)))
        block = tuple(int(b) for b in rng.integers(1, 8, size=3))
        folder = tmp_path / str(trial)
        folder.mkdir()
        paths = write_blocks(labels, block, folder, adjacency)
        want = surftrack.label_surfaces(labels, spacing=(0.5, 1.0, 4.0), origin=(1, -2, 3), adjacency=adjacency, walls="independent")
        summaries = [_surftrack.fragment_file_summary(p) for p in paths]
        assert sorted({s[0] for summary in summaries for s in summary}) == sorted(want)
        for label, w in want.items():
            got = surftrack.Surface(**_surftrack.merge_label_files(label, paths, [0.5, 1.0, 4.0], [1, -2, 3], IDENTITY,
                                                                   0, adjacency, True))
            assert np.array_equal(got.vertices, w.vertices) and np.array_equal(got.faces, w.faces), label
            assert got.components == w.components and got.euler == w.euler


def test_a_block_written_twice_gives_the_same_bytes(tmp_path):
    labels = random_labels(np.random.default_rng(8), (9, 10, 11))
    first = [open(p, "rb").read() for p in write_blocks(labels, (4, 5, 6), tmp_path)]
    second = [open(p, "rb").read() for p in write_blocks(labels, (4, 5, 6), tmp_path)]
    assert first == second
    assert all(p.suffix == ".frag" for p in tmp_path.iterdir())  # no temporary left


def reads_everything(path, labels):
    """Every label of the file read and merged (one file as the whole volume's one block)."""
    for label, _, _ in _surftrack.fragment_file_summary(path):
        _surftrack.merge_label_files(label, [path], [1.0] * 3, [0.0] * 3, IDENTITY, 0, "26-6", False)


def test_damaged_files_are_refused_by_name(tmp_path):
    rng = np.random.default_rng(11)
    labels = np.zeros((5, 4, 6), np.uint64)  # three labels, 2^64 - 1 among them
    labels[1:3, 1:3, 1:4] = 2**64 - 1
    labels[3, 2, 2] = 5
    labels[0, 0, 0] = 2
    (path,) = write_blocks(labels, labels.shape, tmp_path)  # one block: the file is the volume's
    reads_everything(path, labels)
    good = open(path, "rb").read()
    damaged = str(tmp_path / "damaged.frag")

    def refused(data, match):
        with open(damaged, "wb") as f:
            f.write(data)
        with pytest.raises(ValueError, match=match) as e:
            reads_everything(damaged, labels)
        assert "damaged.frag" in str(e.value)

    # Every position in the header and index (80 + 56 bytes a label), every 8th (truncations) or
    # 4th (flips) in the data, which one checksum per label covers, and the last 12 bytes.
    head = 80 + 56 * 3
    assert len(good) > head + 200
    tail = list(range(len(good) - 12, len(good)))
    for n in [*range(head + 8), *range(head + 8, len(good) - 12, 8), *tail]:
        refused(good[:n], "truncated|not a surftrack fragment file")
    refused(good + b"\0", "corrupted")
    for at in [*range(head + 8), *range(head + 8, len(good) - 12, 4), *tail]:  # the bit varies with the byte
        data = bytearray(good)
        data[at] ^= 1 << (at % 8)
        refused(bytes(data), "truncated|corrupted|not a surftrack|version")
    data = bytearray(good)
    data[8] = 9  # the version
    refused(bytes(data), "format version 9, this build reads version 1")
    np.savez(str(tmp_path / "old.npz"), keys=np.arange(3))
    with pytest.raises(ValueError, match="not a surftrack fragment file"):
        _surftrack.fragment_file_summary(str(tmp_path / "old.npz"))
    with pytest.raises(ValueError, match="cannot be read"):
        _surftrack.fragment_file_summary(str(tmp_path / "missing.frag"))


def tree_figures(labels, block, paths, label, budget, spacing, direction):
    return _surftrack.label_figures_by_tree(label, paths, list(labels.shape), list(block), list(spacing), [1, -2, 3],
                                            direction, "26-6", budget)


def expect_figures(got, want):
    table = np.asarray(got["components"]).reshape(-1, 7)
    assert got["voxels"] == want.voxels and got["euler"] == want.euler
    assert got["vertices"] == len(want.vertices) and got["triangles"] == len(want.faces)
    assert len(table) == len(want.components)
    for row, c in zip(table, want.components):
        assert [int(v) for v in row[:5]] == [c[k] for k in ("surfels", "triangles", "edges", "euler", "genus")]
        assert row[5] == pytest.approx(c["area"], rel=1e-9)
        assert row[6] == pytest.approx(c["volume"], rel=1e-9)


@pytest.mark.parametrize("levels,block", [(1, (9, 8, 10)), (2, (5, 4, 5)), (3, (3, 2, 3))])
def test_tree_figures_are_the_single_pass(tmp_path, levels, block):
    rng = np.random.default_rng(100 + levels)
    for trial in range(3):
        shape = (17, 15, 19) if trial < 2 else (16, 14, 18)  # grids of 2, 4 and 8 blocks a side at most
        labels = random_labels(rng, shape)
        direction = MIRROR if trial == 1 else IDENTITY
        spacing = (0.5, 1.0, 4.0)
        folder = tmp_path / str(trial)
        folder.mkdir()
        paths = write_blocks(labels, block, folder)
        want = surftrack.label_surfaces(labels, spacing=spacing, origin=(1, -2, 3), direction=np.array(direction), walls="independent")
        deepest = 0
        for label, w in want.items():
            # Budget 0: down to single blocks, so the tree's depth is that of the block grid.
            got = tree_figures(labels, block, paths, label, 0, spacing, direction)
            expect_figures(got, w)
            deepest = max(deepest, got["levels"])
            # A random budget: leaves of several blocks, at any depth.
            weight = sum(8 * k + 12 * t for p in paths for L, k, t in _surftrack.fragment_file_summary(p) if L == label)
            got = tree_figures(labels, block, paths, label, int(rng.integers(0, weight + 1)), spacing, direction)
            expect_figures(got, w)
            # A budget the label fits: one merge, no tree.
            assert tree_figures(labels, block, paths, label, weight, spacing, direction)["levels"] == 0
        assert deepest == levels


def test_tree_refuses_files_of_another_grid(tmp_path):
    labels = random_labels(np.random.default_rng(3), (9, 9, 9))
    paths = write_blocks(labels, (4, 4, 4), tmp_path)
    label = _surftrack.fragment_file_summary(paths[0])[0][0]
    with pytest.raises(ValueError, match="not a block of the grid"):
        _surftrack.label_figures_by_tree(label, paths, [9, 9, 9], [5, 5, 5], [1.0] * 3, [0.0] * 3, IDENTITY, "26-6", 0)
    with pytest.raises(ValueError, match="of another volume"):
        _surftrack.label_figures_by_tree(label, paths, [9, 9, 10], [4, 4, 4], [1.0] * 3, [0.0] * 3, IDENTITY, "26-6", 0)
    with pytest.raises(ValueError, match="same block"):
        _surftrack.label_figures_by_tree(label, paths + paths[:1], [9, 9, 9], [4, 4, 4], [1.0] * 3, [0.0] * 3,
                                         IDENTITY, "26-6", 0)
    with pytest.raises(ValueError, match="no fragment file holds label 12345"):
        _surftrack.label_figures_by_tree(12345, paths, [9, 9, 9], [4, 4, 4], [1.0] * 3, [0.0] * 3, IDENTITY, "26-6", 0)


def streamed(label, paths, out, budget, spacing=(0.5, 1.0, 4.0), direction=IDENTITY):
    return _surftrack.write_label_mesh_streamed(label, paths, list(spacing), [1, -2, 3], direction, str(out), budget)


def test_streamed_mesh_is_the_single_pass_file(tmp_path):
    """write_label_mesh_streamed (LabelBlockFiles.h, writeLabelMeshStreamed) against
    label_surfaces on the whole volume written by Surface.write: the same bytes for every label,
    every pair, mirrored and not, blocks the shape does not divide (1 voxel thick included), a
    budget of 0 (chunks of 16 items: every stream crosses chunk boundaries) and a large one; no
    temporary file left beside the output."""
    rng = np.random.default_rng(61)
    for trial, adjacency in enumerate(["26-6", "18-6", "6-18", "6-26"] * 2):
        labels = random_labels(rng, tuple(int(n) for n in rng.integers(8, 20, size=3)))
        block = [(1, 5, 3), (4, 4, 4), (7, 2, 6), (30, 30, 30)][trial % 4]
        folder = tmp_path / str(trial)
        folder.mkdir()
        paths = write_blocks(labels, block, folder, adjacency)
        direction = MIRROR if trial % 2 else IDENTITY
        want = surftrack.label_surfaces(labels, spacing=(0.5, 1.0, 4.0), origin=(1, -2, 3), direction=direction,
                                        adjacency=adjacency, walls="independent")
        out = tmp_path / "out"
        out.mkdir(exist_ok=True)
        for label, w in want.items():
            w.write(str(tmp_path / "want.ply"))
            for budget in (0, 1 << 30):
                counts = streamed(label, paths, out / "got.ply", budget, direction=direction)
                assert counts == (len(w.vertices), len(w.faces))
                assert (out / "got.ply").read_bytes() == (tmp_path / "want.ply").read_bytes(), (trial, label, budget)
        assert [p.name for p in out.iterdir()] == ["got.ply"]


def test_streamed_mesh_refuses_damaged_files_by_name(tmp_path):
    """A bit flipped in a label's data (150 random bytes and the last 12) of one of its files: a
    ValueError naming that file (the checksum, the keys' or indices' checks, or the order of
    cubes), no output and no temporary file left."""
    labels = random_labels(np.random.default_rng(67), (10, 9, 11), ids=(3,))
    paths = write_blocks(labels, (5, 9, 6), tmp_path)
    (label,) = {L for p in paths for L, _, _ in _surftrack.fragment_file_summary(p)}
    out = tmp_path / "out"
    out.mkdir()
    streamed(label, paths, out / "m.ply", 0)
    good = open(paths[0], "rb").read()
    head = 80 + 56
    picks = np.random.default_rng(71).choice(np.arange(head, len(good) - 12), size=150, replace=False)
    for at in [*picks.tolist(), *range(len(good) - 12, len(good))]:
        data = bytearray(good)
        data[at] ^= 1 << (at % 8)
        with open(paths[0], "wb") as f:
            f.write(bytes(data))
        with pytest.raises(ValueError, match="fragment file") as e:
            streamed(label, paths, out / "n.ply", 0)
        assert paths[0] in str(e.value)
    assert [p.name for p in out.iterdir()] == ["m.ply"]
    with pytest.raises(ValueError, match="binary .ply"):
        streamed(label, paths, out / "m.obj", 0)
    with pytest.raises(ValueError, match="no fragment file holds label 4"):
        streamed(4, paths, out / "x.ply", 0)
