#pragma once
// Ambient occlusion (integrator "ambient_occlusion"; pbrt-v4's AOIntegrator, "ambientocclusion"):
// not light transport but a picture of the geometry. At the first surface a camera ray meets, one
// occlusion ray leaves in a direction drawn over the hemisphere of the geometric normal turned
// towards the camera (shading normals, bump and normal maps play no part), and the sample is
//   cos(theta) / (pi pdf(direction))   if nothing lies within max_distance along it, else 0,
// whose expectation is the cosine-weighted unoccluded fraction of the hemisphere: 1 where nothing
// occludes, less in creases and under overhangs. With cosine-weighted directions (the default,
// pbrt's "cossample") every unoccluded sample is exactly 1; uniform directions give the same
// expectation with more noise. The value is that of a white illuminant: RGB 1 in an RGB render,
// D65 normalised to luminance 1 in a spectral one (pbrt-v4 multiplies by its colour space's
// illuminant over its luminance), so an unoccluded point is white in both.
//
// As in pbrt-v4:
//   - a camera ray that escapes is black (lights at infinity are not seen), and emitters count only
//     as geometry: nothing emitted is added;
//   - a surface without one of its own (an "interface" material) is passed by the camera ray, which
//     goes on to the surface behind; a mask's absent part (pbrt's alpha) is passed with the
//     probability of its absence;
//   - every surface within max_distance occludes, interfaces and masks included (pbrt's IntersectP
//     does not look at materials);
//   - participating media are ignored: the image is the surfaces' occlusion of each other.
// One camera ray and one occlusion ray per sample, both drawn from the pixel's sampler, so renders
// are identical for every thread count, and the tile loop's checkpoints, parts, single pixels and
// adaptive sampling apply as for the path tracer.
#include "candela/geometry/ray.h"
#include "candela/math/color.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

class AmbientOcclusionIntegrator {
 public:
  // Reads settings.ambient_occlusion (max distance, cosine or uniform directions).
  AmbientOcclusionIntegrator(const Scene& scene, const RenderSettings& settings);

  // The occlusion estimate along the camera ray, as radiance of the white illuminant: RGB, or with
  // wavelengths (a spectral render) the illuminant's values at those wavelengths times the estimate.
  template <typename Sampler>
  RGB radiance(Ray ray, Sampler& sampler, RayCounts& counts, const Wavelengths* wl = nullptr) const;

 private:
  const Scene& scene_;
  float max_distance_;    // occluders beyond this distance along an occlusion ray do not count
  bool cosine_sampling_;  // directions cosine-weighted (true) or uniform over the hemisphere
};

// Integrator "ambient_occlusion": renders `film` with ambient occlusion through the shared tile loop.
RenderStats render_ambient_occlusion(const Scene& scene, const RenderSettings& settings, Film& film,
                                     const RenderOptions& options);

}  // namespace candela
