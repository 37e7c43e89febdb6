// The candela command line: `candela render SCENE [options]`, or `candela` alone to render the
// built-in Cornell box. Reads the scene, applies command-line overrides, renders, writes images.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "candela/film/image_io.h"
#include "candela/io/error.h"
#include "candela/io/scene_reader.h"
#include "candela/render/renderer.h"
#include "candela/scene/scene.h"

namespace fs = std::filesystem;
using namespace candela;

namespace {

constexpr int kExitBadInput = 1;
constexpr int kMaxResolution = 65536;
constexpr long long kMaxPixels = 1LL << 28;

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct RenderCommand {
  std::string scene_file;  // empty = built-in scene
  std::string output;
  std::optional<int> spp, threads, max_depth;
  std::optional<uint64_t> seed;
  std::string resolution;
  std::string integrator;
  std::string sampler, filter, direction_sampling, light_selection, spp_map;
  std::optional<int> shadow_rays, max_spp, adaptive_batch;
  std::optional<float> adaptive_threshold;
  bool no_mis = false;
  bool quiet = false;
};

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

void apply_overrides(const RenderCommand& cmd, SceneDesc& scene) {
  if (cmd.spp) scene.settings.spp = *cmd.spp;
  if (cmd.max_depth) scene.settings.max_depth = *cmd.max_depth;
  if (cmd.seed) scene.settings.seed = *cmd.seed;
  if (!cmd.integrator.empty()) scene.settings.integrator = cmd.integrator;
  RenderSettings& rs = scene.settings;
  if (!cmd.sampler.empty())
    rs.sampler.type = parse_choice<SamplerType>("--sampler", cmd.sampler,
                                                {{"random", SamplerType::Independent},
                                                 {"independent", SamplerType::Independent},
                                                 {"stratified", SamplerType::Stratified},
                                                 {"poisson", SamplerType::Poisson},
                                                 {"zsobol", SamplerType::ZSobol}});
  if (!cmd.filter.empty())
    rs.filter = default_filter(parse_choice<FilterType>(
        "--filter", cmd.filter,
        {{"box", FilterType::Box}, {"tent", FilterType::Tent}, {"gaussian", FilterType::Gaussian},
         {"mitchell", FilterType::Mitchell}}));
  if (!cmd.direction_sampling.empty())
    rs.direction_sampling = parse_choice<DirectionSampling>(
        "--direction-sampling", cmd.direction_sampling,
        {{"bsdf", DirectionSampling::Bsdf}, {"cosine", DirectionSampling::Cosine},
         {"uniform", DirectionSampling::Uniform}});
  if (!cmd.light_selection.empty())
    rs.light_selection = parse_choice<LightSelection>("--light-selection", cmd.light_selection,
                                                      {{"power", LightSelection::Power}, {"paper", LightSelection::Paper}});
  if (cmd.no_mis) rs.mis = false;
  if (cmd.shadow_rays) rs.shadow_rays = *cmd.shadow_rays;
  if (cmd.adaptive_threshold) rs.adaptive_threshold = *cmd.adaptive_threshold;
  if (cmd.adaptive_batch) rs.adaptive_batch = *cmd.adaptive_batch;
  if (cmd.max_spp) rs.adaptive_max_spp = *cmd.max_spp;
  if (rs.adaptive_threshold > 0 && (rs.adaptive_batch & (rs.adaptive_batch - 1)) != 0)
    throw UsageError(fmt::format("--adaptive-batch: must be a power of two, got {}", rs.adaptive_batch));
  if (!cmd.spp_map.empty() && !is_supported_output(cmd.spp_map))
    throw UsageError(fmt::format("--spp-map '{}': unsupported image format (use .exr, .png or .pfm)", cmd.spp_map));
  if (!cmd.resolution.empty()) {
    std::smatch m;
    static const std::regex pattern(R"((\d{1,9})[xX](\d{1,9}))");
    if (!std::regex_match(cmd.resolution, m, pattern))
      throw UsageError(fmt::format("--resolution: expected WIDTHxHEIGHT such as 640x480, got '{}'", cmd.resolution));
    scene.film.width = std::stoi(m[1]);
    scene.film.height = std::stoi(m[2]);
  }
  const auto& f = scene.film;
  if (f.width < 1 || f.height < 1 || f.width > kMaxResolution || f.height > kMaxResolution ||
      (long long)f.width * f.height > kMaxPixels)
    throw UsageError(fmt::format("resolution {}x{} is out of range (each side 1..{}, at most {} pixels)", f.width,
                                 f.height, kMaxResolution, kMaxPixels));
  if (!is_known_integrator(scene.settings.integrator))
    throw UsageError(fmt::format("unknown integrator '{}' (known: path)", scene.settings.integrator));
}

// The files to write: -o wins, then the scene's own film name, then <scene name>.exr. The built-in
// scene writes both cornell-box.png and cornell-box.exr.
std::vector<fs::path> output_files(const RenderCommand& cmd, const SceneDesc& scene) {
  if (!cmd.output.empty()) return {cmd.output};
  if (cmd.scene_file.empty()) return {"cornell-box.png", "cornell-box.exr"};
  if (!scene.film.filename.empty()) return {scene.film.filename};
  return {fs::path(cmd.scene_file).stem().string() + ".exr"};
}

void check_outputs(const std::vector<fs::path>& files) {
  for (const auto& f : files) {
    if (!is_supported_output(f))
      throw UsageError(fmt::format("output '{}': unsupported image format (use .exr, .png or .pfm)", f.string()));
    fs::path dir = f.has_parent_path() ? f.parent_path() : fs::path(".");
    if (!fs::is_directory(dir))
      throw UsageError(fmt::format("output '{}': directory '{}' does not exist", f.string(), dir.string()));
  }
}

// Per-pixel sample counts: raw counts for .exr/.pfm, a black-red-yellow-white heat map scaled to the
// largest count for .png.
Image spp_heat_map(const Film& film, const fs::path& file) {
  Image counts = film.sample_count_image();
  if (file.extension() != ".png") return counts;
  float most = 1;
  for (float v : counts.rgb) most = std::max(most, v);
  Image heat(counts.width, counts.height);
  for (int y = 0; y < counts.height; ++y)
    for (int x = 0; x < counts.width; ++x) {
      float t = counts.at(x, y).r / most;
      // Linear values that the PNG writer's sRGB encoding turns into a perceptually even ramp.
      RGB c(std::clamp(3 * t, 0.0f, 1.0f), std::clamp(3 * t - 1, 0.0f, 1.0f), std::clamp(3 * t - 2, 0.0f, 1.0f));
      heat.set(x, y, RGB(c.r * c.r, c.g * c.g, c.b * c.b));
    }
  return heat;
}

int run_render(const RenderCommand& cmd) {
  SceneDesc desc = cmd.scene_file.empty() ? read_json_scene(builtin_scene_json(), "<built-in cornell-box.json>", ".")
                                          : read_scene_file(cmd.scene_file);
  apply_overrides(cmd, desc);
  std::vector<fs::path> outputs = output_files(cmd, desc);
  check_outputs(outputs);

  Scene scene(desc);
  Film film(desc.film.width, desc.film.height);
  RenderOptions options;
  options.threads = cmd.threads.value_or(0);
  options.progress = !cmd.quiet;
  RenderStats stats = render(scene, desc.settings, film, options);

  std::map<std::string, std::string> metadata = {
      {"candela:scene", cmd.scene_file.empty() ? "<built-in cornell-box.json>" : cmd.scene_file},
      {"candela:spp", desc.settings.adaptive_threshold > 0
                          ? fmt::format("adaptive, {:.2f} on average", double(stats.samples) /
                                                                          (double(film.width()) * film.height()))
                          : std::to_string(desc.settings.spp)},
      {"candela:render_time_seconds", fmt::format("{:.3f}", stats.seconds)},
      {"candela:integrator", desc.settings.integrator},
      {"candela:max_depth", std::to_string(desc.settings.max_depth)},
      {"candela:seed", std::to_string(desc.settings.seed)},
      {"Software", "candela " CANDELA_VERSION}};
  Image image = film.mean_image();
  for (const auto& f : outputs) write_image(f, image, metadata);
  if (!cmd.spp_map.empty()) write_image(cmd.spp_map, spp_heat_map(film, fs::path(cmd.spp_map)), metadata);
  if (stats.non_finite_samples > 0)
    std::fprintf(stderr, "candela: warning: %llu samples were NaN or infinite and counted as black\n",
                 (unsigned long long)stats.non_finite_samples);

  double seconds = std::max(stats.seconds, 1e-9);
  std::string written;
  for (const auto& f : outputs) written += (written.empty() ? "" : ", ") + f.string();
  std::printf("%dx%d, %s spp in %.2f s: %.3f Msamples/s, %.2f Mrays/s (%.3g rays/sample) -> %s\n", desc.film.width,
              desc.film.height, metadata["candela:spp"].c_str(), stats.seconds, double(stats.samples) / seconds * 1e-6,
              double(stats.rays.total()) / seconds * 1e-6, double(stats.rays.total()) / double(stats.samples),
              written.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"candela: a physically based Monte Carlo path tracer.\n"
               "With no arguments, renders the built-in Cornell box to cornell-box.png and cornell-box.exr."};
  app.set_version_flag("--version", "candela " CANDELA_VERSION);
  RenderCommand cmd;
  CLI::App* render_cmd = app.add_subcommand("render", "Render a scene file to an image");
  render_cmd->add_option("scene", cmd.scene_file, "Scene file: .json (candela's format) or .pbrt (pbrt-v4)")
      ->required();
  render_cmd->add_option("-o,--output", cmd.output,
                         "Output image; the extension picks the format: .exr (linear HDR, with metadata), "
                         ".png (sRGB 8-bit), .pfm (linear). Default: the scene's film file name, else SCENE.exr");
  render_cmd->add_option("--spp", cmd.spp, "Samples per pixel (overrides the scene)")->check(CLI::Range(1, 1 << 24));
  render_cmd->add_option("--threads", cmd.threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 4096));
  render_cmd->add_option("--seed", cmd.seed, "Random seed (overrides the scene)");
  render_cmd->add_option("--max-depth", cmd.max_depth, "Maximum number of bounces; 1 = direct light only")
      ->check(CLI::Range(1, 100000));
  render_cmd->add_option("--resolution", cmd.resolution, "Image size WIDTHxHEIGHT (overrides the scene)");
  render_cmd->add_option("--integrator", cmd.integrator, "Integrator: path");
  render_cmd->add_option("--sampler", cmd.sampler,
                         "Pixel sampler: random (independent), stratified (jittered, every dimension), "
                         "poisson (Poisson-disc pixel positions), zsobol (Owen-scrambled Sobol' in Morton order)");
  render_cmd->add_option("--filter", cmd.filter,
                         "Reconstruction filter with pbrt-v4's default size: box (radius 0.5), tent (2), "
                         "gaussian (1.5, sigma 0.5), mitchell (2, B = C = 1/3)");
  render_cmd->add_option("--direction-sampling", cmd.direction_sampling,
                         "Next-direction sampling at non-delta surfaces: bsdf (importance), cosine, uniform "
                         "(the paper's eq. 11)");
  render_cmd->add_flag("--no-mis", cmd.no_mis,
                       "Turn off multiple importance sampling: direct light from shadow rays only");
  render_cmd->add_option("--light-selection", cmd.light_selection,
                         "How shadow rays pick lights: power (each ray one light, chosen by power), paper "
                         "(every light a share proportional to power x projected solid angle)");
  render_cmd->add_option("--shadow-rays", cmd.shadow_rays, "Shadow rays per path vertex")->check(CLI::Range(1, 1024));
  render_cmd->add_option("--adaptive-threshold", cmd.adaptive_threshold,
                         "Adaptive sampling: keep adding batches to pixels whose relative standard error "
                         "(per channel, se / sqrt(mean^2 + 0.01)) exceeds this")
      ->check(CLI::PositiveNumber);
  render_cmd->add_option("--adaptive-batch", cmd.adaptive_batch,
                         "Adaptive sampling: samples per batch, a power of two (default 16)")
      ->check(CLI::Range(1, 1 << 16));
  render_cmd->add_option("--max-spp", cmd.max_spp, "Adaptive sampling: most samples a pixel gets (default 1024)")
      ->check(CLI::Range(1, 1 << 24));
  render_cmd->add_option("--spp-map", cmd.spp_map,
                         "Also write the per-pixel sample counts: a heat map (.png) or raw counts (.exr, .pfm)");
  render_cmd->add_flag("-q,--quiet", cmd.quiet, "No progress bar");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return run_render(cmd);
  } catch (const std::exception& e) {  // SceneError, UsageError, image I/O: one message, no output written
    std::fprintf(stderr, "candela: error: %s\n", e.what());
  }
  return kExitBadInput;
}
