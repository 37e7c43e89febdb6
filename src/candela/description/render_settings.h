#pragma once
// How a scene is rendered: sampler, filter, the integrator and its settings, adaptive sampling. Part of the format-neutral scene description (description/scene_desc.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "candela/base/enum_names.h"
#include "candela/base/error.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"

namespace candela {

// How pixel samples are placed (Häkkinen 2002, sec. 4.3).
enum class SamplerType {
  Independent,  // uniform random numbers
  Stratified,   // jittered strata in every dimension, shuffled per pixel (pbrt-v4's StratifiedSampler)
  Poisson,      // Poisson-disc pixel positions with a minimum distance; other dimensions independent
  ZSobol        // Owen-scrambled Sobol' points in Morton order over the image (pbrt-v4's ZSobolSampler)
};
constexpr std::string_view enum_name(SamplerType v) {
  switch (v) {
    case SamplerType::Independent: return "independent";
    case SamplerType::Stratified: return "stratified";
    case SamplerType::Poisson: return "poisson";
    case SamplerType::ZSobol: return "zsobol";
  }
  return {};
}
struct SamplerDesc {
  // Independent here; the readers choose ZSobol when a scene names no sampler (pbrt-v4's default,
  // and the most efficient measured in docs/performance.md).
  SamplerType type = SamplerType::Independent;
  bool jitter = true;  // stratified: false puts each sample at its stratum's centre
  // Draw every pixel's samples as two independently randomised halves, so the render can estimate
  // its own error (film/error_estimate.h): ZSobol as two interleaved replicas of its sequence, the
  // set-based samplers (stratified, poisson) in sets of half the samples or of one pass. Set by
  // --estimate-error and --target-error. The independent sampler's halves are always independent.
  bool replicas = false;
};

// Pixel reconstruction filters; every sample contributes to its own pixel only, with the weight
// f(offset) / pdf(offset) of filter importance sampling (pbrt-v4).
enum class FilterType { Box, Tent, Gaussian, Mitchell, LanczosSinc };
constexpr std::string_view enum_name(FilterType v) {
  switch (v) {
    case FilterType::Box: return "box";
    case FilterType::Tent: return "tent";
    case FilterType::Gaussian: return "gaussian";
    case FilterType::Mitchell: return "mitchell";
    case FilterType::LanczosSinc: return "sinc";
  }
  return {};
}
struct FilterDesc {
  FilterType type = FilterType::Box;
  Vec2 radius{0.5f, 0.5f};    // in pixels; pbrt's defaults: box 0.5, triangle 2, gaussian 1.5, mitchell 2, sinc 4
  float gaussian_sigma = 0.5f;
  float mitchell_b = 1.0f / 3, mitchell_c = 1.0f / 3;
  float sinc_tau = 3;  // the Lanczos window's width: sinc(x) sinc(x / tau) (Mitsuba's lanczos: tau = lobes)
};

// The largest filter radius the readers accept, in pixels (the filter is tabulated per unit of radius).
constexpr float kMaxFilterRadius = 64;

// A filter of the given type with pbrt-v4's default parameters.
inline FilterDesc default_filter(FilterType type) {
  FilterDesc f;
  f.type = type;
  float r = type == FilterType::Box        ? 0.5f
            : type == FilterType::Gaussian   ? 1.5f
            : type == FilterType::LanczosSinc ? 4.0f
                                              : 2.0f;
  f.radius = {r, r};
  return f;
}

// How the next direction is chosen at non-delta vertices (sec. 4.7).
enum class DirectionSampling {
  Bsdf,     // importance-sample the BSDF's lobes
  Cosine,   // cosine-weighted hemisphere, weighted by the BSDF
  Uniform   // uniform hemisphere (the paper's eq. 11), weighted by the BSDF
};
constexpr std::string_view enum_name(DirectionSampling v) {
  switch (v) {
    case DirectionSampling::Bsdf: return "bsdf";
    case DirectionSampling::Cosine: return "cosine";
    case DirectionSampling::Uniform: return "uniform";
  }
  return {};
}

// How Embree lays out the triangles' acceleration structure.
enum class BvhLayout {
  Fast,    // leaves hold copies of their triangles' vertices: the fastest traversal
  Compact  // leaves index into the shared vertex arrays (Embree's RTC_SCENE_FLAG_COMPACT): about half
           // the memory per triangle, traversal about a third slower (docs/performance.md)
};
constexpr std::string_view enum_name(BvhLayout v) {
  switch (v) {
    case BvhLayout::Fast: return "fast";
    case BvhLayout::Compact: return "compact";
  }
  return {};
}

// How shadow rays are spent at each vertex (sec. 4.5).
enum class LightSelection {
  Power,   // `shadow_rays` rays, each to one light chosen with probability proportional to its power
  Paper,   // every light gets a share of `shadow_rays` proportional to power x projected solid angle
           // as seen from the vertex (stratified over rectangles), kept unbiased
  Uniform, // as Power, but every emitter (a light, or an emissive shape with all its triangles) is
           // equally likely, and a shape's triangles by area (Mitsuba's choice): robust where power
           // misjudges, as for a small spot beside a large sky
  Bvh      // as Power, but each vertex chooses through a light BVH by the power, distance and
           // orientation its lights could have there (lights/light_sampler.h; pbrt-v4's default):
           // near lights and lights facing the vertex get the rays, O(log n) per choice
};
constexpr std::string_view enum_name(LightSelection v) {
  switch (v) {
    case LightSelection::Power: return "power";
    case LightSelection::Paper: return "paper";
    case LightSelection::Uniform: return "uniform";
    case LightSelection::Bvh: return "bvh";
  }
  return {};
}

// Settings only the path tracer reads (integrator "path"; docs/cli.md lists the flags).
struct PathSettings {
  DirectionSampling direction_sampling = DirectionSampling::Bsdf;
  bool mis = true;  // false: light sampling for direct light, emission found by bounces ignored
  int shadow_rays = 1;  // per path vertex
  bool operator==(const PathSettings&) const = default;
};

// Metropolis light transport's settings (integrator "mlt"; RenderSettings::spp is then the number
// of mutations per pixel): bootstrap states per depth, independent chains, the deviation of small
// steps in primary sample space and the probability of a large step (pbrt's defaults), and the
// probabilities of a lens and of a caustic perturbation (mlt_sampler.h); the rest are small steps.
struct MltSettings {
  int bootstrap = 100000;
  int chains = 1000;
  float sigma = 0.01f;
  float large_step = 0.3f;
  float lens = 0;
  float caustic = 0;
  bool operator==(const MltSettings&) const = default;
  // Why these are not a valid set (the mutation probabilities sum past 1), or empty: the one
  // check behind the command line's and the readers' messages.
  std::string problem() const {
    float sum = large_step + lens + caustic;
    return sum > 1 ? fmt::format("large_step + lens + caustic must be at most 1, got {}", sum) : std::string();
  }
  // For image metadata and checkpoint fingerprints.
  std::string describe() const {
    return fmt::format("bootstrap {} chains {} sigma {} large-step {} lens {} caustic {}", bootstrap, chains, sigma,
                       large_step, lens, caustic);
  }
};

// Ambient occlusion's settings (integrator "ambient_occlusion"; pbrt-v4's AOIntegrator, whose
// "maxdistance" and "cossample" they are).
struct AmbientOcclusionSettings {
  // Occluders farther than this from the shaded point along an occlusion ray do not count (world
  // units); infinity: every occluder counts.
  float max_distance = std::numeric_limits<float>::infinity();
  // Occlusion rays drawn cosine-weighted over the hemisphere (true) or uniformly (false): the same
  // expected image, the cosine-weighted one with less noise.
  bool cosine_sampling = true;
  bool operator==(const AmbientOcclusionSettings&) const = default;
  // For image metadata and checkpoint fingerprints.
  std::string describe() const {
    return fmt::format("max-distance {} sampling {}", max_distance, cosine_sampling ? "cosine" : "uniform");
  }
};

// Stochastic progressive photon mapping's settings (integrator "sppm"; pbrt-v4's SPPMIntegrator, whose
// "photonsperiteration" and "radius" they are; its "seed" is RenderSettings::seed). RenderSettings::spp
// is then the number of iterations.
struct SppmSettings {
  // Photons traced per iteration; 0: one per pixel of the image (pbrt-v4's default, its -1).
  int photons_per_iteration = 0;
  // The search radius every pixel's visible point starts with, in world units; it shrinks as photons
  // arrive.
  float radius = 1;
  bool operator==(const SppmSettings&) const = default;
  // For image metadata and checkpoint fingerprints.
  std::string describe() const {
    return fmt::format("photons-per-iteration {} radius {}", photons_per_iteration, radius);
  }
};

// Settings only the volumetric path tracer reads (integrator "volpath").
struct VolPathSettings {
  // Equiangular sampling of the lights on every ray segment through a homogeneous medium (Kulla and
  // Fajardo 2012), combined by MIS with distance sampling for direct light (integrators/volpath.h);
  // off: distance sampling alone, as before.
  bool equiangular = true;
  bool operator==(const VolPathSettings&) const = default;
};

// What a render does. The fields outside `path`, `volpath`, `mlt`, `ambient_occlusion` and `sppm` are read by more than one integrator;
// integrators/integrator.h's registry says which integrator reads which, and the readers and the
// command line reject a setting the chosen integrator does not read.
struct RenderSettings {
  int spp = 16;
  int max_depth = 16;  // maximum number of scattering events; 1 = direct lighting only
  uint64_t seed = 0;
  std::string integrator = "path";
  int rr_start_depth = 3;  // Russian roulette on throughput starts after this many bounces (path, bdpt)
  SamplerDesc sampler;
  FilterDesc filter;
  bool hide_emitters = false;  // emitters seen directly by the camera (depth 0) are not shown (Mitsuba's)
  // Spectral transport (spectral/wavelengths.h): each sample carries four wavelengths and RGB
  // parameters become smooth spectra, as in pbrt-v4; off = RGB transport.
  bool spectral = false;
  // Power, uniform and bvh choose lights for every integrator (scene.h's light_sampler()); the
  // paper's rule is the path tracer's alone.
  LightSelection light_selection = LightSelection::Power;
  BvhLayout bvh = BvhLayout::Fast;
  // Adaptive sampling (sec. 4.3; path and bdpt), on when a threshold or a budget is set (then `spp`
  // is unused). Every pixel first gets `adaptive_batch` samples (a power of two). With a threshold,
  // pixels whose relative standard error falls below it get no more. With a budget of
  // `adaptive_spp` samples per pixel on average, the rest of the budget goes, in rounds, to each
  // pixel in proportion to its estimated relative deviation (the allocation that minimises the
  // image's relMSE); without a budget every pixel above the threshold gets another batch per
  // round. No pixel gets more than `adaptive_max_spp` (0: 1024, or 8 x adaptive_spp with a budget).
  float adaptive_threshold = 0;
  int adaptive_spp = 0;
  int adaptive_batch = 16;
  int adaptive_max_spp = 0;
  bool adaptive() const { return adaptive_threshold > 0 || adaptive_spp > 0; }
  int adaptive_spp_limit() const {
    if (adaptive_max_spp > 0) return adaptive_max_spp;
    return adaptive_spp > 0 ? int(std::min<int64_t>(8 * int64_t(adaptive_spp), std::numeric_limits<int>::max())) : 1024;
  }
  PathSettings path;
  VolPathSettings volpath;
  MltSettings mlt;
  AmbientOcclusionSettings ambient_occlusion;
  SppmSettings sppm;
};

}  // namespace candela
