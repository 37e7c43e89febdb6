#!/usr/bin/env bash
# --integrator auto against every integrator at equal total time (pilots included): on Bitterli's scenes, each of
# path, bdpt and mlt renders for SECONDS (--time-limit), and so does auto (its pilots inside the same limit); relMSE
# (eps 0.01) against pbrt-v4's converged renders. Prints, per scene, auto's choice, its relMSE and each
# integrator's. Usage: bench/auto_integrator.sh [SECONDS] [BUILD_DIR]   (docs/error-estimates.md)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-15}"
candela="${2:-build}/candela"
shared=../shared
out="${OUT_DIR:-/tmp/candela-auto}"
mkdir -p "$out"
relmse() { /usr/bin/python3 "$shared/tools/imgcmp.py" "$1" "$2" | awk '/relmse/ {print $2}'; }
while read -r name resolution; do
  scene=$shared/scenes/bitterli/$name/scene-v4.pbrt
  reference=$shared/scenes/bitterli/$name/pbrt-v4-reference.exr
  line="$name ${seconds}s:"
  for integrator in path bdpt mlt; do
    "$candela" render "$scene" --integrator "$integrator" --resolution "$resolution" --spp 1000000 --time-limit "$seconds" \
      -q -o "$out/$name-$integrator.exr" > /dev/null 2>&1
    line="$line $integrator $(relmse "$out/$name-$integrator.exr" "$reference")"
  done
  choice=$("$candela" render "$scene" --integrator auto --resolution "$resolution" --time-limit "$seconds" -q \
    -o "$out/$name-auto.exr" 2>/dev/null | sed -n 's/.*chose \([a-z]*\) (pilots \([0-9.]*\) s.*/\1 (pilots \2 s)/p')
  echo "$line | auto chose $choice: $(relmse "$out/$name-auto.exr" "$reference")"
done <<LIST
veach-bidir 192x192
veach-ajar 320x180
cornell-box 256x256
veach-mis 320x180
LIST
