"""What surftrack says when it refuses (docs/python.md): messages in the caller's axes, the
argument checks (threads, smooth, huge shapes) and the reasons of a write that fails. Each
expected message is built from the arguments the test passes, never copied from an output."""
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import surftrack
from conftest import ball

SHAPE = (8, 9, 10)  # three different sizes: a domain printed with its axes reversed shows


def domain(shape):
    """The engine's way of printing a domain, in the array's axes."""
    return "x".join(f"[0,{n})" for n in shape)


def voxel(v):
    return "(" + ",".join(str(int(x)) for x in v) + ")"


def message_of(call):
    with pytest.raises(ValueError) as error:
        call()
    return str(error.value)


# --- voxels and domains in numpy index order --------------------------------------------------

def test_seed_voxel_outside_the_domain_is_named_in_array_axes():
    volume = np.zeros(SHAPE, np.uint8)
    volume[2:6, 2:6, 2:6] = 1
    for seed in [(100, 0, 0), (1, 2, 30), (-1, 4, 5)]:
        for rule in ("nearest", "ray"):
            text = message_of(lambda: surftrack.extract(volume, label=1, seed=seed, seed_rule=rule))
            assert f"seed voxel {voxel(seed)} lies outside the image domain {domain(SHAPE)}" in text


def test_seed_surfel_messages_are_in_array_axes():
    volume = np.zeros(SHAPE, np.uint8)
    volume[2:6, 2:6, 2:6] = 1
    c, d = (100, 0, 1), (100, 0, 2)
    text = message_of(lambda: surftrack.extract(volume, label=1, seed=(c, d)))
    assert f"seed surfel[c={voxel(c)} d={voxel(d)}] lies outside the image domain {domain(SHAPE)}" in text
    # Both voxels 0: neither side is selected.
    c, d = (1, 2, 3), (1, 2, 4)
    assert volume[c] == 0 and volume[d] == 0
    text = message_of(lambda: surftrack.extract(volume, label=1, seed=(c, d)))
    assert f"surfel[c={voxel(c)} d={voxel(d)}] is not a boundary surfel: c={voxel(c)} is a 0-voxel" in text


def test_seeds_on_no_boundary_are_named_in_array_axes():
    empty = np.zeros(SHAPE)
    seed = (1, 2, 3)
    text = message_of(lambda: surftrack.extract(empty, level=0.5, seed=seed))
    assert f"seed voxel {voxel(seed)} has no boundary surfel near it" in text
    text = message_of(lambda: surftrack.extract(empty, level=0.5, seed=seed, seed_rule="ray"))
    assert f"seed voxel {voxel(seed)} is not on any boundary" in text


def test_seed_point_outside_gives_its_voxel_index_in_array_axes():
    volume = np.zeros(SHAPE, np.uint8)
    volume[2:6, 2:6, 2:6] = 1
    point = (50.0, 1.0, 2.0)
    spacing = (2.0, 1.0, 0.5)
    index = tuple(p / s for p, s in zip(point, spacing))  # origin 0, identity direction
    text = message_of(lambda: surftrack.extract(volume, label=1, seed_point=point, spacing=spacing))
    assert "seed point (50,1,2) lies outside the image" in text  # physical: as given
    assert f"voxel index ({index[0]:g},{index[1]:g},{index[2]:g})" in text
    assert f"outside the domain {domain(SHAPE)}" in text


def test_label_surfaces_seed_messages_are_in_array_axes():
    labels = np.zeros(SHAPE, np.uint8)
    labels[2:6, 2:6, 2:6] = 3
    seed = (100, 1, 2)
    text = message_of(lambda: surftrack.label_surfaces(labels, seeds=[seed]))
    assert f"seed voxel {voxel(seed)} lies outside the image domain {domain(SHAPE)}" in text
    seed = (0, 1, 2)
    assert labels[seed] == 0
    text = message_of(lambda: surftrack.label_surfaces(labels, seeds=[seed]))
    assert f"seed voxel {voxel(seed)} is on the background label 0" in text


def test_engine_errors_keep_their_type():
    volume = np.zeros(SHAPE, np.uint8)
    with pytest.raises(surftrack.InvalidInput):
        surftrack.extract(volume, level=0.5, seed=(100, 0, 0))


# --- arguments ----------------------------------------------------------------------------------

@pytest.mark.parametrize("threads", [1.5, 2.0, True, False, "2", None, np.float64(1)])
def test_threads_must_be_an_integer(threads):
    volume = ball((12, 12, 12), (6, 6, 6), 4)
    with pytest.raises(TypeError, match="threads must be an integer"):
        surftrack.extract(volume, level=50, mode="all", threads=threads)
    with pytest.raises(TypeError, match="threads must be an integer"):
        surftrack.label_surfaces(volume, threads=threads)


def test_negative_threads_are_refused():
    volume = ball((12, 12, 12), (6, 6, 6), 4)
    with pytest.raises(ValueError, match="threads -2 is negative"):
        surftrack.extract(volume, level=50, mode="all", threads=-2)
    with pytest.raises(ValueError, match="threads -1 is negative"):
        surftrack.label_surfaces(volume, threads=-1)


