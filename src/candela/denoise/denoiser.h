#pragma once
// Feature-based denoising from the render's two halves, with an estimate of the denoised image's own
// error (docs/denoising.md). In the spirit of Bitterli et al., "Nonlinearly Weighted First-order
// Regression for Denoising Monte Carlo Renderings" (EGSR 2016), built for speed:
//
//   1. Fireflies: a half's pixel far above everything around it in both halves is capped.
//   2. Candidates: for each window radius r in kDenoiseRadii, every pixel's colour is fitted in each
//      half separately by a first-order (linear) ridge regression on the features over the (2r+1)^2
//      window around it, evaluated at the pixel: D_A from half A, D_B from half B. The features are
//      first hit's albedo, shading normal and inverse depth (each half's own), which carry texture
//      and geometry edges the colour's noise hides. The window's box weights
//      depend on nothing, so each D_H is a function of half H's samples alone, independent of the
//      other half: the other half is an unbiased reference for it. Box windows make every candidate cost the
//      same whatever r (running sums); the wide ones are fitted at every other pixel and row.
//   3. Error of each candidate, per pixel, from the halves alone: for the combination
//      D = f D_A + (1 - f) D_B (f: half A's share of the pixel's weight),
//        bias^2 = (D_A - A) (D_B - B)   (= [(D_A - B)^2 + (D_B - A)^2 - (D_A - D_B)^2 - (A - B)^2] / 2)
//        MSE(D) = bias^2 + f (1 - f) (D_A - D_B)^2,
//      each term unbiased for independent halves (the raw image, D_A = A, gets exactly the estimate
//      of film/error_estimate.h, f (1 - f) (A - B)^2). Over the channels and relative to D^2 + 0.01.
//   4. Selection: each candidate's per-pixel error, relative to the widest candidate's image squared
//      (+ 0.01), averaged over the 11 x 11 box around each pixel but the pixel itself; each pixel
//      takes the candidate (the raw image among them) with the least. A candidate must be strictly
//      better than the raw pixel, so a noiseless image comes back unchanged.
//   5. The denoised image's relMSE: the chosen candidates' squared errors over an estimate of the
//      truth's square, averaged. The square is estimated from products of the two halves'
//      independent estimates (A B, the narrowest fit's D_A D_B), not from the denoised image's square,
//      which its own noise inflates just where its error is (denoiser.cpp says how they combine). A
//      pixel's choice does not see its own estimate (step 4), so the choice does not bias the sum low.
//
// Deterministic: rows are processed in strips of fixed height, each from its own running sums, so the
// image is the same bit for bit whatever the number of threads.
#include <cstdint>
#include <vector>

#include "candela/film/error_estimate.h"
#include "candela/film/image.h"

namespace candela {

class Film;
class AovFilm;

// The window radii of the candidate filters, besides the raw image (radius 0).
inline constexpr int kDenoiseRadii[] = {2, 5, 10};
inline constexpr int kDenoiseCandidates = 1 + int(std::size(kDenoiseRadii));

// What the denoiser reads, per pixel, row-major.
struct DenoiseInput {
  int width = 0, height = 0;
  // Two independent estimates of each pixel (RGB), from the two halves of its samples, and half A's
  // share of the pixel's weight: the raw image is share_a A + (1 - share_a) B.
  std::vector<float> half_a, half_b, share_a;
  // The features of each half's samples, as the AOV film's halves layer has them (film/aov_film.h):
  // albedo (RGB), shading normal (XYZ), depth (kAovMissDepth where no sample hit). Each half is
  // fitted on its own features: features shared by both halves would tie a half's fit to the other
  // half's noise (at an edge, the share of samples that hit the object is in both), and the halves
  // would no longer check each other.
  std::vector<float> albedo_a, albedo_b, normal_a, normal_b, depth_a, depth_b;

  // Whether the halves are independent estimates: false where every pixel's are equal (a film without
  // halves gives each pixel its mean twice); the image then comes back as it is, without an estimate.
  bool has_halves = true;

  // share_a A + (1 - share_a) B.
  Image raw() const;
  // Throws InternalError unless every buffer has its size.
  void check() const;
};

struct DenoiseResult {
  Image image;          // the denoised image
  ErrorEstimate error;  // its estimated relMSE (eps kErrorEpsilon) and a 95% interval
  std::vector<uint8_t> choice;  // per pixel: 0 the raw pixel, k > 0 the filter of radius kDenoiseRadii[k - 1]
};

// Denoises `input` (which must pass check()).
DenoiseResult denoise(const DenoiseInput& input);

// The input from the AOV film's halves layer (AovLayer of Aov::Halves, film/aov_film.h): its 21
// channels per pixel, width x height pixels.
DenoiseInput denoise_input(int width, int height, const std::vector<float>& halves_layer);
// The halves layer of a finished film's AOV film. Pixels without both halves (never sampled, or all
// their samples in one half) get A = B = their mean. Throws InternalError when `aovs` lacks the
// halves layer.
DenoiseInput denoise_input(const Film& film, const AovFilm& aovs);

}  // namespace candela
