#include "candela/integrators/path_integrator.h"

namespace candela {

RGB PathIntegrator::radiance(Ray ray, IndependentSampler& sampler, RayCounts& counts) const {
  RGB L(0.0f), beta(1.0f);
  bool specular_bounce = false;
  float eta_scale = 1;
  float prev_bsdf_pdf = 0;
  LightSampleContext prev_ctx;
  const Distribution1D& light_choice = scene_.light_distribution();
  ++counts.camera;

  for (int depth = 0;; ++depth) {
    SurfaceHit hit;
    if (!scene_.intersect(ray, hit)) {
      // The ray escapes: add sky radiance, weighted by MIS against light sampling where that could
      // have produced the same direction.
      int sky = scene_.sky_light();
      if (sky >= 0) {
        const auto& light = std::get<SkyLightSource>(scene_.lights()[sky]);
        RGB Le = light.radiance(ray.direction);
        if (depth == 0 || specular_bounce) {
          L += beta * Le;
        } else {
          float light_pdf = light_choice.pmf(sky) * light.pdf_li(prev_ctx, ray.direction, {}, {});
          L += beta * Le * power_heuristic(prev_bsdf_pdf, light_pdf);
        }
      }
      break;
    }

    // Add emission from a surface the path hit, again MIS-weighted after non-delta bounces.
    Vec3 wo = -ray.direction;
    RGB Le = scene_.emitted(hit, wo);
    if (!Le.is_black()) {
      if (depth == 0 || specular_bounce) {
        L += beta * Le;
      } else {
        int li = scene_.light_index(hit);
        float light_pdf = light_choice.pmf(size_t(li)) *
                          light_pdf_li(scene_.lights()[li], prev_ctx, ray.direction, hit.p, hit.ng);
        L += beta * Le * power_heuristic(prev_bsdf_pdf, light_pdf);
      }
    }

    // Terminate the path at the maximum depth.
    if (depth == max_depth_) break;
    const Bsdf& bsdf = scene_.bsdf(hit);
    if (bsdf_is_black(bsdf)) break;

    Frame frame(hit.ns);
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;
    // Light is gathered on the side the path arrived from.
    LightSampleContext ctx{hit.p, wo_local.z > 0 ? hit.ns : -hit.ns};

    // Sample direct illumination from one light chosen by power (next-event estimation).
    if (bsdf_has_non_delta(bsdf) && !light_choice.empty())
      L += beta * sample_direct(hit, bsdf, frame, wo_local, ctx, ray.time, sampler, counts);

    // Sample the BSDF for the next direction; the material's Russian roulette over its modes
    // happens inside (the paper's d, s, t).
    float u_lobe = sampler.get_1d();
    Vec2 u_dir = sampler.get_2d();
    auto bs = bsdf_sample(bsdf, wo_local, u_lobe, u_dir);
    if (!bs || bs->weight.is_black()) break;
    beta *= bs->weight;
    Vec3 wi = normalize(frame.to_world(bs->wi));
    specular_bounce = bs->is_delta;
    prev_bsdf_pdf = bs->pdf;
    prev_ctx = ctx;
    if (bs->eta != 1) eta_scale *= bs->eta * bs->eta;
    ray = Ray{offset_ray_origin(hit.p, hit.ng, wi), wi, std::numeric_limits<float>::infinity(), ray.time};
    ++counts.bounce;

    // Possibly terminate the path with Russian roulette; survivors are reweighted so the estimate
    // stays unbiased. eta_scale undoes the radiance scaling at refractions, which says nothing about
    // the path's importance.
    RGB rr_beta = beta * eta_scale;
    if (depth + 1 > rr_start_depth_ && rr_beta.max_component() < 1) {
      float q = std::max(0.0f, 1 - rr_beta.max_component());
      if (sampler.get_1d() < q) break;
      beta = beta / (1 - q);
    }
  }
  return L;
}

RGB PathIntegrator::sample_direct(const SurfaceHit& hit, const Bsdf& bsdf, const Frame& frame, const Vec3& wo_local,
                                  const LightSampleContext& ctx, float time, IndependentSampler& sampler,
                                  RayCounts& counts) const {
  const Distribution1D& light_choice = scene_.light_distribution();
  float u_light = sampler.get_1d();
  Vec2 u = sampler.get_2d();
  size_t li = light_choice.sample(u_light);
  const Light& light = scene_.lights()[li];
  LightSample ls = light_sample_li(light, ctx, u);
  if (ls.pdf <= 0 || ls.radiance.is_black()) return RGB(0.0f);

  Vec3 wi_local = frame.to_local(ls.wi);
  RGB f = bsdf_eval(bsdf, wo_local, wi_local) * std::abs(wi_local.z);
  if (f.is_black()) return RGB(0.0f);

  // Trace the shadow ray; it stops just short of the sampled point on the light.
  Point3 origin = offset_ray_origin(hit.p, hit.ng, ls.wi);
  Ray shadow = std::isinf(ls.distance)
                   ? Ray{origin, ls.wi, std::numeric_limits<float>::infinity(), time}
                   : Ray{origin, ls.p_light - origin, 1 - 1e-4f, time};
  ++counts.shadow;
  if (scene_.occluded(shadow)) return RGB(0.0f);

  float light_pdf = light_choice.pmf(li) * ls.pdf;
  if (ls.is_delta) return f * ls.radiance / light_pdf;
  float w = power_heuristic(light_pdf, bsdf_pdf(bsdf, wo_local, wi_local));
  return f * ls.radiance * (w / light_pdf);
}

}  // namespace candela
