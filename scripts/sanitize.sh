#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer: builds demcal and its tests into build-asan/ and runs the unit tests
# (ctest -LE _heavy: no YADE, no SLURM, not slow, not a benchmark; the readers' fuzz tests included). Any memory
# error, leak or undefined behaviour fails the test that met it. Arguments go to ctest (e.g. -R fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS="$flags" \
      -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
      >/dev/null
cmake --build build-asan -j "${JOBS:-$(nproc)}" --target demcal test_analytics test_kernel test_orchestrator test_calibration
cd build-asan
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest -LE _heavy --output-on-failure --timeout 1200 "$@"
