#pragma once
// Metropolis light transport (Veach & Guibas 1997; Häkkinen 2002, sec. 5.2) in primary sample
// space (Kelemen et al. 2002), multiplexed over the bidirectional strategies (Hachisuka et al.
// 2014), after pbrt-v3's MLTIntegrator: the Markov chain state is the primary sample vector plus
// the path depth; each state's path is built with one (s, t) strategy that the state itself picks,
// and its contribution is multiplied by the number of strategies of that depth.
//
//   1. Bootstrap: n_bootstrap x (max_depth + 1) independent states with their luminance. The scale b,
//      the image's mean luminance, is estimated separately, per depth, by max(n_bootstrap, mutations / 64)
//      bidirectional samples (all strategies) through a jittered grid over the film: the bootstrap's own mean estimates the
//      share of small bright regions far too noisily.
//   2. Chains: n_chains chains, each started from a bootstrap state chosen proportionally to its
//      luminance (no start-up bias), run spp x pixels / n_chains mutations: a large step (all
//      numbers afresh) with probability p_large, else a small Gaussian perturbation of deviation sigma.
//      Every proposal deposits both the proposed and the current state, weighted by the acceptance
//      probability and its complement (Veach's expected-value splatting).
//   3. The image is the deposits times b x film area / mutations.
//
// Chains are independent and their deposits are summed in fixed point, so the image is the same
// for any number of threads.
#include "candela/film/film.h"
#include "candela/render/renderer.h"
#include "candela/scene/scene.h"

namespace candela {

// Renders settings.spp mutations per pixel into film's splats (and sets its splat scale).
RenderStats render_mlt(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
