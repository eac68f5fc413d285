#!/usr/bin/env bash
# The project's entry points (the README's Quick start):
#   cmake/run.sh demo   install what is missing, build, run the demo
#   cmake/run.sh test   install what is missing, build and run every test configuration, and build the release preset
set -euo pipefail
cd "$(dirname "$0")/.."

cmake/install-deps.sh

# Builds preset $1 and runs its tests.
build_and_test() {
  echo "==> $1: configure, build, test"
  cmake --preset "$1" >/dev/null
  cmake --build --preset "$1"
  ctest --preset "$1"
}

case "${1:-}" in
  demo)
    cmake --preset dev >/dev/null
    cmake --build --preset dev --target rcb4_demo rcb4_cli
    ./build/dev/examples/rcb4_demo          # a virtual RCB-4 plays motion 2; the moving servos are drawn
    echo
    echo "next: build/dev/bin/rcb4 --help   (every command works on the virtual board without a robot)"

    ;;
  test)
    build_and_test dev            # GCC 12, warnings as errors: unit, static, compile-fail, fuzz replay, Cortex-M4
    build_and_test asan-ubsan     # clang 16 with ASan + UBSan, and each libFuzzer harness for a short run
    build_and_test tsan           # clang 16 with ThreadSanitizer: the transport tests (threads, client, server)
    build_and_test no-exceptions  # the codec with -fno-exceptions -fno-rtti
    # The install route users are told to take (docs/install.md): it must build, warnings as errors,
    # with GCC's optimiser (whose false positives the debug build never sees). Its tests are the
    # dev preset's, run above.
    echo "==> release: configure, build"
    cmake --preset release >/dev/null
    cmake --build --preset release
    echo "==> all test configurations passed"
    ;;
  *)
    echo "usage: cmake/run.sh demo|test" >&2
    exit 2
    ;;
esac
