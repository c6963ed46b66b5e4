"""TIFF stacks written by an independent writer (tifffile, Debian's python3-tifffile) read by
`surftrack info --json`: the channels of ImageJ hyperstacks and OME-TIFFs apart, each channel's
slices and voxels exactly those numpy holds, the voxel size the metadata states and its unit;
what surftrack cannot read (no channel chosen, time series, several series) refused with one
line. Run by ctest (tests/CMakeLists.txt) with SURFTRACK_EXE set to the tool."""
import json
import os
import subprocess

import numpy as np
import pytest

tifffile = pytest.importorskip("tifffile")

EXE = os.environ.get("SURFTRACK_EXE", "build/cli/surftrack")

# 40 slices of 2 channels of 64 x 64 uint16, values below 256 so that `info` lists each value's
# voxel count; the channels have different values (channel c holds c * 100 + 0..99).
Z, C, Y, X = 40, 2, 64, 48


def stack():
    rng = np.random.default_rng(7)
    data = rng.integers(0, 100, size=(Z, C, Y, X), dtype=np.uint16)
    for c in range(C):
        data[:, c] += np.uint16(100 * c)
    return data


def info(path, *args):
    run = subprocess.run([EXE, "info", str(path), "--json", *args], capture_output=True, text=True)
    return run.returncode, (json.loads(run.stdout) if run.returncode == 0 else None), run.stderr


def expect_voxels(report, volume):
    """The report's dims, range and per-value counts are those of `volume` (z, y, x)."""
    assert report["dims"] == [volume.shape[2], volume.shape[1], volume.shape[0]]
    assert report["min"] == volume.min() and report["max"] == volume.max()
    assert report["mean"] == pytest.approx(volume.mean(), rel=1e-12)
    values, counts = np.unique(volume, return_counts=True)
    assert [(l["value"], l["voxels"]) for l in report["labels"]] == list(zip(values.tolist(), counts.tolist()))


def expect_refused(path, *args, says):
    code, _, err = info(path, *args)
    assert code == 1
    assert err.count("\n") == 1 and err.startswith("surftrack: error: ") and str(path) in err, err
    for part in says:
        assert part in err, err


@pytest.fixture
def data():
    return stack()


def test_imagej_hyperstack_channels_and_voxel_size(tmp_path, data):
    path = tmp_path / "stack_c2.tif"
    tifffile.imwrite(path, data, imagej=True, resolution=(10, 10),
                     metadata={"spacing": 0.3, "unit": "um", "axes": "ZCYX"})
    expect_refused(path, says=["2 channels", "ImageJ channels=2", "--channel"])
    for c in range(C):
        code, report, err = info(path, "--channel", str(c))
        assert code == 0, err
        expect_voxels(report, data[:, c])
        assert report["spacing"] == pytest.approx([0.1, 0.1, 0.3], rel=1e-9)
        assert report["unit"] == "µm"
        assert (report["channel"], report["channels"]) == (c, C)
    expect_refused(path, "--channel", "2", says=["no channel 2", "0 to 1"])


@pytest.mark.parametrize("axes", ["ZCYX", "CZYX"])  # OME DimensionOrder XYCZT and XYZCT
def test_ome_tiff_channels_and_voxel_size(tmp_path, data, axes):
    path = tmp_path / "stack.ome.tif"
    stored = data if axes == "ZCYX" else np.ascontiguousarray(data.transpose(1, 0, 2, 3))
    tifffile.imwrite(path, stored, ome=True, metadata={
        "axes": axes, "PhysicalSizeX": 0.1, "PhysicalSizeY": 0.2, "PhysicalSizeZ": 0.3,
        "PhysicalSizeZUnit": "nm"})
    expect_refused(path, says=["2 channels", "OME SizeC=2", "--channel"])
    for c in range(C):
        code, report, err = info(path, "--channel", str(c))
        assert code == 0, err
        expect_voxels(report, data[:, c])
        assert report["spacing"] == pytest.approx([0.1, 0.2, 0.3e-3], rel=1e-9)  # nm in µm
        assert report["unit"] == "µm"


def test_one_channel_stacks_and_units(tmp_path, data):
    one = data[:, 1]
    imagej = tmp_path / "one.tif"
    tifffile.imwrite(imagej, one, imagej=True, resolution=(4, 2),
                     metadata={"spacing": 2.5, "unit": "nm", "axes": "ZYX"})
    code, report, err = info(imagej)
    assert code == 0, err
    expect_voxels(report, one)
    assert report["spacing"] == pytest.approx([0.25, 0.5, 2.5], rel=1e-9)
    assert report["unit"] == "nm"
    assert report["channels"] == 1
    assert info(imagej, "--channel", "0")[0] == 0
    expect_refused(imagej, "--channel", "1", says=["no channel 1", "one channel"])
    # A TIFF without ImageJ or OME metadata: every page a slice, ITK's spacing, no unit.
    plain = tmp_path / "plain.tif"
    tifffile.imwrite(plain, one)
    code, report, err = info(plain)
    assert code == 0, err
    expect_voxels(report, one)
    assert "unit" not in report


def test_what_surftrack_cannot_read_is_refused(tmp_path, data):
    frames = tmp_path / "frames.tif"
    tifffile.imwrite(frames, np.stack([data, data]), imagej=True, metadata={"axes": "TZCYX"})
    expect_refused(frames, "--channel", "0", says=["2 time points", "ImageJ frames=2"])
    series = tmp_path / "series.ome.tif"
    with tifffile.TiffWriter(series, ome=True) as writer:
        writer.write(data[:, 0], metadata={"axes": "ZYX"})
        writer.write(data[:, 1], metadata={"axes": "ZYX"})
    expect_refused(series, says=["2 images (series)"])
    rgb = tmp_path / "rgb.ome.tif"
    tifffile.imwrite(rgb, np.zeros((4, 16, 16, 3), np.uint8), ome=True, photometric="rgb",
                     metadata={"axes": "ZYXS"})
    expect_refused(rgb, says=["3 samples per pixel"])


def test_a_date_time_shorter_than_tiff_6_is_refused(tmp_path, data):
    """ITK's TIFF reader copies DateTime's 20 bytes (TIFF 6.0) whatever the file holds: a
    shorter one is refused before ITK reads past it, a well-formed one read as usual."""
    one = data[:, 0]
    good = tmp_path / "dated.tif"
    tifffile.imwrite(good, one, datetime="2026:12:03 10:00:00")
    code, report, err = info(good)
    assert code == 0, err
    expect_voxels(report, one)
    short = tmp_path / "short-date.tif"
    tifffile.imwrite(short, one, extratags=[(306, "s", 0, "2026:12:03", True)])  # DateTime, 11 bytes
    expect_refused(short, says=["DateTime", "11 bytes", "not the 20"])
