#include "candela/integrators/render_option_table.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <tuple>

#include "candela/integrators/integrator.h"

namespace candela {
namespace {

constexpr double kIntMax = std::numeric_limits<int>::max();

// The names of a closed set (base/enum_names.h), `aliases` first.
template <typename E>
ChoiceValue choices_of(std::vector<std::string> aliases = {}) {
  for (E e : enumerators<E>()) aliases.emplace_back(enum_name(e));
  return {aliases};
}

std::string integrator_help() {
  std::string help = "Integrator:";
  for (const IntegratorTraits& traits : integrator_traits())
    help += fmt::format(" {} ({}){}", traits.name, traits.description, &traits == &integrator_traits().back() ? "" : ";");
  return help;
}

// One entry per option, in --help's order. `apply` and `fingerprint` are captureless lambdas.
std::vector<RenderOption> make_table() {
  using R = RenderRequest;
  using S = const SceneDesc&;
  using Q = const RenderRequest&;
  return {
      {.name = "spp", .field = &R::spp, .rule = ValueRange{1, 1 << 24},
       .help = "Samples per pixel (overrides the scene)", .scene_key = "spp",
       .apply = [](Q r, SceneDesc& d) { d.settings.spp = *r.spp; },
       .fingerprint_key = "spp",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.spp); }},
      {.name = "threads", .field = &R::threads, .rule = ValueRange{1, 4096},
       .help = "Worker threads (default: all cores)"},
      {.name = "seed", .field = &R::seed, .rule = AnyValue{}, .help = "Random seed (overrides the scene)",
       .scene_key = "seed", .apply = [](Q r, SceneDesc& d) { d.settings.seed = *r.seed; },
       .fingerprint_key = "seed",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.seed); }},
      {.name = "max_depth", .field = &R::max_depth, .rule = ValueRange{1, 100000},
       .help = "Maximum number of bounces; 1 = direct light only", .scene_key = "max_depth",
       .apply = [](Q r, SceneDesc& d) { d.settings.max_depth = *r.max_depth; },
       .fingerprint_key = "max-depth",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.max_depth); }},
      {.name = "resolution", .field = &R::resolution,
       .rule = FormattedValue{[](const std::string&, const std::string& text) { parse_resolution(text); }},
       .help = "Image size WIDTHxHEIGHT (overrides the scene)", .scene_key = "camera.width, camera.height",
       .apply = [](Q r, SceneDesc& d) { std::tie(d.film.width, d.film.height) = parse_resolution(r.resolution); },
       .fingerprint_key = "resolution",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         return fmt::format("{}x{}", d.film.width, d.film.height);
       }},
      // Checked against the registry once the scene is read (its own integrator may be unknown too;
      // plan_render).
      {.name = "integrator", .field = &R::integrator, .rule = AnyValue{}, .help = integrator_help(),
       .scene_key = "integrator", .apply = [](Q r, SceneDesc& d) { d.settings.integrator = r.integrator; },
       .fingerprint_key = "integrator",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return d.settings.integrator; }},
      {.name = "rr_start_depth", .field = &R::rr_start_depth, .rule = ValueRange{0, kIntMax},
       .help = "Bounces before Russian roulette may end a path (default 3; overrides the scene)",
       .reads = "rr_start_depth", .scene_key = "rr_start_depth",
       .apply = [](Q r, SceneDesc& d) { d.settings.rr_start_depth = *r.rr_start_depth; },
       .fingerprint_key = "rr-start-depth",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.rr_start_depth); }},
      {.name = "bdpt_strategies", .field = &R::bdpt_strategies, .rule = AnyValue{},
       .help = "bdpt: also write each strategy's contribution (depth <= 5) to DIR/bdpt_d<depth>_s<s>_t<t>.exr",
       .python = false},
      {.name = "bdpt_unweighted", .field = &R::bdpt_unweighted, .rule = AnyValue{},
       .help = "bdpt: the strategy images without their MIS weights (each then estimates the whole image of its "
               "depth on its own)",
       .python = false},
      {.name = "mlt_bootstrap", .field = &R::mlt_bootstrap, .rule = ValueRange{1, 100000000},
       .help = "mlt: bootstrap paths per depth (default 100000)", .reads = "mlt", .scene_key = "mlt.bootstrap",
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.bootstrap = *r.mlt_bootstrap; },
       // The MLT parameters go into the fingerprint as one entry, where an MLT render may happen.
       .fingerprint_key = "mlt",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         if (!may_read_setting(*find_integrator_traits(d.settings.integrator), "mlt")) return std::nullopt;
         return d.settings.mlt.describe();
       }},
      {.name = "mlt_chains", .field = &R::mlt_chains, .rule = ValueRange{1, 100000000},
       .help = "mlt: independent Markov chains (default 1000)", .reads = "mlt", .scene_key = "mlt.chains",
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.chains = *r.mlt_chains; }},
      {.name = "mlt_sigma", .field = &R::mlt_sigma, .rule = ValueRange{1e-6, 1},
       .help = "mlt: deviation of small steps in primary sample space (default 0.01)", .reads = "mlt",
       .scene_key = "mlt.sigma", .apply = [](Q r, SceneDesc& d) { d.settings.mlt.sigma = *r.mlt_sigma; }},
      {.name = "mlt_large_step", .field = &R::mlt_large_step, .rule = ValueRange{0, 1},
       .help = "mlt: probability of a large step (default 0.3)", .reads = "mlt", .scene_key = "mlt.large_step",
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.large_step = *r.mlt_large_step; }},
      {.name = "mlt_lens", .field = &R::mlt_lens, .rule = ValueRange{0, 1},
       .help = "mlt: probability of a lens perturbation (only the film position moves; default 0)",
       .reads = "mlt", .scene_key = "mlt.lens",
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.lens = *r.mlt_lens; }},
      {.name = "mlt_caustic", .field = &R::mlt_caustic, .rule = ValueRange{0, 1},
       .help = "mlt: probability of a caustic perturbation (only the direction leaving the light moves; default 0)",
       .reads = "mlt", .scene_key = "mlt.caustic",
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.caustic = *r.mlt_caustic; }},
      {.name = "sampler", .field = &R::sampler, .rule = choices_of<SamplerType>({"random"}),
       .help = "Pixel sampler: random (independent), stratified (jittered, every dimension), poisson "
               "(Poisson-disc pixel positions), zsobol (Owen-scrambled Sobol' in Morton order)",
       .scene_key = "sampler.type",
       .apply = [](Q r, SceneDesc& d) {
         d.settings.sampler.type = r.sampler == "random" ? SamplerType::Independent
                                                         : *enum_from_name<SamplerType>(r.sampler);
       },
       .fingerprint_key = "sampler",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         const SamplerDesc& s = d.settings.sampler;
         return fmt::format("{}{}{}", enum_name(s.type), s.jitter ? "" : " (no jitter)",
                            s.replicas ? " (two independent halves)" : "");
       }},
      {.name = "filter", .field = &R::filter, .rule = choices_of<FilterType>(),
       .help = "Reconstruction filter with pbrt-v4's default size: box (radius 0.5), tent (2), gaussian (1.5, "
               "sigma 0.5), mitchell (2, B = C = 1/3)",
       .scene_key = "filter.type",
       .apply = [](Q r, SceneDesc& d) { d.settings.filter = default_filter(*enum_from_name<FilterType>(r.filter)); },
       .fingerprint_key = "filter",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         const FilterDesc& f = d.settings.filter;
         return fmt::format("{} radius {},{} sigma {} b {} c {}", int(f.type), f.radius.x, f.radius.y,
                            f.gaussian_sigma, f.mitchell_b, f.mitchell_c);
       }},
      {.name = "direction_sampling", .field = &R::direction_sampling, .rule = choices_of<DirectionSampling>(),
       .help = "Next-direction sampling at non-delta surfaces: bsdf (importance), cosine, uniform (the paper's "
               "eq. 11)",
       .reads = "direction_sampling", .scene_key = "direction_sampling",
       .apply = [](Q r, SceneDesc& d) {
         d.settings.path.direction_sampling = *enum_from_name<DirectionSampling>(r.direction_sampling);
       },
       .fingerprint_key = "direction-sampling",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         return std::to_string(int(d.settings.path.direction_sampling));
       }},
      {.name = "transport", .field = &R::transport, .rule = ChoiceValue{{"rgb", "spectral"}},
       .help = "Light transport: rgb (three colour channels) or spectral (four sampled wavelengths per path, RGB "
               "parameters as smooth spectra, as pbrt-v4); default: the scene's (spectral for pbrt-v4 files, rgb "
               "otherwise)",
       .scene_key = "spectral", .apply = [](Q r, SceneDesc& d) { d.settings.spectral = r.transport == "spectral"; },
       .fingerprint_key = "transport",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return d.settings.spectral ? "spectral" : "rgb"; }},
      {.name = "no_mis", .field = &R::no_mis, .rule = AnyValue{},
       .help = "Turn off multiple importance sampling: direct light from shadow rays only", .reads = "mis",
       .scene_key = "mis", .apply = [](Q, SceneDesc& d) { d.settings.path.mis = false; },
       .fingerprint_key = "mis",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return d.settings.path.mis ? "on" : "off"; }},
      {.name = "light_selection", .field = &R::light_selection, .rule = choices_of<LightSelection>(),
       .help = "How shadow rays pick lights: power (each ray one light, chosen by power), uniform (each ray one "
               "emitter, all equally likely, as Mitsuba), bvh (each ray one light, chosen through a light BVH by "
               "power, distance and orientation: for many lights; pbrt-v4's default), paper (every light a share "
               "proportional to power x projected solid angle, O(lights) per vertex)",
       .reads = "light_selection=paper", .reads_when = "paper", .scene_key = "light_selection",
       .apply = [](Q r, SceneDesc& d) {
         d.settings.light_selection = *enum_from_name<LightSelection>(r.light_selection);
       },
       .fingerprint_key = "light-selection",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         return std::to_string(int(d.settings.light_selection));
       }},
      {.name = "bvh", .field = &R::bvh, .rule = choices_of<BvhLayout>(),
       .help = "Acceleration structure: fast (the default) or compact (about half the memory per triangle, "
               "traversal about a third slower)",
       .scene_key = "bvh", .apply = [](Q r, SceneDesc& d) { d.settings.bvh = *enum_from_name<BvhLayout>(r.bvh); }},
      {.name = "shadow_rays", .field = &R::shadow_rays, .rule = ValueRange{1, 1024},
       .help = "Shadow rays per path vertex", .reads = "shadow_rays", .scene_key = "shadow_rays",
       .apply = [](Q r, SceneDesc& d) { d.settings.path.shadow_rays = *r.shadow_rays; },
       .fingerprint_key = "shadow-rays",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.path.shadow_rays); }},
      {.name = "adaptive_threshold", .field = &R::adaptive_threshold, .rule = PositiveValue{},
       .help = "Adaptive sampling: keep adding batches to pixels whose relative standard error (per channel, "
               "se / sqrt(mean^2 + 0.01)) exceeds this",
       .reads = "adaptive", .scene_key = "adaptive.threshold",
       .apply = [](Q r, SceneDesc& d) { d.settings.adaptive_threshold = *r.adaptive_threshold; },
       .fingerprint_key = "adaptive-threshold",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         return fmt::format("{}", d.settings.adaptive_threshold);
       }},
      {.name = "adaptive_spp", .field = &R::adaptive_spp, .rule = ValueRange{1, 1 << 24},
       .help = "Adaptive sampling with a budget: this many samples per pixel on average, each pixel getting a "
               "share proportional to its estimated relative error (lowest relMSE)",
       .reads = "adaptive", .scene_key = "adaptive.spp",
       .apply = [](Q r, SceneDesc& d) { d.settings.adaptive_spp = *r.adaptive_spp; },
       .fingerprint_key = "adaptive-spp",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.adaptive_spp); }},
      {.name = "adaptive_batch", .field = &R::adaptive_batch, .rule = ValueRange{1, 1 << 16},
       .help = "Adaptive sampling: samples per batch, a power of two (default 16)", .reads = "adaptive",
       .scene_key = "adaptive.batch",
       .apply = [](Q r, SceneDesc& d) { d.settings.adaptive_batch = *r.adaptive_batch; }},
      {.name = "max_spp", .field = &R::max_spp, .rule = ValueRange{1, 1 << 24},
       .help = "Adaptive sampling: most samples a pixel gets (default 1024, or 8 x --adaptive-spp)",
       .reads = "adaptive", .scene_key = "adaptive.max_spp",
       .apply = [](Q r, SceneDesc& d) { d.settings.adaptive_max_spp = *r.max_spp; }},
      {.name = "time_limit", .field = &R::time_limit,
       .rule = FormattedValue{[](const std::string& flag, const std::string& text) { parse_duration(flag, text); }},
       .help = "Stop after the pass during which this much time has passed, and write the image: seconds (90, "
               "2.5) or a duration such as 90s, 10m, 2h, 1h30m"},
      {.name = "target_error", .field = &R::target_error, .rule = PositiveValue{},
       .help = "Render until the image's estimated relMSE (eps 0.01, from two independent halves of the samples) "
               "is at most this, then stop; --spp (default 65536) and --time-limit cap it"},
      {.name = "estimate_error", .field = &R::estimate_error, .rule = AnyValue{},
       .help = "Render every pixel's samples as two independent halves and report the image's estimated relMSE "
               "with a 95% interval (always done with the random sampler and with --target-error)"},
      {.name = "clamp", .field = &R::clamp, .rule = PositiveValue{},
       .help = "Scale each sample so its largest RGB component is at most VALUE (biased; off by default)",
       .fingerprint_key = "clamp",
       .fingerprint = [](S, Q r) -> std::optional<std::string> {
         return r.clamp ? fmt::format("{}", *r.clamp) : "off";
       }},
  };
}

}  // namespace

std::string RenderOption::flag() const {
  std::string flag = "--" + name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

std::string RenderOption::flag_for_messages() const {
  return reads_when.empty() ? flag() : fmt::format("{} {}", flag(), reads_when);
}

bool RenderOption::given(const RenderRequest& request) const {
  return std::visit(
      [&](auto member) {
        const auto& value = request.*member;
        using T = std::remove_cvref_t<decltype(value)>;
        if constexpr (std::is_same_v<T, bool>) return value;
        else if constexpr (std::is_same_v<T, std::string>) return !value.empty();
        else return value.has_value();
      },
      field);
}

bool RenderOption::selective_in(const RenderRequest& request) const {
  if (reads.empty() || !given(request)) return false;
  if (reads_when.empty()) return true;
  const auto* text = std::get_if<std::string RenderRequest::*>(&field);
  return text && request.**text == reads_when;
}

const std::vector<RenderOption>& render_options() {
  static const std::vector<RenderOption> table = make_table();
  return table;
}

const RenderOption* find_render_option(std::string_view name) {
  for (const RenderOption& option : render_options())
    if (option.name == name) return &option;
  return nullptr;
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

}  // namespace candela
