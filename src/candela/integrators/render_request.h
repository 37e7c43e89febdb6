#pragma once
// What a render is asked to do, whoever asks: the command line's flags (apps/candela/main.cpp) and
// the Python module's keyword arguments (python/) fill one RenderRequest, which is checked, applied
// to the scene, rendered and described here, so both accept the same values, refuse the same
// combinations with the same messages, and make the same bytes and the same image metadata.
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "candela/base/error.h"  // UsageError: what the checks below throw
#include "candela/film/error_estimate.h"
#include "candela/integrators/auto_integrator.h"
#include "candela/render/render_loop.h"
#include "candela/description/scene_desc.h"

namespace candela {

inline constexpr int kMaxResolution = 65536;       // pixels along either side
inline constexpr long long kMaxPixels = 1LL << 28;  // pixels in all
inline constexpr int kTargetErrorMaxSpp = 65536;    // the spp cap of --target-error without --spp

// Every field is unset by default: the scene's own value holds. The names are the flags'; each field
// is declared, checked and applied through its entry in integrators/render_option_table.h.
struct RenderRequest {
  std::optional<int> spp, threads, max_depth, rr_start_depth;
  std::optional<uint64_t> seed;
  std::string resolution;  // "WIDTHxHEIGHT"
  std::string integrator;  // a registered name (integrators/integrator.h) or "auto"
  std::string sampler, filter, direction_sampling, light_selection, bvh, transport;
  std::optional<int> shadow_rays, max_spp, adaptive_batch, adaptive_spp;
  std::optional<float> adaptive_threshold;
  bool no_mis = false;
  std::string time_limit;  // seconds ("90", "2.5") or a duration ("90s", "10m", "1h30m")
  std::optional<double> target_error;
  bool estimate_error = false;
  std::optional<float> clamp;
  std::string bdpt_strategies;  // a directory for bdpt's per-strategy images
  bool bdpt_unweighted = false;
  std::optional<int> mlt_bootstrap, mlt_chains;
  std::optional<float> mlt_sigma, mlt_large_step, mlt_lens, mlt_caustic;
  bool quiet = false;  // no progress bar, no notes
};

// Checks each value on its own (ranges, the time limit's and the resolution's form), before a scene is read.
// Throws UsageError.
void check_request_values(const RenderRequest& request);

// Checks every value (check_request_values), applies the request to `scene` (its settings and film size) and
// checks the result: the integrator exists and reads every selective setting given, adaptive
// sampling's batch and budget agree, the resolution and MLT probabilities are valid. Throws
// UsageError. Prints a note (unless quiet) for a scene setting the chosen integrator ignores.
void apply_request(const RenderRequest& request, SceneDesc& scene);

// WIDTHxHEIGHT (--resolution), each side 1..kMaxResolution and at most kMaxPixels in all; throws
// UsageError.
std::pair<int, int> parse_resolution(const std::string& text);

// Seconds from "90", "2.5", "90s", "10m", "2h" or "1h30m" (each part a number with a unit, largest
// first); `option` names the flag in the UsageError.
double parse_duration(const std::string& option, const std::string& text);

// The render options the request sets: threads, time limit, target error, clamp (the caller adds
// cancellation, progress, the cluster and its own hooks).
RenderOptions request_options(const RenderRequest& request);

struct RenderOutcome {
  RenderStats stats;              // its seconds include auto's pilots
  std::optional<AutoChoice> choice;  // --integrator auto's pilots and choice
  ErrorEstimate error;            // from the film's halves; .valid false without them
};

// Renders `scene` into `film` as `settings` ask, --integrator auto first running its pilots and
// choosing (then settings.integrator names the choice and `announce` gets its summary). `budget_spp`
// is auto's budget when it has neither a time limit nor a target: the spp asked for.
RenderOutcome render_requested(const Scene& scene, RenderSettings& settings, Film& film, RenderOptions options,
                               int budget_spp, const std::function<void(const std::string&)>& announce = nullptr);

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
