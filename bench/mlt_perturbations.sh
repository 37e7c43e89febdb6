#!/usr/bin/env bash
# MLT's lens and caustic perturbations against small steps alone, at equal mutations, seed by seed, on
# the room lit through a slit (bench/scenes/slit-room.json): relMSE (eps 0.01) against a long BDPT render
# made first (8192 spp, about 5 min on 2 cores; kept in OUT_DIR), and the image-mean ratio (the
# normalisation is the same for every setting of a seed: it does not depend on the mutations). Then
# path, bdpt and mlt at the MLT run's wall time.
# Usage: bench/mlt_perturbations.sh [MUTATIONS_PER_PIXEL (1024)] [SEEDS (8)]
set -euo pipefail
cd "$(dirname "$0")/.."
mutations="${1:-1024}"
seeds="${2:-8}"
candela=./build/candela
scene=bench/scenes/slit-room.json
out="${OUT_DIR:-/tmp/candela-mlt-perturbations}"
mkdir -p "$out"
if [ ! -f "$out/reference.exr" ]; then
  "$candela" render "$scene" --integrator bdpt --spp 8192 --seed 1000 -q -o "$out/reference.exr" > /dev/null
fi
compare() {
  for image in "$@"; do
    printf '%-20s %s\n' "$(basename "$image")" "$(/usr/bin/python3 ../shared/tools/imgcmp.py "$image" "$out/reference.exr" |
      awk '/relmse/ {r=$2} /mean_ratio/ {m=$2} END {printf "relMSE %s mean-ratio %s", r, m}')"
  done
}
seconds=0
for seed in $(seq 1 "$seeds"); do
  for setting in "off" "lens:--mlt-lens 0.3" "caustic:--mlt-caustic 0.3"; do
    name="${setting%%:*}"
    flags=""
    [ "$name" != off ] && flags="${setting#*:}"
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$candela" render "$scene" --integrator mlt --spp "$mutations" --seed "$seed" $flags -q -o "$out/mlt-$name-$seed.exr" > /dev/null
    [ "$name" = off ] && seconds=$(echo "$(date +%s.%N) - $start" | bc)
  done
  compare "$out/mlt-off-$seed.exr" "$out/mlt-lens-$seed.exr" "$out/mlt-caustic-$seed.exr"
done
limit=$(printf '%.0f' "$seconds")
echo "equal time (${limit} s, the last MLT run's):"
for integrator in path bdpt; do
  "$candela" render "$scene" --integrator "$integrator" --spp 1000000 --time-limit "$limit" -q -o "$out/$integrator.exr" > /dev/null
done
compare "$out/path.exr" "$out/bdpt.exr" "$out/mlt-off-$seeds.exr"
