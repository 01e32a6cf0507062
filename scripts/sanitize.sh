#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer. Any memory error, leak or undefined behaviour fails the test that met
# it. Two scopes:
#   bash scripts/sanitize.sh [CTEST ARGS]   demcal and its tests in build-asan/, the unit tests run (ctest -LE _heavy:
#                                           no YADE, no SLURM, not slow, not a benchmark): about 80 min here
#                                           (measured at -O2 -g, stop 21; not again since the -O1 -g1 build).
#   bash scripts/sanitize.sh --fuzz [ARGS]  only the readers' fuzz tests (every "[fuzz]" case: material and geometry
#                                           JSON, measured CSV, silo-dem rates, the campaign store, shear results, flow
#                                           frames, a checkpoint's kernel state) in one executable, test_fuzz, built in
#                                           build-fuzz/ from just the libraries they read with: the part CI can afford
#                                           (scripts/test.sh runs it).
set -euo pipefail
cd "$(dirname "$0")/.."
# (-Wno-maybe-uninitialized: with ASan, GCC 12 warns falsely inside libstdc++'s regex, which Catch2 includes)
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -Wno-maybe-uninitialized"
# -O1 -g1 (line tables: a report still names file and line; no -DNDEBUG, so Eigen's, nlohmann's and our asserts check
# too) and without the kernel's wide inlining: the fuzz build
# took 25 of CI's 52 min at -O2 -g, 14 min of them in kernel/simulation.cpp alone (2.4 min this way, measured).
configure() {
  cmake -S . -B "$1" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
        -DDEMCAL_KERNEL_WIDE_INLINING=OFF -DCMAKE_CXX_FLAGS="$flags" \
        -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
        >/dev/null
}
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
if [ "${1:-}" = "--fuzz" ]; then
  shift
  configure build-fuzz
  cmake --build build-fuzz -j "${JOBS:-$(nproc)}" --target test_fuzz
  build-fuzz/tests/test_fuzz "[fuzz]" "$@"
else
  configure build-asan
  cmake --build build-asan -j "${JOBS:-$(nproc)}" --target demcal test_analytics test_kernel test_orchestrator test_calibration
  cd build-asan
  ctest -LE _heavy --output-on-failure --timeout 1200 "$@"
fi
