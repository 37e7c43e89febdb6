#pragma once
// Bidirectional path tracing (Veach 1997, ch. 10; Häkkinen 2002, sec. 5.1; after pbrt-v3's BDPT).
//
// For every camera sample a camera subpath and a light subpath are traced, and every pair of
// prefixes (s light vertices, t camera vertices) is joined into a complete path:
//   s = 0   the camera subpath itself hits a light (or escapes to a light at infinity)
//   s = 1   a point on a light is sampled from the camera vertex (next-event estimation)
//   t = 1   the light vertex is connected to a point on the lens (light tracing): the contribution
//           lands on whatever pixel it reaches and is splatted onto the film
//   others  the two end vertices are joined by a shadow ray
// Each strategy's contribution is weighted by the power heuristic over all strategies that could
// have produced the same path, computed from the forward and reverse densities stored at the
// vertices (the recursive scheme: ratios of neighbouring strategies, never re-walking a path).
// Light subpaths carry importance, so they use the adjoint BSDF: no 1/eta^2 at refractions and
// the shading-normal correction of Veach's sec. 5.3.
//
// Participating media: subpaths scatter in media (delta tracking against the majorant grid gives the
// distance; a medium vertex scatters by its phase function and connects like a surface vertex), and
// connections carry the transmittance between their ends (exact in homogeneous media, ratio tracking
// in grids) across interfaces. Every sampling decision uses one extinction per path: where media are
// chromatic (or the render spectral), a hero lane (colour channel or wavelength) chosen per camera
// sample, whose value then counts for all the lanes (the others zero): unbiased for every channel,
// with more colour noise than volpath's spectral MIS. The MIS densities leave out transmittance and
// the distance-sampling densities, as pbrt-v3 does: the weights still sum to one over the
// strategies, so the estimate stays unbiased.
// An emissive medium's light is taken where camera subpaths scatter in it (the s = 0 strategy alone,
// weight 1: no strategy samples light vertices in media).
//
// The subpath and connection routines are templates over the sampler, shared with Metropolis light
// transport (mlt.h), which drives them with its primary-sample-space sampler.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "candela/film/film.h"
#include "candela/film/filter.h"
#include "candela/geometry/ray.h"
#include "candela/integrators/path_integrator.h"
#include "candela/materials/bsdf.h"
#include "candela/math/frame.h"
#include "candela/render/render_loop.h"
#include "candela/sampling/rng.h"
#include "candela/scene/scene.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

enum class Transport : uint8_t { Radiance, Importance };

struct BdptVertex {
  enum class Kind : uint8_t { Camera, Light, Surface, Medium };
  Kind kind = Kind::Surface;
  Point3 p;
  Normal3 ng;  // geometric normal; zero where there is no surface (point lights, lights at infinity)
  Normal3 ns;  // shading normal (surfaces)
  Frame frame;  // shading frame (surfaces)
  Vec3 wo;      // surfaces: unit direction towards the previous vertex of the subpath
  SurfaceHit hit;
  SurfaceBsdf bsdf;  // with its wrappers resolved (a mask's absent part is a delta vertex)
  RGB beta;           // the subpath's throughput up to here
  float pdf_fwd = 0;  // density of this vertex when sampled from its predecessor (per area, or per solid angle
                      // for vertices at infinity)
  float pdf_rev = 0;  // density of this vertex when sampled from its successor (the reverse direction)
  int light = -1;     // light vertices: the light; surfaces: the light of an emitter that was hit, or -1
  // Light vertices and emitters hit: the probability that next-event estimation at the neighbouring
  // vertex chooses this light over the probability that a light path starts from it (they differ
  // under the light BVH), for MIS.
  float nee_ratio = 1;
  int medium = -1;    // surfaces: the medium the subpath arrived in; medium vertices and lights: the one they are in
  float g = 0;        // medium vertices: the phase function's mean cosine
  int8_t hero = -1;   // camera vertices: the lane (channel, wavelength) that drives sampling in media (-1: all alike)
  bool delta = false;        // scattered by a delta lobe
  bool at_infinity = false;  // a light at infinity (then p is a point along its direction), or an escaped ray

