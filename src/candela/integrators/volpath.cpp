#include "candela/integrators/volpath.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

#include "candela/materials/spectral_bsdf.h"
#include "candela/render/camera_sample_tiles.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/samplers.h"
#include "candela/sampling/warp.h"

namespace candela {

namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Real scattering events one excursion through a subsurface medium may have before the path ends: a
// guard against walks that would not end in any reasonable time (a non-absorbing medium many thousands
// of mean free paths across), far beyond what any medium that lets light out again needs.
constexpr int kMaxSubsurfaceScatterings = 1 << 16;
// The probability that a segment's direct light from lights equiangular sampling can choose comes from
// equiangular sampling rather than from the point distance sampling chose (one-sample MIS, as Cycles).
constexpr float kEquiangularShare = 0.5f;

// exp(-sigma dt) per lane; 1 where sigma is 0, also over an infinite distance.
RGB exp_neg(const RGB& sigma, float dt) {
  return sigma.map([dt](float s) { return s > 0 ? std::exp(-s * dt) : 1.0f; });
}

RGB clamp_zero(const RGB& c) { return c.map([](float v) { return std::max(v, 0.0f); }); }

// Lights whose point light_sample_li(light, ctx, u) chooses is the same for every ctx that sees it:
// lights of one point, and lights sampled by area. Not the lights whose point depends on where they
// are seen from (a sphere samples the cone it subtends) or that have none (lights at infinity):
// equiangular sampling leaves those to distance sampling.
template <typename T>
constexpr bool kPointLightType = std::is_same_v<T, PointLightSource> || std::is_same_v<T, SpotLightSource> ||
                                 std::is_same_v<T, ProjectorLightSource> || std::is_same_v<T, GoniometricLightSource>;
template <typename T>
constexpr bool kAreaSampledLightType = std::is_same_v<T, TriangleLight> || std::is_same_v<T, RectangleLight> ||
                                       std::is_same_v<T, DiskLight> || std::is_same_v<T, CylinderLight> ||
                                       std::is_same_v<T, PartialSphereLight>;
bool light_has_fixed_point(const Light& light) {
  return std::visit(
      [](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        return kPointLightType<T> || kAreaSampledLightType<T>;
      },
      light);
}
// That point for u: the light's position, or its area sample (the one its emitted rays start from
// for the same u, light_sample_le: the same mapping, tested in volpath_test.cpp).
std::optional<Point3> fixed_light_point(const Light& light, Vec2 u) {
  return std::visit(
      [&](const auto& x) -> std::optional<Point3> {
        using T = std::decay_t<decltype(x)>;
        if constexpr (kPointLightType<T>) return x.position;
        else if constexpr (kAreaSampledLightType<T>) return x.sample_le(u, Vec2(0.5f, 0.5f), SceneSphere{}).p;
        else return std::nullopt;
      },
      light);
}

// A medium's coefficients at a path's wavelengths (RGB when there are none).
struct MediumValues {
  const Medium& medium;
  const Wavelengths* wl;
  RGB sigma_t, albedo;
  MediumValues(const Medium& m, const Wavelengths* w)
      : medium(m),
        wl(w),
        sigma_t(w ? unbounded_at(m.sigma_t(), *w) : m.sigma_t()),
        albedo(m.has_albedo_grid() ? RGB(0.0f)  // looked up per point instead
                                   : w ? reflectance_at(m.albedo(Point3(0.0f)), *w) : m.albedo(Point3(0.0f))) {}
  // The radiance emitted at p, at the path's wavelengths.
  RGB emission(const Point3& p) const { return illuminant_at(medium.emission(p), wl); }
  MediumPoint at(const Point3& p) const {
    RGB st = sigma_t * medium.density(p);
    RGB a = albedo;
    if (medium.has_albedo_grid()) a = wl ? reflectance_at(medium.albedo(p), *wl) : medium.albedo(p);
    RGB ss = st * a;
    return {clamp_zero(st - ss), ss};
  }
};

// Delta tracking against the majorant along `ray` (unit direction) over [t_min, t_max) (pbrt-v4's
// SampleT_maj): tentative collisions are drawn with the hero channel's majorant; at each,
// event(p, point, sigma_maj, T_maj) gets the majorant transmittance since the previous one, and
// returns whether to go on. Returns the majorant transmittance from the last collision to t_max
// (1 when an event stopped the walk).
template <typename Event>
RGB sample_majorant(const MediumValues& mv, const Ray& ray, float t_min, float t_max, int hero, Rng& rng,
                    Event&& event) {
  RGB T_maj(1.0f);
  bool stopped = false;
  mv.medium.for_each_majorant(ray, t_min, t_max, [&](float t0, float t1, float density_bound) {
    const RGB sigma_maj = mv.sigma_t * density_bound;
    if (!(sigma_maj[hero] > 0)) {
      T_maj *= exp_neg(sigma_maj, t1 - t0);
      return true;
    }
    for (float t = t0;;) {
      float dt = -std::log1p(-rng.next_float()) / sigma_maj[hero];
      if (!(t + dt < t1)) {
        T_maj *= exp_neg(sigma_maj, t1 - t);
        return true;
      }
      t += dt;
      T_maj *= exp_neg(sigma_maj, dt);
      const Point3 p = ray.at(t);
      if (!event(p, mv.at(p), sigma_maj, T_maj)) {
        stopped = true;
        return false;
      }
      T_maj = RGB(1.0f);
    }
  });
  return stopped ? RGB(1.0f) : T_maj;
}

}  // namespace

