#pragma once
// The integrators candela renders with, in one table (as pbrt-v4's Integrator::Create and Mitsuba's
// plugin registry): each entry is an integrator's traits (description/integrator_traits.h: its name,
// the line --help shows, the selective settings it reads and what it can do, as data the readers
// share) bound to what runs it: the render function of those that render, the candidates and the
// choice of the one that chooses ("auto", auto_integrator.h), the maker of the per-strategy images
// of the one that writes them. Adding an integrator touches the traits table, the bindings here
// (integrator.cpp) and the integrator's own files.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "candela/description/integrator_traits.h"
#include "candela/film/film.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"

namespace candela {

struct AutoChoice;  // integrators/auto_integrator.h

using RenderFunction = RenderStats (*)(const Scene&, const RenderSettings&, Film&, const RenderOptions&);

struct IntegratorEntry : IntegratorTraits {
  // An integrator that renders: renders `film` (sized to the camera's resolution) as the settings
  // and options ask.
  RenderFunction render = nullptr;
  // The one that chooses (IntegratorTraits::chooses): the integrators it may choose for a scene with
  // or without media whose settings are `settings` (those that read every selective setting they
  // set), and the choice, made by running them (auto_integrator.h's choose_integrator).
  std::vector<const IntegratorEntry*> (*candidates)(const RenderSettings& settings, bool has_media) = nullptr;
  AutoChoice (*choose)(const Scene&, const RenderSettings&, Film&, const RenderOptions&, int budget_spp) = nullptr;
  // The one with strategy_images: its images for a render of `settings` into a width x height film,
  // written into `directory`, MIS weighted or not (RenderOptions::integrator_outputs).
  std::unique_ptr<IntegratorOutputs> (*make_strategy_images)(const RenderSettings& settings, int width, int height,
                                                            const std::string& directory, bool unweighted) = nullptr;
};

// Every integrator, in the traits' order (integrator_traits(): the one that chooses last).
const std::vector<IntegratorEntry>& integrators();

// The integrator named `name`, or null.
const IntegratorEntry* find_integrator(std::string_view name);

// What a render asks of its integrator besides a plain render of the whole image.
struct CapabilityNeeds {
  bool continues_film = false;   // continue a partly rendered film, or save it to be (--checkpoint, --resume)
  bool one_pixel = false;        // one pixel alone (--pixel)
  bool part = false;             // every N-th tile (--part K/N)
  bool strategy_images = false;  // per-strategy images (--bdpt-strategies)
  bool adaptive = false;         // adaptive sampling
  bool media = false;            // a scene with participating media
  bool target_error = false;     // stop at an error target (--target-error), from the film's two halves
  bool denoise = false;          // denoise from the film's two halves (--denoise)
  bool spectral_layer = false;   // a spectral film's buckets (pbrt-v4's Film "spectral", --aov spectral)
};

// Throws UsageError for the first of `needs` that `integrator` cannot do, naming the flag that asks
// for it and the integrator: the one place the capabilities are checked, by plan_render
// (render_request.h) for a request and by render() for a direct call.
void check_capabilities(const IntegratorTraits& integrator, const CapabilityNeeds& needs);

// Renders with `integrator`, one that renders, whose capabilities the caller has checked; then the
// AOVs' pass of their own if the integrator added none (RenderOptions::aovs).
RenderStats render_with(const IntegratorEntry& integrator, const Scene& scene, const RenderSettings& settings,
                        Film& film, const RenderOptions& options);

// Renders `film` (sized to the camera's resolution) with settings.integrator, after checking that it
// can do what `options`, the settings, the scene and the film ask (check_capabilities: adaptive
// sampling, a scene with media, one pixel, a part, continuing a partly rendered film); throws
// UsageError otherwise, for an unknown integrator and for one that chooses (render_requested runs it).
RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
