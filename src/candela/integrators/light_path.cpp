#include "candela/integrators/light_path.h"

#include <fmt/format.h>

#include <vector>

#include "candela/base/error.h"
#include "candela/render/camera_sample_tiles.h"
#include "candela/sampling/samplers.h"

namespace candela {

LightPathIntegrator::LightPathIntegrator(const Scene& scene, const RenderSettings& settings)
    : scene_(scene), bdpt_(scene, settings) {}

template <typename Sampler>
RGB LightPathIntegrator::trace(const Ray& ray, Sampler& sampler, RayCounts& counts, Film& film, const Filter& filter,
                               bool first_half, const Wavelengths* wl) const {
  const int max_depth = bdpt_.max_depth();
  thread_local std::vector<BdptVertex> light_path_vertices;
  light_path_vertices.resize(size_t(max_depth) + 1);
  BdptVertex* light = light_path_vertices.data();
  // Step 1: the camera vertex alone (a camera subpath of one vertex: the lens point of this sample
  // and, in chromatic media, the hero lane the light subpath samples media by). Its ray is not traced.
  BdptVertex camera;
  if (bdpt_.camera_subpath(ray, sampler, counts, 1, &camera, nullptr, wl) == 0) return RGB(0.0f);
  // Step 2: a light subpath of at most max_depth + 1 vertices (the light and max_depth bounces).
  const int vertices = bdpt_.light_subpath(sampler, counts, max_depth + 1, ray.time, light, wl, camera.hero);
  // Step 3: each scattering vertex (s >= 2: depth s - 1) joined to a point on the lens, unweighted,
  // splatted where it lands. The light's own vertex (s = 1) is not: emitters seen directly stay black.
  for (int s = 2; s <= vertices; ++s) {
    const BdptIntegrator::Connection c = bdpt_.connect(light, &camera, s, 1, sampler, counts, ray.time, wl);
    if (c.unweighted.is_black() || !c.unweighted.is_finite()) continue;
    const RGB v = scene_.film_sensor().respond(wavelengths_to_rgb(c.unweighted, wl));
    film.splats().add(c.raster, v, filter);
    if (first_half) film.half_splats().add(c.raster, v, filter);
  }
  return RGB(0.0f);
}

RenderStats render_light_path(const Scene& scene, const RenderSettings& settings, Film& film,
                              const RenderOptions& options) {
  // Its image is made of light paths joined to the lens alone: a camera none can be joined to would
  // give a black image.
  if (scene.camera().is_delta_direction())
    throw UsageError(fmt::format("the light_path integrator joins light paths to the camera, which an {} camera "
                                 "cannot be: use the path or bdpt integrator",
                                 scene.camera().is_orthographic() ? "orthographic" : "spherical"));
  if (!film.has_splats()) film.enable_splats();
  const LightPathIntegrator tracer(scene, settings);
  const Filter filter(settings.filter);
  CameraSampleTiles tiles([&](const Ray& ray, auto& sampler, RayCounts& counts, const PixelSample& pixel,
                              const Wavelengths* wl) {
    return tracer.trace(ray, sampler, counts, film, filter, pixel.first_half, wl);
  });
  // One light path per camera sample: the image is the splats times the importance film's area over
  // their number, as bdpt's light image is.
  film.set_one_light_path_per_sample(double(scene.camera().importance_film_pixels()));
  return render_tiles(scene, settings, film, options, tiles);
}

// One instantiation per pixel sampler.
#define CANDELA_INSTANTIATE(S)                                                                                \
  template RGB LightPathIntegrator::trace<S>(const Ray&, S&, RayCounts&, Film&, const Filter&, bool,          \
                                             const Wavelengths*) const;
CANDELA_FOR_EACH_SAMPLER(CANDELA_INSTANTIATE)
#undef CANDELA_INSTANTIATE

}  // namespace candela
