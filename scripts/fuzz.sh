#!/usr/bin/env bash
# Fuzzes every reader (tests/fuzz/, docs/tests.md "Fuzzing"): builds the
# libFuzzer targets with clang, AddressSanitizer and UndefinedBehaviorSanitizer
# in build-fuzz/, makes their seed corpora from data/ and the project's
# writers, and runs each target for SECONDS (default 15). Inputs kept in
# tests/fuzz/inputs/<target>/ are fed in too. A crash, a leak, a sanitizer
# report or an input slower than 10 s stops that target, writes the input to
# build-fuzz/findings/<target>/ and makes this script fail: keep such an
# input in tests/fuzz/inputs/<target>/, where the test suite replays it.
#     bash scripts/fuzz.sh [SECONDS]
set -euo pipefail
seconds=${1:-15}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$here/build-fuzz"

source "$here/scripts/install-packages.sh"
install_packages clang libclang-rt-14-dev  # clang++ and libFuzzer's runtime

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$here" -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSKINMESH_FUZZ=ON -DSKINMESH_BUILD_TESTS=OFF -DSKINMESH_BUILD_BENCH=OFF -DSKINMESH_INSTALL=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -fsanitize-ignorelist=$here/scripts/ubsan-ignore.txt" \
  "${launcher[@]}" >/dev/null
cmake --build "$build" -j "$(nproc)" --target fuzz_targets

rm -rf "$build/seeds"
"$build/tests/fuzz/fuzz_seeds" "$here/data" "$build/seeds"
targets=$(ls "$build/seeds")
failed=0
printf '%-11s %9s %9s %7s  %s\n' target runs "exec/s" corpus result
for t in $targets; do
  mkdir -p "$build/corpus/$t" "$build/findings/$t"
  log="$build/findings/$t.log"
  # The first corpus folder takes what the run finds; the others are read.
  if UBSAN_OPTIONS=print_stacktrace=1 "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
       -print_final_stats=1 -artifact_prefix="$build/findings/$t/" \
       "$build/corpus/$t" "$build/seeds/$t" "$here/tests/fuzz/inputs/$t" >"$log" 2>&1; then
    result=ok
  else
    result="FINDING (see $log)"
    failed=1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  printf '%-11s %9s %9s %7s  %s\n' "$t" "${runs:-?}" "${speed:-?}" "$(ls "$build/corpus/$t" | wc -l)" "$result"
done
exit $failed
