"""The package as a whole: its version is the project's, and the integer figures are ints."""
import re
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest

import surftrack

SOURCE = Path(__file__).resolve().parents[2]


def test_version_is_the_projects():
    cmake = re.search(r"project\(surftrack\s+VERSION\s+([0-9.]+)", (SOURCE / "CMakeLists.txt").read_text())
    assert surftrack.__version__ == cmake.group(1)
    # pip's metadata comes from setup.py, which reads the same line (check_pip_install.sh
    # compares the installed metadata); pyproject.toml must not pin another one.
    project = tomllib.loads((SOURCE / "pyproject.toml").read_text())["project"]
    assert "version" not in project and "version" in project["dynamic"]


def test_version_is_the_clis():
    # The CLI of the same build: build/cli/surftrack next to build/python/surftrack.
    cli = Path(surftrack.__file__).resolve().parents[2] / "cli" / "surftrack"
    if not cli.exists():
        pytest.skip(f"no CLI next to this package ({cli})")
    out = subprocess.run([str(cli), "--version"], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["surftrack", surftrack.__version__]


def _handles(g, shape=(40, 40, 14)):
    """A slab with g square holes through it: a closed surface of genus g."""
    v = np.zeros(shape, np.uint8)
    v[3:-3, 3:-3, 3:-3] = 1
    for h in range(g):
        x = 6 + 7 * h
        v[x:x + 3, 10:13, :] = 0
    return v


@pytest.mark.parametrize("g", [0, 1, 3])
def test_genus_is_an_int_everywhere(g):
    v = _handles(g)
    s = surftrack.extract(v, label=1, mode="all")
    assert type(s.genus) is int and s.genus == g
    for c in s.components:
        for key in ("surfels", "triangles", "edges", "euler", "genus"):
            assert type(c[key]) is int, (key, c[key])
        assert c["genus"] == g
    (only,) = surftrack.label_surfaces(v).values()
    assert type(only.genus) is int and only.genus == g
    assert type(only.components[0]["genus"]) is int
    smoothed = surftrack.extract(v, label=1, mode="largest", smooth=3, reduce=0.5)
    assert type(smoothed.genus) is int and smoothed.genus == g


def test_a_cavity_counts_as_a_sphere():
    # A hollow ball: two boundaries, both spheres (genus 0), the inner one a cavity's.
    i, j, k = np.indices((24, 24, 24))
    r2 = (i - 12) ** 2 + (j - 12) ** 2 + (k - 12) ** 2
    v = ((r2 < 100) & (r2 > 25)).astype(np.uint8)
    s = surftrack.extract(v, label=1, mode="all")
    assert [c["genus"] for c in s.components] == [0, 0] and s.genus == 0
    assert type(s.genus) is int
