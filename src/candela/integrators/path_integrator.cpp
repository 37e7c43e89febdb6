#include "candela/integrators/path_integrator.h"

#include "candela/materials/spectral_bsdf.h"
#include "candela/render/camera_sample_tiles.h"
#include "candela/sampling/samplers.h"
#include "candela/sampling/warp.h"

namespace candela {

struct PathIntegrator::Vertex {
  const SurfaceHit& hit;
  const SurfaceBsdf& bsdf;
  const Frame& frame;
  Vec3 wo_local;
  LightSampleContext ctx;
  float time;
  const Wavelengths* wl;
};

PathIntegrator::PathIntegrator(const Scene& scene, const RenderSettings& settings)
    : scene_(scene),
      max_depth_(settings.max_depth),
      rr_start_depth_(settings.rr_start_depth),
      direction_sampling_(settings.path.direction_sampling),
      mis_(settings.path.mis),
      hide_emitters_(settings.hide_emitters),
      shadow_rays_(std::max(1, settings.path.shadow_rays)) {}

template <typename Sampler>
RGB PathIntegrator::radiance(Ray ray, Sampler& sampler, RayCounts& counts, const Wavelengths* wl,
                             PathVertexVisitor* visitor) const {
  RGB L(0.0f), beta(1.0f);
  int max_depth = max_depth_;  // a visitor may end the path earlier
  bool specular_bounce = false;
  float eta_scale = 1;
  float prev_bsdf_pdf = 0;
  LightSampleContext prev_ctx;
  ++counts.camera;

  for (int depth = 0;;) {
    SurfaceHit hit;
    if (!scene_.intersect(ray, hit)) {
      // The ray escapes: add the radiance of the lights at infinity, weighted by MIS against light
      // sampling where that could have produced the same direction.
      for (uint32_t li : scene_.infinite_lights()) {
        if (depth == 0 && hide_emitters_) break;
        RGB Le = illuminant_at(scene_.escaped_radiance(li, ray.direction), wl);
        if (Le.is_black()) continue;
        if (depth == 0 || specular_bounce)
          L += beta * Le;
        else
          L += beta * Le *
               emitter_mis_weight(li, prev_bsdf_pdf, light_pdf_li(scene_.lights()[li], prev_ctx, ray.direction, {}, {}),
                                  prev_ctx);
      }
      break;
    }

    // Add emission from a surface the path hit, again MIS-weighted after non-delta bounces.
    Vec3 wo = -ray.direction;
    RGB Le = depth == 0 && hide_emitters_ ? RGB(0.0f) : illuminant_at(scene_.emitted(hit, wo), wl);
    if (!Le.is_black()) {
      if (depth == 0 || specular_bounce) {
        L += beta * Le;
      } else {
        size_t li = size_t(scene_.light_index(hit));
        float pdf_li = light_pdf_li(scene_.lights()[li], prev_ctx, ray.direction, hit.p, hit.ng);
        L += beta * Le * emitter_mis_weight(li, prev_bsdf_pdf, pdf_li, prev_ctx);
      }
    }

    // An interface has no surface: continue the ray beyond it without counting a bounce. Light
    // sampling cannot see through it (shadow rays stop there), so what lies behind counts in full.
    if (scene_.is_interface(hit)) {
      specular_bounce = true;
      ray = Ray{offset_ray_origin(hit.p, hit.ng, ray.direction), ray.direction,
                std::numeric_limits<float>::infinity(), ray.time};
      ++counts.bounce;
      continue;
    }

    // Terminate the path at the maximum depth.
    if (depth == max_depth) break;
    ++depth;
    // The BSDF and its shading frame (normal or bump mapped). A mask's "absent" part is a delta
    // event of this BSDF: it continues the path straight on and counts as a bounce (as Mitsuba does).
    Shading shading = scene_.shading(hit, wo);
    bsdf_at_wavelengths(shading.bsdf, wl);
    const SurfaceBsdf& bsdf = shading.bsdf;
    if (bsdf_is_black(bsdf)) break;

    const Frame& frame = shading.frame;
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;
    // Light is gathered on the side the path arrived from, or on both for diffusely transmitting BSDFs.
    Normal3 gather_n = bsdf_has_non_delta_transmission(bsdf) ? Normal3(0.0f) : wo_local.z > 0 ? frame.n : -frame.n;
    Vertex vertex{hit, bsdf, frame, wo_local, {hit.p, gather_n}, ray.time, wl};

    // Sample direct illumination with shadow rays (next-event estimation).
    if (bsdf_has_non_delta(bsdf) && !scene_.lights().empty()) L += beta * direct_light(vertex, sampler, counts);
    if (visitor && visitor->visit(PathVertexView{hit, shading, wo, beta, depth})) max_depth = depth;

    // Choose the next direction; the material's Russian roulette over its modes happens inside
    // (the paper's d, s, t).
    auto bs = sample_direction(bsdf, wo_local, sampler);
    if (!bs || bs->weight.is_black()) break;
    beta *= bs->weight;
    Vec3 wi = normalize(frame.to_world(bs->wi));
    specular_bounce = bs->is_delta;
    prev_bsdf_pdf = bs->pdf;
    prev_ctx = vertex.ctx;
    if (bs->eta != 1) eta_scale *= bs->eta * bs->eta;
    ray = Ray{offset_ray_origin(hit.p, hit.ng, wi), wi, std::numeric_limits<float>::infinity(), ray.time};

    // Possibly terminate the path with Russian roulette; survivors are reweighted so the estimate
    // stays unbiased. eta_scale undoes the radiance scaling at refractions, which says nothing about
    // the path's importance.
    RGB rr_beta = beta * eta_scale;
    if (depth > rr_start_depth_ && rr_beta.max_component() < 1) {
      float q = std::max(0.0f, 1 - rr_beta.max_component());
      if (sampler.get_1d() < q) break;
      beta = beta / (1 - q);
    }
    ++counts.bounce;  // counted once the ray is sure to be traced
  }
  return L;
}

template <typename Sampler>
std::optional<BsdfSample> PathIntegrator::sample_direction(const SurfaceBsdf& bsdf, const Vec3& wo, Sampler& sampler) const {
  float u_lobe = sampler.get_1d();
  Vec2 u = sampler.get_2d();
  float non_delta = bsdf_non_delta_probability(bsdf, wo);
  if (direction_sampling_ == DirectionSampling::Bsdf || u_lobe >= non_delta) return bsdf_sample(bsdf, wo, u_lobe, u);
  // A non-delta lobe was chosen: draw the direction from the hemisphere on wo's side instead of the
  // lobe (or, for BSDFs that transmit diffusely, from either side with probability 1/2), and weight
  // it by the BSDF (sec. 4.7).
  Vec3 wi = direction_sampling_ == DirectionSampling::Cosine ? square_to_cosine_hemisphere(u)
                                                              : square_to_uniform_hemisphere(u);
  bool other_side = bsdf_has_non_delta_transmission(bsdf) && u_lobe < 0.5f * non_delta;
  if ((wo.z < 0) != other_side) wi.z = -wi.z;
  float pdf = direction_pdf(bsdf, wo, wi);
  if (pdf <= 0) return std::nullopt;
  return BsdfSample{wi, bsdf_eval(bsdf, wo, wi) * (std::abs(wi.z) / pdf), pdf, false, 1};
}

float PathIntegrator::direction_pdf(const SurfaceBsdf& bsdf, const Vec3& wo, const Vec3& wi) const {
  if (direction_sampling_ == DirectionSampling::Bsdf) return bsdf_pdf(bsdf, wo, wi);
  float hemisphere = direction_sampling_ == DirectionSampling::Cosine ? std::abs(wi.z) * kInvPi : kInv2Pi;
  float p = bsdf_non_delta_probability(bsdf, wo) * hemisphere;
  if (bsdf_has_non_delta_transmission(bsdf)) return 0.5f * p;  // either side, half the time each
  return wo.z * wi.z > 0 ? p : 0.0f;
}

float PathIntegrator::expected_shadow_rays(size_t li, const LightSampleContext& ctx) const {
  return float(shadow_rays_) * scene_.light_sampler().pmf(ctx, li);
}

float PathIntegrator::emitter_mis_weight(size_t li, float bsdf_pdf, float light_pdf_li, const LightSampleContext& prev) const {
  if (!mis_) return 0;  // without MIS, light found by bounces is left to the shadow rays
  float light_pdf = expected_shadow_rays(li, prev) * light_pdf_li;
  return power_heuristic(bsdf_pdf, light_pdf);
}

namespace {

// Maps u into cell (k + rotation) mod (nx ny) of an nx x ny grid over [0,1)^2, nx ny >= n: the n
// samples of one vertex land in distinct strata, and each is still uniform on its own (the random
// rotation picks its cell uniformly), which is what keeps the estimate unbiased for any n.
Vec2 stratified_square(Vec2 u, int k, int n, float rotation) {
  if (n <= 1) return u;
  int nx = int(std::ceil(std::sqrt(float(n)))), ny = (n + nx - 1) / nx;
  int cells = nx * ny;
  int cell = (k + std::min(int(rotation * float(cells)), cells - 1)) % cells;
  return {std::min((float(cell % nx) + u.x) / float(nx), 0x1.fffffep-1f),
          std::min((float(cell / nx) + u.y) / float(ny), 0x1.fffffep-1f)};
}

}  // namespace

template <typename Sampler>
RGB PathIntegrator::direct_light(const Vertex& v, Sampler& sampler, RayCounts& counts) const {
  // Each shadow ray goes to one light chosen by the scene's light sampler: by power, uniformly over
  // emitters, through the light BVH by what each light can give here, or by the paper's rule (its
  // estimate of each light's irradiance here, found through the same tree); with several rays, the
  // light choices and the points on the lights are stratified, so that a light of share p here
  // gets p x shadow_rays of them on average (the paper's expected values, sec. 4.5).
  RGB sum(0.0f);
  const LightSampler& choice = scene_.light_sampler();
  float rotation = shadow_rays_ > 1 ? sampler.get_1d() : 0.0f;
  for (int k = 0; k < shadow_rays_; ++k) {
    float u_choice = (float(k) + sampler.get_1d()) / float(shadow_rays_);
    SampledLight chosen = choice.sample(v.ctx, std::min(u_choice, 0x1.fffffep-1f));
    Vec2 u = stratified_square(sampler.get_2d(), k, shadow_rays_, rotation);
    if (chosen.pmf > 0)  // (none: no light can reach this vertex)
      sum += shadow_ray_estimate(v, chosen.light, u, float(shadow_rays_) * chosen.pmf, counts);
  }
  return sum;
}

RGB PathIntegrator::shadow_ray_estimate(const Vertex& v, size_t li, const Vec2& u, float expected_rays,
                                        RayCounts& counts) const {
  const Light& light = scene_.lights()[li];
  LightSample ls = light_sample_li(light, v.ctx, u);
  if (ls.pdf <= 0 || ls.radiance.is_black()) return RGB(0.0f);
  Vec3 wi_local = v.frame.to_local(ls.wi);
  RGB f = bsdf_eval(v.bsdf, v.wo_local, wi_local) * std::abs(wi_local.z);
  if (f.is_black()) return RGB(0.0f);

  // Trace the shadow ray; it stops just short of the sampled point on the light.
  Point3 origin = offset_ray_origin(v.hit.p, v.hit.ng, ls.wi);
  Ray shadow = std::isinf(ls.distance) ? Ray{origin, ls.wi, std::numeric_limits<float>::infinity(), v.time}
                                       : Ray{origin, ls.p_light - origin, 1 - 1e-4f, v.time};
  ++counts.shadow;
  if (scene_.occluded(shadow)) return RGB(0.0f);

  // One sample of the light strategy, of which `expected_rays` are taken on average here (its
  // emission at the path's wavelengths only now that it counts).
  const RGB Le = illuminant_at(ls.radiance, v.wl);
  float light_pdf = expected_rays * ls.pdf;
  if (ls.is_delta || !mis_) return f * Le / light_pdf;
  float w = power_heuristic(light_pdf, direction_pdf(v.bsdf, v.wo_local, wi_local));
  return f * Le * (w / light_pdf);
}

RenderStats render_path(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  return render_camera_samples<PathIntegrator>(scene, settings, film, options);
}

// One instantiation per sampler type of the variant.
#define CANDELA_INSTANTIATE(S) \
  template RGB PathIntegrator::radiance<S>(Ray, S&, RayCounts&, const Wavelengths*, PathVertexVisitor*) const;
CANDELA_FOR_EACH_SAMPLER(CANDELA_INSTANTIATE)
#undef CANDELA_INSTANTIATE

}  // namespace candela