struct VolPathIntegrator::ScatterPoint {
  LightSampleContext ctx;  // the point, and the gathering side's normal (zero in media)
  Normal3 ng;              // surfaces: the geometric normal (ray offsets); zero in media
  const SurfaceHit* hit = nullptr;
  const SurfaceBsdf* bsdf = nullptr;  // surfaces
  const Frame* frame = nullptr;
  Vec3 wo_local;
  const HenyeyGreenstein* phase = nullptr;  // media
  Vec3 wo;                                  // world space, towards the previous vertex
  int medium = -1;                          // the medium the path is in at this point
  float time = 0;
  const Wavelengths* wl = nullptr;
  // On a segment where equiangular sampling took part (one-sample MIS between it and light sampling
  // from this point, for the lights it can choose): whether it did, that is whether light sampling
  // here leaves those lights out; the probability that light sampling here takes them (a_share);
  // and, where equiangular sampling could have made this path, the segment, the point's distance
  // along it and what multiplies equiangular sampling's density in the weights (the channels'
  // densities at the segment's start over this point's hero density, times its probability).
  bool mixed = false;
  bool skip_fixed_lights = false;
  float a_share = 1;
  const MediumSegment* segment = nullptr;
  float segment_t = 0;
  RGB r_e{0.0f};
};

struct VolPathIntegrator::MediumSegment {
  Ray ray;  // unit direction
  float t0 = 0, t1 = kInfinity;
  int medium = -1;
  const Wavelengths* wl = nullptr;
  // Where the light is chosen: the segment's midpoint (its start when it is infinite).
  LightSampleContext ref;
  // Equiangular sampling over [t0, t1) towards light point y.
  EquiangularSegment towards(const Point3& y) const {
    const Vec3 v = y - ray.origin;
    const float delta = dot(v, ray.direction);
    return equiangular_segment(delta, length(v - ray.direction * delta), t0, t1);
  }
};

VolPathIntegrator::VolPathIntegrator(const Scene& scene, const RenderSettings& settings)
    : scene_(scene),
      max_depth_(settings.max_depth),
      rr_start_depth_(settings.rr_start_depth),
      hide_emitters_(settings.hide_emitters),
      // Equiangular sampling runs only where it may choose a light (else it would cost sample dimensions).
      equiangular_(settings.volpath.equiangular &&
                   std::any_of(scene.lights().begin(), scene.lights().end(), light_has_fixed_point)) {}

