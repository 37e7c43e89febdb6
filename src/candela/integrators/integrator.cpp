#include "candela/integrators/integrator.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/integrators/bdpt.h"
#include "candela/integrators/mlt.h"
#include "candela/integrators/path_integrator.h"
#include "candela/integrators/volpath.h"
#include "candela/render/first_hit_aovs.h"

namespace candela {

const std::vector<IntegratorEntry>& integrators() {
  static const std::vector<IntegratorEntry> table = {
      {"path", "path tracing (Häkkinen 2002): next-event estimation, MIS, Russian roulette",
       {"direction_sampling", "mis", "shadow_rays", "light_selection=paper", "rr_start_depth", "adaptive"},
       /*resumable=*/true, /*single_pixel=*/true, /*strategy_images=*/false, /*samples_are_mutations=*/false,
       render_path},
      {"bdpt", "bidirectional path tracing: every connection strategy, MIS, light tracing splatted",
       {"rr_start_depth", "adaptive"},
       /*resumable=*/true, /*single_pixel=*/true, /*strategy_images=*/true, /*samples_are_mutations=*/false,
       render_bdpt, /*participating_media=*/true},
      {"mlt", "Metropolis light transport over bidirectional paths (--spp is then mutations per pixel)",
       {"mlt"},
       /*resumable=*/false, /*single_pixel=*/false, /*strategy_images=*/false, /*samples_are_mutations=*/true,
       render_mlt, /*participating_media=*/true},
      {"volpath", "volumetric path tracing: participating media by delta and ratio tracking, spectral MIS, NEE",
       {"rr_start_depth", "adaptive"},
       /*resumable=*/true, /*single_pixel=*/true, /*strategy_images=*/false, /*samples_are_mutations=*/false,
       render_volpath, /*participating_media=*/true},
  };
  return table;
}

bool IntegratorEntry::reads_setting(std::string_view key) const {
  return std::find(reads.begin(), reads.end(), key) != reads.end();
}

const IntegratorEntry* find_integrator(std::string_view name) {
  for (const IntegratorEntry& entry : integrators())
    if (entry.name == name) return &entry;
  return nullptr;
}

std::string integrator_names() {
  std::string names;
  for (const IntegratorEntry& entry : integrators()) names += (names.empty() ? "" : ", ") + std::string(entry.name);
  return names;
}

std::string unread_setting_message(const IntegratorEntry& integrator, std::string_view key) {
  std::string readers;
  for (const IntegratorEntry& entry : integrators())
    if (entry.reads_setting(key)) readers += (readers.empty() ? "" : ", ") + std::string(entry.name);
  std::string_view what;
  for (const SelectiveSetting& s : kSelectiveSettings)
    if (s.key == key) what = s.what;
  return fmt::format("the {} integrator does not read {} ({}; read by: {})", integrator.name, key, what, readers);
}

std::vector<std::string_view> set_but_unread(const IntegratorEntry& integrator, const RenderSettings& settings) {
  std::vector<std::string_view> unread;
  for (const SelectiveSetting& s : kSelectiveSettings)
    if (!integrator.reads_setting(s.key) && s.is_set(settings)) unread.push_back(s.key);
  return unread;
}

RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  const IntegratorEntry* integrator = find_integrator(settings.integrator);
  if (!integrator)
    throw UsageError(fmt::format("unknown integrator '{}' (known: {})", settings.integrator, integrator_names()));
  if (settings.adaptive() && !integrator->reads_setting("adaptive"))
    throw UsageError(fmt::format("adaptive sampling does not apply to the {} integrator", integrator->name));
  if (scene.has_media() && !integrator->participating_media)
    throw UsageError(fmt::format(
        "the scene has participating media, which the {} integrator does not render: use --integrator volpath",
        integrator->name));
  if (options.only_x >= 0 && !integrator->single_pixel)
    throw UsageError(fmt::format("the {} integrator cannot render a single pixel", integrator->name));
  const bool started = film.total_samples() > 0 ||
                       (film.has_splats() && std::any_of(film.splats().sums().begin(), film.splats().sums().end(),
                                                         [](int64_t v) { return v != 0; }));
  if (started && !integrator->resumable)
    throw UsageError(fmt::format("the {} integrator cannot continue a partly rendered film", integrator->name));
  RenderStats stats = integrator->render(scene, settings, film, options);
  // Every integrator here traces its camera samples (MLT: its depth-0 pass) through CameraSampleTiles,
  // which adds the AOVs; one that does not leaves them empty, and they get a pass of their own.
  if (options.aovs && options.aovs->has_sample_layers() && options.aovs->empty() && !stats.cancelled)
    render_aovs(scene, settings, *options.aovs, options);
  return stats;
}

}  // namespace candela
