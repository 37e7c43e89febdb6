#pragma once
// pbrt-v4's goniometric light: a point light at the origin of to_world whose intensity over
// directions is a square image in Clarberg's equal-area parameterisation (sampling/warp.h). The
// local unit direction d (in to_world's frame) reads the image at the square point
//   s = equal_area_sphere_to_square(d.x, d.z, d.y)
// (the light's +y at the square's centre: pbrt-v4 swaps y and z between its light frame and the
// square's), nearest texel (floor(s * resolution), row 0 the top), each texel being the mean of its
// R, G and B (pbrt-v4 makes the image one channel so), negative values counting as zero:
//   I(d) = intensity x texel(s).
// The square is equal-area (d(omega) = 4 pi ds), so emission directions are importance-sampled
// exactly: a 2D distribution over the texels in proportion to their values, solid-angle pdf
// p_s / (4 pi), which is proportional to I; the emitted power is 4 pi intensity x the texels' mean.
#include <memory>
#include <vector>

#include "candela/film/image.h"
#include "candela/lights/light_sample.h"
#include "candela/math/transform.h"
#include "candela/sampling/distribution2d.h"
#include "candela/sampling/warp.h"
#include "candela/description/lights.h"

namespace candela {

struct GoniometricLightSource {
  static constexpr LightFlags flags = LightFlags::DeltaPosition;

  // The image with its sampling distribution, shared and immutable so the Light variant stays small.
  struct Texels {
    int resolution = 0;                // the square image's side
    std::vector<float> values;         // resolution^2 texel values (mean of R, G, B, at least 0), row 0 the top
    float mean = 0;                    // their mean: the intensity's average over the sphere is intensity x mean
    Distribution2D distribution;       // over the square in proportion to the texels; row = the square's v
  };

  Point3 position;
  Transform to_world;   // the light's frame to the world (directions are normalised after it)
  RGB intensity{1.0f};  // W/sr, times the texel value
  std::shared_ptr<const Texels> texels;

  // The square point a local unit direction reads (the light's +y to the square's +z pole), and back.
  static Vec2 local_to_square(const Vec3& d) { return equal_area_sphere_to_square(Vec3(d.x, d.z, d.y)); }
  static Vec3 square_to_local(Vec2 s) {
    Vec3 w = equal_area_square_to_sphere(s);
    return {w.x, w.z, w.y};
  }
  // The texel value at square point s (nearest texel, clamped at the square's edges).
  float texel(Vec2 s) const {
    const int n = texels->resolution;
    const int x = std::clamp(int(s.x * float(n)), 0, n - 1), y = std::clamp(int(s.y * float(n)), 0, n - 1);
    return texels->values[size_t(y) * size_t(n) + size_t(x)];
  }
  // The intensity along the world direction w (need not be unit length).
  RGB intensity_towards(const Vec3& w) const {
    const Vec3 d = to_world.inverse().vector(w);
    const float len = length(d);
    if (!(len > 0)) return RGB(0.0f);
    return intensity * texel(local_to_square(d / len));
  }

  LightSample sample_li(const LightSampleContext& ctx, Vec2) const {
    const Vec3 to_ctx = ctx.p - position;
    const float dist2 = length_squared(to_ctx);
    if (!(dist2 > 0)) return {};
    const float dist = std::sqrt(dist2);
    RGB L = intensity_towards(to_ctx) / dist2;
    if (L.is_black()) return {};
    return {L, -to_ctx / dist, dist, 1, position, Normal3(0.0f), true};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const Point3&, const Normal3&) const { return 0; }

  // Emission: a square point from the texel distribution, its direction, pdf p_s / (4 pi).
  LightEmission sample_le(Vec2, Vec2 u_dir, const SceneSphere&) const {
    Distribution2DSample s = texels->distribution.sample(u_dir);
    if (!(s.pdf > 0)) return {};
    const Vec3 w = normalize(to_world.vector(square_to_local(s.point)));
    return {intensity * texel(s.point), position, w, Normal3(0.0f), 1, s.pdf * kInv4Pi};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere&) const {
    const Vec3 d = to_world.inverse().vector(w);
    const float len = length(d);
    if (!(len > 0)) return {1, 0};
    return {1, texels->distribution.pdf(local_to_square(d / len)) * kInv4Pi};
  }
  // Phi = integral of I over the sphere = 4 pi x the intensity's luminance x the texels' mean.
  float power() const { return 4 * kPi * intensity.luminance() * texels->mean; }
  // Estimated irradiance at ctx: I(towards ctx) cos / d^2.
  float importance(const LightSampleContext& ctx) const {
    LightSample ls = sample_li(ctx, {});
    if (!(ls.pdf > 0)) return 0;
    const float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, ls.wi));
    return ls.radiance.luminance() * cos_p;
  }
};

// Builds the light from an image already in memory (linear RGB). Throws SceneError for an empty or
// non-square image, or a `power` that an all-black image cannot meet.
GoniometricLightSource make_goniometric_light(const GoniometricLight& desc, const Image& image);
// Reads desc.filename with read_image_shared and builds the light; throws SceneError naming the file.
GoniometricLightSource make_goniometric_light(const GoniometricLight& desc);

}  // namespace candela