template <typename Sampler>
RGB VolPathIntegrator::radiance(Ray ray, Sampler& sampler, RayCounts& counts, const Wavelengths* wl) const {
  // Distances in media are measured in world units.
  const float length_scale = length(ray.direction);
  ray.direction = ray.direction / length_scale;
  ray.t_min *= length_scale;

  RGB L(0.0f), beta(1.0f), r_u(1.0f), r_l(1.0f);
  // The hero lane drives distance sampling in media; the others follow by spectral MIS.
  const int lanes = transport_lanes(wl);
  const int hero = std::min(int(sampler.get_1d() * float(lanes)), lanes - 1);
  bool specular_bounce = false;
  float eta_scale = 1;
  LightSampleContext prev_ctx;
  int medium = scene_.camera_medium();
  int depth = 0;
  int subsurface_scatterings = 0;  // in the current excursion through a subsurface medium
  ++counts.camera;

  // Possibly terminate the path with Russian roulette (after a real scattering event); survivors
  // are reweighted so that the estimate stays unbiased.
  auto survives_roulette = [&]() {
    RGB rr_beta = beta * (eta_scale / r_u.lane_average(lanes));
    float u = sampler.get_1d();
    if (depth > rr_start_depth_ && rr_beta.max_component() < 1) {
      float q = std::max(0.0f, 1 - rr_beta.max_component());
      if (u < q) return false;
      beta = beta / (1 - q);
    }
    return true;
  };

  // Light found by the path (an emitter hit or the sky): MIS-weighted against light sampling from
  // the previous real scattering point unless nothing else could have found it.
  auto add_emitted = [&](const RGB& Le, uint32_t light, const Point3& p, const Normal3& n) {
    if (depth == 0 || specular_bounce) {
      L += beta * Le / r_u.lane_average(lanes);
      return;
    }
    float light_pdf = scene_.light_sampler().pmf(prev_ctx, light) *
                      light_pdf_li(scene_.lights()[light], prev_ctx, ray.direction, p, n);
    L += beta * Le / (r_u + r_l * light_pdf).lane_average(lanes);
  };

  for (;;) {
    SurfaceHit hit;
    const bool found = scene_.intersect(ray, hit);

    // Sample the medium the ray travels in, up to the surface: absorption, real scattering (then
    // the path continues from the scattering point), or null collisions that walk on.
    if (medium >= 0) {
      bool scattered = false, terminated = false;
      Ray scattered_ray;  // the continuation after a real scattering event
      const Medium& m = scene_.media()[size_t(medium)];
      const MediumValues mv(m, wl);
      const float t_end = found ? hit.t : kInfinity;
      // Equiangular sampling of direct light scattered from the segment, in a medium of constant
      // density where the path may still scatter (a scattering point here would be a bounce of depth + 1).
      MediumSegment segment;
      const bool equiangular = equiangular_ && m.has_constant_density() && !m.is_subsurface() &&
                               depth < max_depth_ && !scene_.lights().empty() && t_end > ray.t_min;
      // One-sample MIS: with probability kEquiangularShare the light of the lights it can choose
      // comes from equiangular sampling on this segment, else from light sampling at the point
      // distance sampling chooses (if it scatters here).
      bool equiangular_chosen = false;
      if (equiangular) {
        segment.ray = ray;
        segment.t0 = ray.t_min;
        segment.t1 = t_end;
        segment.medium = medium;
        segment.wl = wl;
        segment.ref = {ray.at(std::isinf(t_end) ? ray.t_min : 0.5f * (ray.t_min + t_end)), Normal3(0.0f)};
        equiangular_chosen = sampler.get_1d() < kEquiangularShare;
        if (equiangular_chosen) L += sample_equiangular_direct(segment, sampler, beta, r_u, hero, counts);
      }
      const RGB r_segment = r_u;  // the channels' densities at the segment's start
      bool null_collided = false;  // then equiangular sampling cannot make the path (it has a null vertex)
      Rng rng = medium_walk_rng(sampler);
      RGB T_maj = sample_majorant(
          mv, ray, ray.t_min, t_end, hero, rng,
          [&](const Point3& p, const MediumPoint& mp, const RGB& sigma_maj, const RGB& T) {
            // Add the medium's emission (source term sigma_a Le) at every tentative collision. Light
            // emitted on the segment after `depth` scattering events is a path of that depth, as a
            // surface's light found there is (pbrt-v4 leaves out depth == max_depth for media only).
            if (depth <= max_depth_ && m.is_emissive()) {
              float pdf = sigma_maj[hero] * T[hero];
              RGB r_e = r_u * sigma_maj * T / pdf;
              if (!r_e.is_black()) L += beta * T / pdf * mp.sigma_a * mv.emission(p) / r_e.lane_average(lanes);
            }
            // A real collision (with probability sigma_t over the majorant) scatters, its weight
            // the albedo: absorption is taken as a weight, not by ending paths (as Mitsuba's
            // volpath does), which keeps colour noise down in chromatic media; Russian roulette
            // ends the paths whose weight has become small.
            const RGB sigma_t = mp.sigma_a + mp.sigma_s;
            if (rng.next_float() < sigma_t[hero] / sigma_maj[hero]) {
              // Real scattering: estimate direct light, then continue along a phase-function sample.
              // In a subsurface medium the whole excursion is one bounce: the one that entered it.
              if (m.is_subsurface() ? ++subsurface_scatterings > kMaxSubsurfaceScatterings : depth++ >= max_depth_) {
                terminated = true;
                return false;
              }
              float pdf = T[hero] * sigma_t[hero];
              beta *= T * mp.sigma_s / pdf;
              r_u *= T * sigma_t / pdf;
              if (beta.is_black() || r_u.is_black()) {
                terminated = true;
                return false;
              }
              ScatterPoint at;
              at.ctx = {p, Normal3(0.0f)};
              at.phase = &m.phase();
              at.wo = -ray.direction;
              at.medium = medium;
              at.time = ray.time;
              at.wl = wl;
              if (equiangular) {
                at.mixed = true;
                at.skip_fixed_lights = equiangular_chosen;
                at.a_share = 1 - kEquiangularShare;
                if (!null_collided) {
                  at.segment = &segment;
                  at.segment_t = dot(p - ray.origin, ray.direction);
                  at.r_e = r_segment * (kEquiangularShare / pdf);
                }
              }
              if (!scene_.lights().empty()) L += sample_direct(at, sampler, beta, r_u, hero, counts);
              PhaseSample ps = m.phase().sample(at.wo, sampler.get_2d());
              if (!(ps.pdf > 0)) {
                terminated = true;
                return false;
              }
              // HG is sampled exactly: the weight p / pdf is 1.
              r_l = r_u / ps.pdf;
              prev_ctx = at.ctx;
              specular_bounce = false;
              scattered_ray = Ray{p, ps.wi, kInfinity, ray.time};
              scattered = true;
              if (!survives_roulette()) terminated = true;
              return false;
            }
            // A null collision: walk on, carrying sigma_n over the hero's density.
            null_collided = true;
            RGB sigma_n = clamp_zero(sigma_maj - mp.sigma_a - mp.sigma_s);
            float pdf = T[hero] * sigma_n[hero];
            if (!(pdf > 0)) {
              beta = RGB(0.0f);
              return false;
            }
            beta *= T * sigma_n / pdf;
            r_u *= T * sigma_n / pdf;
            r_l *= T * sigma_maj / pdf;
            return !beta.is_black() && !r_u.is_black();
          });
      if (terminated || beta.is_black() || r_u.is_black()) return L;
      if (scattered) {
        ray = scattered_ray;
        ++counts.bounce;
        continue;
      }
      // Reached the surface (or infinity): the hero's majorant transmittance was sampled, the
      // others' are ratios.
      if (!(T_maj[hero] > 0)) return L;
      beta *= T_maj / T_maj[hero];
      r_u *= T_maj / T_maj[hero];
      r_l *= T_maj / T_maj[hero];
    }

    if (!found) {
      // The ray escapes: the lights at infinity.
      if (!(depth == 0 && hide_emitters_))
        for (uint32_t li : scene_.infinite_lights()) {
          RGB Le = illuminant_at(scene_.escaped_radiance(li, ray.direction), wl);
          if (!Le.is_black()) add_emitted(Le, li, {}, {});
        }
      break;
    }

    // Light emitted by the surface hit.
    const Vec3 wo = -ray.direction;
    if (!(depth == 0 && hide_emitters_)) {
      RGB Le = illuminant_at(scene_.emitted(hit, wo), wl);
      if (!Le.is_black()) add_emitted(Le, uint32_t(scene_.light_index(hit)), hit.p, hit.ng);
    }

    // An interface has no surface: continue beyond it in the medium on its other side.
    if (scene_.is_interface(hit)) {
      medium = scene_.medium_after(hit, ray.direction, medium);
      ray = Ray{offset_ray_origin(hit.p, hit.ng, ray.direction), ray.direction, kInfinity, ray.time};
      continue;
    }

    Shading shading = scene_.shading(hit, wo);
    bsdf_at_wavelengths(shading.bsdf, wl);
    const SurfaceBsdf& bsdf = shading.bsdf;
    if (bsdf.is_black()) break;
    const Frame& frame = shading.frame;
    const Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;

    // Sample direct illumination where the BSDF is not purely specular, if one more scattering
    // event is allowed. Surfaces met from inside a subsurface medium (its boundary's internal
    // reflections and the way out) belong to the bounce that entered it.
    const bool inside_subsurface = medium >= 0 && scene_.media()[size_t(medium)].is_subsurface();
    const bool may_scatter = inside_subsurface || depth < max_depth_;
    const Normal3 gather_n = bsdf.has_non_delta_transmission() ? Normal3(0.0f) : wo_local.z > 0 ? frame.n : -frame.n;
    const LightSampleContext ctx{hit.p, gather_n};
    if (may_scatter && bsdf.has_non_delta() && !scene_.lights().empty()) {
      ScatterPoint at;
      at.ctx = ctx;
      at.ng = hit.ng;
      at.hit = &hit;
      at.bsdf = &bsdf;
      at.frame = &frame;
      at.wo_local = wo_local;
      at.wo = wo;
      at.medium = medium;
      at.time = ray.time;
      at.wl = wl;
      L += sample_direct(at, sampler, beta, r_u, hero, counts);
    }

    // Sample the BSDF for the next direction.
    float u_lobe = sampler.get_1d();
    Vec2 u = sampler.get_2d();
    auto bs = bsdf.sample(wo_local, u_lobe, u);
    if (!bs || bs->weight.is_black()) break;
    const Vec3 wi = normalize(frame.to_world(bs->wi));
    beta *= bs->weight;
    medium = scene_.medium_after(hit, wi, medium);
    if (medium < 0 || !scene_.media()[size_t(medium)].is_subsurface()) subsurface_scatterings = 0;
    ray = Ray{offset_ray_origin(hit.p, hit.ng, wi), wi, kInfinity, ray.time};
    // Light passing straight on is not a bounce: the MIS state of the last real scattering holds.
    if (bs->passes_through) continue;
    if (!may_scatter) break;
    if (!inside_subsurface) ++depth;
    r_l = bs->is_delta ? r_u : r_u / bs->pdf;
    specular_bounce = bs->is_delta;
    prev_ctx = ctx;
    if (bs->eta != 1) eta_scale *= bs->eta * bs->eta;
    if (!survives_roulette()) break;
    ++counts.bounce;
  }
  return L;
}

