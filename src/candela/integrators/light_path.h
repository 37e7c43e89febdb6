#pragma once
// Light tracing (integrator "light_path"; pbrt-v4's LightPathIntegrator, "lightpath"): for every
// camera sample one light subpath is traced from a light chosen by power, and each of its vertices
// is joined to a point on the lens (bidirectional path tracing's t = 1 strategies alone, without MIS
// weights) and splatted onto the film where it lands. The camera sample's own ray is not traced: the
// pixel gets nothing but splats, whose sum over the light paths, scaled by the importance film's
// area over their number, is the image.
//
// What it cannot render: anything the camera sees through a delta surface (a mirror or glass seen
// directly is black: its BSDF has nothing to join to the lens), emitters seen directly (the
// light's own vertex is not joined to the lens), and lights at infinity seen directly (the sky is
// black). Elsewhere it converges to the path tracer's image. The traits' partial_transport says so.
//
// The subpaths and the lens connection are bdpt.h's (BdptIntegrator::light_subpath and connect with
// t = 1): light subpaths scatter in participating media and connections carry the transmittance, as
// bdpt's do; Russian roulette ends light subpaths as it ends bdpt's (pbrt-v4's light tracer has
// none: the same expectation, with different noise).
#include "candela/film/film.h"
#include "candela/film/filter.h"
#include "candela/geometry/ray.h"
#include "candela/integrators/bdpt.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

class LightPathIntegrator {
 public:
  LightPathIntegrator(const Scene& scene, const RenderSettings& settings);

  // One light path for the camera sample whose ray is `ray` (its time, and the camera vertex that
  // sets the hero lane in chromatic media): every vertex joined to the lens is splatted onto `film`
  // (and its first half's splats when `first_half`) with `filter`. Returns what the pixel itself
  // gets: nothing (black), as every contribution is a splat.
  template <typename Sampler>
  RGB trace(const Ray& ray, Sampler& sampler, RayCounts& counts, Film& film, const Filter& filter, bool first_half,
            const Wavelengths* wl = nullptr) const;

 private:
  const Scene& scene_;
  BdptIntegrator bdpt_;  // the light subpaths and the lens connections
};

// Integrator "light_path": renders `film` through the shared tile loop, one light path per camera
// sample, the light image being the splats times the importance film's area over their number.
RenderStats render_light_path(const Scene& scene, const RenderSettings& settings, Film& film,
                              const RenderOptions& options);

}  // namespace candela
