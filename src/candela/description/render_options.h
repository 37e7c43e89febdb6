#pragma once
// Every render option, declared once (as Mitsuba's Properties and pbrt-v4's ParameterDictionary
// declare a plugin's parameters once): its name, where it lives in the RenderRequest, the values it
// takes, its help text, which integrators read it, its key in the scene file's "render" object, where
// it lands in the scene's settings and what it adds to the fingerprint of checkpoints and --part
// files. Generated from this table:
//   - the command line's flags (apps/candela/main.cpp): --NAME with '-' for '_', the help text;
//   - the Python module's render() keywords (python/module.cpp) and their kinds;
//   - check_request_values' range, choice and format checks, with the flag in every message;
//   - plan_render's assignments to the scene (integrators/render_request.cpp);
//   - the refusal of an option the chosen integrator does not read;
//   - the JSON scene format's "render" keys: read (io/json/settings.cpp) with the same rules, and
//     written (io/json_writer.cpp);
//   - the fingerprint that a checkpoint or a part must match to be resumed or merged.
// Adding an option: a RenderRequest field (below) and an entry in render_options.cpp; nothing else
// (integrators/render_options_test.cpp walks the table through each front end). It sits in the
// bottom layer so that the readers and the writer (io/) use it without including the integrators.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "candela/description/schema.h"
#include "candela/description/scene_desc.h"

namespace candela {

// What a render is asked to do, whoever asks (the command line, the Python module; integrators/
// render_request.h checks, plans and renders it). Every field is unset by default: the scene's own value holds. The names are the flags'; each field
// before `quiet` is declared, checked and applied through its entry in this table.
struct RenderRequest {
  std::optional<int> spp, threads, max_depth, rr_start_depth;
  std::optional<uint64_t> seed;
  std::string resolution;  // "WIDTHxHEIGHT"
  std::string integrator;  // a registered name (description/integrator_traits.h), "auto" included
  std::string sampler, filter, direction_sampling, light_selection, bvh, transport;
  std::optional<int> shadow_rays, max_spp, adaptive_batch, adaptive_spp;
  std::optional<float> adaptive_threshold;
  bool no_mis = false;
  std::string time_limit;  // seconds ("90", "2.5") or a duration ("90s", "10m", "1h30m")
  std::optional<double> target_error;
  bool estimate_error = false;
  bool denoise = false;  // --denoise: the image denoised (denoise/denoiser.h), the raw one kept beside it
  std::optional<float> clamp;
  std::string bdpt_strategies;  // a directory for bdpt's per-strategy images
  bool bdpt_unweighted = false;
  std::optional<int> mlt_bootstrap, mlt_chains;
  std::optional<float> mlt_sigma, mlt_large_step, mlt_lens, mlt_caustic;
  std::optional<float> ao_max_distance;
  std::string ao_sampling;  // "cosine" or "uniform"
  std::optional<int> sppm_photons;
  std::optional<float> sppm_radius;
  std::string equiangular;  // "on" or "off"
  bool quiet = false;  // no progress bar, no notes (the command line's -q; Python renders quietly)
  // What only the command line asks (flags of its own, no Python keywords), checked by plan_render
  // with the rest because each asks something of the integrator.
  std::string pixel;               // --pixel X,Y: that pixel alone
  std::string part;                // --part K/N: every N-th tile, from the K-th
  std::string checkpoint, resume;  // --checkpoint FILE, --resume FILE: the film is saved to be continued, or continued
};


// Where an option's value lives in the request.
using RequestField = std::variant<std::optional<int> RenderRequest::*, std::optional<uint64_t> RenderRequest::*,
                                  std::optional<float> RenderRequest::*, std::optional<double> RenderRequest::*,
                                  std::string RenderRequest::*, bool RenderRequest::*>;

// The values an option takes beyond its type.
struct AnyValue {};
struct PositiveValue {};  // finite and > 0
struct ChoiceValue {      // one of these names
  std::vector<std::string> names;
};
struct FormattedValue {  // text of a form `check` knows; throws UsageError naming `flag`
  void (*check)(const std::string& flag, const std::string& text);
};
using ValueRule = std::variant<AnyValue, ValueRange, PositiveValue, ChoiceValue, FormattedValue>;

struct RenderOption {
  std::string name;  // the Python keyword; the flag is --name with '-' for '_'
  RequestField field;
  ValueRule rule;
  std::string help;  // one paragraph, for --help and docs/cli.md
  // The selective setting (description/integrator_traits.h) an integrator must read to accept the option,
  // or empty: every integrator reads it. With `reads_when`, only that value is selective.
  std::string_view reads, reads_when;
  // Its key in the scene file's "render" object ("spp"; "adaptive.spp": the key "spp" of the object
  // "adaptive"), or empty: the request's alone. The file holds the value as the request does, but:
  std::string_view scene_key;
  std::string_view scene_true;  // a text option the file holds as a flag: true is this value, false the other
  bool scene_negated = false;   // a flag option the file holds as its opposite (--no-mis is "mis": false)
  // The scene's value as the request would give it, for the writer; leaves the field unset where the
  // file says nothing (adaptive sampling off). Set exactly for the options with a scene key.
  void (*extract)(const SceneDesc&, RenderRequest&) = nullptr;
  bool python = true;          // a keyword of the Python module's render() (false: the command line's alone)
  // Sets what the option sets in the scene description; called only when the option is given.
  void (*apply)(const RenderRequest&, SceneDesc&) = nullptr;
  // What it adds to a render's fingerprint (render_fingerprint): the key and the value the scene and
  // request give; nullopt: nothing for this render. Null for options that leave the image alone.
  std::string_view fingerprint_key;
  std::optional<std::string> (*fingerprint)(const SceneDesc&, const RenderRequest&) = nullptr;

  std::string flag() const;                       // "--max-depth"
  bool given(const RenderRequest& request) const;  // set to anything but "unset"
  // Given with a value only some integrators read (`reads`, and `reads_when` if any).
  bool selective_in(const RenderRequest& request) const;
  // The flag as messages name it: "--light-selection paper" where only one value is selective.
  std::string flag_for_messages() const;
};

// Every option, in the order --help lists them.
const std::vector<RenderOption>& render_options();

// The option named `name` (its keyword, "max_depth"), or null.
const RenderOption* find_render_option(std::string_view name);

// What is wrong among adaptive sampling's settings, if anything (nothing while it is off): the scene
// key at fault ("adaptive.batch") and what ("must be a power of two, got 12"). The JSON reader reports
// it at that key and plan_render with the key's flag, so that a file and a request refuse the same.
struct SettingProblem {
  std::string_view scene_key;
  std::string message;
};
std::optional<SettingProblem> adaptive_problem(const RenderSettings& settings);

// WIDTHxHEIGHT (--resolution), each side 1..kMaxResolution and at most kMaxPixels in all; throws
// UsageError.
std::pair<int, int> parse_resolution(const std::string& text);

// A film size in range; `shown` is the size as the user gave it, for the UsageError.
void check_resolution_range(long long width, long long height, const std::string& shown);

// Seconds from "90", "2.5", "90s", "10m", "2h" or "1h30m" (each part a number with a unit, largest
// first); `option` names the flag in the UsageError.
double parse_duration(const std::string& option, const std::string& text);

}  // namespace candela
