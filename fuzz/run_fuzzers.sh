#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang in a build directory of their own, writes
# their seed corpus, replays the kept findings and runs each target for a bounded time: the
# volume-header readers (fuzz_volume_header_<f>, f = mha, mhd, nrrd, nhdr, nii, nii.gz, raw,
# tif) and the chunked-store readers (fuzz_chunked_store_<f>, f = zarr, n5, omezarr: whole
# stores, metadata and chunk files; blosc, zstd, gzip: one chunk decoded; fuzz/ChunkedStoreFuzz.h).
#
#   fuzz/run_fuzzers.sh [seconds per target, default 30] [build directory, default ./build-fuzz]
#
# Inputs, per format f:
#   fuzz/corpus/f/    the corpus kept in the repository: inputs that reach code the generated
#                     seeds do not, grown by exploratory runs (SURFTRACK_FUZZ_KEEP=1 below) and
#                     minimised with libFuzzer's -merge=1; small files.
#   fuzz/findings/f/  every input that once crashed, hung or made the readers disagree, kept
#                     once fixed: replayed first, each must pass (the gcc build's tests replay
#                     them too, and the corpus: tests/test_load_volume.cpp the header formats',
#                     tests/test_chunked_fuzz_replay.cpp the chunked formats').
#   <build>/corpus/f/ the seeds make_seed_corpus (header formats, by ITK and by hand) and
#                     make_store_seeds.py (chunked formats, by zarr-python and numcodecs) write.
# The store targets take fuzz/chunked_store.dict, the metadata's keys, as their dictionary.
#
# With SURFTRACK_FUZZ_RUNS=N each target runs N inputs from a fixed seed (SURFTRACK_FUZZ_SEED,
# default 1) instead of for a time: the same inputs on every machine, so that a finding is the
# code's, not the luck of one run (CI runs this way; exploring is for runs by time). With
# SURFTRACK_FUZZ_FORMATS="nii zarr" only those formats run. With SURFTRACK_FUZZ_KEEP=1 the
# inputs of the run that add coverage are merged into fuzz/corpus/f (minimised again, the
# corpus rewritten): run by time for a minute or two per format, then commit the corpus.
#
# Exit status: 0 no finding; 1 a crash, hang (> 10 s on one input), leak in surftrack code,
# out-of-memory or sanitizer report, a broken guarantee (fuzz_chunked_store: an exception the
# readers do not document, an error of more than one line, reads that disagree), or a kept
# finding that fails again (the reproducer is in <build>/runs/<format>/findings/, replay it with
# <build>/fuzz_<target>_<format> <file>; once fixed, keep it in fuzz/findings/<format>/); 77
# skipped: no clang++ (or g++).
# ctest-runnable with SKIP_RETURN_CODE 77 (tests/CMakeLists.txt registers it only with
# -DSURFTRACK_FUZZ_TEST=ON). Needs clang (Debian: apt-get install clang), ITK, and Debian's
# python3-zarr and python3-numcodecs for the store seeds.
set -euo pipefail

seconds=${1:-30}
build=${2:-$PWD/build-fuzz}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
formats=(${SURFTRACK_FUZZ_FORMATS:-mha mhd nrrd nhdr nii nii.gz raw tif zarr n5 omezarr blosc zstd gzip})

for tool in clang++ clang g++; do
  if ! command -v "$tool" >/dev/null; then
    echo "run_fuzzers: $tool not found: skipped (apt-get install clang)"
    exit 77
  fi
done

