#!/usr/bin/env bash
# High-budget agreement of path, bdpt and mlt (the long version of tests/bidirectional_test.cpp's
# BidirectionalAgreement): small images at many samples, then each image's mean against the path
# tracer's and the relMSE (eps 0.01) between them. Usage: bench/integrator_agreement.sh
set -euo pipefail
cd "$(dirname "$0")/.."
candela=./build/candela
shared=../shared
out="${OUT_DIR:-/tmp/candela-agreement}"
mkdir -p "$out"
while read -r name scene resolution path_spp bdpt_spp mlt_mutations; do
  "$candela" render "$scene" --integrator path --spp "$path_spp" --resolution "$resolution" -q -o "$out/$name-path.exr" > /dev/null 2>&1
  "$candela" render "$scene" --integrator bdpt --spp "$bdpt_spp" --resolution "$resolution" -q -o "$out/$name-bdpt.exr" > /dev/null 2>&1
  "$candela" render "$scene" --integrator mlt --spp "$mlt_mutations" --resolution "$resolution" -q -o "$out/$name-mlt.exr" > /dev/null 2>&1
  for integrator in bdpt mlt; do
    /usr/bin/python3 "$shared/tools/imgcmp.py" "$out/$name-$integrator.exr" "$out/$name-path.exr" |
      awk -v n="$name" -v i="$integrator" '/relmse/ {r=$2} /mean_ratio/ {m=$2} END {printf "%-12s %-4s vs path: mean ratio %s, relMSE %s\n", n, i, m, r}'
  done
done <<LIST
cornell-box scenes/cornell-box.json 64x64 8192 1024 4096
veach-mis $shared/scenes/bitterli/veach-mis/scene-v4.pbrt 64x36 16384 2048 8192
caustic scenes/caustic.json 48x36 65536 4096 8192
room scenes/room.json 64x48 8192 1024 4096
LIST
