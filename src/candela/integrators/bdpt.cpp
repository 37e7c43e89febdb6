#include "candela/integrators/bdpt.h"

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "candela/film/image_io.h"
#include "candela/integrators/mlt_sampler.h"
#include "candela/materials/spectral_bsdf.h"
#include "candela/render/camera_sample_tiles.h"
#include "candela/sampling/samplers.h"

namespace candela {
namespace {

using Kind = BdptVertex::Kind;

// Veach's correction for shading normals on importance-carrying paths (sec. 5.3): the adjoint of a
// BSDF evaluated in a shading frame picks up |wo . ns| |wi . ng| / (|wo . ng| |wi . ns|).
float shading_normal_correction(const BdptVertex& v, const Vec3& wo, const Vec3& wi) {
  float denom = std::abs(dot(wo, v.ng)) * std::abs(dot(wi, v.ns));
  if (denom == 0) return 0;
  return std::abs(dot(wo, v.ns)) * std::abs(dot(wi, v.ng)) / denom;
}

// The power heuristic's ratios do not care about a zero density of a delta vertex: it counts as 1.
float remap0(float f) { return f != 0 ? f : 1.0f; }

// Restores a value when it goes out of scope (the temporary densities of mis_weight).
template <typename T>
class Restore {
 public:
  Restore() = default;
  Restore(T* target, T value) : target_(target), saved_(*target) { *target = value; }
  Restore(const Restore&) = delete;
  Restore& operator=(Restore&& o) noexcept {
    target_ = o.target_;
    saved_ = o.saved_;
    o.target_ = nullptr;
    return *this;
  }
  ~Restore() {
    if (target_) *target_ = saved_;
  }

