#!/usr/bin/env bash
# The checks beyond the README's test command:
#   fuzz [seconds]  the libFuzzer targets of fuzz/: the header readers that locate voxel data
#                   (8 formats) and the chunked-store readers (zarr, N5 and OME-Zarr stores,
#                   metadata and chunk files; the blosc, zstd and gzip/zlib chunk decoders), run
#                   per format for a bounded time, seeded with files written by ITK, zarr-python
#                   and numcodecs (fuzz/run_fuzzers.sh; default 10 s per format; with
#                   SURFTRACK_FUZZ_RUNS=N, N inputs from a fixed seed instead). CI runs this
#                   with N = 1000 (.ci/run).
#   sanitize        the whole test suite again, in a build of its own with AddressSanitizer and
#                   UndefinedBehaviorSanitizer's value checks on the engine
#                   (-DSURFTRACK_SANITIZE=ON; CMakeLists.txt says which checks and where; any
#                   report fails its test). Run by hand before landing engine changes: it no
#                   longer fits in CI's 30 minutes. The CPU time of the build and of the tests
#                   is printed (the machines are shared: wall-clock figures depend on the
#                   others' load).
#   all [seconds]   both; the fuzzing, which runs one target at a time on one core, beside the
#                   sanitized build (its log printed when both are done), then the sanitized
#                   tests on a machine of their own.
#
#   scripts/ci-checks.sh fuzz|sanitize|all [seconds per fuzz target]
#
# Needs what scripts/setup.sh installs, plus clang for the fuzzers (installed here when missing).
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-all}
seconds=${2:-10}
here=$PWD
case $mode in
  fuzz | sanitize | all) ;;
  *) echo "usage: scripts/ci-checks.sh fuzz|sanitize|all [seconds per fuzz target]" >&2; exit 2 ;;
esac

# The CPU seconds of this script's finished child processes so far, in $cpu: on a shared
# machine the figure that says what a stage costs.
child_cpu() {
  local f
  read -r -a f </proc/$$/stat
  cpu=$(((f[15] + f[16]) / $(getconf CLK_TCK)))
}

sanitize_build() {
  local start cpu cpu0
  start=$(date +%s)
  child_cpu
  cpu0=$cpu
  # -O1: instrumented code at -O3 compiles about 4x slower (one test file: 765 s against 177 s
  # at -O1) for tests that run about 2x faster; stacks name functions (frame pointers kept), not
  # lines. No benchmarks (nor the CGAL tool they use).
  # The engine and its tests only: without the Python module (about 100 CPU-s of compile and
  # 100 of tests) nor the command-line tool and the ITK readers (about 450 CPU-s of compile),
  # to keep it within a quarter of an hour. Those are tested by the main build's suite, and the volume-header and
  # chunked-store readers under both sanitizers by the fuzzing beside this build (fuzz/).
  cmake -S . -B build-sanitize -DSURFTRACK_SANITIZE=ON -DSURFTRACK_BUILD_BENCH=OFF -DSURFTRACK_BUILD_PYTHON=OFF \
        -DSURFTRACK_BUILD_CLI=OFF \
        -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" >/dev/null
  cmake --build build-sanitize -j2 >build-sanitize.log 2>&1 || { tail -60 build-sanitize.log; exit 1; }
  child_cpu
  echo "ci-checks: sanitized build in $(($(date +%s) - start)) s ($((cpu - cpu0)) CPU-s)"
}

sanitize_tests() {
  local start cpu cpu0
  start=$(date +%s)
  child_cpu
  cpu0=$cpu
  # Not chunked_readers: it runs the tool and chunk_dump on stores in a hundred processes (108 s
  # sanitized); the store readers are fuzzed under both sanitizers by the fuzz stage, and their
  # findings and corpus replayed here by test_chunked_fuzz_replay.
  # Leaks inside third-party readers on their error paths are theirs (tests/lsan.supp names
  # each); every other leak, and every ASan or UBSan report, fails the test that caused it.
  # Exit code 86 for a report, so that a tool run by a test (test_cli) cannot pass a report
  # off as one of its own error exits.
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:exitcode=86" \
  LSAN_OPTIONS="suppressions=$here/tests/lsan.supp:print_suppressions=0" \
  UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=86" \
    ctest --test-dir build-sanitize --output-on-failure -j2 -E '^chunked_readers$'
  child_cpu
  echo "ci-checks: sanitized test suite in $(($(date +%s) - start)) s ($((cpu - cpu0)) CPU-s)"
}

fuzz() {
  if ! command -v clang++ >/dev/null; then
    local sudo=""
    [[ $(id -u) -eq 0 ]] || sudo="sudo"
    echo "ci-checks: installing clang (the fuzzers)" >&2
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq clang >/dev/null
  fi
  bash fuzz/run_fuzzers.sh "$seconds" "$here/build-fuzz"
}

case $mode in
  fuzz) fuzz ;;
  sanitize) sanitize_build; sanitize_tests ;;
  all)
    # The fuzzers run one at a time: on a 2-core machine their second core builds meanwhile.
    fuzz >build-fuzz.ci.log 2>&1 &
    fuzzing=$!
    trap 'kill $fuzzing 2>/dev/null || true' EXIT  # a failed build stops the fuzzing too
    sanitize_build
    fuzz_status=0
    wait $fuzzing || fuzz_status=$?
    cat build-fuzz.ci.log
    ((fuzz_status == 0)) || { echo "ci-checks: fuzzing failed (exit $fuzz_status)"; exit 1; }
    sanitize_tests ;;
esac
