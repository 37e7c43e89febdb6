#pragma once
// How far the image is from the one it converges to, estimated from the render itself: the relMSE
// (mean over pixels and channels of (value - truth)^2 / (truth^2 + 0.01), the project's metric)
// with a 95% interval for the actual relMSE of this image.
//
// The estimator: every pixel's samples (and the splats of light paths and Markov chains) fall into
// two halves that are independent estimates A and B of the pixel (film.h, render_loop.h). With
// a share f of the weight in A, the mean M = f A + (1 - f) B has variance f (1 - f) E[(A - B)^2]
// whatever the sampler does inside each half: ZSobol's nets, stratification and the correlation
// of a Markov chain's deposits all stay inside one half, which is why the halves are independently
// randomised replicas and not, say, alternate samples of one net (whose halves would be
// anti-correlated, and the estimate far too high). The per-sample variance would miss exactly
// those correlations, and it does not exist for splats.
//
// One pixel's (A - B)^2 is a single draw (one degree of freedom), but the image's relMSE averages
// thousands of them. The truth in the denominator is not known either; error_estimate.cpp takes the
// pixel's mean, capped against fireflies by its neighbourhood (the median of the neighbours' means
// or the largest of their lesser halves), floored by its own lesser half, less at most half its
// variance; a capped pixel's also floored by its 11 x 11 neighbourhood's mean less that
// neighbourhood's fireflies (error_estimate.cpp says why each). The 95% interval combines the spread of the pixels' draws (each pixel's
// actual squared error and its estimate as independent one-degree-of-freedom draws of the same
// variance, exact for Gaussian halves: variance sum 4/3 e_i^2 / N^2) with a systematic 30% for
// the denominators, the largest miss measured against converged references
// (docs/error-estimates.md).
#include <cstdint>
#include <string>
#include <vector>

#include "candela/film/film.h"

namespace candela {

struct ErrorEstimate {
  bool valid = false;
  std::string why_not;  // when !valid: what the film lacks
  double relmse = 0;    // estimated relMSE of the film's image (epsilon kErrorEpsilon)
  double low = 0, high = 0;  // 95% interval for the image's actual relMSE
  // The share of relmse from the splats (light paths', chains') alone, as if the pixels' own samples
  // had no error: how an integrator's error splits between its two kinds of samples.
  double splat_relmse = 0;
  uint64_t pixels = 0;       // pixels the estimate covers (both halves sampled)
};

inline constexpr double kErrorEpsilon = 0.01;

// `scale_relative_error`: the relative standard error of a factor that scales all splats alike
// (MLT's normalisation), which the two halves share and so cannot see. `pixel_errors`, when given,
// receives each pixel's estimated relative squared error (row-major; NaN where it has none).
ErrorEstimate estimate_error(const Film& film, double scale_relative_error = 0,
                             std::vector<double>* pixel_errors = nullptr);

// "relMSE 0.0031 (95% interval 0.0028-0.0034)" or "not available: ...".
std::string describe(const ErrorEstimate& e);

}  // namespace candela
