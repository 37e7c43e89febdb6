#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, -fsanitize=fuzzer,address,undefined) in build-fuzz/.
# Usage: [FUZZ_OPT=-O0] fuzz/build.sh   -> build-fuzz/fuzz_{json,pbrt,obj,ply,serialized}_reader
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
# FUZZ_OPT (default -O1) is the optimisation level: CI builds at -O0, which compiles in about half the
# time (its 8-second runs are a smoke test; long fuzzing runs want the default). Line tables only:
# enough for symbolised sanitizer stacks, far cheaper to compile than full debug information.
CC=clang-14 CXX=clang++-14 cmake -S "$root/fuzz" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="${FUZZ_OPT:--O1} -gline-tables-only -DNDEBUG"
cmake --build "$build" -j "${FUZZ_JOBS:-2}"
