#pragma once
// The AOVs (film/aov_film.h) of one camera sample: what its ray sees first. CameraSampleTiles
// (camera_sample_tiles.h) calls first_hit_aovs for every camera sample when RenderOptions::aovs is
// set, with the sample's ray, and adds the result to the AovFilm with the sample's filter weight, so
// the layers are filtered as the colour is; render_aovs renders them alone through the same code.
//
// - depth, position: at the first surface the ray meets (interfaces without a surface, and what a
//   mask's absent part or a thin sheet lets pass straight on, are looked through). Depth is the
//   distance along the camera's viewing axis (planar z-depth, as Blender's Depth pass), measured from
//   the camera's z = 0 plane, where every camera ray starts.
// - albedo: the hemispherical-directional reflectance of the hit's BSDF for wo = -ray direction,
//   estimated with one BSDF sample (f |cos| / pdf, which is the reflectance exactly for a Lambertian
//   surface), with refraction's 1 / eta^2 radiance scaling undone (it is not reflectance), clamped to
//   [0, 1]. Surfaces with only delta lobes (mirrors, smooth glass) are followed, as OIDN's
//   documentation recommends: the sampled reflection or refraction is traced on, up to
//   kAovMaxSpecularBounces times, to the first surface with a non-delta lobe, whose albedo is taken
//   times the delta surfaces' throughput (averaged over samples, a smooth dielectric's albedo is then
//   the Fresnel blend of the reflected and transmitted albedos). Past that many bounces the last
//   delta surface's own one-sample estimate counts. BSDFs with both delta and non-delta lobes (a
//   smooth coat over a base) are estimated at the hit, whichever lobe the sample picks.
// - normal: the world-space shading normal (normal and bump maps included) of the surface whose
//   albedo is taken, turned to face the ray.
// - geometric_normal, uv, dpdx, dpdy: at the hit depth and position are taken at. The geometric
//   normal faces the ray (pbrt-v4's FaceForward(n, wo)). dpdx and dpdy follow pbrt-v4's ray
//   differentials of a camera ray: the rays through the film position one pixel to the right and one
//   pixel down (same lens point; an orthographic ray's origin moves instead) are intersected with the
//   hit's tangent plane, and the offsets of those points from the hit are dpdx and dpdy (zero where an
//   offset ray runs parallel to the plane).
// - A ray that escapes, directly or after delta bounces, has albedo 0 and normal 0. OIDN's
//   documentation says nothing about the albedo of escaped rays (its examples show none for the
//   background), and a zero normal is its "no surface". A camera ray that escapes has no depth or
//   position (AovFilm gives those pixels kAovMissDepth and 0).
//
// The random numbers (the BSDF samples) come from a generator of their own, seeded by (pixel, sample
// index, seed), never from the path's sampler: the colour is bitwise the same with and without AOVs,
// and the AOVs are the same for any thread count. Participating media do not change the AOVs.
#include <cstdint>

#include "candela/film/aov_film.h"
#include "candela/geometry/ray.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"

namespace candela {

inline constexpr int kAovMaxSpecularBounces = 4;

// The camera's frame and per-pixel ray steps (film/aov_film.h), from rays through the film's centre
// and the positions one pixel right and one down, through the lens centre at shutter open.
AovCameraFrame aov_camera_frame(const Camera& camera);

// The AOVs of the camera ray of sample `sample` of pixel (x, y). Without `shade` only the hit is
// found (depth and position), not the BSDF (albedo and normal stay 0).
AovSample first_hit_aovs(const Scene& scene, const Ray& camera_ray, bool shade, int x, int y, uint64_t sample,
                         uint64_t seed);

// Renders `aovs` alone, `spp` camera samples per pixel placed as the integrators place theirs
// (settings' sampler, filter and seed), through CameraSampleTiles with no radiance: for an
// integrator that does not trace its camera samples through CameraSampleTiles. options.aovs is
// ignored; the rest of `options` (threads, cancellation, ranks) applies.
void render_aovs(const Scene& scene, const RenderSettings& settings, AovFilm& aovs, const RenderOptions& options,
                 int spp = 16);

}  // namespace candela