start=$(date +%s)
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
cmake -S "$here" -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang "${launcher[@]}" >"$build.configure.log" 2>&1 ||
  { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j"${SURFTRACK_FUZZ_JOBS:-2}" >"$build.build.log" 2>&1 || { tail -40 "$build.build.log"; exit 1; }
built=$(date +%s)
per="${seconds} s"
[[ -z ${SURFTRACK_FUZZ_RUNS:-} ]] || per="$SURFTRACK_FUZZ_RUNS inputs (seed ${SURFTRACK_FUZZ_SEED:-1})"
echo "run_fuzzers: built in $((built - start)) s; $per per target"

export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
limits=(-timeout=10 -rss_limit_mb=2048)
status=0
for f in "${formats[@]}"; do
  case $f in
    zarr | n5 | omezarr) target="$build/fuzz_chunked_store_$f" extra=(-dict="$here/chunked_store.dict") ;;
    blosc | zstd | gzip) target="$build/fuzz_chunked_store_$f" extra=() ;;
    *) target="$build/fuzz_volume_header_$f" extra=() ;;
  esac
  run="$build/runs/$f"
  rm -rf "$run"
  mkdir -p "$run/corpus" "$run/findings"
  # The kept findings, each run once.
  kept=("$here/findings/$f"/*)
  [[ -e ${kept[0]} ]] || kept=()
  if [[ ${#kept[@]} -gt 0 ]] &&
     ! "$target" "${kept[@]}" "${limits[@]}" -artifact_prefix="$run/findings/" </dev/null >"$run/replay.log" 2>&1; then
    echo "run_fuzzers: $f: a kept finding fails again (fuzz/findings/$f/):"
    grep -m3 -E "Running:|ERROR|SUMMARY|fuzz_[a-z_]* \(" "$run/replay.log" || tail -5 "$run/replay.log"
    status=1
    continue
  fi
  # A fresh corpus each run (kept in $run/corpus for inspection), grown from the seeds and the
  # repository's corpus.
  seeds=("$build/corpus/$f")
  [[ -d $here/corpus/$f ]] && seeds+=("$here/corpus/$f")
  if [[ -n ${SURFTRACK_FUZZ_RUNS:-} ]]; then
    budget=(-runs="$SURFTRACK_FUZZ_RUNS" -seed="${SURFTRACK_FUZZ_SEED:-1}")
  else
    budget=(-max_total_time="$seconds")
  fi
  if "$target" "$run/corpus" "${seeds[@]}" "${budget[@]}" "${limits[@]}" "${extra[@]}" \
       -artifact_prefix="$run/findings/" -print_final_stats=1 </dev/null >"$run/log" 2>&1; then
    result=ok
  elif [[ -n $(ls "$run/findings") ]]; then
    result="FINDING: $run/findings/$(ls "$run/findings" | head -1)"
    status=1
  else
    result="stopped without a finding: $(grep -m1 -E 'interrupted|ERROR' "$run/log" || echo 'see the log')"
    status=1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$run/log")
  cov=$(grep -o 'cov: [0-9]*' "$run/log" | tail -1)
  echo "run_fuzzers: $f: ${runs:-?} inputs, $cov, corpus $(ls "$run/corpus" | wc -l) files, ${#kept[@]} kept findings replayed: $result"
  [[ $result == ok ]] || grep -m3 -E "ERROR|SUMMARY|fuzz_[a-z_]* \(" "$run/log" || true
  # The repository's corpus and the run's inputs, minimised together: -merge=1 adds to a copy
  # of the generated seeds the fewest inputs that reach what the seeds do not; those (named by
  # their SHA-1) become fuzz/corpus/f.
  if [[ ${SURFTRACK_FUZZ_KEEP:-} == 1 && $result == ok ]]; then
    merged="$run/merged"
    mkdir -p "$merged" "$here/corpus/$f"
    cp "$build/corpus/$f"/* "$merged"/
    "$target" -merge=1 "$merged" "$here/corpus/$f" "$run/corpus" "${limits[@]}" "${extra[@]}" </dev/null >"$run/merge.log" 2>&1
    for seed in "$build/corpus/$f"/*; do rm -f "$merged/$(basename "$seed")"; done
    before=$(ls "$here/corpus/$f" | wc -l)
    rm -f "$here/corpus/$f"/*
    cp "$merged"/* "$here/corpus/$f"/ 2>/dev/null || true
    echo "run_fuzzers: $f: fuzz/corpus/$f: $before -> $(ls "$here/corpus/$f" | wc -l) files ($(du -sk "$here/corpus/$f" | cut -f1) KiB)"
  fi
done
echo "run_fuzzers: $(( $(date +%s) - start )) s in all"
exit $status
