#include "candela/description/integrator_traits.h"

#include <fmt/format.h>

#include <algorithm>

namespace candela {

const std::vector<IntegratorTraits>& integrator_traits() {
  static const std::vector<IntegratorTraits> table = {
      {.name = "path",
       .description = "path tracing (Häkkinen 2002): next-event estimation, MIS, Russian roulette",
       .reads = {"direction_sampling", "mis", "shadow_rays", "light_selection=paper", "rr_start_depth", "adaptive"},
       .resumable = true,
       .single_pixel = true,
       .spectral_layer = true},
      {.name = "bdpt",
       .description = "bidirectional path tracing: every connection strategy, MIS, light tracing splatted",
       .reads = {"rr_start_depth", "adaptive"},
       .resumable = true,
       .single_pixel = true,
       .strategy_images = true,
       .participating_media = true},
      {.name = "mlt",
       .description = "Metropolis light transport over bidirectional paths (--spp is then mutations per pixel)",
       .reads = {"mlt"},
       .samples_are_mutations = true,
       .participating_media = true},
      {.name = "volpath",
       .description = "volumetric path tracing: participating media by delta and ratio tracking, spectral MIS, NEE, "
                      "equiangular light sampling in homogeneous media",
       .reads = {"equiangular", "rr_start_depth", "adaptive"},
       .resumable = true,
       .single_pixel = true,
       .participating_media = true,
       .spectral_layer = true},
      // Media are ignored, as pbrt-v4's does: the occlusion of the surfaces by surfaces is what it shows.
      {.name = "ambient_occlusion",
       .description = "ambient occlusion (pbrt-v4's ambientocclusion): the cosine-weighted unoccluded fraction of the "
                      "hemisphere at the first surface seen, white where nothing occludes; no light transport",
       .reads = {"ambient_occlusion", "adaptive"},
       .resumable = true,
       .single_pixel = true,
       .participating_media = true,
       .geometric = true,
       .spectral_layer = true},
      // Light subpaths as bdpt traces them (Russian roulette included), each vertex joined to the lens
      // (t = 1 alone, unweighted) and splatted. Media: the light subpaths scatter in them as bdpt's do.
      {.name = "light_path",
       .description = "light tracing (pbrt-v4's lightpath): light subpaths joined to the lens and splatted; "
                      "black where the camera sees a delta surface, an emitter or the sky",
       .reads = {"rr_start_depth"},
       .resumable = true,
       .participating_media = true,
       .partial_transport = true},
      // Surfaces only, as pbrt-v4's: a scene with media is refused.
      {.name = "sppm",
       .description = "stochastic progressive photon mapping (pbrt-v4's sppm; --spp is then iterations): photons "
                      "gathered at the first diffuse surface each camera path meets, for caustics",
       .reads = {"sppm"},
       .progressive = true},
      {.name = "auto",
       .description = "short pilots of each measure which reaches the lowest error in the budget: --time-limit, "
                      "--target-error, or the path tracer's time for --spp; the pilots aim at 10%",
       .participating_media = true,
       .chooses = true},
  };
  return table;
}

bool IntegratorTraits::reads_setting(std::string_view key) const {
  return std::find(reads.begin(), reads.end(), key) != reads.end();
}

const IntegratorTraits* find_integrator_traits(std::string_view name) {
  for (const IntegratorTraits& traits : integrator_traits())
    if (traits.name == name) return &traits;
  return nullptr;
}

std::string integrator_names(bool and_choosers) {
  std::string names;
  for (const IntegratorTraits& traits : integrator_traits())
    if (and_choosers || !traits.chooses) names += (names.empty() ? "" : ", ") + std::string(traits.name);
  return names;
}

std::string integrators_with(bool IntegratorTraits::*capability) {
  std::string names;
  for (const IntegratorTraits& traits : integrator_traits())
    if (!traits.chooses && traits.*capability) names += (names.empty() ? "" : ", ") + std::string(traits.name);
  return names;
}

bool may_read_setting(const IntegratorTraits& integrator, std::string_view key) {
  if (!integrator.chooses) return integrator.reads_setting(key);
  return std::any_of(integrator_traits().begin(), integrator_traits().end(),
                     [&](const IntegratorTraits& t) { return !t.chooses && t.reads_setting(key); });
}

std::string unread_setting_message(const IntegratorTraits& integrator, std::string_view key) {
  std::string readers;
  for (const IntegratorTraits& traits : integrator_traits())
    if (traits.reads_setting(key)) readers += (readers.empty() ? "" : ", ") + std::string(traits.name);
  std::string_view what;
  for (const SelectiveSetting& s : kSelectiveSettings)
    if (s.key == key) what = s.what;
  return fmt::format("the {} integrator does not read {} ({}; read by: {})", integrator.name, key, what, readers);
}

std::vector<std::string_view> set_but_unread(const IntegratorTraits& integrator, const RenderSettings& settings) {
  std::vector<std::string_view> unread;
  for (const SelectiveSetting& s : kSelectiveSettings)
    if (!integrator.reads_setting(s.key) && s.is_set(settings)) unread.push_back(s.key);
  return unread;
}

}  // namespace candela
