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

struct RenderCommand {
  std::string scene_file;  // empty = built-in scene
  std::string output;
  std::optional<int> spp, threads, max_depth;
  std::optional<uint64_t> seed;
  std::string resolution;
  std::string integrator;
  bool quiet = false;
};

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void apply_overrides(const RenderCommand& cmd, SceneDesc& scene) {
  if (cmd.spp) scene.settings.spp = *cmd.spp;
  if (cmd.max_depth) scene.settings.max_depth = *cmd.max_depth;
  if (cmd.seed) scene.settings.seed = *cmd.seed;
  if (!cmd.integrator.empty()) scene.settings.integrator = cmd.integrator;
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
      {"candela:spp", std::to_string(desc.settings.spp)},
      {"candela:render_time_seconds", fmt::format("{:.3f}", stats.seconds)},
      {"candela:integrator", desc.settings.integrator},
      {"candela:max_depth", std::to_string(desc.settings.max_depth)},
      {"candela:seed", std::to_string(desc.settings.seed)},
      {"Software", "candela " CANDELA_VERSION}};
  Image image = film.mean_image();
  for (const auto& f : outputs) write_image(f, image, metadata);

  double seconds = std::max(stats.seconds, 1e-9);
  std::string written;
  for (const auto& f : outputs) written += (written.empty() ? "" : ", ") + f.string();
  std::printf("%dx%d, %d spp in %.2f s: %.3f Msamples/s, %.2f Mrays/s (%.3g rays/sample) -> %s\n", desc.film.width,
              desc.film.height, desc.settings.spp, stats.seconds, double(stats.samples) / seconds * 1e-6,
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
