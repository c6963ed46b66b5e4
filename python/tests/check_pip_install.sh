#!/usr/bin/env bash
# ctest: the install path of docs/python.md with Debian's packages only: a virtual environment
# that sees Debian's numpy, `pip install --no-build-isolation` from the checkout, then an import
# and one extraction from outside the source tree.
set -euo pipefail
python=$1 source=$2 work=$3 build=$4
rm -rf "$work" && mkdir -p "$work"
"$python" -m venv --system-site-packages "$work/venv"
# A copy of the checkout, so that the build writes nothing into the source tree.
tar -C "$source" --exclude=./build --exclude=./.git -cf - . | (mkdir -p "$work/src" && tar -C "$work/src" -xf -)
# The module comes from the build that runs this test (SURFTRACK_BUILD_DIR, setup.py): the
# project is not compiled a second time; what is checked is the install path around it.
SURFTRACK_BUILD_DIR=$build "$work/venv/bin/pip" install --no-build-isolation --no-deps --no-index -q "$work/src"
cd "$work"
"$work/venv/bin/python" - <<'PY'
import importlib.metadata
import numpy as np, surftrack
assert "venv" in surftrack.__file__, surftrack.__file__
# One version: pip's metadata (setup.py, from CMakeLists.txt) and the module's (CMake).
assert importlib.metadata.version("surftrack") == surftrack.__version__, (
    importlib.metadata.version("surftrack"), surftrack.__version__)
x = np.indices((20, 20, 20)) - 9.5
s = surftrack.extract((x ** 2).sum(0) < 36, level=0.5, seed=(10, 10, 10))
assert s.euler == 2 and len(s.faces) > 0, (s.euler, len(s.faces))
print("pip-installed surftrack:", surftrack.__file__, len(s.vertices), "vertices")
PY
