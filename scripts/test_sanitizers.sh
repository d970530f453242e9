#!/usr/bin/env bash
# The sanitizer and fuzz step (docs/validation.md, "Bad input"): builds the asan preset (clang,
# AddressSanitizer + UndefinedBehaviorSanitizer, the libFuzzer targets) in build/asan, then
#   1. runs the C++ tests (ctest) under the sanitizers;
#   2. runs every bad input of tests/python/bad_corpus.py (and the seeds) once through each
#      fuzz target, and the bad traces through the sanitized rtsim-sim (each must exit 2);
#   3. runs the bad-input pytest corpus against the sanitized rtsim-sim;
#   4. fuzzes each target for FUZZ_SECONDS from the project's own seed corpus.
# Needs scripts/setup.sh first (the rtsim package makes the corpus). Installs clang and the
# libFuzzer runtime if missing. Env: FUZZ_SECONDS (default 45), PYTHON (default python),
# SANITIZER_SCOPE: "full" (default: every step above) or "ci" (what .ci/run does within its time
# budget: the fuzz targets and the C++ tests of the loader, BVH builders, intersection, ray
# generation, trace format and tracer under the sanitizers (not the SystemC model's, nor the
# structures' suite test_accel); steps 1, 2 and 4 for them; no sanitized rtsim-sim).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PYTHON="${PYTHON:-python}"
FUZZ_SECONDS="${FUZZ_SECONDS:-45}"
SANITIZER_SCOPE="${SANITIZER_SCOPE:-full}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  SUDO="sudo"
fi
missing=()
for pkg in clang libclang-rt-14-dev; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "sanitizers: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

start=$(date +%s)
echo "== sanitizers: building build/asan (clang, ASan + UBSan, fuzz targets)"
# The ci scope builds in unity batches (about half the compile time); the full scope builds file
# by file, with no precompiled header either, so a file that forgot an include fails here.
unity=OFF
[ "$SANITIZER_SCOPE" = "ci" ] && unity=ON
cmake --preset asan -DCMAKE_UNITY_BUILD=$unity >/dev/null
# The ci scope leaves out the model's tests and test_accel (the structures' suite: a quarter of
# this build and two thirds of its test time under the sanitizers); the structures still run here
# through the tracer's tests and the trace reader's fuzz target, and the full scope runs them all.
CI_TESTS="test_bvh test_format test_isect test_raygen test_scene test_tracer"
if [ "$SANITIZER_SCOPE" = "ci" ]; then
  # shellcheck disable=SC2086  # the list is words on purpose
  cmake --build build/asan -j "${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}" \
    --target fuzz_gltf_loader fuzz_trace_reader fuzz_config $CI_TESTS
else
  cmake --build build/asan -j "${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}"
fi
built=$(date +%s)

# SystemC allocates kernels and processes it never frees (and the tests make one kernel per
# test): leak checking is for the fuzzers, which do not use SystemC.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=0:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
echo "== sanitizers: C++ tests ($SANITIZER_SCOPE scope)"
# Not built in the ci scope: the model's tests (ctest lists them as test_model_NOT_BUILT).
# Known failure under clang -O1 only (docs/accel.md, grid "Known limits"): the grid's DDA
# disagrees with brute force on 3 of 3,000 random rays through a soup scaled to 1e-15.
# The binned builder's identity test compares tree hashes recorded from the GCC Release build;
# clang -O1 builds other trees from the same input (its multi-threaded trees still equal its
# single-threaded ones): a known compiler dependence, under investigation (docs/bvh_layout.md).
known="GridHardCases.HugeAndTinyCoordinates|BinnedSahIdentity.TreesHashToTheOriginalAlgorithms"
# Too slow for CI under the sanitizers (8 and 1.2 minutes at -O1; seconds in the plain ctest):
# the full scope runs them.
slow="MailboxPerStructure.ChangesNoHitAndKeepsTheLedgerExact|SpacePartition.HitsEqualOnEveryProceduralScene"
skip="_NOT_BUILT|$known|$slow"
[ "$SANITIZER_SCOPE" = "ci" ] || skip="$known"
ctest --test-dir build/asan --output-on-failure -j2 -E "$skip" || status=1

work=build/asan/fuzz-work
rm -rf "$work"
mkdir -p "$work/artifacts"
"$PYTHON" scripts/make_fuzz_corpus.py "$work/corpus"

echo "== sanitizers: every bad input and seed once, through each fuzz target"
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1"
for target in gltf_loader trace_reader config; do
  short=${target%%_*}
  exe="build/asan/tests/fuzz/fuzz_$target"
  # With files as arguments libFuzzer runs each once and stops at the first crash.
  "$exe" -timeout=20 -artifact_prefix="$work/artifacts/" \
    "$work/corpus/$short"/bad/* "$work/corpus/$short"/seed/* </dev/null >"$work/$short-once.log" 2>&1 \
    || { echo "sanitizers: an input crashed $exe (log: $work/$short-once.log)"; tail -30 "$work/$short-once.log"; status=1; }
  echo "  fuzz_$target: $(grep -c "^Running: " "$work/$short-once.log") inputs, $(grep -c "^Executed " "$work/$short-once.log") ran clean"
done

if [ "$SANITIZER_SCOPE" != "ci" ]; then
echo "== sanitizers: bad traces through the sanitized rtsim-sim (each must exit 2)"
export ASAN_OPTIONS="detect_leaks=0"
for trace in "$work"/corpus/sim/*; do
  code=0
  build/asan/sim/rtsim-sim "$trace" -o "$work/run" >"$work/sim.log" 2>&1 || code=$?
  if [ "$code" -ne 2 ] || ! grep -q "$trace/trace.rtt" "$work/sim.log"; then
    echo "sanitizers: rtsim-sim $trace exited $code:"; cat "$work/sim.log"; status=1
  fi
done
echo "== sanitizers: bad-input pytest corpus against the sanitized rtsim-sim"
RTSIM_SIM="$PWD/build/asan/sim/rtsim-sim" "$PYTHON" -m pytest tests/python/test_bad_inputs.py \
  tests/python/test_hostile_traces.py -q -k "trace or manifest or config or frame or grid or edits" \
  || status=1
fi

echo "== sanitizers: fuzzing each target for ${FUZZ_SECONDS} s"
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1"
for target in gltf_loader trace_reader config; do
  short=${target%%_*}
  corpus="$work/live-$short"
  mkdir -p "$corpus"
  cp "$work/corpus/$short"/seed/* "$corpus/"
  if ! "build/asan/tests/fuzz/fuzz_$target" "$corpus" -max_total_time="$FUZZ_SECONDS" -timeout=20 \
      -rss_limit_mb=3072 -print_final_stats=1 -artifact_prefix="$work/artifacts/" </dev/null \
      >"$work/fuzz-$target.log" 2>&1; then
    echo "sanitizers: fuzz_$target found a crash, hang or leak (artifacts: $work/artifacts):"
    grep -E "ERROR|SUMMARY|Test unit written|runtime error" "$work/fuzz-$target.log" | head -20
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$work/fuzz-$target.log" | sed "s/^/  fuzz_$target: /"
done

end=$(date +%s)
echo "sanitizers: build $((built - start)) s, checks $((end - built)) s"
if [ "$status" -ne 0 ]; then
  echo "sanitizers: FAILED" >&2
else
  echo "sanitizers: all passed"
fi
exit "$status"
