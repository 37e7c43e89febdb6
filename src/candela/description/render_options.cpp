#include "candela/description/render_options.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <regex>
#include <tuple>

#include "candela/base/error.h"
#include "candela/description/integrator_traits.h"

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
       .extract = [](S d, R& r) { r.spp = d.settings.spp; },
       .apply = [](Q r, SceneDesc& d) { d.settings.spp = *r.spp; },
       .fingerprint_key = "spp",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.spp); }},
      {.name = "threads", .field = &R::threads, .rule = ValueRange{1, 4096},
       .help = "Worker threads (default: all cores)"},
      {.name = "seed", .field = &R::seed, .rule = AnyValue{}, .help = "Random seed (overrides the scene)",
       .scene_key = "seed", .extract = [](S d, R& r) { r.seed = d.settings.seed; },
       .apply = [](Q r, SceneDesc& d) { d.settings.seed = *r.seed; },
       .fingerprint_key = "seed",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.seed); }},
      {.name = "max_depth", .field = &R::max_depth, .rule = ValueRange{1, 100000},
       .help = "Maximum number of bounces; 1 = direct light only", .scene_key = "max_depth",
       .extract = [](S d, R& r) { r.max_depth = d.settings.max_depth; },
       .apply = [](Q r, SceneDesc& d) { d.settings.max_depth = *r.max_depth; },
       .fingerprint_key = "max-depth",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.max_depth); }},
      {.name = "resolution", .field = &R::resolution,
       .rule = FormattedValue{[](const std::string&, const std::string& text) { parse_resolution(text); }},
       .help = "Image size WIDTHxHEIGHT (overrides the scene's camera width and height)",
       .apply =
           [](Q r, SceneDesc& d) {
             std::tie(d.film.width, d.film.height) = parse_resolution(r.resolution);
             d.film.crop.reset();  // the crop's view at another size no longer lies in the full image
           },
       .fingerprint_key = "resolution",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         return fmt::format("{}x{}", d.film.width, d.film.height);
       }},
      // Checked against the registry once the scene is read (its own integrator may be unknown too;
      // plan_render).
      {.name = "integrator", .field = &R::integrator, .rule = AnyValue{}, .help = integrator_help(),
       .scene_key = "integrator", .extract = [](S d, R& r) { r.integrator = d.settings.integrator; },
       .apply = [](Q r, SceneDesc& d) { d.settings.integrator = r.integrator; },
       .fingerprint_key = "integrator",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return d.settings.integrator; }},
      {.name = "rr_start_depth", .field = &R::rr_start_depth, .rule = ValueRange{0, kIntMax},
       .help = "Bounces before Russian roulette may end a path (default 3; overrides the scene)",
       .reads = "rr_start_depth", .scene_key = "rr_start_depth",
       .extract = [](S d, R& r) { r.rr_start_depth = d.settings.rr_start_depth; },
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
       .help = "mlt: bootstrap paths per depth (default 100000)", .reads = "mlt", .scene_key = "mlt.bootstrap", .extract = [](S d, R& r) { r.mlt_bootstrap = d.settings.mlt.bootstrap; },
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.bootstrap = *r.mlt_bootstrap; },
       // The MLT parameters go into the fingerprint as one entry, where an MLT render may happen.
       .fingerprint_key = "mlt",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         if (!may_read_setting(*find_integrator_traits(d.settings.integrator), "mlt")) return std::nullopt;
         return d.settings.mlt.describe();
       }},
      {.name = "mlt_chains", .field = &R::mlt_chains, .rule = ValueRange{1, 100000000},
       .help = "mlt: independent Markov chains (default 1000)", .reads = "mlt", .scene_key = "mlt.chains", .extract = [](S d, R& r) { r.mlt_chains = d.settings.mlt.chains; },
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.chains = *r.mlt_chains; }},
      {.name = "mlt_sigma", .field = &R::mlt_sigma, .rule = ValueRange{1e-6, 1},
       .help = "mlt: deviation of small steps in primary sample space (default 0.01)", .reads = "mlt",
       .scene_key = "mlt.sigma", .extract = [](S d, R& r) { r.mlt_sigma = d.settings.mlt.sigma; }, .apply = [](Q r, SceneDesc& d) { d.settings.mlt.sigma = *r.mlt_sigma; }},
      {.name = "mlt_large_step", .field = &R::mlt_large_step, .rule = ValueRange{0, 1},
       .help = "mlt: probability of a large step (default 0.3)", .reads = "mlt", .scene_key = "mlt.large_step", .extract = [](S d, R& r) { r.mlt_large_step = d.settings.mlt.large_step; },
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.large_step = *r.mlt_large_step; }},
      {.name = "mlt_lens", .field = &R::mlt_lens, .rule = ValueRange{0, 1},
       .help = "mlt: probability of a lens perturbation (only the film position moves; default 0)",
       .reads = "mlt", .scene_key = "mlt.lens", .extract = [](S d, R& r) { r.mlt_lens = d.settings.mlt.lens; },
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.lens = *r.mlt_lens; }},
      {.name = "mlt_caustic", .field = &R::mlt_caustic, .rule = ValueRange{0, 1},
       .help = "mlt: probability of a caustic perturbation (only the direction leaving the light moves; default 0)",
       .reads = "mlt", .scene_key = "mlt.caustic", .extract = [](S d, R& r) { r.mlt_caustic = d.settings.mlt.caustic; },
       .apply = [](Q r, SceneDesc& d) { d.settings.mlt.caustic = *r.mlt_caustic; }},
      {.name = "ao_max_distance", .field = &R::ao_max_distance, .rule = PositiveValue{},
       .help = "ambient_occlusion: occluders farther than this along an occlusion ray do not count (default: "
               "every occluder counts)",
       .reads = "ambient_occlusion", .scene_key = "ambient_occlusion.max_distance",
       .extract = [](S d, R& r) {
         if (std::isfinite(d.settings.ambient_occlusion.max_distance))
           r.ao_max_distance = d.settings.ambient_occlusion.max_distance;
       },
       .apply = [](Q r, SceneDesc& d) { d.settings.ambient_occlusion.max_distance = *r.ao_max_distance; },
       // Ambient occlusion's parameters go into the fingerprint as one entry, where it may render.
       .fingerprint_key = "ambient-occlusion",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         if (!may_read_setting(*find_integrator_traits(d.settings.integrator), "ambient_occlusion"))
           return std::nullopt;
         return d.settings.ambient_occlusion.describe();
       }},
      {.name = "ao_sampling", .field = &R::ao_sampling, .rule = ChoiceValue{{"cosine", "uniform"}},
       .help = "ambient_occlusion: occlusion rays cosine-weighted over the hemisphere (the default) or uniform "
               "(the same image, noisier)",
       .reads = "ambient_occlusion", .scene_key = "ambient_occlusion.sampling",
       .extract = [](S d, R& r) { r.ao_sampling = d.settings.ambient_occlusion.cosine_sampling ? "cosine" : "uniform"; },
       .apply = [](Q r, SceneDesc& d) { d.settings.ambient_occlusion.cosine_sampling = r.ao_sampling == "cosine"; }},
      {.name = "sppm_photons", .field = &R::sppm_photons, .rule = ValueRange{1, kIntMax},
       .help = "sppm: photons traced per iteration (default: one per pixel)", .reads = "sppm",
       .scene_key = "sppm.photons_per_iteration",
       .extract = [](S d, R& r) {
         if (d.settings.sppm.photons_per_iteration > 0) r.sppm_photons = d.settings.sppm.photons_per_iteration;
       },
       .apply = [](Q r, SceneDesc& d) { d.settings.sppm.photons_per_iteration = *r.sppm_photons; },
       // Photon mapping's parameters go into the fingerprint as one entry, where it may render.
       .fingerprint_key = "sppm",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         if (!may_read_setting(*find_integrator_traits(d.settings.integrator), "sppm")) return std::nullopt;
         return d.settings.sppm.describe();
       }},
      {.name = "sppm_radius", .field = &R::sppm_radius, .rule = PositiveValue{},
       .help = "sppm: the search radius each pixel's visible point starts with, in world units (default 1)",
       .reads = "sppm", .scene_key = "sppm.radius",
       .extract = [](S d, R& r) { r.sppm_radius = d.settings.sppm.radius; },
       .apply = [](Q r, SceneDesc& d) { d.settings.sppm.radius = *r.sppm_radius; }},
      {.name = "equiangular", .field = &R::equiangular, .rule = ChoiceValue{{"on", "off"}},
       .help = "volpath: direct light on each ray segment through a homogeneous medium also from a point drawn "
               "by equiangular sampling towards a light point, combined by MIS with distance sampling (default on)",
       .reads = "equiangular", .scene_key = "equiangular", .scene_true = "on",
       .extract = [](S d, R& r) {
         if (!d.settings.volpath.equiangular) r.equiangular = "off";  // on, the default, is not written
       },
       .apply = [](Q r, SceneDesc& d) { d.settings.volpath.equiangular = r.equiangular == "on"; },
       .fingerprint_key = "equiangular",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         if (!may_read_setting(*find_integrator_traits(d.settings.integrator), "equiangular")) return std::nullopt;
         return d.settings.volpath.equiangular ? "on" : "off";
       }},
      {.name = "sampler", .field = &R::sampler, .rule = choices_of<SamplerType>({"random"}),
       .help = "Pixel sampler: random (independent), stratified (jittered, every dimension), poisson "
               "(Poisson-disc pixel positions), zsobol (Owen-scrambled Sobol' in Morton order)",
       .scene_key = "sampler.type",
       .extract = [](S d, R& r) { r.sampler = enum_name(d.settings.sampler.type); },
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
       .extract = [](S d, R& r) { r.filter = enum_name(d.settings.filter.type); },
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
       .extract = [](S d, R& r) { r.direction_sampling = enum_name(d.settings.path.direction_sampling); },
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
       .scene_key = "spectral", .scene_true = "spectral",
       .extract = [](S d, R& r) { r.transport = d.settings.spectral ? "spectral" : "rgb"; },
       .apply = [](Q r, SceneDesc& d) { d.settings.spectral = r.transport == "spectral"; },
       .fingerprint_key = "transport",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return d.settings.spectral ? "spectral" : "rgb"; }},
      {.name = "no_mis", .field = &R::no_mis, .rule = AnyValue{},
       .help = "Turn off multiple importance sampling: direct light from shadow rays only", .reads = "mis",
       .scene_key = "mis", .scene_negated = true,
       .extract = [](S d, R& r) { r.no_mis = !d.settings.path.mis; }, .apply = [](Q, SceneDesc& d) { d.settings.path.mis = false; },
       .fingerprint_key = "mis",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return d.settings.path.mis ? "on" : "off"; }},
      {.name = "light_selection", .field = &R::light_selection, .rule = choices_of<LightSelection>(),
       .help = "How shadow rays pick lights: power (each ray one light, chosen by power), uniform (each ray one "
               "emitter, all equally likely, as Mitsuba), bvh (each ray one light, chosen through a light BVH by "
               "power, distance and orientation: for many lights; pbrt-v4's default), paper (every light a share "
               "proportional to power x projected solid angle, O(lights) per vertex)",
       .reads = "light_selection=paper", .reads_when = "paper", .scene_key = "light_selection",
       .extract = [](S d, R& r) { r.light_selection = enum_name(d.settings.light_selection); },
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
       .scene_key = "bvh", .extract = [](S d, R& r) { r.bvh = enum_name(d.settings.bvh); },
       .apply = [](Q r, SceneDesc& d) { d.settings.bvh = *enum_from_name<BvhLayout>(r.bvh); }},
      {.name = "shadow_rays", .field = &R::shadow_rays, .rule = ValueRange{1, 1024},
       .help = "Shadow rays per path vertex", .reads = "shadow_rays", .scene_key = "shadow_rays",
       .extract = [](S d, R& r) { r.shadow_rays = d.settings.path.shadow_rays; },
       .apply = [](Q r, SceneDesc& d) { d.settings.path.shadow_rays = *r.shadow_rays; },
       .fingerprint_key = "shadow-rays",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.path.shadow_rays); }},
      {.name = "adaptive_threshold", .field = &R::adaptive_threshold, .rule = PositiveValue{},
       .help = "Adaptive sampling: keep adding batches to pixels whose relative standard error (per channel, "
               "se / sqrt(mean^2 + 0.01)) exceeds this",
       .reads = "adaptive", .scene_key = "adaptive.threshold",
       .extract = [](S d, R& r) {
         if (d.settings.adaptive_threshold > 0) r.adaptive_threshold = d.settings.adaptive_threshold;
       },
       .apply = [](Q r, SceneDesc& d) { d.settings.adaptive_threshold = *r.adaptive_threshold; },
       .fingerprint_key = "adaptive-threshold",
       .fingerprint = [](S d, Q) -> std::optional<std::string> {
         return fmt::format("{}", d.settings.adaptive_threshold);
       }},
      {.name = "adaptive_spp", .field = &R::adaptive_spp, .rule = ValueRange{1, 1 << 24},
       .help = "Adaptive sampling with a budget: this many samples per pixel on average, each pixel getting a "
               "share proportional to its estimated relative error (lowest relMSE)",
       .reads = "adaptive", .scene_key = "adaptive.spp",
       .extract = [](S d, R& r) {
         if (d.settings.adaptive_spp > 0) r.adaptive_spp = d.settings.adaptive_spp;
       },
       .apply = [](Q r, SceneDesc& d) { d.settings.adaptive_spp = *r.adaptive_spp; },
       .fingerprint_key = "adaptive-spp",
       .fingerprint = [](S d, Q) -> std::optional<std::string> { return std::to_string(d.settings.adaptive_spp); }},
      {.name = "adaptive_batch", .field = &R::adaptive_batch, .rule = ValueRange{1, 1 << 16},
       .help = "Adaptive sampling: samples per batch, a power of two (default 16)", .reads = "adaptive",
       .scene_key = "adaptive.batch",
       .extract = [](S d, R& r) {
         if (d.settings.adaptive()) r.adaptive_batch = d.settings.adaptive_batch;
       },
       .apply = [](Q r, SceneDesc& d) { d.settings.adaptive_batch = *r.adaptive_batch; }},
      {.name = "max_spp", .field = &R::max_spp, .rule = ValueRange{1, 1 << 24},
       .help = "Adaptive sampling: most samples a pixel gets (default 1024, or 8 x --adaptive-spp)",
       .reads = "adaptive", .scene_key = "adaptive.max_spp",
       .extract = [](S d, R& r) {
         if (d.settings.adaptive_max_spp > 0) r.max_spp = d.settings.adaptive_max_spp;
       },
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
      {.name = "denoise", .field = &R::denoise, .rule = AnyValue{},
       .help = "Denoise the image (feature regression on the albedo, normal and depth AOVs, filters chosen per "
               "pixel by their error estimated from the two independent halves; docs/denoising.md) and report the "
               "denoised image's estimated relMSE; the raw image is kept as the EXR layer Noisy"},
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

void check_resolution_range(long long width, long long height, const std::string& shown) {
  if (width < 1 || height < 1 || width > kMaxResolution || height > kMaxResolution || width * height > kMaxPixels)
    throw UsageError(fmt::format("resolution {} is out of range (each side 1..{}, at most {} pixels)", shown,
                                 kMaxResolution, kMaxPixels));
}

std::optional<SettingProblem> adaptive_problem(const RenderSettings& s) {
  if (!s.adaptive()) return std::nullopt;
  // Batches of a power of two keep every sampler's stratification within a batch.
  if ((s.adaptive_batch & (s.adaptive_batch - 1)) != 0)
    return SettingProblem{"adaptive.batch", fmt::format("must be a power of two, got {}", s.adaptive_batch)};
  if (s.adaptive_spp > 0 && s.adaptive_spp < s.adaptive_batch)
    return SettingProblem{"adaptive.spp", fmt::format("must be at least the batch size ({}), got {}",
                                                      s.adaptive_batch, s.adaptive_spp)};
  if (s.adaptive_max_spp > 0 && s.adaptive_max_spp < s.adaptive_batch)
    return SettingProblem{"adaptive.max_spp", fmt::format("must be at least the batch size ({}), got {}",
                                                          s.adaptive_batch, s.adaptive_max_spp)};
  if (s.adaptive_max_spp > 0 && s.adaptive_max_spp < s.adaptive_spp)
    return SettingProblem{"adaptive.max_spp", fmt::format("must be at least the mean spp ({}), got {}",
                                                          s.adaptive_spp, s.adaptive_max_spp)};
  return std::nullopt;
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

}  // namespace candela
