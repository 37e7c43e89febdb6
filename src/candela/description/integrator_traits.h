#pragma once
// What is known about each integrator without rendering, as data: its name, the line --help and
// docs/cli.md show, the settings it reads beyond those every integrator reads, and what it can do
// besides a plain render. It sits in the bottom layer so that the readers and the writer (io/) check
// a scene's integrator and its settings without including the integrators; integrators/integrator.h
// binds each entry to its render function (the registry), and the command line and the Python module
// check a request against the same table (integrators/render_request.h's plan_render).
//
// Every integrator reads: spp, max_depth, seed, sampler, filter, spectral, hide_emitters, bvh,
// light_selection power/uniform/bvh (the scene's light distribution). The others are "selective":
// only the integrators that list them read them, and the readers and the command line reject a
// selective setting the chosen integrator does not read, naming both.
#include <string>
#include <string_view>
#include <vector>

#include "candela/description/render_settings.h"

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
    {"equiangular", "equiangular sampling of lights in homogeneous media",
     [](const RenderSettings& s) { return s.volpath != VolPathSettings{}; }},
    {"rr_start_depth", "the depth where Russian roulette starts",
     [](const RenderSettings& s) { return s.rr_start_depth != RenderSettings{}.rr_start_depth; }},
    {"adaptive", "adaptive sampling", [](const RenderSettings& s) { return s.adaptive(); }},
    {"mlt", "Metropolis light transport's parameters",
     [](const RenderSettings& s) { return s.mlt != MltSettings{}; }},
    {"ambient_occlusion", "ambient occlusion's parameters",
     [](const RenderSettings& s) { return s.ambient_occlusion != AmbientOcclusionSettings{}; }},
    {"sppm", "stochastic progressive photon mapping's parameters",
     [](const RenderSettings& s) { return s.sppm != SppmSettings{}; }},
};

struct IntegratorTraits {
  std::string_view name;
  std::string_view description;         // one line, for --help and docs/cli.md
  std::vector<std::string_view> reads;  // keys of kSelectiveSettings
  bool resumable = false;               // continues a partly rendered film (checkpoints, --resume, --part)
  bool single_pixel = false;            // can render one pixel alone (--pixel)
  bool strategy_images = false;         // writes per-strategy images (--bdpt-strategies)
  bool samples_are_mutations = false;   // RenderSettings::spp counts Markov chain mutations per pixel
  bool participating_media = false;     // renders scenes with participating media
  // Renders a geometric quantity of the surfaces seen (ambient occlusion), not the light the scene
  // carries: a different image, so the one that chooses never chooses it and the light-transport
  // tests (furnace_test.cpp) leave it out.
  bool geometric = false;
  // Renders only part of the light transport (the light tracer: nothing the camera sees through a
  // delta surface, no emitter seen directly): a different image wherever the camera sees those, so
  // the one that chooses never chooses it and the furnace tests leave it out.
  bool partial_transport = false;
  // Converges only as its iterations accumulate, biased for any finite number of them (photon density
  // estimation, sppm.h), and its pixels hold no two independent halves: the film gives no error
  // estimate, so the one that chooses never chooses it and --target-error does not apply.
  bool progressive = false;
  // Every contribution is a camera sample added to its own pixel (no splats, no AOV pass of its
  // own), so the sample's values at its wavelengths can fill a spectral film's buckets (aov_film.h).
  bool spectral_layer = false;
  // Renders nothing itself but chooses one of the others for the scene and the budget ("auto": short
  // pilots, integrators/auto_integrator.h): a name a request may give, not a scene file. Reads what
  // the one it chooses reads (the candidates are those that read every setting given).
  bool chooses = false;

  bool reads_setting(std::string_view key) const;
};

// Every integrator, in the order --help lists them (the one that chooses last).
const std::vector<IntegratorTraits>& integrator_traits();

// The integrator named `name`, or null.
const IntegratorTraits* find_integrator_traits(std::string_view name);

// "path, bdpt, mlt, volpath, ambient_occlusion": the integrators that render (the names a scene file
// may give), for messages; with `and_choosers`, every name a request may give (then also "auto").
std::string integrator_names(bool and_choosers = false);

// "bdpt" or "path, bdpt, volpath": the integrators that render and have `capability`, for messages.
std::string integrators_with(bool IntegratorTraits::*capability);

// Whether a render with `integrator` may read the selective setting `key`: it reads it, or it
// chooses and one of those it chooses from does.
bool may_read_setting(const IntegratorTraits& integrator, std::string_view key);

// "the bdpt integrator does not read mis (multiple importance sampling of direct light; read by:
// path)": the message behind every unread-setting error, wherever the setting was given.
std::string unread_setting_message(const IntegratorTraits& integrator, std::string_view key);

// The selective settings that `settings` sets to something other than their defaults and that
// `integrator` does not read (for a note when the command line changes a scene's integrator).
std::vector<std::string_view> set_but_unread(const IntegratorTraits& integrator, const RenderSettings& settings);

}  // namespace candela
