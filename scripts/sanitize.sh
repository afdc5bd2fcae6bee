#!/usr/bin/env bash
# The test suite built with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer (the command it runs included) in build-asan/,
# and run by ctest: any sanitizer report fails the test that caused it
# (docs/tests.md, "Sanitizers"). The consumer test, which needs an installed
# package, the Python module (an instrumented module would need the
# sanitizers' runtime preloaded into python3) and the README's printed block
# (what the main build prints; another compiler at -O1 may round its last
# digits differently) are left to the main build, and so is the test under
# an address-space limit (ulimit -v leaves no room for AddressSanitizer's
# shadow memory). The long runs are left out too, to keep CI within its
# time: the Catch2 cases tagged [large] (each over 40 s here under the
# sanitizers; shorter cases take the same code) and the viewer and batch
# tests, which run the command on whole molecules.
#     bash scripts/sanitize.sh [CTEST ARGS...]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$here/build-asan"

source "$here/scripts/install-packages.sh"
install_packages clang libclang-rt-14-dev  # clang++ and the sanitizers' runtimes

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# -O1: a third less compile time than -O2 here, and the tests still run in
# minutes; -g1: line numbers in reports.
cmake -S "$here" -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=None \
  -DSKINMESH_BUILD_TESTS=ON -DSKINMESH_BUILD_BENCH=OFF -DSKINMESH_INSTALL=OFF -DSKINMESH_PYTHON=OFF \
  "-DSKINMESH_TEST_SPEC=~[slow]~[large]" \
  -DCMAKE_CXX_FLAGS="-O1 -g1 -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -fsanitize-ignorelist=$here/scripts/ubsan-ignore.txt" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  "${launcher[@]}" >/dev/null
cmake --build "$build" -j "$(nproc)" --target skinmesh_tests skinmesh

# halt_on_error: the first report ends the process, so ctest sees a failure.
export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:abort_on_error=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" -E 'consumer|readme|doc_outputs|out of memory|viewer|batch_workflow' "$@"
