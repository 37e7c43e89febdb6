#include "candela/integrators/render_request.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <regex>
#include <tuple>

#include "candela/integrators/integrator.h"
#include "candela/sampling/zsobol_sampler.h"

namespace candela {
namespace {

// The option's value against its rule (description/render_options.h).
void check_value(const RenderOption& option, const RenderRequest& request) {
  const std::string flag = option.flag();
  std::visit(
      [&](auto member) {
        const auto& value = request.*member;
        using T = std::remove_cvref_t<decltype(value)>;
        if constexpr (std::is_same_v<T, std::string>) {
          if (value.empty()) return;
          if (const auto* choice = std::get_if<ChoiceValue>(&option.rule)) {
            if (std::find(choice->names.begin(), choice->names.end(), value) == choice->names.end())
              throw UsageError(fmt::format("{}: unknown value '{}' (expected one of: {})", flag, value,
                                           fmt::join(choice->names, ", ")));
          } else if (const auto* formatted = std::get_if<FormattedValue>(&option.rule)) {
            formatted->check(flag, value);
          }
        } else if constexpr (!std::is_same_v<T, bool>) {
          if (!value) return;
          const double x = double(*value);
          if (const auto* range = std::get_if<ValueRange>(&option.rule); range && !range->contains(x))
            throw UsageError(fmt::format("{}: {} is out of range ({} to {})", flag, *value, range->lo, range->hi));
          if (std::holds_alternative<PositiveValue>(option.rule) && !(std::isfinite(x) && x > 0))
            throw UsageError(fmt::format("{}: must be a positive number, got {}", flag, *value));
        }
      },
      option.field);
}

}  // namespace

void check_request_values(const RenderRequest& r) {
  for (const RenderOption& option : render_options()) check_value(option, r);
}

namespace {

// The request given to the scene's settings, each option setting its own field (description/render_options.cpp),
// then what depends on several.
void apply_options(const RenderRequest& request, SceneDesc& scene) {
  for (const RenderOption& option : render_options())
    if (option.apply && option.given(request)) option.apply(request, scene);
  RenderSettings& rs = scene.settings;
  // An integrator that chooses runs pilots of the others, which measure their error, and the winner
  // continues its pilot: they share one sampler setup, so the scene's or the given spp is then the
  // budget, not the count.
  const IntegratorTraits* traits = find_integrator_traits(rs.integrator);
  const bool chooses = traits && traits->chooses;
  // An error estimate, and the denoiser's choice of filters, need two independent halves of every
  // pixel's samples; with a target the spp is the most a pixel may get (--spp, or 65536).
  if (request.estimate_error || request.target_error || request.denoise || chooses) rs.sampler.replicas = true;
  if (chooses && !request.target_error) rs.spp = kTargetErrorMaxSpp;
  if (request.target_error) rs.spp = request.spp.value_or(kTargetErrorMaxSpp);
}

// The settings as applied agree with each other.
void check_settings(const RenderRequest& request, const SceneDesc& scene) {
  const RenderSettings& rs = scene.settings;
  // ZSobol's replicas alternate in blocks of 8 samples (sampling/samplers.h): fewer than two blocks
  // leave a pixel one half, and the denoiser nothing to check its fits against.
  if (request.denoise && rs.sampler.type == SamplerType::ZSobol && !rs.adaptive() && !request.target_error &&
      rs.spp < 2 * int(ZSobolSampler::kReplicaBlock))
    throw UsageError(fmt::format("--denoise needs two independent halves of every pixel's samples, which the zsobol "
                                 "sampler makes in blocks of {} samples: give at least {} spp, or --sampler independent",
                                 ZSobolSampler::kReplicaBlock, 2 * ZSobolSampler::kReplicaBlock));
  if (std::string problem = rs.mlt.problem(); !problem.empty())
    throw UsageError("--mlt-large-step, --mlt-lens, --mlt-caustic: " + problem);
  if (std::optional<SettingProblem> problem = adaptive_problem(rs))
    for (const RenderOption& option : render_options())
      if (option.scene_key == problem->scene_key) throw UsageError(option.flag() + ": " + problem->message);
  const auto& f = scene.film;
  check_resolution_range(f.width, f.height, fmt::format("{}x{}", f.width, f.height));
  if (request.target_error && rs.adaptive())
    throw UsageError("--target-error: adaptive sampling (--adaptive-threshold, --adaptive-spp) has its own stopping "
                     "rule; use one or the other");
}

// The scene's integrator (as the request may have changed it), which must read every selective
// setting the request gives (description/integrator_traits.h); what the scene file sets for another
// integrator gets a note. One that chooses needs a candidate that reads every setting given.
const IntegratorEntry& resolve_integrator(const RenderRequest& request, const SceneDesc& scene) {
  const IntegratorEntry* integrator = find_integrator(scene.settings.integrator);
  if (!integrator)
    throw UsageError(fmt::format("unknown integrator '{}' (known: {})", scene.settings.integrator,
                                 integrator_names(/*and_choosers=*/true)));
  if (integrator->chooses) {
    if (integrator->candidates(scene.settings, !scene.media.empty()).empty())
      throw UsageError(fmt::format("--integrator {}: no integrator reads every setting given (see --help for who "
                                   "reads what)",
                                   integrator->name));
    return *integrator;
  }
  for (const RenderOption& option : render_options()) {
    if (!option.selective_in(request) || integrator->reads_setting(option.reads)) continue;
    throw UsageError(fmt::format("{}: {}", option.flag_for_messages(), unread_setting_message(*integrator, option.reads)));
  }
  if (!request.integrator.empty() && !request.quiet)
    for (std::string_view key : set_but_unread(*integrator, scene.settings))
      fmt::print(stderr, "note: the scene sets {}, which --integrator {} does not read\n", key, integrator->name);
  return *integrator;
}

// --pixel X,Y inside the image.
std::pair<int, int> parse_pixel(const std::string& text, const FilmDesc& film) {
  std::smatch m;
  static const std::regex pattern(R"((\d{1,9}),(\d{1,9}))");
  if (!std::regex_match(text, m, pattern))
    throw UsageError(fmt::format("--pixel: expected X,Y such as 10,20, got '{}'", text));
  const int x = std::stoi(m[1]), y = std::stoi(m[2]);
  if (x >= film.width || y >= film.height)
    throw UsageError(fmt::format("--pixel {},{} is outside the {}x{} image", x, y, film.width, film.height));
  return {x, y};
}


// Which pixels: --pixel and --part, and what they cannot be combined with.
void plan_pixels(const RenderRequest& request, const SceneDesc& scene, RenderPlan& plan) {
  const bool adaptive = scene.settings.adaptive();
  const bool checkpoints = !request.checkpoint.empty() || !request.resume.empty();
  if (adaptive && checkpoints)
    throw UsageError("--checkpoint and --resume are not supported with adaptive sampling (--adaptive-threshold, "
                     "--adaptive-spp)");
  if (!request.pixel.empty() && checkpoints) throw UsageError("--pixel cannot be combined with --checkpoint or --resume");
  if (!request.pixel.empty()) std::tie(plan.pixel_x, plan.pixel_y) = parse_pixel(request.pixel, scene.film);
  if (!request.part.empty()) {
    std::tie(plan.part_index, plan.part_count) = parse_part(request.part);
    if (adaptive)
      throw UsageError("--part cannot be combined with adaptive sampling (its decisions look across the whole image)");
    if (request.target_error)
      throw UsageError("--part cannot be combined with --target-error (the error is the whole image's)");
    if (plan.one_pixel()) throw UsageError("--part cannot be combined with --pixel");
  }
  // The denoiser reads the whole image's AOVs, which neither parts nor checkpoints keep.
  if (request.denoise && plan.one_pixel())
    throw UsageError("--denoise cannot be combined with --pixel (it denoises a whole image)");
  if (request.denoise && !request.part.empty())
    throw UsageError("--denoise cannot be combined with --part (parts do not keep the AOVs the denoiser reads)");
  if (request.denoise && !request.resume.empty())
    throw UsageError("--denoise cannot be combined with --resume (checkpoints do not keep the AOVs the denoiser reads)");
}

// The outputs besides the image, and whether they can be made.
void plan_outputs(const RenderRequest& request, RenderPlan& plan) {
  if (request.bdpt_unweighted && request.bdpt_strategies.empty())
    throw UsageError("--bdpt-unweighted needs --bdpt-strategies DIR");
  if (std::error_code ec; !request.bdpt_strategies.empty() && !std::filesystem::is_directory(request.bdpt_strategies, ec))
    throw UsageError(fmt::format("--bdpt-strategies '{}': not a directory", request.bdpt_strategies));
  plan.strategy_images = request.bdpt_strategies;
  plan.strategy_images_unweighted = request.bdpt_unweighted;
  plan.report_error = request.estimate_error;
  plan.denoise = request.denoise;
  plan.checkpoint = request.checkpoint;
  plan.resume = request.resume;
}

}  // namespace

RenderPlan plan_render(const RenderRequest& request, SceneDesc& scene) {
  check_request_values(request);
  RenderPlan plan;
  // Auto's budget without a time limit or target: the spp asked for, before auto's cap replaces it.
  plan.budget_spp = request.spp.value_or(scene.settings.spp);
  apply_options(request, scene);
  check_settings(request, scene);
  plan.integrator = &resolve_integrator(request, scene);
  plan_pixels(request, scene, plan);
  // Everything asked of the integrator, checked in one place.
  check_capabilities(*plan.integrator, {.continues_film = !request.checkpoint.empty() || !request.resume.empty(),
                                        .one_pixel = plan.one_pixel(),
                                        .part = !request.part.empty(),
                                        .strategy_images = !request.bdpt_strategies.empty(),
                                        .adaptive = scene.settings.adaptive(),
                                        .media = !scene.media.empty(),
                                        .target_error = request.target_error.has_value(),
                                        .denoise = request.denoise});
  plan_outputs(request, plan);
  plan.time_limit_seconds = request.time_limit.empty() ? 0 : parse_duration("--time-limit", request.time_limit);
  plan.target_error = request.target_error.value_or(0.0);
  plan.threads = request.threads.value_or(0);
  plan.clamp = request.clamp.value_or(0.0f);
  plan.quiet = request.quiet;
  return plan;
}

std::pair<int, int> parse_part(const std::string& text) {
  std::smatch m;
  static const std::regex pattern(R"((\d{1,6})/(\d{1,6}))");
  if (!std::regex_match(text, m, pattern) || std::stoi(m[1]) < 1 || std::stoi(m[1]) > std::stoi(m[2]))
    throw UsageError(fmt::format("--part: expected K/N with 1 <= K <= N, such as 2/8, got '{}'", text));
  return {std::stoi(m[1]) - 1, std::stoi(m[2])};
}

RenderOptions RenderPlan::options() const {
  RenderOptions options;
  options.threads = threads;
  options.progress = !quiet;
  options.time_limit_seconds = time_limit_seconds;
  options.target_error = target_error;
  options.clamp = clamp;
  options.part_index = part_index;
  options.part_count = part_count;
  if (one_pixel()) {
    options.only_x = pixel_x;
    options.only_y = pixel_y;
    options.max_reported_non_finite = 1000;
  }
  return options;
}

std::unique_ptr<IntegratorOutputs> RenderPlan::make_integrator_outputs(const RenderSettings& settings, int width,
                                                                       int height) const {
  if (strategy_images.empty() || !integrator->make_strategy_images) return nullptr;
  return integrator->make_strategy_images(settings, width, height, strategy_images, strategy_images_unweighted);
}

RenderFingerprint render_fingerprint(const std::string& scene_bytes, const SceneDesc& desc,
                                     const RenderRequest& request) {
  RenderFingerprint fp;
  fp.scene_hash = fnv1a64(scene_bytes.data(), scene_bytes.size());
  for (const RenderOption& option : render_options())
    if (option.fingerprint)
      if (std::optional<std::string> value = option.fingerprint(desc, request))
        fp.settings.emplace_back(option.fingerprint_key, std::move(*value));
  return fp;
}


RenderOutcome render_requested(const Scene& scene, RenderSettings& settings, Film& film, const RenderPlan& plan,
                               RenderOptions options, const std::function<void(const std::string&)>& announce) {
  RenderOutcome outcome;
  const IntegratorEntry* integrator = plan.integrator;
  // One that chooses (auto): pilots of each candidate measure which reaches the lowest error in the budget.
  if (integrator->chooses) {
    outcome.choice = integrator->choose(scene, settings, film, options, plan.budget_spp);
    integrator = outcome.choice->integrator;
    settings.integrator = std::string(integrator->name);
    if (announce) announce(outcome.choice->summary());
    // The rest of the budget; a cancelled pilot leaves none.
    if (outcome.choice->budget_seconds > 0)
      options.time_limit_seconds = std::max(outcome.choice->budget_seconds - outcome.choice->pilot_seconds, 1e-3);
  }
  outcome.stats = render_with(*integrator, scene, settings, film, options);
  if (outcome.choice) outcome.stats.seconds += outcome.choice->pilot_seconds;
  // How good the image is, from its own two halves (film/error_estimate.h).
  outcome.error = estimate_error(film, outcome.stats.splat_scale_relative_error);
  return outcome;
}

SampleCountText describe_samples(const RenderSettings& settings, const Film& film, const RenderOutcome& outcome) {
  const double pixels = double(film.width()) * film.height();
  const uint64_t min_spp = film.min_samples(), max_spp = film.max_samples();
  const double mean_spp = double(film.total_samples()) / pixels;
  const bool stopped = outcome.stats.cancelled || outcome.stats.time_limited;
  if (find_integrator(settings.integrator)->samples_are_mutations)
    return {fmt::format("{:.2f} mutations per pixel", double(outcome.stats.samples) / pixels), ""};
  if (find_integrator(settings.integrator)->progressive) return {fmt::format("{} iterations", min_spp), ""};
  if (settings.adaptive() && !stopped) return {fmt::format("adaptive, {:.2f} spp on average", mean_spp), ""};
  if (min_spp == max_spp) return {std::to_string(min_spp)};
  return {fmt::format("min {}, mean {:.2f}", min_spp, mean_spp)};
}

std::map<std::string, std::string> image_metadata(const std::string& scene_name, const RenderSettings& settings,
                                                  const Film& film, const RenderOutcome& outcome,
                                                  const RenderOptions& options, int ranks,
                                                  uint64_t non_finite_samples) {
  const RenderStats& stats = outcome.stats;
  const double mean_spp = double(film.total_samples()) / (double(film.width()) * film.height());
  std::map<std::string, std::string> metadata = {
      {"candela:scene", scene_name},
      {"candela:spp", describe_samples(settings, film, outcome).text},
      {"candela:spp_min", std::to_string(film.min_samples())},
      {"candela:spp_mean", fmt::format("{:.4f}", mean_spp)},
      {"candela:render_time_seconds", fmt::format("{:.3f}", stats.seconds)},
      {"candela:integrator", settings.integrator},
      {"candela:transport", settings.spectral ? "spectral" : "rgb"},
      {"candela:max_depth", std::to_string(settings.max_depth)},
      {"candela:seed", std::to_string(settings.seed)},
      {"candela:ranks", std::to_string(ranks)},
      {"Software", "candela " CANDELA_VERSION}};
  if (stats.cancelled) metadata["candela:interrupted"] = "true";
  if (stats.time_limited) metadata["candela:time-limited"] = "true";
  if (outcome.error.valid) {
    metadata["candela:relmse_estimate"] = fmt::format("{:.6g}", outcome.error.relmse);
    metadata["candela:relmse_interval95"] = fmt::format("{:.6g} {:.6g}", outcome.error.low, outcome.error.high);
  }
  if (options.target_error > 0) {
    metadata["candela:target_error"] = fmt::format("{}", options.target_error);
    metadata["candela:target_reached"] = stats.reached_target ? "true" : "false";
  }
  if (options.clamp > 0) metadata["candela:clamp"] = fmt::format("{}", options.clamp);
  if (non_finite_samples > 0) metadata["candela:non_finite_samples"] = std::to_string(non_finite_samples);
  if (find_integrator(settings.integrator)->reads_setting("mlt")) metadata["candela:mlt"] = settings.mlt.describe();
  if (find_integrator(settings.integrator)->reads_setting("sppm")) metadata["candela:sppm"] = settings.sppm.describe();
  if (find_integrator(settings.integrator)->reads_setting("equiangular"))
    metadata["candela:equiangular"] = settings.volpath.equiangular ? "on" : "off";
  if (outcome.choice) metadata["candela:auto"] = outcome.choice->summary();
  return metadata;
}

}  // namespace candela
