#!/usr/bin/env bash
# ctest: installs the build into a fresh prefix, builds docs/example_extract.cpp against it with
# find_package(surftrack), runs it, and checks that no internal header was installed.
set -euo pipefail
build=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
for internal in TrackComponent.h BrickSlot.h BrickStepTable.h FrontQueue.h SurfaceGraph.h Image.h; do
  if [[ -e $work/prefix/include/surftrack/$internal ]]; then
    echo "internal header $internal was installed" >&2
    exit 1
  fi
done
cmake -S "$source/docs/example_project" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
LD_LIBRARY_PATH="$work/prefix/lib:${LD_LIBRARY_PATH:-}" "$work/build/example_extract" "$work/ball.ply"
test -s "$work/ball.ply"
