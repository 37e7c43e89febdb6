#!/usr/bin/env bash
# MLT's lens and caustic perturbations against small steps alone, at equal mutations, over seeds; then
# path and bdpt at the same wall time. Scenes: bench/scenes/ball-lens-room.json (the default: where the
# perturbations win) and bench/scenes/slit-room.json (where they do not); docs/bidirectional.md has both.
# Neither scene can be given a converged reference in reasonable time (BDPT and the path tracer barely find
# their light), so bench/mlt_seed_variance.py measures each setting's error from its spread over seeds and
# against the pooled renders of the other settings.
# Usage: bench/mlt_perturbations.sh [SCENE] [MUTATIONS_PER_PIXEL (1024)] [SEEDS (8)]
# Environment: EXTRA_SETTINGS="name:flags;name:flags" adds settings (e.g. "sigma0.003:--mlt-sigma 0.003");
# CROP="X0 X1 Y0 Y1" also reports the variance within those pixels (bench/scenes/small-caustic.json: the
# caustic is "50 96 62 86").
set -euo pipefail
cd "$(dirname "$0")/.."
scene="${1:-bench/scenes/ball-lens-room.json}"
mutations="${2:-1024}"
seeds="${3:-8}"
candela=./build/candela
out="${OUT_DIR:-/tmp/candela-mlt-perturbations}/$(basename "$scene" .json)"
mkdir -p "$out"
rm -f "$out"/mlt-*.exr  # a previous run's seeds would join this one's
settings=("off:" "lens:--mlt-lens 0.3" "caustic:--mlt-caustic 0.3" "lens+caustic:--mlt-lens 0.3 --mlt-caustic 0.3")
if [ -n "${EXTRA_SETTINGS:-}" ]; then
  IFS=';' read -r -a extra <<< "$EXTRA_SETTINGS"
  settings+=("${extra[@]}")
fi
names=()
for setting in "${settings[@]}"; do names+=("${setting%%:*}"); done
declare -A seconds
for seed in $(seq 1 "$seeds"); do
  for setting in "${settings[@]}"; do
    name="${setting%%:*}"
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$candela" render "$scene" --integrator mlt --spp "$mutations" --seed "$seed" ${setting#*:} -q \
      -o "$out/mlt-$name-$seed.exr" > /dev/null
    seconds[$name]=$(echo "${seconds[$name]:-0} + $(date +%s.%N) - $start" | bc)
  done
done
for setting in "${settings[@]}"; do
  name="${setting%%:*}"
  printf '%s: %.2f s per render\n' "$name" "$(echo "${seconds[$name]} / $seeds" | bc -l)"
done
limit=$(printf '%.0f' "$(echo "${seconds[off]} / $seeds" | bc -l)")
echo "path and bdpt at ${limit} s (the mean time of an MLT render without perturbations):"
for integrator in path bdpt; do
  "$candela" render "$scene" --integrator "$integrator" --spp 1000000 --time-limit "$limit" -q -o "$out/$integrator.exr" > /dev/null
done
# shellcheck disable=SC2086
/usr/bin/python3 bench/mlt_seed_variance.py "$out/mlt-NAME-[0-9]*.exr" "${names[@]}" \
  --also "$out/path.exr" "$out/bdpt.exr" ${CROP:+--crop $CROP}
