#!/usr/bin/env bash
# Builds the page that tests/browser/test_neuroglancer.py opens: Neuroglancer from the npm
# registry (package.json, exact versions, package-lock.json) bundled by Vite into OUT/dist, with
# the driver's playwright-core in OUT/node_modules. Rebuilt only when one of the files below
# changes (a hash of them in OUT/stamp), the packages reinstalled only when package.json or
# package-lock.json changes: 15-22 s for npm ci the first time, then a 3 s build (24-38 s on the
# 2-core machine while others compile), nothing after.
#
#   tests/browser/build_viewer.sh OUT
#
# Exits 77 (ctest's SKIP_RETURN_CODE) without node and npm: the browser test is then skipped.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:?usage: build_viewer.sh OUT}
files=(package.json package-lock.json vite.config.js index.html viewer.js open_viewer.mjs)

for tool in node npm; do
  if ! command -v "$tool" >/dev/null; then
    echo "build_viewer: SKIPPED: no $tool (Node.js 20.19 or later with npm, as the machines have; Debian 12's nodejs 18 is too old for Vite 7)" >&2
    exit 77
  fi
done

mkdir -p "$out"
out=$(cd "$out" && pwd)
hash() { (cd "$here" && sha256sum "$@" | sha256sum | cut -d' ' -f1); }
stamp=$(hash "${files[@]}")
if [[ -f $out/stamp && $(cat "$out/stamp") == "$stamp" && -f $out/dist/index.html ]]; then
  echo "build_viewer: $out/dist is up to date"
  exit 0
fi
rm -f "$out/stamp"
(cd "$here" && cp "${files[@]}" "$out/")
cd "$out"
start=$(date +%s)
# npm ci only when the packages change. --ignore-scripts: the only install scripts are core-js's
# banner and msgpackr's optional native addon (msgpackr falls back to JavaScript), nothing the
# bundle needs.
packages=$(hash package.json package-lock.json)
if [[ ! -f packages.stamp || $(cat packages.stamp) != "$packages" ]]; then
  rm -f packages.stamp
  npm ci --ignore-scripts --no-audit --no-fund --loglevel=error
  echo "$packages" >packages.stamp
fi
installed=$(date +%s)
npx --no-install vite build
echo "build_viewer: npm ci $((installed - start)) s, vite build $(($(date +%s) - installed)) s"
echo "$stamp" >stamp
