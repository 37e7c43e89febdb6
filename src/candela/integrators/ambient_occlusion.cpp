#include "candela/integrators/ambient_occlusion.h"

#include <limits>

#include "candela/math/frame.h"
#include "candela/render/camera_sample_tiles.h"
#include "candela/sampling/samplers.h"
#include "candela/sampling/warp.h"

namespace candela {
namespace {

// Surfaces a camera ray may pass before it is given up as black (a ray caught between coincident
// interfaces, a deep stack of masks).
constexpr int kAoMaxSurfacesPassed = 256;

// The probability that the surface is absent where the hit is: the null part of its BSDF mixture (a
// mask's 1 - opacity, pbrt-v4's 1 - alpha) over the whole mixture.
float ao_absent_probability(const SurfaceBsdf& bsdf) {
  if (!(bsdf.null_weight > 0)) return 0;
  float total = bsdf.null_weight;
  for (int k = 0; k < bsdf.count; ++k) total += bsdf.components[size_t(k)].weight;
  return bsdf.null_weight / total;
}

// The camera ray continued past `hit` in its own direction.
Ray ao_ray_past(const SurfaceHit& hit, const Ray& ray) {
  return Ray{offset_ray_origin(hit.p, hit.ng, ray.direction), ray.direction, std::numeric_limits<float>::infinity(),
             ray.time};
}

}  // namespace

AmbientOcclusionIntegrator::AmbientOcclusionIntegrator(const Scene& scene, const RenderSettings& settings)
    : scene_(scene),
      max_distance_(settings.ambient_occlusion.max_distance),
      cosine_sampling_(settings.ambient_occlusion.cosine_sampling) {}

template <typename Sampler>
RGB AmbientOcclusionIntegrator::radiance(Ray ray, Sampler& sampler, RayCounts& counts, const Wavelengths* wl) const {
  ++counts.camera;
  // Step 1: the first surface the camera ray meets that has a surface of its own there.
  SurfaceHit hit;
  for (int passed = 0;; ++passed) {
    if (passed == kAoMaxSurfacesPassed || !scene_.intersect(ray, hit)) return RGB(0.0f);  // escaped: black
    // An interface has no surface: the ray goes on (pbrt-v4 skips a hit without a BSDF).
    bool passes = scene_.is_interface(hit);
    // A mask's absent part is passed with its probability (pbrt-v4's stochastic alpha test). Only
    // surfaces that have one draw the number, so plain scenes give the direction the first dimensions.
    if (!passes && scene_.may_pass_through(hit)) {
      const float absent = ao_absent_probability(scene_.bsdf(hit));
      passes = absent > 0 && sampler.get_1d() < absent;
    }
    if (!passes) break;
    ray = ao_ray_past(hit, ray);
    ++counts.bounce;
  }

  // Step 2: a direction over the hemisphere of the geometric normal on the camera's side.
  Vec3 n = normalize(hit.ng);
  if (dot(n, ray.direction) > 0) n = -n;
  const Vec2 u = sampler.get_2d();
  const Vec3 local = cosine_sampling_ ? square_to_cosine_hemisphere(u) : square_to_uniform_hemisphere(u);
  const float pdf = cosine_sampling_ ? cosine_hemisphere_pdf(local) : uniform_hemisphere_pdf(local);
  if (!(pdf > 0)) return RGB(0.0f);  // a grazing cosine-weighted direction: zero weight
  const Vec3 wi = Frame(n).to_world(local);

  // Step 3: the occlusion ray. Any surface within max_distance occludes, whatever its material.
  const Ray occlusion{offset_ray_origin(hit.p, hit.ng, wi), wi, max_distance_, ray.time};
  ++counts.shadow;
  if (scene_.occluded(occlusion)) return RGB(0.0f);

  // Step 4: the estimate cos / (pi pdf), 1 for a fully open hemisphere on average (exactly 1 per
  // sample when cosine-weighted), as the white illuminant's radiance.
  const float estimate = local.z / (kPi * pdf);
  return illuminant_at(RGB(1.0f), wl) * estimate;
}

RenderStats render_ambient_occlusion(const Scene& scene, const RenderSettings& settings, Film& film,
                                     const RenderOptions& options) {
  return render_camera_samples<AmbientOcclusionIntegrator>(scene, settings, film, options);
}

// One instantiation per sampler type of the variant.
#define CANDELA_INSTANTIATE(S) \
  template RGB AmbientOcclusionIntegrator::radiance<S>(Ray, S&, RayCounts&, const Wavelengths*) const;
CANDELA_FOR_EACH_SAMPLER(CANDELA_INSTANTIATE)
#undef CANDELA_INSTANTIATE

}  // namespace candela
