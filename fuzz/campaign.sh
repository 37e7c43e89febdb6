#!/usr/bin/env bash
# A fuzzing campaign: each target run until it has executed RUNS inputs in all (default 10 million), over a
# corpus kept between campaigns in CAMPAIGN_DIR/<target>/ (default ../fuzz-campaign, outside the tree),
# seeded from fuzz/corpus/<target>/. Runs go in chunks of CHUNK inputs (default 1 million), one line each
# in CAMPAIGN_DIR/summary.tsv: date, target, executions, seconds, inputs/s, coverage (edges), corpus size,
# peak RSS, result. The executions of earlier clean lines count towards RUNS, so a campaign killed with
# its session loses one chunk at most and the next call goes on where it stopped. A crashing input stays
# in CAMPAIGN_DIR/artifacts-<target>/ and ends that target's campaign. docs/reliability.md records them.
# TIMEOUT (default 60 s, CI has 10) is per input in wall time: generous, as a campaign runs at nice 19
# beside builds, where a 0.5 s input can take 30 s of wall time.
# Usage: fuzz/campaign.sh [RUNS] [TARGET...]   (targets as in fuzz/run.sh; build them with fuzz/build.sh)
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
campaign="${CAMPAIGN_DIR:-$root/../fuzz-campaign}"
chunk="${CHUNK:-1000000}"
runs="${1:-10000000}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(checkpoint_reader json_reader pbrt_reader obj_reader mitsuba_reader vol_reader
  ply_reader gzip serialized_reader http_request gltf_reader nanovdb_reader part_reader spectrum_file)
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan_suppressions.txt${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
mkdir -p "$campaign"
touch "$campaign/summary.tsv"
# Executions so far: the clean lines of the summary (and runs ended without a finding, marked "no finding").
executed() { awk -F'\t' -v t="$1" '$2 == t && ($9 == "clean" || $9 ~ /no finding/) { n += $3 } END { print n + 0 }' \
  "$campaign/summary.tsv"; }
status=0
for target in "${targets[@]}"; do
  corpus="$campaign/$target" artifacts="$campaign/artifacts-$target" log="$campaign/$target.log"
  mkdir -p "$corpus" "$artifacts"
  while done_so_far=$(executed "$target"); [ "$done_so_far" -lt "$runs" ]; do
    this_run=$(( runs - done_so_far < chunk ? runs - done_so_far : chunk ))
    start=$(date +%s)
    # A random seed per run (libFuzzer picks one).
    "$build/fuzz_$target" -runs="$this_run" -timeout="${TIMEOUT:-60}" -rss_limit_mb=2048 -dict="$root/fuzz/${target%_reader}.dict" \
      -artifact_prefix="$artifacts/" -print_final_stats=1 "$corpus" "$root/fuzz/corpus/$target" > "$log" 2>&1
    rc=$?
    seconds=$(( $(date +%s) - start ))
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
    rss=$(grep -o 'stat::peak_rss_mb: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || true)
    result=clean
    [ $rc -eq 0 ] || result="FAILED (exit $rc; $log)"
    line="$(date -u +%F)	$target	${execs:-?}	$seconds	$(( ${execs:-0} / (seconds > 0 ? seconds : 1) ))	${cov:-?}	$(ls "$corpus" | wc -l)	${rss:-?} MB	$result"
    echo "$line" | tee -a "$campaign/summary.tsv"
    if [ $rc -ne 0 ]; then
      cp "$log" "$campaign/$target.failed.log"
      status=1
      break
    fi
  done
done
exit $status
