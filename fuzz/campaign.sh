#!/usr/bin/env bash
# A fuzzing campaign: each target run until it has executed RUNS inputs (default 10 million), over a
# corpus kept between campaigns in CAMPAIGN_DIR/<target>/ (default ../fuzz-campaign, outside the tree),
# seeded from fuzz/corpus/<target>/. One line per target goes to CAMPAIGN_DIR/summary.tsv: date,
# target, executions, seconds, inputs/s, coverage (edges), corpus size, peak RSS, result; a crashing
# input stays in CAMPAIGN_DIR/artifacts-<target>/. docs/reliability.md records the campaigns run.
# Usage: fuzz/campaign.sh [RUNS] [TARGET...]   (targets as in fuzz/run.sh; build them with fuzz/build.sh)
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
campaign="${CAMPAIGN_DIR:-$root/../fuzz-campaign}"
runs="${1:-10000000}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(checkpoint_reader json_reader pbrt_reader obj_reader mitsuba_reader vol_reader
  ply_reader gzip serialized_reader http_request gltf_reader nanovdb_reader part_reader)
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan_suppressions.txt${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
mkdir -p "$campaign"
status=0
for target in "${targets[@]}"; do
  corpus="$campaign/$target" artifacts="$campaign/artifacts-$target" log="$campaign/$target.log"
  mkdir -p "$corpus" "$artifacts"
  start=$(date +%s)
  # A random seed per campaign (libFuzzer picks one).
  "$build/fuzz_$target" -runs="$runs" -timeout=10 -rss_limit_mb=2048 -dict="$root/fuzz/${target%_reader}.dict" \
    -artifact_prefix="$artifacts/" -print_final_stats=1 "$corpus" "$root/fuzz/corpus/$target" > "$log" 2>&1
  rc=$?
  seconds=$(( $(date +%s) - start ))
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  rss=$(grep -o 'stat::peak_rss_mb: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || true)
  result=clean
  if [ $rc -ne 0 ]; then
    result="FAILED (exit $rc; $log)"
    status=1
  fi
  line="$(date -u +%F)	$target	${execs:-?}	$seconds	$(( ${execs:-0} / (seconds > 0 ? seconds : 1) ))	${cov:-?}	$(ls "$corpus" | wc -l)	${rss:-?} MB	$result"
  echo "$line" | tee -a "$campaign/summary.tsv"
done
exit $status
