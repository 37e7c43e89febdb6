#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, -fsanitize=fuzzer,address,undefined) in build-fuzz/.
# Usage: fuzz/build.sh   -> build-fuzz/fuzz_{json,pbrt,obj,ply,serialized,mitsuba,gltf,vol,nanovdb,part,checkpoint}_reader,
#          build-fuzz/fuzz_http_request, build-fuzz/fuzz_gzip, build-fuzz/fuzz_spectrum_file
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
CC=clang-14 CXX=clang++-14 cmake -S "$root/fuzz" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$build" -j "${FUZZ_JOBS:-2}"