  bool on_surface() const { return !(ng == Normal3(0.0f)); }
};

// Where an image-space contribution goes: t = 1 strategies splat onto the film; with `strategies`,
// every strategy's contribution also goes to its own image (index BdptIntegrator::strategy_index).
struct BdptTarget {
  Film* film = nullptr;
  const Filter* filter = nullptr;
  std::vector<SplatImage>* strategies = nullptr;
  bool unweighted = false;  // strategy images without the MIS weight (each then estimates the whole image)
};

class BdptIntegrator {
 public:
  BdptIntegrator(const Scene& scene, const RenderSettings& settings);

  // The estimate of the strategies with t >= 2 for the camera ray of pixel (x, y) (added to that
  // pixel with the filter weight by the caller); the t = 1 strategies are splatted onto target.film.
  // With wavelengths (a spectral render) the estimate is their values; splats are converted to RGB.
  template <typename Sampler>
  // `first_half`: the camera sample is in the film's first half, and so are its light path's splats.
  RGB radiance(const Ray& ray, Sampler& sampler, RayCounts& counts, const BdptTarget& target, int x, int y,
               float filter_weight, bool first_half, const Wavelengths* wl = nullptr) const;

  // The building blocks, shared with Metropolis light transport. `wl`: the wavelengths of a spectral
  // render (null: RGB), at which BSDFs and emission are evaluated.
  // A camera subpath from `ray` (vertex 0 on the lens) of at most max_vertices vertices; returns how many.
  // Emitters without a surface of their own (interface material) are passed through, not made
  // vertices: the MIS-weighted light of the one the path would have ended on as its t-th vertex is
  // added to crossed_emission[t] (an array of max_vertices + 1, when given).
  template <typename Sampler>
  int camera_subpath(const Ray& ray, Sampler& sampler, RayCounts& counts, int max_vertices, BdptVertex* path,
                     RGB* crossed_emission = nullptr, const Wavelengths* wl = nullptr) const;
  // A light subpath of at most max_vertices vertices, starting on a light chosen by power.
  // `hero`: the camera subpath's (path[0].hero of camera_subpath), so both sample media alike.
  template <typename Sampler>
  int light_subpath(Sampler& sampler, RayCounts& counts, int max_vertices, float time, BdptVertex* path,
                    const Wavelengths* wl = nullptr, int hero = -1) const;
  struct Connection {
    RGB L;                // the MIS-weighted contribution
    RGB unweighted;       // the same without the weight
    float weight = 0;
    Vec2 raster;          // t = 1: where on the film it lands
  };
  // Joins the first s light vertices with the first t camera vertices. The vertex arrays are
  // modified during the call (the densities the MIS weight needs) and restored before it returns.
  template <typename Sampler>
  Connection connect(BdptVertex* light, BdptVertex* camera, int s, int t, Sampler& sampler, RayCounts& counts,
                     float time, const Wavelengths* wl = nullptr) const;

  int max_depth() const { return max_depth_; }
  // Strategies (s, t) with s + t = depth + 2, numbered depth by depth: depth (depth + 5) / 2 + s.
  static int strategy_index(int s, int t) {
    int depth = s + t - 2;
    return depth * (depth + 5) / 2 + s;
  }
  static int strategy_count(int max_depth) { return strategy_index(0, max_depth + 3); }

 private:
  template <typename Sampler>
  int random_walk(Ray ray, Sampler& sampler, RayCounts& counts, RGB beta, float pdf, int max_vertices,
                  Transport mode, BdptVertex* path, RGB* crossed_emission, const Wavelengths* wl, int medium,
                  int hero) const;

  // The extinction per unit density that sampling uses in `medium` (one value: see above).
  float path_sigma_t(int medium, int hero, const Wavelengths* wl) const;
  // The medium a connection leaving v along dir starts in.
  int outgoing_medium(const BdptVertex& v, const Vec3& dir) const;