template <typename Sampler>
RGB VolPathIntegrator::sample_direct(const ScatterPoint& at, Sampler& sampler, const RGB& beta, const RGB& r_p,
                                     int hero, RayCounts& counts) const {
  // Choose a light and a point on it.
  const SampledLight chosen = scene_.light_sampler().sample(at.ctx, sampler.get_1d());
  const Vec2 u = sampler.get_2d();
  Rng rng = medium_walk_rng(sampler);
  if (!(chosen.pmf > 0)) return RGB(0.0f);
  const uint64_t seed = hash_values(rng.next_u32(), rng.next_u32());
  return light_contribution(at, chosen.light, chosen.pmf, u, seed, beta, r_p, hero, counts);
}

RGB VolPathIntegrator::light_contribution(const ScatterPoint& at, size_t li, float pmf, Vec2 u, uint64_t seed,
                                          const RGB& beta, const RGB& r_p, int hero, RayCounts& counts) const {
  const Light& light = scene_.lights()[li];
  const bool mixed = at.mixed && light_has_fixed_point(light);
  if (mixed && at.skip_fixed_lights) return RGB(0.0f);  // equiangular sampling's turn on this segment
  const LightSample ls = light_sample_li(light, at.ctx, u);
  if (!(ls.pdf > 0) || ls.radiance.is_black()) return RGB(0.0f);

  // What the scattering point does with light from there.
  RGB f_hat;
  float scatter_pdf;
  Point3 origin = at.ctx.p;
  int medium = at.medium;
  if (at.bsdf) {
    Vec3 wi_local = at.frame->to_local(ls.wi);
    f_hat = at.bsdf->eval(at.wo_local, wi_local) * std::abs(wi_local.z);
    scatter_pdf = at.bsdf->pdf(at.wo_local, wi_local);
    origin = offset_ray_origin(at.ctx.p, at.ng, ls.wi);
    medium = scene_.medium_after(*at.hit, ls.wi, medium);
  } else {
    f_hat = RGB(at.phase->p(at.wo, ls.wi));
    scatter_pdf = at.phase->pdf(at.wo, ls.wi);
  }
  if (f_hat.is_black()) return RGB(0.0f);

  // The shadow ray's transmittance, and the two strategies' path densities along it.
  float t_max = kInfinity;
  if (!std::isinf(ls.distance)) t_max = length(ls.p_light - origin) * (1 - 1e-4f);
  RGB r_u(1.0f), r_l(1.0f);
  RGB T_ray = trace_transmittance(origin, ls.wi, t_max, medium, hero, seed, at.time, at.wl, r_u, r_l, counts);
  if (T_ray.is_black()) return RGB(0.0f);

  const RGB Le = illuminant_at(ls.radiance, at.wl);
  const int lanes = transport_lanes(at.wl);
  // Equiangular sampling's density of the same path (e) times its probability, where it could have
  // made this path: its light choice at the segment's midpoint, the point's density (ls.pdf, as for
  // light sampling here: the same point), and the distance's equiangular density.
  RGB r_e(0.0f);
  if (mixed && at.segment) {
    const float p = scene_.light_sampler().pmf(at.segment->ref, li) *
                    equiangular_pdf(at.segment->towards(ls.p_light), at.segment_t);
    if (p > 0) r_e = r_l * at.r_e * (p * ls.pdf);
  }
  r_l *= r_p * (pmf * ls.pdf);
  if (ls.is_delta) {
    if (!mixed) return beta * f_hat * T_ray * Le / r_l.lane_average(lanes);
    // Light sampling (a, taken with probability a_share) and equiangular sampling (e) are the only
    // strategies: the one-sample balance heuristic's 1 / avg(a_share a + e).
    const float ae = (r_l * at.a_share + r_e).lane_average(lanes);
    return ae > 0 ? beta * f_hat * T_ray * Le / ae : RGB(0.0f);
  }
  r_u *= r_p * scatter_pdf;
  if (!mixed) return beta * f_hat * T_ray * Le / (r_l + r_u).lane_average(lanes);
  // Light sampling's share against phase or BSDF sampling, avg(a) / avg(a + b), split between
  // light sampling here and equiangular sampling by the one-sample balance heuristic: the weight
  // over the density is avg(a) / (avg(a + b) avg(a_share a + e)).
  const float a = r_l.lane_average(lanes), ab = (r_l + r_u).lane_average(lanes),
              ae = (r_l * at.a_share + r_e).lane_average(lanes);
  if (!(ab > 0 && ae > 0)) return RGB(0.0f);
  return beta * f_hat * T_ray * Le * (a / (ab * ae));
}

