#!/usr/bin/env bash
# Runs every fuzz target built by fuzz/build.sh: first the committed crash inputs of
# fuzz/regressions/<target>/ once each, then SECONDS (default 30) of fuzzing over fuzz/corpus/<target>/.
# Exits non-zero on the first crash, sanitizer report, timeout (>10 s for one input) or OOM.
# Usage: fuzz/run.sh [SECONDS] [TARGET...]   TARGET is json_reader, pbrt_reader, obj_reader, ply_reader,
# serialized_reader, mitsuba_reader, gltf_reader, vol_reader, nanovdb_reader, part_reader, checkpoint_reader,
# http_request, gzip, spectrum_file
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${1:-30}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(json_reader pbrt_reader obj_reader ply_reader serialized_reader mitsuba_reader gltf_reader
  vol_reader nanovdb_reader part_reader checkpoint_reader http_request gzip spectrum_file)
# Leaks inside libraries candela cannot fix are suppressed by name (fuzz/lsan_suppressions.txt).
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan_suppressions.txt${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for target in "${targets[@]}"; do
  binary="$build/fuzz_$target"
  dict="$root/fuzz/${target%_reader}.dict"
  mkdir -p "$work/$target" "$work/artifacts-$target"
  regressions=("$root"/fuzz/regressions/"$target"/*)
  if [ -e "${regressions[0]}" ]; then
    echo "-- $target: ${#regressions[@]} regression inputs"
    "$binary" -timeout=10 -rss_limit_mb=2048 "${regressions[@]}" 2>&1 | tail -n 3
  fi
  echo "-- $target: fuzzing for ${seconds}s"
  # A fixed seed makes CI's short run repeatable (FUZZ_SEED=0 picks a random one).
  if ! "$binary" -seed="${FUZZ_SEED:-1}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -dict="$dict" \
      -artifact_prefix="$work/artifacts-$target/" -print_final_stats=1 \
      "$work/$target" "$root/fuzz/corpus/$target" > "$work/$target.log" 2>&1; then
    tail -n 60 "$work/$target.log"
    for crash in "$work/artifacts-$target"/*; do
      [ -e "$crash" ] && { echo "crash input $crash (base64):"; base64 "$crash" | head -c 4000; echo; }
    done
    echo "fuzz target $target FAILED"
    exit 1
  fi
  grep -E '^Done|stat::number_of_executed_units' "$work/$target.log" || true
done
echo "all fuzz targets passed"
