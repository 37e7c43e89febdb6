#pragma once
// The integrators candela renders with, in one table (as pbrt-v4's Integrator::Create and Mitsuba's
// plugin registry): each entry's name, the line that --help and docs/cli.md show, the settings it
// reads beyond those every integrator reads, what it can do besides a plain render, and its render
// function. Adding an integrator touches this table (integrator.cpp) and the integrator's own files.
//
// Every integrator reads: spp, max_depth, seed, sampler, filter, spectral, hide_emitters, bvh,
// light_selection power/uniform (the scene's light distribution). The others are "selective": only
// the integrators that list them read them, and the readers and the command line reject a selective
// setting the chosen integrator does not read, naming both.
#include <string>
#include <string_view>
#include <vector>

#include "candela/film/film.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"

namespace candela {

// A setting only some integrators read, named as in the JSON scene format's "render" object (the
// command line's flags map onto these names; docs/cli.md).
struct SelectiveSetting {
  std::string_view key;
  std::string_view what;  // for messages and docs
  // The settings set it to something other than its default (for the note when the command line
  // changes a scene's integrator to one that ignores it).
  bool (*is_set)(const RenderSettings&);
};
inline constexpr SelectiveSetting kSelectiveSettings[] = {
    {"direction_sampling", "the next-direction sampling strategy",
     [](const RenderSettings& s) { return s.path.direction_sampling != PathSettings{}.direction_sampling; }},
    {"mis", "multiple importance sampling of direct light",
     [](const RenderSettings& s) { return s.path.mis != PathSettings{}.mis; }},
    {"shadow_rays", "the number of shadow rays per vertex",
     [](const RenderSettings& s) { return s.path.shadow_rays != PathSettings{}.shadow_rays; }},
    {"light_selection=paper", "the paper's rule for choosing lights for shadow rays",
     [](const RenderSettings& s) { return s.light_selection == LightSelection::Paper; }},
    {"rr_start_depth", "the depth where Russian roulette starts",
     [](const RenderSettings& s) { return s.rr_start_depth != RenderSettings{}.rr_start_depth; }},
    {"adaptive", "adaptive sampling", [](const RenderSettings& s) { return s.adaptive(); }},
    {"mlt", "Metropolis light transport's parameters",
     [](const RenderSettings& s) { return s.mlt != MltSettings{}; }},
};

struct IntegratorEntry {
  std::string_view name;
  std::string_view description;  // one line, for --help and docs/cli.md
  std::vector<std::string_view> reads;  // keys of kSelectiveSettings
  bool resumable = false;        // continues a partly rendered film (checkpoints, --resume)
  bool single_pixel = false;     // can render one pixel alone (--pixel)
  bool strategy_images = false;  // writes per-strategy images (--bdpt-strategies)
  bool samples_are_mutations = false;  // RenderSettings::spp counts Markov chain mutations per pixel
  RenderStats (*render)(const Scene&, const RenderSettings&, Film&, const RenderOptions&) = nullptr;
  bool participating_media = false;  // renders scenes with participating media

  bool reads_setting(std::string_view key) const;
};

// Every integrator, in the order --help lists them.
const std::vector<IntegratorEntry>& integrators();

// The integrator named `name`, or null.
const IntegratorEntry* find_integrator(std::string_view name);

// "path, bdpt, mlt", for messages.
std::string integrator_names();

// "the bdpt integrator does not read mis (multiple importance sampling of direct light; read by:
// path)": the message behind every unread-setting error, wherever the setting was given.
std::string unread_setting_message(const IntegratorEntry& integrator, std::string_view key);

// The selective settings that `settings` sets to something other than their defaults and that
// `integrator` does not read (for a note when the command line changes a scene's integrator).
std::vector<std::string_view> set_but_unread(const IntegratorEntry& integrator, const RenderSettings& settings);

// Renders `film` (sized to the camera's resolution) with settings.integrator, after checking that
// it can do what `options` and the film ask (adaptive sampling, one pixel, continuing a partly
// rendered film, a scene with media); throws UsageError otherwise, and for an unknown integrator.
RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
