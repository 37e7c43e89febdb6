#pragma once
// Metropolis light transport (Veach & Guibas 1997; Häkkinen 2002, sec. 5.2) in primary sample
// space (Kelemen et al. 2002), multiplexed over the bidirectional strategies (Hachisuka et al.
// 2014), after pbrt-v3's MLTIntegrator: the Markov chain state is the primary sample vector plus
// the path depth; each state's path is built with one (s, t) strategy that the state itself picks,
// and its contribution is multiplied by the number of strategies of that depth.
//
//   0. Depth 0 (emission seen directly) is rendered as the path tracer does, into the film's pixel
//      sums, with spp / 16 samples per pixel (16 to 256; under a time limit at most a twentieth of
//      it); the chains render the depths >= 1 on top of it.
//   1. Bootstrap: n_bootstrap x (max_depth + 1) independent states with their luminance. The
//      brightness of each depth (its mean luminance over the film) is estimated separately, by
//      max(n_bootstrap, mutations / 8) bidirectional samples (all strategies) through a jittered
//      grid over the film: the bootstrap's own mean estimates the share of small bright regions far
//      too noisily.
//   2. Chains: about n_chains chains, shared among the depths in proportion to their brightness (at
//      least one for each lit depth), each started from a bootstrap state of its depth chosen
//      proportionally to its luminance (no start-up bias), run spp x pixels / chains mutations in
//      rounds: a large step (all numbers afresh) with probability p_large, else a small Gaussian
//      perturbation of deviation sigma.
//      Every proposal deposits both the proposed and the current state, weighted by the acceptance
//      probability and its complement (Veach's expected-value splatting), with Kelemen's weights that
//      count a large step also as an independent sample.
//   3. Each depth's deposits are scaled by its brightness over its number of chains; the image is
//      the deposits times the film's area over the mutations per chain.
//
// Chains are independent and their deposits are summed in fixed point, so the image is the same
// for any number of threads.
#include <algorithm>
#include <any>
#include <cstdint>

#include "candela/film/film.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"

namespace candela {

// Depth 0's samples per pixel for `spp` mutations per pixel, and its most share of a time limit.
inline int mlt_direct_spp(int spp) { return std::clamp(spp / 16, 16, 256); }
inline constexpr double kMltDirectTimeShare = 1.0 / 20;

// What an MLT render reports besides RenderStats (its RenderStats::details; the normalisation's
// relative error is RenderStats::splat_scale_relative_error): the estimate of the image's mean
// luminance that scales the chains' deposits, the samples it took and their seconds, and the
// seconds of the depth-0 pass and of the bootstrap.
struct MltStats {
  double normalization = 0;
  uint64_t normalization_samples = 0;
  double normalization_seconds = 0;
  double direct_seconds = 0, bootstrap_seconds = 0;
};

// The MltStats of a render by render_mlt, or null for another integrator's.
inline const MltStats* mlt_stats(const RenderStats& stats) { return std::any_cast<MltStats>(&stats.details); }

// Integrator "mlt": renders settings.spp mutations per pixel into film's splats (and sets its
// splat scale), on top of depth 0 rendered by the path tracer into its pixel sums.
RenderStats render_mlt(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
