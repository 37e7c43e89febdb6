#!/usr/bin/env bash
# The bitwise-identity check: renders a fixed list of scenes with two candela binaries (say, the
# last release and a refactored build) and reports per scene whether the two images are the same
# bytes. Images are written as .pfm (raw floats; an .exr's metadata holds the render time). Covers
# candela's JSON and pbrt-v4 readers, BDPT (with light-tracing splats), MLT, Mitsuba scenes
# (instancing; an environment map; a normal map), glTF (normal-mapped, a 1M-triangle model) and an
# environment-lit JSON scene written here.
#
# Usage: bench/bitwise_identity.sh OLD_CANDELA NEW_CANDELA [WORK_DIR]
# Exit status: 0 when every scene is identical, 1 otherwise.
set -uo pipefail
old="$1" new="$2"
work="${3:-$(mktemp -d)}"
root="$(cd "$(dirname "$0")/.." && pwd)"
shared="$root/../shared"
mkdir -p "$work"

# An environment-lit scene (equirectangular map, written here so that the list is self-contained).
cat > "$work/environment.json" <<JSON
{ "camera": { "position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov": 40, "width": 48, "height": 32 },
  "lights": [ { "type": "environment", "filename": "$shared/scenes/mitsuba-tests/common/textures/museum.exr",
                "rotate": 30 } ],
  "materials": { "metal": { "type": "conductor", "roughness": 0.2 } },
  "shapes": [ { "type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "metal" },
              { "type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0] } ] }
JSON

mitsuba="$shared/scenes/mitsuba-tests/tests/scenes"
gltf="$shared/meshes/gltf-sample-assets"
scenes=(
  "cornell-json|$root/scenes/cornell-box.json --resolution 64x64 --spp 16"
  "cornell-pbrt|$root/scenes/cornell-box.pbrt --resolution 64x64 --spp 16"
  "veach-mis|$shared/scenes/bitterli/veach-mis/scene-v4.pbrt --resolution 96x54 --spp 8"
  "veach-bidir-bdpt|$shared/scenes/bitterli/veach-bidir/scene-v4.pbrt --integrator bdpt --resolution 64x64 --spp 4"
  "caustic-mlt|$root/scenes/caustic.json --integrator mlt --resolution 48x48 --spp 4"
  "mitsuba-instancing|$mitsuba/instancing/test_instancing_path.xml --spp 16"
  "mitsuba-envmap|$mitsuba/bsdf_spheres/test_envmap_path.xml --spp 16"
  "mitsuba-normalmap|$mitsuba/bsdf_spheres/test_normalmap_path.xml --spp 16"
  "gltf-normal-tangent|$gltf/NormalTangentTest/glTF/NormalTangentTest.gltf --resolution 64x64 --spp 8"
  "gltf-1M-triangles|$gltf/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf --resolution 64x36 --spp 4"
  "json-environment|$work/environment.json --spp 16"
)

status=0
for entry in "${scenes[@]}"; do
  name="${entry%%|*}" args="${entry#*|}"
  # shellcheck disable=SC2086
  "$old" render $args --seed 7 -q -o "$work/$name-old.pfm" > "$work/$name-old.log" 2>&1 || { echo "$name: the old binary failed (see $work/$name-old.log)"; status=1; continue; }
  # shellcheck disable=SC2086
  "$new" render $args --seed 7 -q -o "$work/$name-new.pfm" > "$work/$name-new.log" 2>&1 || { echo "$name: the new binary failed (see $work/$name-new.log)"; status=1; continue; }
  if cmp -s "$work/$name-old.pfm" "$work/$name-new.pfm"; then
    echo "$name: identical ($(stat -c %s "$work/$name-new.pfm") bytes)"
  else
    echo "$name: DIFFERENT"
    status=1
  fi
done
exit $status