def test_more_threads_than_cpus_run_quietly_on_the_cpus(capfd):
    volume = ball((40, 40, 40), (20, 20, 20), 15)
    ref = surftrack.extract(volume, level=50, mode="all", threads=1, smooth=2)
    capfd.readouterr()
    many = surftrack.extract(volume, level=50, mode="all", threads=10000, smooth=2)
    labels = surftrack.label_surfaces((volume > 50).astype(np.uint8), threads=np.int64(10000))
    out, err = capfd.readouterr()
    assert out == "" and err == "", (out, err)  # no TBB warning on stderr (the C level)
    assert np.array_equal(many.vertices, ref.vertices) and np.array_equal(many.faces, ref.faces)
    assert list(labels) == [1]


def test_smooth_is_capped_as_in_the_cli():
    volume = ball((12, 12, 12), (6, 6, 6), 4)
    # Refused before any work (10^9 iterations would run for hours: ctest's timeout would say so).
    with pytest.raises(ValueError, match="smooth takes at most 100000 iterations"):
        surftrack.extract(volume, label=100, mode="largest", smooth=10 ** 9)
    assert surftrack.extract(volume, label=100, mode="largest", smooth=2).refine["smooth_iterations"] == 2


@pytest.mark.parametrize("call", [
    lambda v: surftrack.marching_cubes(v),
    lambda v: surftrack.marching_cubes(v, 0.5),
    lambda v: surftrack.extract(v, mode="all"),
    lambda v: surftrack.extract(v, level=0.5, seed=(1, 2, 3)),
    lambda v: surftrack.label_surfaces(np.broadcast_to(np.uint8(1), v.shape)),
])
def test_a_vast_broadcast_volume_is_refused_at_once(call):
    # 2^60 voxels of one value: any scan of them would run for years, so a refusal that comes
    # back at all came before the scan (ctest's timeout catches one that does not).
    vast = np.broadcast_to(np.float32(1), (2 ** 20,) * 3)
    with pytest.raises(ValueError, match="each dimension must be at most 524285"):
        call(vast)


def test_the_largest_dimension_is_taken():
    v = np.zeros((3, 3, 524285), np.uint8)
    v[1, 1, 1] = 1
    with pytest.warns(UserWarning, match="speck"):
        s = surftrack.extract(v, label=1, seed=(1, 1, 1))
    assert len(s.vertices) == 6


# --- writing --------------------------------------------------------------------------------

def _cube_surface():
    v = np.zeros((6, 6, 6), np.uint8)
    v[1:4, 2:5, 1:3] = 1
    return surftrack.extract(v, label=1, mode="largest")


def test_write_into_a_missing_directory_says_so(tmp_path):
    target = tmp_path / "no" / "such" / "ball.ply"
    with pytest.raises(FileNotFoundError) as error:
        _cube_surface().write(target)
    assert error.value.errno == 2
    assert f"cannot write '{target}': directory '{target.parent}' does not exist" in str(error.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["out.ply", "out", "out.obj"])
def test_write_onto_a_directory_says_so(tmp_path, name):
    target = tmp_path / name
    target.mkdir()
    with pytest.raises(IsADirectoryError) as error:
        _cube_surface().write(target)
    assert isinstance(error.value, OSError) and error.value.errno == 21
    assert f"cannot write '{target}': it is a directory" in str(error.value)
    assert [p.name for p in tmp_path.iterdir()] == [name] and target.is_dir()


def test_write_under_a_file_says_so(tmp_path):
    (tmp_path / "file").write_text("x")
    target = tmp_path / "file" / "ball.ply"
    with pytest.raises(NotADirectoryError) as error:
        _cube_surface().write(target)
    assert f"'{target.parent}' is not a directory" in str(error.value)


WRITE_CHILD = r"""
import sys
import numpy as np
import surftrack
v = np.zeros((6, 6, 6), np.uint8)
v[1:4, 2:5, 1:3] = 1
try:
    surftrack.extract(v, label=1, mode="largest").write(sys.argv[1])
except OSError as error:
    print(type(error).__name__, error.errno, error.strerror, sep="\n")
"""


def test_write_into_an_unwritable_directory_says_so():
    # As root the permission bits do not bind: the write then runs as the user nobody.
    directory = Path(tempfile.mkdtemp(prefix="surftrack-readonly-"))
    try:
        directory.chmod(0o555)
        target = directory / "ball.ply"
        if os.geteuid() == 0:
            package_dir = str(Path(surftrack.__file__).resolve().parents[1])
            result = subprocess.run([sys.executable, "-c", WRITE_CHILD, str(target)], capture_output=True,
                                    text=True, user=65534, cwd="/",
                                    env=dict(os.environ, PYTHONPATH=package_dir))
            kind, errno, text = result.stdout.strip().split("\n")
            errno = int(errno)
        else:
            with pytest.raises(OSError) as error:
                _cube_surface().write(target)
            kind, errno, text = type(error.value).__name__, error.value.errno, str(error.value)
        assert kind == "PermissionError" and errno == 13
        assert f"cannot write '{target}': directory '{directory}' is not writable" in text
        assert list(directory.iterdir()) == []
    finally:
        directory.chmod(0o755)
        shutil.rmtree(directory)


def test_write_with_an_unknown_extension_is_a_value_error(tmp_path):
    with pytest.raises(ValueError, match="unknown extension '.xyz'"):
        _cube_surface().write(tmp_path / "ball.xyz")