  // A surface vertex reached by `ray` (its BSDF, frame and densities are the caller's).
  BdptVertex surface_vertex(const SurfaceHit& hit, const Ray& ray, const RGB& beta) const;

  // The pieces of the MIS weight: densities between vertices, converted to the measure of `next`.
  float convert_density(float pdf, const BdptVertex& from, const BdptVertex& next) const;
  float vertex_pdf(const BdptVertex* prev, const BdptVertex& v, const BdptVertex& next) const;
  float light_pdf(const BdptVertex& light_vertex, const BdptVertex& next) const;
  float light_origin_pdf(const BdptVertex& light_vertex, const BdptVertex& next) const;
  float infinite_lights_pdf(const Vec3& emitted_dir) const;
  // The density of light vertex x0 as next-event estimation at x1 chooses its light, over its
  // density as a light path's start (they differ under the light BVH): for MIS.
  float nee_light_pdf_ratio(const BdptVertex& x0, const BdptVertex& x1) const;
  float mis_weight(BdptVertex* light, BdptVertex* camera, BdptVertex& sampled, int s, int t) const;

  // Light emitted by a light vertex (or an emitter that was hit) towards `towards`.
  RGB emitted(const BdptVertex& v, const BdptVertex& towards, const Wavelengths* wl) const;
  // The BSDF at a surface vertex towards `next`, adjoint when mode is Importance.
  RGB scatter(const BdptVertex& v, const BdptVertex& next, Transport mode) const;
  bool is_connectible(const BdptVertex& v) const;
  bool is_light(const BdptVertex& v) const { return v.kind == BdptVertex::Kind::Light || v.light >= 0; }
  bool is_delta_light(const BdptVertex& v) const;
  // What gets from a to b: 0 when a surface (other than interfaces) lies between, else the
  // transmittance of the media on the way (1 without media). `rng` drives ratio tracking in grids.
  RGB visibility(const BdptVertex& a, const BdptVertex& b, float time, RayCounts& counts, Rng& rng, int hero,
                 const Wavelengths* wl) const;
  float geometry_term(const BdptVertex& a, const BdptVertex& b) const;

  const Scene& scene_;
  int max_depth_;
  int rr_start_depth_;
  bool hide_emitters_;  // no depth-0 strategies: emitters seen directly are not shown
  bool chromatic_media_ = false;  // some medium's extinction differs between the colour channels
};

// --bdpt-strategies DIR: every strategy's (s, t) contribution of the depths up to 5 (or max_depth) in
// an image of its own (index BdptIntegrator::strategy_index), MIS weighted or, `unweighted`, not,
// scaled like the light image; written as DIR/bdpt_d<depth>_s<s>_t<t>.exr. What the registry's
// entry for bdpt makes (integrators/integrator.h) and render_bdpt finds in RenderOptions::integrator_outputs.
class BdptStrategyImages final : public IntegratorOutputs {
 public:
  BdptStrategyImages(const RenderSettings& settings, int width, int height, std::string directory, bool unweighted);
  void sum_across(Cluster& cluster) override;
  void write(const Film& film, const std::map<std::string, std::string>& metadata) const override;
  std::vector<SplatImage>& images() { return images_; }
  bool unweighted() const { return unweighted_; }

 private:
  int depth_;  // the deepest strategies with an image
  std::string directory_;
  bool unweighted_;
  std::vector<SplatImage> images_;
};

// The registry's maker of the strategy images (null: none asked for).
std::unique_ptr<IntegratorOutputs> make_bdpt_strategy_images(const RenderSettings& settings, int width, int height,
                                                             const std::string& directory, bool unweighted);

// Integrator "bdpt": renders `film` through the shared tile loop, one light subpath per camera
// sample; light tracing lands in the film's splats, scaled by the importance film's area over the
// number of light paths. With a BdptStrategyImages in options.integrator_outputs, fills it too.
RenderStats render_bdpt(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
