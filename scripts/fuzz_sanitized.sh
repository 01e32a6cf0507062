#!/usr/bin/env bash
# The readers' fuzz tests (every "[fuzz]" case: material and geometry JSON, measured CSV, silo-dem rates, the campaign
# store, shear results, flow frames) built with AddressSanitizer + UndefinedBehaviorSanitizer into build-fuzz/ and
# run: a mutation that makes a reader touch memory it must not, or compute undefined behaviour, fails here even where
# the unsanitized run happened to survive it. Only the libraries the readers use are built (not the app, not the other
# tests): the part of scripts/sanitize.sh (about 80 min) that CI can afford. Arguments go to the test executable.
set -euo pipefail
cd "$(dirname "$0")/.."
# (-Wno-maybe-uninitialized: with ASan, GCC 12 warns falsely inside libstdc++'s regex, which Catch2 includes)
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -Wno-maybe-uninitialized"
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS="$flags" \
      -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
      >/dev/null
cmake --build build-fuzz -j "${JOBS:-$(nproc)}" --target test_fuzz
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
build-fuzz/tests/test_fuzz "[fuzz]" "$@"
