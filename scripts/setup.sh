#!/usr/bin/env bash
# Installs what surftrack needs on Debian 12 (run as root; uses sudo otherwise).
# Only missing packages are installed, so a second run costs a second.
set -euo pipefail

packages=(
  build-essential cmake          # compiler and build system
  libboost-graph-dev             # Boost.Graph: the surface graph, voxel components in tests
  libopenmesh-dev                # OpenMesh: half-edge meshes and mesh IO, the Decimater (refine/)
  libcgal-dev                    # CGAL 5.5, header-only: the refine tests' independent checks (self-intersection, point-in-mesh, distance); never linked into the engine
  libgtest-dev                   # GoogleTest
  libinsighttoolkit5-dev         # ITK: NIfTI / NRRD / MetaImage / DICOM volumes for the CLI
  libgdcm-dev zlib1g-dev         # linked directly by io/ (DICOM series, gzip streams)
  libdeflate-dev pkg-config      # io/: a .nii.gz inflated in one call
  libblosc-dev libzstd-dev       # io/: the chunks of zarr and N5 stores (blosc, zstd)
  libdraco-dev                   # Draco: the fragments of Neuroglancer's multi-resolution meshes (converter/DracoFragment.cpp)
  draco                          # draco_decoder: decodes every fragment independently in python/tests/test_precomputed_multires.py
  libcli11-dev                   # CLI11: the command line
  nlohmann-json3-dev             # nlohmann-json: the CLI's JSON output
  libtbb-dev                     # oneTBB: the scanning method on every core
  gnuplot-nox                    # plots of the Figure 9 benchmark
  python3-dev python3-numpy pybind11-dev   # the Python package (Debian's python3, /usr/bin/python3)
  python3-pytest python3-skimage python3-nibabel python3-meshio  # its tests and examples
  python3-venv python3-pip python3-setuptools  # 'pip install --no-build-isolation .' in a venv
  python3-pil                    # PNG screenshots read by tests/browser/test_neuroglancer.py
  python3-tifffile               # TIFF stacks (ImageJ, OME-TIFF) written independently for tests/test_tiff_stacks.py
  python3-dask python3-distributed  # surftrack.distributed: every label by blocks on a Dask cluster
  python3-zarr python3-numcodecs # zarr, OME-Zarr and N5 stores written independently for the tests (readers, Dask)
  mricron-data                   # real MRI volumes used by the demo and one test
)
# Installed without their recommended packages (for Chromium: printing, desktop and network
# services, a hundred packages a headless browser does not use).
lean_packages=(
  chromium                       # headless Chromium for tests/browser/ (Neuroglancer opening the output); node and npm come with the machine
)

sudo=""
[[ $(id -u) -eq 0 ]] || sudo="sudo"
updated=false
# apt_install [apt-get options...] -- packages...: those not installed yet.
apt_install() {
  local options=() missing=() p
  while [[ $1 != -- ]]; do options+=("$1"); shift; done
  shift
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  ((${#missing[@]})) || return 0
  echo "setup: installing ${missing[*]}" >&2
  $updated || { $sudo apt-get update -qq; updated=true; }
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${options[@]}" "${missing[@]}" >/dev/null
}
apt_install -- "${packages[@]}"
apt_install --no-install-recommends -- "${lean_packages[@]}"

# draco3d from npm (Google's Emscripten build of Draco): a second decoder of the multi-resolution
# fragments, independent of Debian's libdraco that writes them
# (python/tests/test_precomputed_multires.py; skipped there when node or the package is missing).
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if command -v npm >/dev/null && [[ ! -d "$root/python/tests/node/node_modules/draco3d" ]]; then
  echo "setup: installing draco3d (npm) in python/tests/node" >&2
  npm install --silent --no-audit --no-fund --prefix "$root/python/tests/node" >/dev/null
fi
