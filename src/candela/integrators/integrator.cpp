#include "candela/integrators/integrator.h"

#include <fmt/format.h>

#include <algorithm>

#include "candela/base/error.h"
#include "candela/integrators/ambient_occlusion.h"
#include "candela/integrators/auto_integrator.h"
#include "candela/integrators/bdpt.h"
#include "candela/integrators/light_path.h"
#include "candela/integrators/mlt.h"
#include "candela/integrators/path_integrator.h"
#include "candela/integrators/sppm.h"
#include "candela/integrators/volpath.h"
#include "candela/render/first_hit_aovs.h"

namespace candela {
namespace {

// What runs each integrator of the traits table, by name.
struct Binding {
  std::string_view name;
  RenderFunction render = nullptr;
  decltype(IntegratorEntry::candidates) candidates = nullptr;
  decltype(IntegratorEntry::choose) choose = nullptr;
  decltype(IntegratorEntry::make_strategy_images) make_strategy_images = nullptr;
};

std::vector<IntegratorEntry> bind_traits() {
  const Binding bindings[] = {
      {.name = "path", .render = render_path},
      {.name = "bdpt", .render = render_bdpt, .make_strategy_images = make_bdpt_strategy_images},
      {.name = "mlt", .render = render_mlt},
      {.name = "volpath", .render = render_volpath},
      {.name = "ambient_occlusion", .render = render_ambient_occlusion},
      {.name = "light_path", .render = render_light_path},
      {.name = "sppm", .render = render_sppm},
      {.name = "auto", .candidates = auto_candidates, .choose = choose_integrator},
  };
  std::vector<IntegratorEntry> entries;
  for (const IntegratorTraits& traits : integrator_traits()) {
    const Binding* binding = std::find_if(std::begin(bindings), std::end(bindings),
                                          [&](const Binding& b) { return b.name == traits.name; });
    if (binding == std::end(bindings))
      throw InternalError(fmt::format("the integrator '{}' has traits but nothing in the registry runs it", traits.name));
    IntegratorEntry entry;
    static_cast<IntegratorTraits&>(entry) = traits;
    entry.render = binding->render;
    entry.candidates = binding->candidates;
    entry.choose = binding->choose;
    entry.make_strategy_images = binding->make_strategy_images;
    entries.push_back(std::move(entry));
  }
  return entries;
}

// "bdpt does", "path, bdpt, volpath do": the integrators that can, for messages.
std::string those_that_do(bool IntegratorTraits::*capability) {
  const std::string names = integrators_with(capability);
  return names + (names.find(',') == std::string::npos ? " does" : " do");
}

bool film_started(const Film& film) {
  return film.total_samples() > 0 ||
         (film.has_splats() &&
          std::any_of(film.splats().sums().begin(), film.splats().sums().end(), [](int64_t v) { return v != 0; }));
}

}  // namespace

const std::vector<IntegratorEntry>& integrators() {
  static const std::vector<IntegratorEntry> table = bind_traits();
  return table;
}

const IntegratorEntry* find_integrator(std::string_view name) {
  for (const IntegratorEntry& entry : integrators())
    if (entry.name == name) return &entry;
  return nullptr;
}

void check_capabilities(const IntegratorTraits& integrator, const CapabilityNeeds& needs) {
  const std::string_view name = integrator.name;
  if (integrator.chooses) {
    // What it chooses is not known before its pilots, and they render neither a part nor a pixel.
    if (needs.continues_film || needs.one_pixel || needs.part)
      throw UsageError(fmt::format(
          "--integrator {} cannot be combined with --checkpoint, --resume, --pixel or --part (name the integrator)",
          name));
    if (needs.strategy_images)
      throw UsageError(fmt::format("--bdpt-strategies needs --integrator {}, not {}",
                                   integrators_with(&IntegratorTraits::strategy_images), name));
    if (needs.spectral_layer)
      throw UsageError(fmt::format("the spectral layer needs --integrator {}, not {} (it may choose one that splats)",
                                   integrators_with(&IntegratorTraits::spectral_layer), name));
    return;
  }
  if (needs.strategy_images && !integrator.strategy_images)
    throw UsageError(fmt::format("--bdpt-strategies: the {} integrator writes no strategy images ({})", name,
                                 those_that_do(&IntegratorTraits::strategy_images)));
  if (needs.spectral_layer && !integrator.spectral_layer)
    throw UsageError(fmt::format("the spectral layer (pbrt-v4's spectral film) is not kept by the {} integrator, whose "
                                 "light reaches the film other than as camera samples ({})",
                                 name, those_that_do(&IntegratorTraits::spectral_layer)));
  if (needs.continues_film && !integrator.resumable)
    throw UsageError(fmt::format(
        "--checkpoint and --resume are not supported with the {} integrator (it cannot continue a partly rendered film)",
        name));
  if (needs.one_pixel && !integrator.single_pixel)
    throw UsageError(
        fmt::format("--pixel cannot be used with the {} integrator (it cannot render one pixel alone)", name));
  if (needs.part && !integrator.resumable)
    throw UsageError(fmt::format("--part: the {} integrator does not render tile by tile ({})", name,
                                 those_that_do(&IntegratorTraits::resumable)));
  if (needs.adaptive && !integrator.reads_setting("adaptive"))
    throw UsageError(fmt::format("adaptive sampling does not apply to the {} integrator", name));
  if (needs.target_error && integrator.progressive)
    throw UsageError(fmt::format("--target-error: the {} integrator gives no error estimate (its pixels have no two "
                                 "independent halves)",
                                 name));
  if (needs.denoise && integrator.progressive)
    throw UsageError(fmt::format("--denoise: the {} integrator's pixels have no two independent halves, from which the "
                                 "denoiser estimates its filters' error",
                                 name));
  if (needs.media && !integrator.participating_media)
    throw UsageError(fmt::format(
        "the scene has participating media, which the {} integrator does not render: use --integrator volpath", name));
}

RenderStats render_with(const IntegratorEntry& integrator, const Scene& scene, const RenderSettings& settings,
                        Film& film, const RenderOptions& options) {
  if (!integrator.render) throw InternalError(fmt::format("the {} integrator renders nothing itself", integrator.name));
  RenderStats stats = integrator.render(scene, settings, film, options);
  // Every integrator here traces its camera samples (MLT: its depth-0 pass) through CameraSampleTiles,
  // which adds the AOVs; one that does not leaves them empty, and they get a pass of their own.
  if (options.aovs && options.aovs->has_sample_layers() && options.aovs->empty() && !stats.cancelled)
    render_aovs(scene, settings, *options.aovs, options);
  return stats;
}

RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  const IntegratorEntry* integrator = find_integrator(settings.integrator);
  if (!integrator)
    throw UsageError(fmt::format("unknown integrator '{}' (known: {})", settings.integrator, integrator_names()));
  if (integrator->chooses)
    throw UsageError(fmt::format("the {} integrator chooses another and renders nothing itself: render it through "
                                 "render_requested (integrators/render_request.h)",
                                 integrator->name));
  check_capabilities(*integrator, {.continues_film = film_started(film),
                                   .one_pixel = options.only_x >= 0,
                                   .part = options.part_count > 1,
                                   .adaptive = settings.adaptive(),
                                   .media = scene.has_media(),
                                   .target_error = options.target_error > 0});
  return render_with(*integrator, scene, settings, film, options);
}

}  // namespace candela
