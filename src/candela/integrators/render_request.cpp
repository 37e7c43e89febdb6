#include "candela/integrators/render_request.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <regex>
#include <tuple>

#include "candela/integrators/integrator.h"

namespace candela {
namespace {

template <typename Enum>
Enum parse_choice(const std::string& option, const std::string& value,
                  std::initializer_list<std::pair<const char*, Enum>> choices) {
  std::string names;
  for (const auto& [name, e] : choices) {
    if (value == name) return e;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  throw UsageError(fmt::format("{}: unknown value '{}' (expected one of: {})", option, value, names));
}

// lo <= value <= hi (NaN is outside every range).
template <typename T>
void check_range(const char* option, const std::optional<T>& value, double lo, double hi) {
  if (value && !(double(*value) >= lo && double(*value) <= hi))
    throw UsageError(fmt::format("{}: {} is out of range ({} to {})", option, *value, lo, hi));
}
template <typename T>
void check_positive(const char* option, const std::optional<T>& value) {
  if (value && !(std::isfinite(double(*value)) && *value > 0))
    throw UsageError(fmt::format("{}: must be a positive number, got {}", option, *value));
}

// `shown` is the size as the user gave it (WIDTHxHEIGHT), for the message.
void check_resolution_range(long long width, long long height, const std::string& shown) {
  if (width < 1 || height < 1 || width > kMaxResolution || height > kMaxResolution || width * height > kMaxPixels)
    throw UsageError(fmt::format("resolution {} is out of range (each side 1..{}, at most {} pixels)", shown,
                                 kMaxResolution, kMaxPixels));
}

// --resolution WIDTHxHEIGHT, in range. Sides of any number of digits are read (saturating), so that
// 1000000000x1000000000 is out of range, not malformed.
std::pair<int, int> parse_resolution(const std::string& text) {
  std::smatch m;
  static const std::regex pattern(R"((\d+)[xX](\d+))");
  if (!std::regex_match(text, m, pattern))
    throw UsageError(fmt::format("--resolution: expected WIDTHxHEIGHT such as 640x480, got '{}'", text));
  const auto side = [](const std::string& digits) {
    long long value = 0;
    if (std::from_chars(digits.data(), digits.data() + digits.size(), value).ec != std::errc())
      value = std::numeric_limits<long long>::max();
    return value;
  };
  const long long width = side(m[1]), height = side(m[2]);
  check_resolution_range(width, height, text);
  return {int(width), int(height)};
}

}  // namespace

void check_request_values(const RenderRequest& r) {
  check_range("--spp", r.spp, 1, 1 << 24);
  check_range("--threads", r.threads, 1, 4096);
  check_range("--max-depth", r.max_depth, 1, 100000);
  check_range("--mlt-bootstrap", r.mlt_bootstrap, 1, 100000000);
  check_range("--mlt-chains", r.mlt_chains, 1, 100000000);
  check_range("--mlt-sigma", r.mlt_sigma, 1e-6, 1);
  check_range("--mlt-large-step", r.mlt_large_step, 0, 1);
  check_range("--mlt-lens", r.mlt_lens, 0, 1);
  check_range("--mlt-caustic", r.mlt_caustic, 0, 1);
  check_range("--shadow-rays", r.shadow_rays, 1, 1024);
  check_positive("--adaptive-threshold", r.adaptive_threshold);
  check_range("--adaptive-spp", r.adaptive_spp, 1, 1 << 24);
  check_range("--adaptive-batch", r.adaptive_batch, 1, 1 << 16);
  check_range("--max-spp", r.max_spp, 1, 1 << 24);
  check_positive("--target-error", r.target_error);
  check_positive("--clamp", r.clamp);
  if (!r.time_limit.empty()) parse_duration("--time-limit", r.time_limit);
  if (!r.resolution.empty()) parse_resolution(r.resolution);
}

namespace {

// The chosen integrator must read every selective setting the request gives
// (integrators/integrator.h); what the scene file sets for another integrator gets a note.
void check_integrator_flags(const RenderRequest& request, const SceneDesc& scene) {
  if (scene.settings.integrator == "auto") {
    // Every candidate must read what the scene and the flags set.
    if (auto_candidates(scene.settings, !scene.media.empty()).empty())
      throw UsageError("--integrator auto: no integrator reads every setting given (see --help for who reads what)");
    if (!request.bdpt_strategies.empty()) throw UsageError("--bdpt-strategies needs --integrator bdpt, not auto");
    return;
  }
  const IntegratorEntry* integrator = find_integrator(scene.settings.integrator);
  if (!integrator)
    throw UsageError(fmt::format("unknown integrator '{}' (known: {}, auto)", scene.settings.integrator, integrator_names()));
  struct SelectiveFlag {
    const char* flag;
    std::string_view key;
    bool given;
  };
  const SelectiveFlag flags[] = {
      {"--direction-sampling", "direction_sampling", !request.direction_sampling.empty()},
      {"--no-mis", "mis", request.no_mis},
      {"--shadow-rays", "shadow_rays", request.shadow_rays.has_value()},
      {"--light-selection paper", "light_selection=paper", request.light_selection == "paper"},
      {"--adaptive-threshold", "adaptive", request.adaptive_threshold.has_value()},
      {"--adaptive-spp", "adaptive", request.adaptive_spp.has_value()},
      {"--adaptive-batch", "adaptive", request.adaptive_batch.has_value()},
      {"--max-spp", "adaptive", request.max_spp.has_value()},
      {"--mlt-bootstrap", "mlt", request.mlt_bootstrap.has_value()},
      {"--mlt-chains", "mlt", request.mlt_chains.has_value()},
      {"--mlt-sigma", "mlt", request.mlt_sigma.has_value()},
      {"--mlt-large-step", "mlt", request.mlt_large_step.has_value()},
      {"--mlt-lens", "mlt", request.mlt_lens.has_value()},
      {"--mlt-caustic", "mlt", request.mlt_caustic.has_value()},
  };
  for (const SelectiveFlag& f : flags)
    if (f.given && !integrator->reads_setting(f.key))
      throw UsageError(fmt::format("{}: {}", f.flag, unread_setting_message(*integrator, f.key)));
  if (!request.bdpt_strategies.empty() && !integrator->strategy_images)
    throw UsageError(fmt::format("--bdpt-strategies: the {} integrator writes no strategy images (bdpt does)",
                                 integrator->name));
  if (!request.integrator.empty() && !request.quiet)
    for (std::string_view key : set_but_unread(*integrator, scene.settings))
      fmt::print(stderr, "note: the scene sets {}, which --integrator {} does not read\n", key, integrator->name);
}

}  // namespace

void apply_request(const RenderRequest& request, SceneDesc& scene) {
  check_request_values(request);
  if (request.spp) scene.settings.spp = *request.spp;
  if (request.max_depth) scene.settings.max_depth = *request.max_depth;
  if (request.seed) scene.settings.seed = *request.seed;
  if (!request.integrator.empty()) scene.settings.integrator = request.integrator;
  RenderSettings& rs = scene.settings;
  if (!request.sampler.empty())
    rs.sampler.type = parse_choice<SamplerType>("--sampler", request.sampler,
                                                {{"random", SamplerType::Independent},
                                                 {"independent", SamplerType::Independent},
                                                 {"stratified", SamplerType::Stratified},
                                                 {"poisson", SamplerType::Poisson},
                                                 {"zsobol", SamplerType::ZSobol}});
  if (!request.filter.empty())
    rs.filter = default_filter(parse_choice<FilterType>(
        "--filter", request.filter,
        {{"box", FilterType::Box}, {"tent", FilterType::Tent}, {"gaussian", FilterType::Gaussian},
         {"mitchell", FilterType::Mitchell}}));
  if (!request.direction_sampling.empty())
    rs.path.direction_sampling = parse_choice<DirectionSampling>(
        "--direction-sampling", request.direction_sampling,
        {{"bsdf", DirectionSampling::Bsdf}, {"cosine", DirectionSampling::Cosine},
         {"uniform", DirectionSampling::Uniform}});
  if (!request.bvh.empty())
    rs.bvh = parse_choice<BvhLayout>("--bvh", request.bvh, {{"fast", BvhLayout::Fast}, {"compact", BvhLayout::Compact}});
  if (!request.light_selection.empty())
    rs.light_selection = parse_choice<LightSelection>("--light-selection", request.light_selection,
                                                      {{"power", LightSelection::Power},
                                                       {"paper", LightSelection::Paper},
                                                       {"uniform", LightSelection::Uniform},
                                                       {"bvh", LightSelection::Bvh}});
  if (request.no_mis) rs.path.mis = false;
  // An error estimate needs two independent halves of every pixel's samples; with a target the
  // spp is the most a pixel may get (--spp, or 65536).
  if (request.estimate_error || request.target_error || rs.integrator == "auto") rs.sampler.replicas = true;
  // --integrator auto: the pilots and the winner share one sampler setup (spp sets its sets), so the
  // winner can continue its pilot; the scene's or the given spp is then the budget, not the count.
  if (rs.integrator == "auto" && !request.target_error) rs.spp = kTargetErrorMaxSpp;
  if (request.target_error) rs.spp = request.spp.value_or(kTargetErrorMaxSpp);
  if (!request.transport.empty())
    rs.spectral = parse_choice<bool>("--transport", request.transport, {{"rgb", false}, {"spectral", true}});
  if (request.mlt_bootstrap) rs.mlt.bootstrap = *request.mlt_bootstrap;
  if (request.mlt_chains) rs.mlt.chains = *request.mlt_chains;
  if (request.mlt_sigma) rs.mlt.sigma = *request.mlt_sigma;
  if (request.mlt_large_step) rs.mlt.large_step = *request.mlt_large_step;
  if (request.mlt_lens) rs.mlt.lens = *request.mlt_lens;
  if (request.mlt_caustic) rs.mlt.caustic = *request.mlt_caustic;
  if (std::string problem = rs.mlt.problem(); !problem.empty())
    throw UsageError("--mlt-large-step, --mlt-lens, --mlt-caustic: " + problem);
  if (request.shadow_rays) rs.path.shadow_rays = *request.shadow_rays;
  if (request.adaptive_threshold) rs.adaptive_threshold = *request.adaptive_threshold;
  if (request.adaptive_spp) rs.adaptive_spp = *request.adaptive_spp;
  if (request.adaptive_batch) rs.adaptive_batch = *request.adaptive_batch;
  if (request.max_spp) rs.adaptive_max_spp = *request.max_spp;
  if (rs.adaptive() && (rs.adaptive_batch & (rs.adaptive_batch - 1)) != 0)
    throw UsageError(fmt::format("--adaptive-batch: must be a power of two, got {}", rs.adaptive_batch));
  if (rs.adaptive_spp > 0 && rs.adaptive_spp < rs.adaptive_batch)
    throw UsageError(fmt::format("--adaptive-spp ({}) must be at least the batch size ({})", rs.adaptive_spp,
                                 rs.adaptive_batch));
  if (rs.adaptive_spp > 0 && rs.adaptive_max_spp > 0 && rs.adaptive_max_spp < rs.adaptive_spp)
    throw UsageError(fmt::format("--max-spp ({}) must be at least --adaptive-spp ({})", rs.adaptive_max_spp,
                                 rs.adaptive_spp));
  if (!request.resolution.empty())
    std::tie(scene.film.width, scene.film.height) = parse_resolution(request.resolution);
  const auto& f = scene.film;
  check_resolution_range(f.width, f.height, fmt::format("{}x{}", f.width, f.height));
  if (request.target_error && rs.adaptive())
    throw UsageError("--target-error: adaptive sampling (--adaptive-threshold, --adaptive-spp) has its own stopping "
                     "rule; use one or the other");
  check_integrator_flags(request, scene);
  if (request.bdpt_unweighted && request.bdpt_strategies.empty())
    throw UsageError("--bdpt-unweighted needs --bdpt-strategies DIR");
}

double parse_duration(const std::string& option, const std::string& text) {
  static const std::regex plain(R"(\d{1,9}(\.\d{0,9})?)");
  static const std::regex parts(R"((\d{1,9}(?:\.\d{0,9})?h)?(\d{1,9}(?:\.\d{0,9})?m)?(\d{1,9}(?:\.\d{0,9})?s)?)");
  double seconds = 0;
  std::smatch m;
  if (std::regex_match(text, plain)) {
    seconds = std::stod(text);
  } else if (!text.empty() && std::regex_match(text, m, parts)) {
    const double unit[] = {3600, 60, 1};
    for (int i = 0; i < 3; ++i)
      if (m[i + 1].matched) seconds += std::stod(m[i + 1].str()) * unit[i];
  } else {
    throw UsageError(fmt::format("{}: expected seconds or a duration such as 90s, 10m, 2h or 1h30m, got '{}'", option, text));
  }
  if (!(seconds > 0)) throw UsageError(fmt::format("{}: must be more than 0, got '{}'", option, text));
  return seconds;
}

RenderOptions request_options(const RenderRequest& request) {
  RenderOptions options;
  options.threads = request.threads.value_or(0);
  options.progress = !request.quiet;
  options.time_limit_seconds = request.time_limit.empty() ? 0 : parse_duration("--time-limit", request.time_limit);
  options.target_error = request.target_error.value_or(0.0);
  options.clamp = request.clamp.value_or(0.0f);
  return options;
}

RenderOutcome render_requested(const Scene& scene, RenderSettings& settings, Film& film, RenderOptions options,
                               int budget_spp, const std::function<void(const std::string&)>& announce) {
  RenderOutcome outcome;
  // --integrator auto: pilots of each integrator measure which reaches the lowest error in the budget.
  if (settings.integrator == "auto") {
    outcome.choice = choose_integrator(scene, settings, film, options, budget_spp);
    settings.integrator = std::string(outcome.choice->integrator->name);
    if (announce) announce(outcome.choice->summary());
    // The rest of the budget; a cancelled pilot leaves none.
    if (outcome.choice->budget_seconds > 0)
      options.time_limit_seconds = std::max(outcome.choice->budget_seconds - outcome.choice->pilot_seconds, 1e-3);
  }
  outcome.stats = render(scene, settings, film, options);
  if (outcome.choice) outcome.stats.seconds += outcome.choice->pilot_seconds;
  // How good the image is, from its own two halves (film/error_estimate.h).
  outcome.error = estimate_error(film, outcome.stats.mlt_normalization_relative_error);
  return outcome;
}

SampleCountText describe_samples(const RenderSettings& settings, const Film& film, const RenderOutcome& outcome) {
  const double pixels = double(film.width()) * film.height();
  const uint64_t min_spp = film.min_samples(), max_spp = film.max_samples();
  const double mean_spp = double(film.total_samples()) / pixels;
  const bool stopped = outcome.stats.cancelled || outcome.stats.time_limited;
  if (find_integrator(settings.integrator)->samples_are_mutations)
    return {fmt::format("{:.2f} mutations per pixel", double(outcome.stats.samples) / pixels), ""};
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
  if (outcome.choice) metadata["candela:auto"] = outcome.choice->summary();
  return metadata;
}

}  // namespace candela