template <typename Sampler>
RGB VolPathIntegrator::sample_equiangular_direct(const MediumSegment& segment, Sampler& sampler, const RGB& beta,
                                                 const RGB& r_u, int hero, RayCounts& counts) const {
  // The sample dimensions, in a fixed order whatever happens below: the light, the point on it, the
  // distance, the shadow ray's random stream.
  const float u_light = sampler.get_1d();
  const Vec2 u = sampler.get_2d();
  const float u_t = sampler.get_1d();
  Rng rng = medium_walk_rng(sampler);
  const uint64_t seed = hash_values(rng.next_u32(), rng.next_u32());

  // 1. A light, chosen at the segment's midpoint, and the point y it samples for u.
  const SampledLight chosen = scene_.light_sampler().sample(segment.ref, u_light);
  if (!(chosen.pmf > 0)) return RGB(0.0f);
  const std::optional<Point3> y = fixed_light_point(scene_.lights()[chosen.light], u);
  if (!y) return RGB(0.0f);
  // 2. A distance t along the segment, with density proportional to the inverse squared distance to y.
  const EquiangularSegment towards = segment.towards(*y);
  if (!towards.valid()) return RGB(0.0f);
  const float t = sample_equiangular(towards, u_t, segment.t0, segment.t1);
  // 3. Scattering at t: the transmittance from the segment's start (exact: the extinction is the
  //    majorant) times sigma_s; and the channels' densities distance sampling gives the same point,
  //    sigma_t T, for the weights. The path's densities are relative to its hero's at the segment's
  //    start; light_contribution's weights hold equiangular sampling's density.
  const Medium& m = scene_.media()[size_t(segment.medium)];
  const MediumValues mv(m, segment.wl);
  const Point3 p = segment.ray.at(t);
  const MediumPoint mp = mv.at(p);
  const RGB T = exp_neg(mv.sigma_t * m.density(p), t - segment.t0);
  ScatterPoint at;
  at.ctx = {p, Normal3(0.0f)};
  at.phase = &m.phase();
  at.wo = -segment.ray.direction;
  at.medium = segment.medium;
  at.time = segment.ray.time;
  at.wl = segment.wl;
  at.mixed = true;
  at.a_share = 1 - kEquiangularShare;
  at.segment = &segment;
  at.segment_t = t;
  at.r_e = r_u * kEquiangularShare;
  const float pmf = scene_.light_sampler().pmf(at.ctx, chosen.light);
  return light_contribution(at, chosen.light, pmf, u, seed, beta * T * mp.sigma_s, r_u * T * (mp.sigma_a + mp.sigma_s),
                            hero, counts);
}

