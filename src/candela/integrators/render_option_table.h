#pragma once
// Every render option, declared once (as Mitsuba's Properties and pbrt-v4's ParameterDictionary
// declare a plugin's parameters once): its name, where it lives in the RenderRequest, the values it
// takes, its help text, which integrators read it, where it lands in the scene's settings and what
// it adds to the fingerprint of checkpoints and --part files. Generated from this table:
//   - the command line's flags (apps/candela/main.cpp): --NAME with '-' for '_', the help text;
//   - the Python module's render() keywords (python/module.cpp) and their kinds;
//   - check_request_values' range, choice and format checks, with the flag in every message;
//   - plan_render's assignments to the scene (integrators/render_request.cpp);
//   - the refusal of an option the chosen integrator does not read;
//   - the fingerprint that a checkpoint or a part must match to be resumed or merged.
// Adding an option: a RenderRequest field (render_request.h) and an entry here; nothing else
// (render_option_table_test.cpp walks the table through each front end). What the scene file's
// "render" object holds is read and written by io/json/settings.cpp and io/json_writer.cpp, with the
// same enum names (base/enum_names.h); `scene_key` names the key an option overrides, for docs/cli.md.
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "candela/description/schema.h"
#include "candela/integrators/render_request.h"
#include "candela/render/checkpoint.h"

namespace candela {

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
  // The selective setting (integrators/integrator.h) an integrator must read to accept the option,
  // or empty: every integrator reads it. With `reads_when`, only that value is selective.
  std::string_view reads, reads_when;
  std::string_view scene_key;  // the scene file's "render" key it overrides ("adaptive.spp"), or empty
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

// What the image depends on besides the scene file's bytes: every option's fingerprint entry.
RenderFingerprint render_fingerprint(const std::string& scene_bytes, const SceneDesc& desc,
                                     const RenderRequest& request);

}  // namespace candela
