#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/) with clang, ASan and UBSan, makes the seed corpora from
# ../shared/data, and runs each harness for FUZZ_TIME seconds (FUZZ_JOBS at once), keeping going
# after a finding (fork mode). Findings land in $FUZZ_BUILD/findings/<harness>/, the grown corpus
# in $FUZZ_BUILD/corpus/<harness>/, one log per harness in $FUZZ_BUILD/logs/.
# Usage: scripts/fuzz.sh [harness ...]   (default: all seven)
#   FUZZ_TIME=1800 FUZZ_JOBS=2 FUZZ_BUILD=build-fuzz DATA=../shared/data
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ_TIME=${FUZZ_TIME:-1800}
FUZZ_JOBS=${FUZZ_JOBS:-2}
FUZZ_BUILD=${FUZZ_BUILD:-build-fuzz}
DATA=${DATA:-../shared/data}
harnesses=("$@")
[ ${#harnesses[@]} -eq 0 ] && harnesses=(pcd ply rgbd config database folder_database view)

command -v clang++-14 >/dev/null || { echo "fuzz: needs clang-14 and libclang-rt-14-dev (scripts/install-deps.sh --fuzz)" >&2; exit 1; }
flags="-O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all"
cmake -S . -B "$FUZZ_BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang-14 \
  -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="" -DPROXSEG_FUZZ=ON -DPROXSEG_BUILD_TESTS=OFF \
  -DPROXSEG_BUILD_BENCH=OFF -DPROXSEG_SHARED=OFF >/dev/null
cmake --build "$FUZZ_BUILD" -j "$(nproc)" --target make_seeds $(printf 'fuzz_%s ' "${harnesses[@]}")

export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
rm -rf "$FUZZ_BUILD/seeds"
"$FUZZ_BUILD/fuzz/make_seeds" "$DATA" "$FUZZ_BUILD/seeds"
mkdir -p "$FUZZ_BUILD/logs"
run() {
  local h=$1 b=$FUZZ_BUILD
  mkdir -p "$b/corpus/$h" "$b/findings/$h"
  # Regression inputs are seeds too: a fixed finding must stay fixed.
  local regress=()
  [ -d "tests/fuzz-regressions/$h" ] && regress=("tests/fuzz-regressions/$h")
  local dict=()
  [ -f "fuzz/$h.dict" ] && dict=("-dict=fuzz/$h.dict")
  "$b/fuzz/fuzz_$h" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$FUZZ_TIME" -timeout=20 -rss_limit_mb=2560 -max_len=262144 \
    -artifact_prefix="$b/findings/$h/" "${dict[@]}" "$b/corpus/$h" "$b/seeds/$h" "${regress[@]}" \
    >"$b/logs/$h.log" 2>&1 || true
  echo "fuzz_$h: $(grep -c '^==.*ERROR\|deadly signal\|Test unit written' "$b/logs/$h.log" || true) error lines," \
    "$(ls "$b/findings/$h" | wc -l) findings, $(ls "$b/corpus/$h" | wc -l) corpus inputs;" \
    "last status: $(grep -a '#[0-9]' "$b/logs/$h.log" | tail -n 1 | cut -c1-120)"
}
export -f run
export FUZZ_BUILD FUZZ_TIME
printf '%s\n' "${harnesses[@]}" | xargs -P "$FUZZ_JOBS" -I{} bash -c 'run {}'
# Fork-mode children that were stopped leave their scratch directories behind.
rm -rf /dev/shm/proxseg-fuzz-* 2>/dev/null || true