RGB VolPathIntegrator::trace_transmittance(Point3 origin, const Vec3& dir, float t_max, int medium, int hero,
                                           uint64_t seed, float time, const Wavelengths* wl, RGB& r_u, RGB& r_l,
                                           RayCounts& counts) const {
  Rng rng(seed, hash_values(seed));
  RGB T_ray(1.0f);
  // Each segment aims at the same end point: a crossing's offset origin, moved off the surface along
  // its normal, would otherwise shift the line, which then meets the light's plane early (by the
  // offset over the cosine, millimetres for grazing rays) and is taken for blocked.
  const bool finite = std::isfinite(t_max);
  const Point3 end = finite ? origin + dir * t_max : origin;
  Vec3 direction = dir;
  for (float remaining = t_max;;) {
    Ray ray{origin, direction, remaining, time};
    SurfaceHit hit;
    ++counts.shadow;
    const bool found = scene_.intersect(ray, hit);
    if (found && !scene_.may_pass_through(hit)) return RGB(0.0f);
    if (medium >= 0 && scene_.media()[size_t(medium)].has_constant_density()) {
      // A constant extinction is its own majorant: ratio tracking would be all or nothing (no null
      // collisions), and its expectation is known. The transmittance itself, with the densities of
      // the walk that met no collision, is that expectation (the same MIS weights, less noise).
      const Medium& m = scene_.media()[size_t(medium)];
      const MediumValues mv(m, wl);
      const RGB T_maj = exp_neg(mv.sigma_t * m.density(origin), found ? hit.t : remaining);
      if (!(T_maj[hero] > 0)) return RGB(0.0f);
      T_ray *= T_maj;
      r_l *= T_maj / T_maj[hero];
      r_u *= T_maj / T_maj[hero];
    } else if (medium >= 0) {
      // Ratio tracking: every tentative collision multiplies by sigma_n over the majorant.
      const MediumValues mv(scene_.media()[size_t(medium)], wl);
      RGB T_maj = sample_majorant(mv, ray, 0, found ? hit.t : remaining, hero, rng,
                                  [&](const Point3&, const MediumPoint& mp, const RGB& sigma_maj, const RGB& T) {
                                    RGB sigma_n = clamp_zero(sigma_maj - mp.sigma_a - mp.sigma_s);
                                    float pdf = T[hero] * sigma_maj[hero];
                                    T_ray *= T * sigma_n / pdf;
                                    r_l *= T * sigma_maj / pdf;
                                    r_u *= T * sigma_n / pdf;
                                    // Russian roulette where little light gets through.
                                    RGB Tr = T_ray / (r_l + r_u).lane_average(transport_lanes(wl));
                                    if (Tr.max_component() < 0.05f) {
                                      if (rng.next_float() < 0.75f)
                                        T_ray = RGB(0.0f);
                                      else
                                        T_ray = T_ray / 0.25f;
                                    }
                                    return !T_ray.is_black();
                                  });
      if (!(T_maj[hero] > 0)) return RGB(0.0f);
      T_ray *= T_maj / T_maj[hero];
      r_l *= T_maj / T_maj[hero];
      r_u *= T_maj / T_maj[hero];
    }
    if (T_ray.is_black() || !found) return T_ray;
    // Cross the surface: all of an interface's light, a mask's or a thin sheet's straight share.
    if (!scene_.is_interface(hit)) {
      Shading shading = scene_.shading(hit, -direction);
      bsdf_at_wavelengths(shading.bsdf, wl);
      T_ray *= shading.bsdf.pass_through(shading.frame.to_local(-direction));
      if (T_ray.is_black()) return T_ray;
    }
    medium = scene_.medium_after(hit, direction, medium);
    origin = offset_ray_origin(hit.p, hit.ng, direction);
    if (finite) {
      const Vec3 rest = end - origin;
      remaining = length(rest);
      if (!(remaining > 0) || dot(rest, direction) <= 0) return T_ray;
      direction = rest / remaining;
    }
  }
}

RGB VolPathIntegrator::transmittance(const Point3& from, const Point3& to, int medium, int hero, uint64_t seed,
                                     float time, const Wavelengths* wl) const {
  RGB r_u(1.0f), r_l(1.0f);
  RayCounts counts;
  float d = length(to - from);
  RGB T = trace_transmittance(from, (to - from) / d, d, medium, hero, seed, time, wl, r_u, r_l, counts);
  return T / r_l.lane_average(transport_lanes(wl));
}

RenderStats render_volpath(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  return render_camera_samples<VolPathIntegrator>(scene, settings, film, options);
}

#define CANDELA_INSTANTIATE(S) \
  template RGB VolPathIntegrator::radiance<S>(Ray, S&, RayCounts&, const Wavelengths*) const;
CANDELA_FOR_EACH_SAMPLER(CANDELA_INSTANTIATE)
#undef CANDELA_INSTANTIATE

}  // namespace candela
