#pragma once
// The tile body of integrators that trace one camera ray per pixel sample (path tracing, BDPT):
// for each sample, place it in the pixel by importance-sampling the reconstruction filter, pick the
// lens point and the time, trace the ray with the integrator's radiance function, and add the
// result to the pixel with the filter's weight. A template over the radiance function so that the
// sampler and the integrator are dispatched once per tile, not per sample.
#include <utility>
#include <variant>

#include "candela/film/aov_film.h"
#include "candela/render/first_hit_aovs.h"
#include "candela/render/render_loop.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

// Where a camera sample lies: its pixel and its reconstruction filter weight.
struct PixelSample {
  int x = 0, y = 0;
  float filter_weight = 1;
  bool first_half = true;  // which of the film's two independent halves the sample belongs to
};

// With TileContext::aovs set, each sample's camera ray also gives its AOVs (render/first_hit_aovs.h).
// Radiance: a callable (const Ray&, auto& sampler, RayCounts&, const PixelSample&, const Wavelengths*)
// returning the radiance along the camera ray (at the wavelengths, when given).
template <typename Radiance>
class CameraSampleTiles final : public TileIntegrator {
 public:
  explicit CameraSampleTiles(Radiance radiance) : radiance_(std::move(radiance)) {}

  uint64_t render_tile(const Tile& tile, const SampleRanges& range, const TileContext& context,
                       RayCounts& counts) const override {
    uint64_t done = 0;
    std::visit(
        [&](const auto& prototype) {
          auto sampler = prototype;
          for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
              SampleRange r = range(x, y);
              if (r.count <= 0) continue;
              render_pixel(context, sampler, x, y, uint64_t(r.first), r.count, counts);
              done += uint64_t(r.count);
            }
        },
        context.prototype);
    return done;
  }

 private:
  // Renders samples [first, first + count) of pixel (x, y).
  template <typename S>
  void render_pixel(const TileContext& context, S& sampler, int x, int y, uint64_t first, int count,
                    RayCounts& counts) const {
    const PerspectiveCamera& camera = context.scene.camera();
    for (uint64_t s = first; s < first + uint64_t(count); ++s) {
      sampler.start_pixel_sample(x, y, s);
      // Place the sample in the pixel by importance-sampling the reconstruction filter (eq. 9 with a
      // filter); the sample counts for this pixel only, with the filter's weight.
      Filter::Sample fs = context.filter.sample(sampler.get_pixel_2d());
      // Only effects that exist take sampler dimensions: a pinhole needs no lens sample, a scene where
      // nothing moves no time (the path's first vertices then get the better-stratified dimensions).
      Vec2 lens = camera.has_lens() ? sampler.get_2d() : Vec2(0.5f, 0.5f);
      // Pick the path's time in the shutter interval (sec. 4.2); every object is seen at it.
      float time = context.scene.has_motion() ? lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close())
                                              : camera.shutter_open();
      Ray ray = camera.generate_ray({float(x) + 0.5f + fs.offset.x, float(y) + 0.5f + fs.offset.y}, lens, time);
      // A spectral render draws the path's wavelengths next; its radiance comes back as their values.
      Wavelengths storage;
      const Wavelengths* wl = sample_wavelengths_if(context.spectral, sampler, storage);
      const bool first_half = context.first_half(s);
      RGB values = radiance_(ray, sampler, counts, PixelSample{x, y, fs.weight, first_half}, wl);
      RGB L = wavelengths_to_rgb(values, wl);
      if (!L.is_finite() || !values.is_finite()) {
        // Never reaches the film: counted, the first few logged, and the sample counts as black.
        context.non_finite.fetch_add(1, std::memory_order_relaxed);
        context.non_finite_log.add(x, y, s);
        L = values = RGB(0.0f);
      } else {
        L = context.scene.film_sensor().respond(L);
      }
      // pbrt-v4's spectral film: the values at the wavelengths themselves, before they become RGB.
      if (wl && context.aovs && context.aovs->spectral().count > 0)
        context.aovs->add_spectral_sample(x, y, values, *wl, fs.weight, context.scene.film_sensor().max_component());
      if (context.clamp > 0) {
        float m = L.max_component();
        if (m > context.clamp) L *= context.clamp / m;
      }
      context.film.add_sample(x, y, L, fs.weight, first_half);
      // The AOV layers of the same camera ray, with the same filter weight (their random numbers
      // are their own: the sampler above is untouched).
      if (context.aovs && context.aovs->has_first_hit_layers())
        context.aovs->add_sample(
            x, y, first_hit_aovs(context.scene, ray, context.aovs->needs_shading(), x, y, s, context.seed), fs.weight,
            first_half);
    }
  }

  Radiance radiance_;
};

// The render of an integrator that estimates each camera sample with
// radiance(ray, sampler, counts, wavelengths) (path, volpath): built once, shared by every tile.
template <typename Integrator>
RenderStats render_camera_samples(const Scene& scene, const RenderSettings& settings, Film& film,
                                  const RenderOptions& options) {
  const Integrator integrator(scene, settings);
  CameraSampleTiles tiles([&integrator](const Ray& ray, auto& sampler, RayCounts& counts, const PixelSample&,
                                        const Wavelengths* wl) { return integrator.radiance(ray, sampler, counts, wl); });
  return render_tiles(scene, settings, film, options, tiles);
}

}  // namespace candela
