#!/usr/bin/env bash
# Equal-time comparison of candela's integrators (path, bdpt, mlt): each renders for the same wall
# time (--time-limit; whole passes, so a little over), then relMSE (eps 0.01) against a reference:
# pbrt-v4's converged renders of Bitterli's scenes, and for the glass-sphere caustic a long bdpt
# render made here first. Prints one line per render. Usage: bench/bidirectional_equal_time.sh [SECONDS]
# TRANSPORT=rgb|spectral overrides each scene's transport (pbrt-v4 files default to spectral).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-20}"
candela=./build/candela
shared=../shared
out="${OUT_DIR:-/tmp/candela-equal-time}"
mkdir -p "$out"
transport=(${TRANSPORT:+--transport "$TRANSPORT"})
imgcmp() { /usr/bin/python3 "$shared/tools/imgcmp.py" "$1" "$2" | awk '/relmse/ {r=$2} /mean_ratio/ {m=$2} END {printf "relMSE %s mean-ratio %s", r, m}'; }

if [ ! -f "$out/caustic-reference.exr" ]; then
  "$candela" render scenes/caustic.json --integrator bdpt --spp 8192 --resolution 160x120 -q -o "$out/caustic-reference.exr" > /dev/null
fi
while read -r name scene resolution reference; do
  for integrator in path bdpt mlt; do
    "$candela" render "$scene" --integrator "$integrator" --resolution "$resolution" --spp 1000000 "${transport[@]}" \
      --time-limit "$seconds" -q -o "$out/$name-$integrator.exr" > /dev/null 2>&1 || true
    printf '%-12s %-5s %4ss  %s\n' "$name" "$integrator" "$seconds" "$(imgcmp "$out/$name-$integrator.exr" "$reference")"
  done
done <<LIST
veach-bidir $shared/scenes/bitterli/veach-bidir/scene-v4.pbrt 192x192 $shared/scenes/bitterli/veach-bidir/pbrt-v4-reference.exr
veach-ajar $shared/scenes/bitterli/veach-ajar/scene-v4.pbrt 320x180 $shared/scenes/bitterli/veach-ajar/pbrt-v4-reference.exr
caustic scenes/caustic.json 160x120 $out/caustic-reference.exr
cornell-box $shared/scenes/bitterli/cornell-box/scene-v4.pbrt 256x256 $shared/scenes/bitterli/cornell-box/pbrt-v4-reference.exr
LIST
