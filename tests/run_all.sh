#!/usr/bin/env bash
# The whole test run (README "Run the tests", and what .ci/run runs), in two
# builds:
#   1. the suite on an optimised GCC build with warnings as errors (build/);
#   2. one clang build instrumented with AddressSanitizer and
#      UndefinedBehaviorSanitizer, whose libraries under tests/fuzz's
#      harnesses also carry libFuzzer's coverage (build-check/):
#      the suite again under the sanitizers, halting on the first error (all
#      but the statistical batteries, which stage 2 ran), then
#      every libFuzzer harness of tests/fuzz for PVTWIN_FUZZ_SECONDS each
#      (default 60; one harness per core at a time) on its seeds, the
#      golden inputs and the example configs, after replaying every kept
#      crash.
# Neither build uses link-time optimisation (it buys the product a few per
# cent and costs the test build minutes), and both carry line tables only
# (-g1): the sanitizers' backtraces keep their file:line, the code is the
# same as with -g, and the full debug information cost a quarter to a third
# of each file's compile time. Each stage's time is printed, and a summary
# at the end. Stops at the first failure. A crash the fuzzer finds
# is written to build-check/crashes/: copy it into tests/fuzz/corpus/<harness>/
# once fixed, where the replay keeps it as a regression case.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
fuzz_seconds=${PVTWIN_FUZZ_SECONDS:-60}

stage_names=()
stage_seconds=()
stage_name=""
stage_start=0
finish_stage() {
  [ -n "$stage_name" ] || return 0
  local took=$((SECONDS - stage_start))
  stage_names+=("$stage_name")
  stage_seconds+=("$took")
  printf '=== %s: %d min %02d s\n' "$stage_name" $((took / 60)) $((took % 60))
  stage_name=""
}
stage() {
  finish_stage
  stage_name=$1
  stage_start=$SECONDS
  printf '\n=== %s (started %s UTC)\n' "$1" "$(date -u +%H:%M:%S)"
}
summary() {
  local status=$?
  finish_stage
  printf '\n=== time per stage\n'
  local i
  for i in "${!stage_names[@]}"; do
    printf '%6d s  %s\n' "${stage_seconds[$i]}" "${stage_names[$i]}"
  done
  printf '%6d s  in all\n' "$SECONDS"
  return $status
}
trap summary EXIT

# Ninja where it is installed: it compiles a target's files while the
# libraries under it still link, where make finishes each library first and
# leaves a core idle at every such step. A build directory keeps the
# generator it was configured with (the README's quick start uses make).
generator() {
  if [ -f "$1/CMakeCache.txt" ]; then
    sed -n 's/^CMAKE_GENERATOR:INTERNAL=//p' "$1/CMakeCache.txt"
  elif command -v ninja >/dev/null; then
    echo Ninja
  else
    echo "Unix Makefiles"
  fi
}

stage "1/5 optimised build (GCC, warnings as errors)"
flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"
  -DPVTWIN_BUILD_TESTS=ON -DPVTWIN_LTO=OFF)
cmake -S . -B build -G "$(generator build)" "${flags[@]}" -DPVTWIN_WERROR=ON >/dev/null
cmake --build build -j"$jobs"

stage "2/5 test suite"
ctest --test-dir build --output-on-failure -j"$jobs"

stage "3/5 sanitizer and fuzzing build (clang, ASan, UBSan, libFuzzer)"
# No -Werror here: build/ above enforces the warnings.
CXX=clang++ cmake -S . -B build-check -G "$(generator build-check)" "${flags[@]}" -DPVTWIN_WERROR=OFF \
  -DPVTWIN_SANITIZE=ON -DPVTWIN_FUZZ=ON >/dev/null
cmake --build build-check -j"$jobs"

stage "4/5 test suite under AddressSanitizer and UndefinedBehaviorSanitizer"
# alloc_dealloc_mismatch=0: libstdc++ 12 frees std::stable_sort's temporary
# buffer (stl_tempbuf.h, operator new(nothrow)) in a way ASan takes for
# new/free, a false report on every stable_sort; fixed in GCC 13's headers.
export ASAN_OPTIONS=halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1:alloc_dealloc_mismatch=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
# The statistical batteries (label battery, tests/CMakeLists.txt) ran in stage 2.
ctest --test-dir build-check --output-on-failure -j"$jobs" --timeout 900 -LE 'fuzz|battery'

stage "5/5 fuzzing, ${fuzz_seconds} s per harness"
ctest --test-dir build-check --output-on-failure -L fuzz  # every kept seed and crash
harnesses=(modbus_reply csv config model weather)
mkdir -p build-check/crashes
fuzz_one() {
  local name=$1 d
  # New inputs go to the first directory (scratch); the others are read-only seeds.
  local scratch=build-check/corpus-$name
  mkdir -p "$scratch"
  local seeds=(tests/fuzz/corpus/"$name") existing=()
  case "$name" in
    csv | model) seeds+=(tests/golden/csv tests/data/htwsaar-pvt) ;;
    config) seeds+=(tests/golden/config config/examples) ;;
    weather) seeds+=(tests/weather/data) ;;
  esac
  for d in "${seeds[@]}"; do [ -d "$d" ] && existing+=("$d"); done
  build-check/tests/fuzz/fuzz_"$name" -max_total_time="$fuzz_seconds" -max_len=65536 \
    -artifact_prefix=build-check/crashes/"$name"- -print_final_stats=1 \
    "$scratch" "${existing[@]}" 2>build-check/fuzz_"$name".log
}
# One harness per core at a time (each fuzzes on one core for the full
# time); a harness that finds a crash fails the stage after its round.
failed=0
for ((i = 0; i < ${#harnesses[@]}; i += jobs)); do
  round=("${harnesses[@]:i:jobs}")
  pids=()
  for name in "${round[@]}"; do
    echo "fuzz_$name: ${fuzz_seconds} s"
    fuzz_one "$name" &
    pids+=("$!")
  done
  for k in "${!round[@]}"; do
    name=${round[$k]}
    if wait "${pids[$k]}"; then
      grep -E '^stat::number_of_executed_units|^Done' build-check/fuzz_"$name".log || true
    else
      echo "fuzz_$name failed; a crash it found is kept as build-check/crashes/$name-*"
      tail -n 60 build-check/fuzz_"$name".log
      failed=1
    fi
  done
done
((failed == 0))
