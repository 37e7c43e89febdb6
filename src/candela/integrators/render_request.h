#pragma once
// What a render is asked to do, whoever asks: the command line's flags (apps/candela/main.cpp) and
// the Python module's keyword arguments (python/) fill one RenderRequest, which is checked, applied
// to the scene, rendered and described here, so both accept the same values, refuse the same
// combinations with the same messages, and make the same bytes and the same image metadata.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "candela/base/error.h"  // UsageError: what the checks below throw
#include "candela/film/error_estimate.h"
#include "candela/integrators/auto_integrator.h"
#include "candela/integrators/integrator.h"
#include "candela/description/render_options.h"  // RenderRequest, the option table
#include "candela/render/checkpoint.h"          // RenderFingerprint
#include "candela/render/render_loop.h"
#include "candela/description/scene_desc.h"

namespace candela {

inline constexpr int kTargetErrorMaxSpp = 65536;    // the spp cap of --target-error without --spp

// A request resolved against its scene, once, by plan_render: everything the render does, checked.
// The settings it resolves stay in the scene's RenderSettings (the sampler's two independent halves
// where an error estimate needs them, auto's spp cap), which the render reads.
struct RenderPlan {
  // The settings' integrator: one that renders, or one that chooses (auto), which render_requested
  // runs first.
  const IntegratorEntry* integrator = nullptr;
  // The pixels: every one, those of part K of N (every N-th tile, K = part_index + 1), or one.
  int part_index = 0, part_count = 1;
  int pixel_x = -1, pixel_y = -1;
  // The budget: a time limit and an error target (0: none; with a target, settings.spp caps the
  // samples), and, without either, the spp that auto's budget is the path tracer's time for (the
  // spp asked for, before auto's cap replaced it).
  double time_limit_seconds = 0, target_error = 0;
  int budget_spp = 0;
  int threads = 0;  // 0: all cores
  float clamp = 0;  // 0: off
  bool quiet = false;
  // The outputs besides the image: the error estimate's report (it is made whenever the film has
  // halves), the film's checkpoint (empty: none) and the integrator's strategy images (a directory;
  // empty: none), MIS weighted or not.
  bool report_error = false;
  // Denoise the image (denoise/denoised_render.h): the AOV film collects the denoiser's features
  // (kDenoiseFeatures) and the sampler makes two independent halves.
  bool denoise = false;
  std::string checkpoint, resume;
  std::string strategy_images;
  bool strategy_images_unweighted = false;

  bool one_pixel() const { return pixel_x >= 0; }
  // The render options the plan sets: threads, progress, the budget, the clamp, the part or pixel
  // (the caller adds cancellation, progress reporting, the cluster, AOVs and its own hooks).
  RenderOptions options() const;
  // What the integrator makes besides the film for a width x height film (the strategy images), to
  // hand to the render as RenderOptions::integrator_outputs; null when none are asked for.
  std::unique_ptr<IntegratorOutputs> make_integrator_outputs(const RenderSettings& settings, int width,
                                                             int height) const;
};

// --part K/N as {K - 1, N}; throws UsageError naming --part.
std::pair<int, int> parse_part(const std::string& text);

// Checks each value on its own (ranges, the time limit's and the resolution's form), before a scene is read.
// Throws UsageError.
void check_request_values(const RenderRequest& request);

// The one validator of a request, for the command line and the Python module alike: checks every
// value (check_request_values), applies the request to `scene` (its settings and film size) and checks
// the result: adaptive sampling's batch and budget agree, the resolution and MLT probabilities are
// valid, the integrator exists (or chooses among candidates that read what is set) and reads every
// selective setting given, the pixel and the part are well formed and combine, and the integrator
// can do what is asked (check_capabilities, integrator.h). Throws UsageError. Prints a note (unless
// quiet) for a scene setting the chosen integrator ignores.
RenderPlan plan_render(const RenderRequest& request, SceneDesc& scene);

// What the image depends on besides the scene file's bytes: every option's fingerprint entry
// (description/render_options.h), which a checkpoint or a part must match to be resumed or merged.
RenderFingerprint render_fingerprint(const std::string& scene_bytes, const SceneDesc& desc,
                                     const RenderRequest& request);

struct RenderOutcome {
  RenderStats stats;              // its seconds include auto's pilots
  std::optional<AutoChoice> choice;  // --integrator auto's pilots and choice
  ErrorEstimate error;            // from the film's halves; .valid false without them
};

// Renders `scene` into `film` as `plan` (made from the scene's description with `settings`) and
// `options` ask, with the plan's integrator, whose capabilities the plan checked. One that chooses
// (auto) first runs its pilots and chooses (then settings.integrator names the choice and
// `announce` gets its summary), within the plan's budget.
RenderOutcome render_requested(const Scene& scene, RenderSettings& settings, Film& film, const RenderPlan& plan,
                               RenderOptions options,
                               const std::function<void(const std::string&)>& announce = nullptr);

// "64", "min 12, mean 15.20", "adaptive, 15.20 spp on average" or "1.20 mutations per pixel": the
// samples the film holds, as the closing line and the metadata say them. `spp_unit` is " spp"
// where the text is a bare count, else empty.
struct SampleCountText {
  std::string text;
  const char* spp_unit = " spp";
};
SampleCountText describe_samples(const RenderSettings& settings, const Film& film, const RenderOutcome& outcome);

// The image metadata (EXR attributes "candela:*") of a finished render of `scene_name`.
std::map<std::string, std::string> image_metadata(const std::string& scene_name, const RenderSettings& settings,
                                                  const Film& film, const RenderOutcome& outcome,
                                                  const RenderOptions& options, int ranks,
                                                  uint64_t non_finite_samples);

}  // namespace candela