 private:
  T* target_ = nullptr;
  T saved_{};
};

}  // namespace

float BdptIntegrator::path_sigma_t(int medium, int hero, const Wavelengths* wl) const {
  const RGB& sigma = scene_.media()[size_t(medium)].sigma_t();
  if (hero < 0) return sigma.r;
  return wl ? unbounded_at(sigma, *wl)[hero] : sigma[hero];
}

int BdptIntegrator::outgoing_medium(const BdptVertex& v, const Vec3& dir) const {
  switch (v.kind) {
    case Kind::Camera: return scene_.camera_medium();
    case Kind::Surface: return scene_.medium_after(v.hit, dir, v.medium);
    case Kind::Light:
    case Kind::Medium: return v.medium;
  }
  return -1;
}

BdptIntegrator::BdptIntegrator(const Scene& scene, const RenderSettings& settings)
    : scene_(scene),
      max_depth_(settings.max_depth),
      rr_start_depth_(settings.rr_start_depth),
      hide_emitters_(settings.hide_emitters) {
  for (const Medium& m : scene.media()) {
    const RGB& sigma = m.sigma_t();
    chromatic_media_ = chromatic_media_ || sigma.r != sigma.g || sigma.g != sigma.b;
  }
}

// ------------------------------------------------------------------------------------------ subpaths

BdptVertex BdptIntegrator::surface_vertex(const SurfaceHit& hit, const Ray& ray, const RGB& beta) const {
  BdptVertex v;
  v.kind = Kind::Surface;
  v.p = hit.p;
  v.ng = hit.ng;
  v.ns = hit.ns;
  v.hit = hit;
  v.wo = -normalize(ray.direction);
  v.beta = beta;
  v.light = scene_.light_index(hit);
  return v;
}

template <typename Sampler>
int BdptIntegrator::camera_subpath(const Ray& ray, Sampler& sampler, RayCounts& counts, int max_vertices,
                                   BdptVertex* path, RGB* crossed_emission, const Wavelengths* wl) const {
  if (max_vertices == 0) return 0;
  BdptVertex& camera = path[0];
  camera = BdptVertex{};
  camera.kind = Kind::Camera;
  camera.p = ray.origin;
  camera.beta = RGB(1.0f);  // W_e / pdf = 1 for the camera's own rays
  // An orthographic camera's directions are a delta: no strategy connects to it (t = 1), and MIS
  // leaves that strategy out as it leaves out connections to delta lights.
  camera.delta = scene_.camera().is_delta_direction();
  // Media whose extinction differs between the lanes are sampled by one lane per path (a colour
  // channel, or a wavelength), which then counts for all of them.
  if (scene_.has_media() && (wl || chromatic_media_)) {
    const int lanes = transport_lanes(wl);
    camera.hero = int8_t(std::min(int(sampler.get_1d() * float(lanes)), lanes - 1));
    // (In an RGB render the fourth lane mirrors green, hero or not.)
    const int hero = camera.hero, mirror = wl ? -1 : 3;
    camera.beta = RGB::from_lanes([&](int c) { return c == hero || (c == mirror && hero == 1) ? float(lanes) : 0.0f; });
  }
  ++counts.camera;
  Ray r = ray;
  const float length_scale = length(r.direction);
  r.direction = r.direction / length_scale;
  r.t_min *= length_scale;
  float pdf_dir = scene_.camera().pdf_importance(r.origin, r.direction).dir;
  const int n = random_walk(r, sampler, counts, camera.beta, pdf_dir, max_vertices, Transport::Radiance, path,
                            crossed_emission, wl, scene_.camera_medium(), camera.hero);
  // Emitters the path found: how next-event estimation at the vertex before would have chosen them.
  if (scene_.light_sampler().uses_bvh())
    for (int i = 2; i < n; ++i)
      if (path[i].light >= 0 || path[i].at_infinity) path[i].nee_ratio = nee_light_pdf_ratio(path[i], path[i - 1]);
  return n;
}

template <typename Sampler>
int BdptIntegrator::light_subpath(Sampler& sampler, RayCounts& counts, int max_vertices, float time,
                                  BdptVertex* path, const Wavelengths* wl, int hero) const {
  if (max_vertices == 0 || scene_.lights().empty()) return 0;
  // Choose a light by power (or uniformly over emitters; no point to ask a light BVH from), then a
  // ray leaving it.
  float u_light = sampler.get_1d();
  Vec2 u_pos = sampler.get_2d(), u_dir = sampler.get_2d();
  const SampledLight chosen = scene_.light_sampler().sample_emitter(u_light);
  const size_t li = chosen.light;
  const float pmf = chosen.pmf;
  const Light& light = scene_.lights()[li];
  LightEmission e = light_sample_le(light, u_pos, u_dir, scene_.bounding_sphere());
  if (!(e.pdf_pos > 0) || !(e.pdf_dir > 0) || e.radiance.is_black() || pmf <= 0) return 0;
  e.radiance = illuminant_at(e.radiance, wl);

  BdptVertex& v = path[0];
  v = BdptVertex{};
  v.kind = Kind::Light;
  v.p = e.p;
  v.ng = v.ns = e.n;
  v.light = int(li);
  v.at_infinity = light_is_at_infinity(light);
  v.beta = e.radiance;
  v.pdf_fwd = e.pdf_pos * pmf;
  float cos_light = v.on_surface() ? std::abs(dot(e.n, e.w)) : 1.0f;
  RGB beta = e.radiance * (cos_light / (pmf * e.pdf_pos * e.pdf_dir));
  Point3 origin = v.on_surface() ? offset_ray_origin(e.p, e.n, e.w) : e.p;
  // The medium the light shines into (lights carry none of their own). Light from infinity cannot
  // cross fog that fills all space.
  if (scene_.has_media()) {
    if (v.at_infinity && scene_.ambient_medium() >= 0) return 0;
    v.medium = v.at_infinity ? -1 : scene_.medium_at(origin, time);
  }
  int n = random_walk(Ray{origin, e.w, std::numeric_limits<float>::infinity(), time}, sampler, counts, beta,
                      e.pdf_dir, max_vertices, Transport::Importance, path, nullptr, wl, v.medium, hero);

  // Lights at infinity: the first vertex's density is the disk's per-area density projected onto
  // it, and the light's own "position" is its direction, with the density all lights at infinity
  // together give it (an escaping camera ray sees them all).
  if (v.at_infinity) {
    if (n > 1) {
      path[1].pdf_fwd = e.pdf_pos;
      if (path[1].on_surface()) path[1].pdf_fwd *= std::abs(dot(e.w, path[1].ng));
    }
    v.pdf_fwd = infinite_lights_pdf(e.w);
  }
  if (n > 1 && scene_.light_sampler().uses_bvh()) v.nee_ratio = nee_light_pdf_ratio(v, path[1]);
  return n;
}

template <typename Sampler>
int BdptIntegrator::random_walk(Ray ray, Sampler& sampler, RayCounts& counts, RGB beta, float pdf,
                                int max_vertices, Transport mode, BdptVertex* path, RGB* crossed_emission,
                                const Wavelengths* wl, int medium, int hero) const {
  int n = 1;
  float pdf_fwd = pdf;
  float eta_scale = 1;
  // Russian roulette looks at the throughput relative to the subpath's start (light subpaths start
  // with the light's power, not with 1).
  const float start = std::max(beta.max_component(), 1e-30f);
  // Russian roulette, after a vertex that scattered (false: the subpath ends here).
  auto survives_roulette = [&]() {
    int depth = n - 1;
    float rr = (beta * eta_scale).max_component() / start;
    if (depth > rr_start_depth_ && rr < 1) {
      float q = std::max(0.0f, 1 - rr);
      if (sampler.get_1d() < q) return false;
      beta = beta / (1 - q);
    }
    ++counts.bounce;  // counted once the ray is sure to be traced
    return true;
  };
  while (n < max_vertices) {
    SurfaceHit hit;
    const bool found = scene_.intersect(ray, hit);
    // In a medium, the subpath may scatter before it reaches the surface.
    if (medium >= 0) {
      const Medium& m = scene_.media()[size_t(medium)];
      Rng rng = medium_walk_rng(sampler);
      const float t = sample_collision(m, path_sigma_t(medium, hero, wl), ray,
                                       found ? hit.t : std::numeric_limits<float>::infinity(), rng);
      if (t < std::numeric_limits<float>::infinity()) {
        BdptVertex& v = path[n];
        BdptVertex& prev = path[n - 1];
        v = BdptVertex{};
        v.kind = Kind::Medium;
        v.p = ray.at(t);
        v.wo = -ray.direction;
        v.medium = medium;
        v.g = m.phase().g;
        // Distances were sampled by the extinction: what scatters of it is the albedo.
        RGB albedo = m.albedo(v.p);
        if (wl) albedo = reflectance_at(albedo, *wl);
        // An emissive medium: the s = 0 path that ends here, by the collision estimator (sigma_a Le
        // over the sigma_t that chose this distance). No other strategy samples points of a medium
        // as light vertices, so its MIS weight is 1. A path of depth n - 1, as volpath counts it
        // (there, at every tentative collision of a segment).
        if (crossed_emission && m.is_emissive() && n - 1 <= max_depth_)
          crossed_emission[n + 1] += beta * (RGB(1.0f) - albedo) * illuminant_at(m.emission(v.p), wl);
        beta *= albedo;
        v.beta = beta;
        v.pdf_fwd = convert_density(pdf_fwd, prev, v);
        ++n;
        if (n >= max_vertices || beta.is_black()) break;
        PhaseSample ps = m.phase().sample(v.wo, sampler.get_2d());
        if (!(ps.pdf > 0)) break;
        pdf_fwd = ps.pdf;
        prev.pdf_rev = convert_density(m.phase().pdf(ps.wi, v.wo), v, prev);
        ray = Ray{v.p, ps.wi, std::numeric_limits<float>::infinity(), ray.time};
        if (!survives_roulette()) break;
        continue;
      }
    }
    if (!found) {
      // A camera ray that escapes ends on the lights at infinity (a vertex even when there are none,
      // as the s = 0 strategy's end point).
      if (mode == Transport::Radiance) {
        BdptVertex& v = path[n];
        v = BdptVertex{};
        v.kind = Kind::Light;
        v.at_infinity = true;
        v.p = ray.origin + normalize(ray.direction);
        v.beta = beta;
        v.pdf_fwd = pdf_fwd;
        ++n;
      }
      break;
    }
    // An interface has no surface: continue beyond it. If it emits (pbrt's area lights of material
    // "interface"), the s = 0 strategy's path ends on it: weigh that now, as if it were the next vertex.
    if (scene_.is_interface(hit)) {
      if (crossed_emission && scene_.light_index(hit) >= 0 && !(n == 1 && hide_emitters_)) {
        BdptVertex& v = path[n];
        v = surface_vertex(hit, ray, beta);
        v.bsdf = SurfaceBsdf(BlackBsdf{});
        v.pdf_fwd = convert_density(pdf_fwd, path[n - 1], v);
        crossed_emission[n + 1] += connect<Sampler>(nullptr, path, 0, n + 1, sampler, counts, ray.time, wl).L;
      }
      medium = scene_.medium_after(hit, ray.direction, medium);
      ray.origin = offset_ray_origin(hit.p, hit.ng, ray.direction);
      ray.t_max = std::numeric_limits<float>::infinity();
      ray.t_min = 0;
      continue;
    }

    BdptVertex& v = path[n];
    BdptVertex& prev = path[n - 1];
    v = surface_vertex(hit, ray, beta);
    v.medium = medium;
    v.pdf_fwd = convert_density(pdf_fwd, prev, v);
    Shading shading = scene_.shading(hit, v.wo);
    bsdf_at_wavelengths(shading.bsdf, wl);
    v.bsdf = shading.bsdf;
    v.frame = shading.frame;
    v.ns = shading.frame.n;  // normal and bump maps tilt it
    ++n;
    if (n >= max_vertices || bsdf_is_black(v.bsdf)) break;

    // Sample the next direction.
    Vec3 wo_local = v.frame.to_local(v.wo);
    if (wo_local.z == 0) break;
    float u_lobe = sampler.get_1d();
    Vec2 u = sampler.get_2d();
    auto bs = bsdf_sample(v.bsdf, wo_local, u_lobe, u);
    if (!bs || bs->weight.is_black()) break;
    Vec3 wi = normalize(v.frame.to_world(bs->wi));
    RGB weight = bs->weight;
    if (mode == Transport::Importance) {
      // The adjoint BSDF: importance is not compressed at refractions; shading normals are corrected.
      // A BSDF that is not reciprocal (hair) was sampled by f(wo, .): its sample is weighted by the
      // adjoint f(., wo) it carries importance with.
      if (!bs->is_delta && !v.bsdf.is_reciprocal())
        weight = bsdf_eval_adjoint(v.bsdf, wo_local, bs->wi) * (std::abs(bs->wi.z) / bs->pdf);
      else if (bs->eta != 1)
        weight *= bs->eta * bs->eta;
      weight *= shading_normal_correction(v, v.wo, wi);
    } else if (bs->eta != 1) {
      eta_scale *= bs->eta * bs->eta;
    }
    beta *= weight;
    pdf_fwd = bs->pdf;
    float pdf_rev = bsdf_pdf(v.bsdf, bs->wi, wo_local);
    if (bs->is_delta) {
      v.delta = true;
      pdf_fwd = pdf_rev = 0;
    }
    prev.pdf_rev = convert_density(pdf_rev, v, prev);
    medium = scene_.medium_after(hit, wi, medium);
    ray = Ray{offset_ray_origin(hit.p, hit.ng, wi), wi, std::numeric_limits<float>::infinity(), ray.time};

    // Possibly terminate the subpath with Russian roulette. The MIS densities ignore it: the
    // weights stay a partition of unity, so the estimate stays unbiased.
    if (!survives_roulette()) break;
  }
  return n;
}

// ------------------------------------------------------------------------------- densities and MIS

float BdptIntegrator::convert_density(float pdf, const BdptVertex& from, const BdptVertex& next) const {
  if (next.at_infinity) return pdf;  // directions to infinity stay per solid angle
  Vec3 w = next.p - from.p;
  float d2 = length_squared(w);
  if (d2 == 0) return 0;
  float inv_d2 = 1 / d2;
  if (next.on_surface()) pdf *= std::abs(dot(next.ng, w * std::sqrt(inv_d2)));
  return pdf * inv_d2;
}

float BdptIntegrator::vertex_pdf(const BdptVertex* prev, const BdptVertex& v, const BdptVertex& next) const {
  if (v.kind == Kind::Light) return light_pdf(v, next);
  Vec3 wn = next.p - v.p;
  if (length_squared(wn) == 0) return 0;
  wn = normalize(wn);
  float pdf;
  if (v.kind == Kind::Camera) {
    pdf = scene_.camera().pdf_importance(v.p, wn).dir;
  } else if (v.kind == Kind::Medium) {
    pdf = HenyeyGreenstein{v.g}.pdf(normalize(prev->p - v.p), wn);
  } else {
    Vec3 wp = normalize(prev->p - v.p);
    pdf = bsdf_pdf(v.bsdf, v.frame.to_local(wp), v.frame.to_local(wn));
  }
  return convert_density(pdf, v, next);
}

float BdptIntegrator::light_pdf(const BdptVertex& lv, const BdptVertex& next) const {
  Vec3 w = next.p - lv.p;
  float d2 = length_squared(w);
  if (d2 == 0) return 0;
  w = w / std::sqrt(d2);
  float pdf;
  const SceneSphere& sphere = scene_.bounding_sphere();
  if (lv.at_infinity) {
    // Light paths from infinity start on the scene disk facing their direction.
    if (!scene_disk_covers(sphere, w, next.p)) return 0;
    pdf = 1 / (kPi * sphere.radius * sphere.radius);
  } else {
    if (lv.light < 0) return 0;
    pdf = light_pdf_le(scene_.lights()[size_t(lv.light)], lv.p, lv.ng, w, sphere).dir / d2;
  }
  if (next.on_surface()) pdf *= std::abs(dot(next.ng, w));
  return pdf;
}

float BdptIntegrator::light_origin_pdf(const BdptVertex& lv, const BdptVertex& next) const {
  Vec3 w = next.p - lv.p;
  if (length_squared(w) == 0) return 0;
  w = normalize(w);
  if (lv.at_infinity) return infinite_lights_pdf(w);
  if (lv.light < 0) return 0;
  const Light& light = scene_.lights()[size_t(lv.light)];
  return scene_.light_sampler().emitter_pmf(size_t(lv.light)) *
         light_pdf_le(light, lv.p, lv.ng, w, scene_.bounding_sphere()).pos;
}

float BdptIntegrator::nee_light_pdf_ratio(const BdptVertex& x0, const BdptVertex& x1) const {
  const LightSampler& choice = scene_.light_sampler();
  // The context next-event estimation at x1 would have used: the side of x1 facing the light (the
  // side the path arrives from wherever the path carries light) or, transmitting, both.
  Normal3 n(0.0f);
  if (x1.kind == Kind::Surface && !bsdf_has_non_delta_transmission(x1.bsdf))
    n = dot(x1.ns, x0.p - x1.p) > 0 ? x1.ns : -x1.ns;
  const LightSampleContext ctx{x1.p, n};
  if (x0.at_infinity) {
    // The light vertex stands for every light at infinity along its direction.
    Vec3 w = x1.p - x0.p;
    if (length_squared(w) == 0) return 1;
    w = normalize(w);
    float by_point = 0, by_power = 0;
    for (uint32_t li : scene_.infinite_lights()) {
      float pdf = light_pdf_le(scene_.lights()[li], {}, {}, w, scene_.bounding_sphere()).dir;
      by_point += choice.pmf(ctx, li) * pdf;
      by_power += choice.emitter_pmf(li) * pdf;
    }
    return by_power > 0 ? by_point / by_power : 1.0f;
  }
  if (x0.light < 0) return 1;
  const float by_power = choice.emitter_pmf(size_t(x0.light));
  return by_power > 0 ? choice.pmf(ctx, size_t(x0.light)) / by_power : 1.0f;
}

float BdptIntegrator::infinite_lights_pdf(const Vec3& emitted_dir) const {
  float pdf = 0;
  for (uint32_t li : scene_.infinite_lights())
    pdf += scene_.light_sampler().emitter_pmf(li) *
           light_pdf_le(scene_.lights()[li], {}, {}, emitted_dir, scene_.bounding_sphere()).dir;
  return pdf;
}

float BdptIntegrator::mis_weight(BdptVertex* light, BdptVertex* camera, BdptVertex& sampled, int s, int t) const {
  if (s + t == 2) return 1;
  BdptVertex* qs = s > 0 ? &light[s - 1] : nullptr;
  BdptVertex* pt = t > 0 ? &camera[t - 1] : nullptr;
  BdptVertex* qs_minus = s > 1 ? &light[s - 2] : nullptr;
  BdptVertex* pt_minus = t > 1 ? &camera[t - 2] : nullptr;

  // The connection's end vertices as this strategy made them: a freshly sampled light or lens
  // point replaces the subpath's own, neither end is delta, and the reverse densities across the
  // connection are those of the joined path.
  Restore<BdptVertex> a1;
  if (s == 1) a1 = Restore<BdptVertex>(qs, sampled);
  else if (t == 1) a1 = Restore<BdptVertex>(pt, sampled);
  Restore<bool> a2, a3;
  if (pt) a2 = Restore<bool>(&pt->delta, false);
  if (qs) a3 = Restore<bool>(&qs->delta, false);
  Restore<float> a4, a5, a6, a7;
  if (pt) a4 = Restore<float>(&pt->pdf_rev, s > 0 ? vertex_pdf(qs_minus, *qs, *pt) : light_origin_pdf(*pt, *pt_minus));
  if (pt_minus) a5 = Restore<float>(&pt_minus->pdf_rev, s > 0 ? vertex_pdf(qs, *pt, *pt_minus) : light_pdf(*pt, *pt_minus));
  if (qs) a6 = Restore<float>(&qs->pdf_rev, vertex_pdf(pt_minus, *pt, *qs));
  if (qs_minus) a7 = Restore<float>(&qs_minus->pdf_rev, vertex_pdf(pt, *qs, *qs_minus));

  // The light vertex's density in the s = 1 strategy differs from the others' by the factor
  // nee (its light chosen at the next vertex instead of by power; 1 unless the light BVH chooses),
  // which the subpaths and the s = 1 connection left on the light vertex.
  const float nee = s > 0 ? light[0].nee_ratio : camera[t - 1].nee_ratio;
  // p_other / p_this for strategy s_other, given the ratio r of their densities from the subpaths'
  // vertices alone. (Where s = 1 made the path, nee > 0: its light was chosen with that probability.)
  auto ratio = [&](float r, int s_other) {
    return r * (s_other == 1 ? nee : 1.0f) / (s == 1 ? std::max(nee, 1e-30f) : 1.0f);
  };

  // Sum over the other strategies of (p_other / p_this)^2, the ratios built up one vertex at a time
  // outwards from the connection on each side.
  float sum = 0;
  float r = 1;
  for (int i = t - 1; i > 0; --i) {
    r *= remap0(camera[i].pdf_rev) / remap0(camera[i].pdf_fwd);
    if (!camera[i].delta && !camera[i - 1].delta) sum += sqr(ratio(r, s + t - i));
  }
  r = 1;
  for (int i = s - 1; i >= 0; --i) {
    r *= remap0(light[i].pdf_rev) / remap0(light[i].pdf_fwd);
    bool delta_before = i > 0 ? light[i - 1].delta : is_delta_light(light[0]);
    if (!light[i].delta && !delta_before) sum += sqr(ratio(r, i));
  }
  return 1 / (1 + sum);
}

// ------------------------------------------------------------------------------------- connections

RGB BdptIntegrator::emitted(const BdptVertex& v, const BdptVertex& towards, const Wavelengths* wl) const {
  if (!is_light(v)) return RGB(0.0f);
  Vec3 w = towards.p - v.p;
  if (length_squared(w) == 0) return RGB(0.0f);
  w = normalize(w);
  if (v.at_infinity) {
    RGB L(0.0f);
    for (uint32_t li : scene_.infinite_lights()) L += scene_.escaped_radiance(li, -w);
    return illuminant_at(L, wl);
  }
  return illuminant_at(scene_.emitted(v.hit, w), wl);
}

RGB BdptIntegrator::scatter(const BdptVertex& v, const BdptVertex& next, Transport mode) const {
  Vec3 wi = next.p - v.p;
  if (length_squared(wi) == 0) return RGB(0.0f);
  wi = normalize(wi);
  if (v.kind == Kind::Medium) return RGB(HenyeyGreenstein{v.g}.p(v.wo, wi));  // symmetric: the same both ways
  Vec3 wo_local = v.frame.to_local(v.wo), wi_local = v.frame.to_local(wi);
  if (mode == Transport::Importance)
    return bsdf_eval_adjoint(v.bsdf, wo_local, wi_local) * shading_normal_correction(v, v.wo, wi);
  return bsdf_eval(v.bsdf, wo_local, wi_local);
}

bool BdptIntegrator::is_connectible(const BdptVertex& v) const {
  switch (v.kind) {
    case Kind::Camera: return true;
    case Kind::Light:
      // (a light of a single direction cannot be reached from another point)
      return v.light >= 0 && !has(light_flags(scene_.lights()[size_t(v.light)]), LightFlags::DeltaDirection);
    case Kind::Surface: return bsdf_has_non_delta(v.bsdf);
    case Kind::Medium: return true;
  }
  return false;
}

bool BdptIntegrator::is_delta_light(const BdptVertex& v) const {
  return v.kind == Kind::Light && v.light >= 0 && light_is_delta(scene_.lights()[size_t(v.light)]);
}

RGB BdptIntegrator::visibility(const BdptVertex& a, const BdptVertex& b, float time, RayCounts& counts, Rng& rng,
                               int hero, const Wavelengths* wl) const {
  Ray ray;
  ray.time = time;
  const BdptVertex* from = &a;
  if (a.at_infinity || b.at_infinity) {
    const BdptVertex& finite = a.at_infinity ? b : a;
    const BdptVertex& far = a.at_infinity ? a : b;
    from = &finite;
    ray.direction = normalize(far.p - finite.p);
    ray.origin = finite.on_surface() ? offset_ray_origin(finite.p, finite.ng, ray.direction) : finite.p;
    ray.t_max = std::numeric_limits<float>::infinity();
  } else {
    Vec3 d = b.p - a.p;
    ray.origin = a.on_surface() ? offset_ray_origin(a.p, a.ng, d) : a.p;
    Point3 to = b.on_surface() ? offset_ray_origin(b.p, b.ng, -d) : b.p;
    Vec3 segment = to - ray.origin;
    float len = length(segment);
    if (!(len > 0)) return RGB(1.0f);
    ray.direction = segment / len;
    ray.t_max = len * (1 - 1e-4f);
  }
  ++counts.shadow;
  if (!scene_.has_interfaces() && !scene_.has_media()) return RGB(scene_.occluded(ray) ? 0.0f : 1.0f);
  // Look past interfaces (surfaces without a material of their own), through the media between.
  int medium = scene_.has_media() ? outgoing_medium(*from, ray.direction) : -1;
  const Point3 end = ray.at(std::isfinite(ray.t_max) ? ray.t_max : 0.0f);
  float T = 1;
  for (int crossed = 0; crossed < 256; ++crossed) {
    SurfaceHit hit;
    const bool found = scene_.intersect(ray, hit);
    if (found && !scene_.is_interface(hit)) return RGB(0.0f);
    if (medium >= 0) {
      T *= estimate_transmittance(scene_.media()[size_t(medium)], path_sigma_t(medium, hero, wl), ray,
                                 found ? hit.t : ray.t_max, rng);
      if (!(T > 0)) return RGB(0.0f);
    }
    if (!found) return RGB(T);
    medium = scene_.medium_after(hit, ray.direction, medium);
    ray.origin = offset_ray_origin(hit.p, hit.ng, ray.direction);
    // Aim at the same end point again (the offset origin is off the original line).
    if (std::isfinite(ray.t_max)) {
      const Vec3 rest = end - ray.origin;
      const float len = length(rest);
      if (!(len > 0) || dot(rest, ray.direction) <= 0) return RGB(T);
      ray.direction = rest / len;
      ray.t_max = len;
    }
    ++counts.shadow;
  }
  return RGB(0.0f);
}

float BdptIntegrator::geometry_term(const BdptVertex& a, const BdptVertex& b) const {
  Vec3 d = a.p - b.p;
  float g = 1 / length_squared(d);
  d = d * std::sqrt(g);
  if (a.on_surface()) g *= std::abs(dot(a.ns, d));
  if (b.on_surface()) g *= std::abs(dot(b.ns, d));
  return g;
}

template <typename Sampler>
BdptIntegrator::Connection BdptIntegrator::connect(BdptVertex* light, BdptVertex* camera, int s, int t,
                                                   Sampler& sampler, RayCounts& counts, float time,
                                                   const Wavelengths* wl) const {
  Connection c;
  // A camera subpath that escaped can only be completed by itself (s = 0).
  if (t > 1 && s != 0 && camera[t - 1].kind == Kind::Light) return c;
  RGB L(0.0f);
  BdptVertex sampled;
  Rng rng;
  if (scene_.has_media() && s > 0) rng = medium_walk_rng(sampler);
  const int hero = camera[0].hero;
  if (s == 0) {
    // The camera subpath hit a light.
    const BdptVertex& pt = camera[t - 1];
    if (is_light(pt)) L = pt.beta * emitted(pt, camera[t - 2], wl);
  } else if (t == 1) {
    // Light tracing: join the light vertex to a point on the lens.
    const BdptVertex& qs = light[s - 1];
    Vec2 u = sampler.get_2d();
    if (!is_connectible(qs)) return c;
    auto lens = scene_.camera().sample_lens(qs.p, u);
    if (!lens) return c;
    sampled.kind = Kind::Camera;
    sampled.p = lens->p;
    sampled.beta = RGB(lens->importance / lens->pdf);
    L = qs.beta * scatter(qs, sampled, Transport::Importance) * sampled.beta;
    if (qs.on_surface()) L *= std::abs(dot(lens->wi, qs.ns));
    // Visibility up to the near clipping plane only (the lens point itself without one).
    BdptVertex visible = sampled;
    visible.p = lens->p_visible;
    if (L.is_black()) return c;
    // The lens point counts once, as the camera vertex of the camera subpath does: with a hero
    // channel, three times that channel alone.
    if (hero >= 0) L *= camera[0].beta;
    L *= visibility(qs, visible, time, counts, rng, hero, wl);
    if (L.is_black()) return c;
    c.raster = lens->raster;
  } else if (s == 1) {
    // Next-event estimation: a point on a light chosen by the scene's light sampler (the light BVH
    // asks what each light can give at the camera vertex), seen from the camera vertex.
    const BdptVertex& pt = camera[t - 1];
    float u_light = sampler.get_1d();
    Vec2 u = sampler.get_2d();
    if (!is_connectible(pt)) return c;
    Vec3 wo_local = pt.frame.to_local(pt.wo);
    Normal3 gather = pt.kind == Kind::Medium || bsdf_has_non_delta_transmission(pt.bsdf) ? Normal3(0.0f)
                     : wo_local.z > 0                                                   ? pt.ns
                                                                                        : -pt.ns;
    const SampledLight chosen = scene_.light_sampler().sample(LightSampleContext{pt.p, gather}, u_light);
    const size_t li = chosen.light;
    const float pmf = chosen.pmf;
    if (!(pmf > 0)) return c;
    const Light& lt = scene_.lights()[li];
    LightSample ls = light_sample_li(lt, LightSampleContext{pt.p, gather}, u);
    if (!(ls.pdf > 0) || ls.radiance.is_black() || pmf <= 0) return c;
    sampled.kind = Kind::Light;
    sampled.light = int(li);
    sampled.at_infinity = std::isinf(ls.distance);
    sampled.p = sampled.at_infinity ? pt.p + ls.wi * (2 * scene_.bounding_sphere().radius) : ls.p_light;
    sampled.ng = sampled.ns = sampled.at_infinity ? Normal3(0.0f) : ls.n_light;
    if (scene_.light_sampler().uses_bvh()) {
      // (A light at infinity stands for all of them, as in light_origin_pdf.)
      const float by_power = scene_.light_sampler().emitter_pmf(li);
      sampled.nee_ratio = sampled.at_infinity ? nee_light_pdf_ratio(sampled, pt)
                          : by_power > 0      ? pmf / by_power
                                              : 1.0f;
    }
    sampled.beta = illuminant_at(ls.radiance, wl) / (ls.pdf * pmf);
    sampled.pdf_fwd = light_origin_pdf(sampled, pt);
    L = pt.beta * scatter(pt, sampled, Transport::Radiance) * sampled.beta;
    if (pt.on_surface()) L *= std::abs(dot(ls.wi, pt.ns));
    if (L.is_black()) return c;
    L *= visibility(pt, sampled, time, counts, rng, hero, wl);
  } else {
    // Join the two subpaths' end vertices with a shadow ray.
    const BdptVertex& qs = light[s - 1];
    const BdptVertex& pt = camera[t - 1];
    if (!is_connectible(qs) || !is_connectible(pt)) return c;
    L = qs.beta * scatter(qs, pt, Transport::Importance) * scatter(pt, qs, Transport::Radiance) * pt.beta;
    if (L.is_black()) return c;
    L *= geometry_term(qs, pt);
    if (L.is_black()) return c;
    L *= visibility(qs, pt, time, counts, rng, hero, wl);
  }
  if (L.is_black()) return c;
  c.unweighted = L;
  c.weight = mis_weight(light, camera, sampled, s, t);
  c.L = L * c.weight;
  return c;
}

// ----------------------------------------------------------------------------------- the estimator

template <typename Sampler>
RGB BdptIntegrator::radiance(const Ray& ray, Sampler& sampler, RayCounts& counts, const BdptTarget& target, int x,
                             int y, float filter_weight, bool first_half, const Wavelengths* wl) const {
  thread_local std::vector<BdptVertex> camera_path, light_path;
  camera_path.resize(size_t(max_depth_) + 2);
  light_path.resize(size_t(max_depth_) + 1);
  BdptVertex* cv = camera_path.data();
  BdptVertex* lv = light_path.data();
  thread_local std::vector<RGB> crossed;
  crossed.assign(size_t(max_depth_) + 3, RGB(0.0f));
  int nc = camera_subpath(ray, sampler, counts, max_depth_ + 2, cv, crossed.data(), wl);
  int nl = light_subpath(sampler, counts, max_depth_ + 1, ray.time, lv, wl, nc > 0 ? cv[0].hero : -1);
  // What reaches an image directly (splats, strategy images) is RGB.
  auto to_rgb = [wl](const RGB& v) { return wavelengths_to_rgb(v, wl); };

  // Strategy images are scaled like the light image (importance film area / light paths); camera
  // samples of a pixel count per pixel, hence the ratio of the image's area to the importance film's.
  const PerspectiveCamera& camera = scene_.camera();
  const float camera_part_scale = float(camera.width()) * float(camera.height()) / camera.importance_film_pixels();
  RGB L(0.0f);
  for (int t = 2; t <= max_depth_ + 2; ++t) {
    if (crossed[size_t(t)].is_black()) continue;
    L += crossed[size_t(t)];
    if (target.strategies && strategy_index(0, t) < int(target.strategies->size()) && !target.unweighted)
      (*target.strategies)[size_t(strategy_index(0, t))].add_to_pixel(
          x, y, to_rgb(crossed[size_t(t)]) * (filter_weight / target.filter->integral() * camera_part_scale));
  }
  for (int t = 1; t <= nc; ++t)
    for (int s = 0; s <= nl; ++s) {
      int depth = s + t - 2;
      if ((s == 1 && t == 1) || depth < 0 || depth > max_depth_ || (depth == 0 && hide_emitters_)) continue;
      Connection c = connect(lv, cv, s, t, sampler, counts, ray.time, wl);
      if (t == 1) {
        if (!c.L.is_black()) {
          const RGB v = scene_.film_sensor().respond(to_rgb(c.L));
          target.film->splats().add(c.raster, v, *target.filter);
          if (first_half) target.film->half_splats().add(c.raster, v, *target.filter);
        }
      } else {
        L += c.L;
      }
      if (target.strategies) {
        int index = strategy_index(s, t);
        if (index < int(target.strategies->size())) {
          RGB v = to_rgb(target.unweighted ? c.unweighted : c.L);
          SplatImage& img = (*target.strategies)[size_t(index)];
          if (v.is_black() || !v.is_finite()) continue;
          if (t == 1) img.add(c.raster, v, *target.filter);
          else img.add_to_pixel(x, y, v * (filter_weight / target.filter->integral() * camera_part_scale));
        }
      }
    }
  return L;
}

BdptStrategyImages::BdptStrategyImages(const RenderSettings& settings, int width, int height, std::string directory,
                                       bool unweighted)
    : depth_(std::min(settings.max_depth, 5)),
      directory_(std::move(directory)),
      unweighted_(unweighted),
      images_(size_t(BdptIntegrator::strategy_count(depth_)), SplatImage(width, height)) {}

void BdptStrategyImages::sum_across(Cluster& cluster) {
  for (SplatImage& image : images_) cluster.sum_int64(image.sums());
}

void BdptStrategyImages::write(const Film& film, const std::map<std::string, std::string>& metadata) const {
  for (int depth = 0; depth <= depth_; ++depth)
    for (int s = 0; s <= depth + 1; ++s) {
      const int t = depth + 2 - s;
      const std::filesystem::path file =
          std::filesystem::path(directory_) / fmt::format("bdpt_d{}_s{}_t{}.exr", depth, s, t);
      write_image(file, images_[size_t(BdptIntegrator::strategy_index(s, t))].image(film.splat_scale()), metadata);
    }
}

std::unique_ptr<IntegratorOutputs> make_bdpt_strategy_images(const RenderSettings& settings, int width, int height,
                                                             const std::string& directory, bool unweighted) {
  if (directory.empty()) return nullptr;
  return std::make_unique<BdptStrategyImages>(settings, width, height, directory, unweighted);
}

RenderStats render_bdpt(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  if (!film.has_splats()) film.enable_splats();
  const BdptIntegrator bdpt(scene, settings);
  const Filter filter(settings.filter);
  auto* strategies = dynamic_cast<BdptStrategyImages*>(options.integrator_outputs);
  const BdptTarget target{&film, &filter, strategies ? &strategies->images() : nullptr,
                          strategies && strategies->unweighted()};
  CameraSampleTiles tiles([&](const Ray& ray, auto& sampler, RayCounts& counts, const PixelSample& pixel,
                              const Wavelengths* wl) {
    return bdpt.radiance(ray, sampler, counts, target, pixel.x, pixel.y, pixel.filter_weight, pixel.first_half, wl);
  });
  // One light path is traced per camera sample: the light image is the splats times the
  // importance film's area over their number.
  film.set_one_light_path_per_sample(double(scene.camera().importance_film_pixels()));
  return render_tiles(scene, settings, film, options, tiles);
}

// One instantiation per pixel sampler, and one for Metropolis light transport's sampler.
#define CANDELA_INSTANTIATE(S)                                                                              \
  template RGB BdptIntegrator::radiance<S>(const Ray&, S&, RayCounts&, const BdptTarget&, int, int, float, bool,   \
                                           const Wavelengths*) const;                                           \
  template int BdptIntegrator::camera_subpath<S>(const Ray&, S&, RayCounts&, int, BdptVertex*, RGB*,            \
                                                 const Wavelengths*) const;                                     \
  template int BdptIntegrator::light_subpath<S>(S&, RayCounts&, int, float, BdptVertex*, const Wavelengths*, int) \
      const;                                                                                                    \
  template BdptIntegrator::Connection BdptIntegrator::connect<S>(BdptVertex*, BdptVertex*, int, int, S&,       \
                                                                 RayCounts&, float, const Wavelengths*) const;
CANDELA_FOR_EACH_SAMPLER(CANDELA_INSTANTIATE)
CANDELA_INSTANTIATE(MltSampler)
#undef CANDELA_INSTANTIATE

}  // namespace candela
