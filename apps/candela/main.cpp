// The candela command line: `candela render SCENE [options]`, or `candela` alone to render the
// built-in Cornell box. Reads the scene, applies command-line overrides, renders, writes images.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "candela/animation/frames.h"
#include "candela/animation/pose.h"
#include "candela/denoise/denoise_file.h"
#include "candela/denoise/denoised_render.h"
#include "candela/film/error_estimate.h"
#include "candela/film/aov_film.h"
#include "candela/film/image_io.h"
#include "candela/film/live_film.h"
#include "candela/preview/preview_server.h"
#include "candela/preview/tev_client.h"
#include "candela/base/error.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/render/checkpoint.h"
#include "candela/render/cluster.h"
#include "candela/render/film_part.h"
#include "candela/render/first_hit_aovs.h"
#include "candela/description/render_options.h"
#include "candela/integrators/render_request.h"
#include "candela/scene/resource_limits.h"
#include "candela/scene/scene.h"

namespace fs = std::filesystem;
using namespace candela;

namespace {

// The exit status of each outcome (kExitBadInput, kExitUsage, kExitInterrupted, ...) is base/error.h's,
// one per error type; docs/cli.md lists them.

// What the command is doing, for the signal handler: before rendering begins nothing is worth
// keeping, so the first SIGINT/SIGTERM leaves at once (reading a big scene file or building the BVH of
// a big mesh can take many seconds, and neither looks at a flag); while rendering, the render loop
// polls g_stop between tiles and passes and the partial image is written; while the finished images
// are written, the writing (well under a second) completes.
enum Phase : int { kReadingScene, kBuildingScene, kRendering, kWriting };
std::atomic<int> g_phase{kReadingScene};
// Set by the signal handler; the render loop polls it between tiles and passes.
std::atomic<bool> g_stop{false};
std::atomic<int> g_signals{0};
std::atomic<bool> g_stopped_from_page{false};  // the stop came from the preview page's button
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free);

template <size_t N>
void say_from_handler(const char (&text)[N]) {
  ssize_t ignored = write(STDERR_FILENO, text, N - 1);
  (void)ignored;
}

extern "C" void on_stop_signal(int) {
  // Only atomics, write and _exit (async-signal-safe). Files are written atomically (temporary +
  // rename), so leaving at any moment never leaves a half-written image or checkpoint.
  if (g_signals.fetch_add(1) > 0) _exit(kExitSecondSignal);
  switch (Phase(g_phase.load())) {
    case kReadingScene:
      say_from_handler("candela: interrupted while reading the scene: nothing written\n");
      _exit(kExitInterrupted);
    case kBuildingScene:
      say_from_handler("candela: interrupted while building the scene (textures, BVH): nothing written\n");
      _exit(kExitInterrupted);
    case kRendering:
    case kWriting:
      g_stop.store(true);
  }
}

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}
// An error every rank of the job has agreed on (the lowest failing rank's): the root prints it once
// and every rank exits with the exit status of that error's type.
struct AgreedError : std::runtime_error {
  AgreedError(const std::string& message, int exit_code) : std::runtime_error(message), exit_code(exit_code) {}
  int exit_code;
};

// Runs `step` on every rank. Whatever is read before rendering can fail on one rank only (a file
// that differs on one node), so the ranks compare notes before the next collective step: if `step`
// threw anywhere, every rank throws the same AgreedError.
template <typename Step>
void on_every_rank(Cluster& cluster, Step&& step) {
  std::string error;
  int exit_code = 0;
  try {
    step();
  } catch (const std::exception& e) {
    error = e.what();
    if (error.empty()) error = "unknown error";
    exit_code = exit_code_for(e);
  }
  const Cluster::RankError first = cluster.first_error(error, exit_code);
  if (!first.message.empty()) throw AgreedError(first.message, first.exit_code);
}

// The render subcommand: the request (integrators/render_request.h) and what only the command line does.
struct RenderCommand : RenderRequest {
  std::string scene_file;  // empty = built-in scene
  std::string output, spp_map;
  std::string display_server;  // --display-server HOST:PORT of a tev viewer (preview/tev_client.h); empty = none
  std::string aov;  // --aov: the AOV layers; empty = the scene's (FilmDesc::aovs)
  std::optional<double> checkpoint_every;  // with --checkpoint (RenderRequest::checkpoint)
  std::string preview;          // [HOST:]PORT of the browser preview; empty = none
  bool preview_public = false;  // allow a preview address reachable from other machines
  // An animation's frames (animation/frames.h): the list, the frame rate, the shutter's open fraction
  // of a frame, and whether frames whose images all exist are skipped (a restarted farm job).
  std::string frames;
  double fps = 24, shutter = 0.5;
  bool skip_existing = false;
};

// The files to write: -o wins, then the scene's own film name, then <scene name>.exr. The built-in
// scene writes both cornell-box.png and cornell-box.exr.
// With --frames, the names are patterns with the frame number in a run of '#' (shot_####.exr); a
// default name without one gets _#### before its extension.
std::vector<fs::path> output_files(const RenderCommand& cmd, const SceneDesc& scene) {
  if (!cmd.output.empty()) return {cmd.output};
  std::vector<fs::path> names = cmd.scene_file.empty()         ? std::vector<fs::path>{"cornell-box.png", "cornell-box.exr"}
                                : !scene.film.filename.empty() ? std::vector<fs::path>{scene.film.filename}
                                                               : std::vector<fs::path>{fs::path(cmd.scene_file).stem().string() + ".exr"};
  if (!cmd.frames.empty())
    for (fs::path& name : names)
      if (!has_frame_placeholder(name.string()))
        name = name.parent_path() / (name.stem().string() + "_####" + name.extension().string());
  return names;
}

bool is_exr(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".exr";
}

// That `file` can be written, found out before the scene is read and rendered rather than after:
// its directory exists and takes a new file (the temporary file it is written to, then renamed).
// `what` names the file in the message, e.g. "output 'out.png'". A full disk is still only found
// when the image is written; the existing file is then left as it was.
void check_can_write(const fs::path& file, const std::string& what) {
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw UsageError(fmt::format("{}: directory '{}' does not exist", what, dir.string()));
  if (!fs::is_directory(dir, ec)) throw UsageError(fmt::format("{}: '{}' is not a directory", what, dir.string()));
  if (fs::is_directory(file, ec)) throw UsageError(fmt::format("{}: it is a directory", what));
  // Permissions alone do not tell (root writes anywhere, but not on a read-only file system or in
  // /sys): create a file there and remove it.
  std::string probe = (dir / ".candela-write-check-XXXXXX").string();
  const int fd = mkstemp(probe.data());
  if (fd < 0)
    throw UsageError(fmt::format("{}: cannot write in directory '{}': {}", what, dir.string(), std::strerror(errno)));
  close(fd);
  unlink(probe.c_str());
}

void check_outputs(const std::vector<fs::path>& files) {
  for (const auto& f : files) {
    if (!is_supported_output(f))
      throw UsageError(fmt::format("output '{}': unsupported image format (use .exr, .png or .pfm)", f.string()));
    check_can_write(f, fmt::format("output '{}'", f.string()));
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

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw UsageError(fmt::format("cannot read '{}'", file.string()));
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// What the ranks of a job must all have read alike: the scene file's bytes and every mesh.
uint64_t scene_content_hash(const std::string& scene_bytes, const SceneDesc& desc) {
  uint64_t hash = fnv1a64(scene_bytes.data(), scene_bytes.size());
  for (const ShapeDesc& shape : desc.shapes)
    if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
      hash = fnv1a64(m->mesh.positions.data(), m->mesh.positions.size() * sizeof(Point3), hash);
      hash = fnv1a64(m->mesh.indices.data(), m->mesh.indices.size() * sizeof(uint32_t), hash);
    }
  return hash;
}

// ---- The render subcommand, step by step: plan (read and check everything), render, report.

// What the render subcommand does, resolved and checked before the scene is built: the request's
// plan (plan_render: the integrator, the pixels, the budget, its outputs) and what only the command
// line adds.
struct CommandPlan {
  SceneDesc desc;
  RenderPlan render;
  // The scene file's bytes where something must know they are the same: the ranks of a job, a
  // checkpoint, a part (a plain render does not read the file twice).
  std::string scene_bytes;
  std::vector<fs::path> outputs;  // the images to write
  AovSelection aovs;              // --aov, else the scene's (none with --resume or --part)
  AovSelection film_aovs;         // the layers the AOV film collects: `aovs`, and the denoiser's with --denoise
};

AovSelection parse_aov_list(const std::string& list, const char* where) {
  try {
    return parse_aov_selection(list);
  } catch (const UsageError& e) {
    throw UsageError(fmt::format("{}: {}", where, e.what()));
  }
}

// The command line's own flags that can be checked before the scene is read (with the request's
// values, so that a value out of range is said before a big scene is read).
void check_command_flags(const RenderCommand& cmd) {
  check_request_values(cmd);
  const bool pixel_mode = !cmd.pixel.empty();
  if (!cmd.aov.empty()) parse_aov_list(cmd.aov, "--aov");
  if (!cmd.preview.empty()) {
    const PreviewAddress address = parse_preview_address(cmd.preview);
    if (!address.loopback() && !cmd.preview_public)
      throw UsageError(fmt::format("--preview {}: the preview listens on this machine only (127.0.0.1) unless "
                                   "--preview-public is given", cmd.preview));
    if (pixel_mode) throw UsageError("--preview shows the whole image: it cannot be combined with --pixel");
  }
  if (!cmd.display_server.empty()) {
    try {
      parse_display_server_address(cmd.display_server);
    } catch (const UsageError& e) {
      throw UsageError(fmt::format("--display-server: {}", e.what()));
    }
    if (pixel_mode) throw UsageError("--display-server shows the whole image: it cannot be combined with --pixel");
  }
  if (cmd.checkpoint_every && !(*cmd.checkpoint_every > 0))
    throw UsageError(fmt::format("--checkpoint-every: must be a positive number, got {}", *cmd.checkpoint_every));
  if (!cmd.frames.empty()) {
    if (!(cmd.fps > 0 && cmd.fps <= 1e6)) throw UsageError(fmt::format("--fps: must be in (0, 1e6], got {}", cmd.fps));
    if (!(cmd.shutter >= 0 && cmd.shutter <= 1))
      throw UsageError(fmt::format("--shutter: the fraction of a frame the shutter is open, in [0, 1], got {}", cmd.shutter));
    if (pixel_mode) throw UsageError("--frames renders whole images: it cannot be combined with --pixel");
    if (!cmd.checkpoint.empty() || !cmd.resume.empty())
      throw UsageError("--frames cannot be combined with --checkpoint or --resume: a restarted job skips the frames "
                       "it finished with --skip-existing");
    if (!cmd.preview.empty() || !cmd.display_server.empty())
      throw UsageError("--frames cannot be combined with --preview or --display-server yet (a viewer shows one image)");
    if (cmd.denoise) throw UsageError("--frames cannot be combined with --denoise yet");
    if (!cmd.spp_map.empty() && !has_frame_placeholder(cmd.spp_map))
      throw UsageError(fmt::format("--spp-map '{}': with --frames, name the frame number with a run of '#' "
                                   "(spp_####.png)", cmd.spp_map));
  } else {
    if (cmd.skip_existing) throw UsageError("--skip-existing needs --frames");
  }
}

// The AOV layers: --aov, else the scene's; checkpoints and parts do not keep them.
AovSelection plan_aovs(const RenderCommand& cmd, const CommandPlan& plan, Cluster& cluster) {
  const bool keeps_none = !cmd.resume.empty() || !cmd.part.empty();
  const char* which = cmd.resume.empty() ? "--part" : "--resume";
  if (!cmd.aov.empty() && keeps_none)
    throw UsageError(fmt::format("--aov cannot be combined with {} (checkpoints and parts do not keep the AOVs)", which));
  AovSelection layers;
  if (!cmd.aov.empty()) {
    layers = parse_aov_list(cmd.aov, "--aov");
  } else if (!plan.desc.film.aovs.empty()) {
    layers = parse_aov_list(plan.desc.film.aovs, "the scene's aovs");
    if (keeps_none) {
      if (!cmd.quiet && cluster.is_root())
        std::fprintf(stderr, "note: the scene's AOVs are not written with %s (checkpoints and parts do not keep them)\n",
                     which);
      layers = AovSelection{};
    }
  }
  if (layers.wants_spectral()) {
    // The buckets hold the values at each sample's wavelengths: only a spectral render has them.
    if (!plan.desc.settings.spectral)
      throw UsageError("the spectral layer needs spectral transport (--transport spectral, or the scene's render.spectral)");
    check_capabilities(*plan.render.integrator, {.spectral_layer = true});
  }
  if (!layers.empty() && !plan.render.one_pixel() && !cmd.quiet && cluster.is_root())
    for (const fs::path& f : plan.outputs)
      if (!is_exr(f)) {
        std::fprintf(stderr, "note: AOVs are written into .exr outputs only: '%s' gets the colour alone\n",
                     f.string().c_str());
        break;
      }
  return layers;
}

// The files the command writes, and whether they can be: the images, the spp map, the checkpoint.
void check_command_outputs(const RenderCommand& cmd, const CommandPlan& plan, Cluster& cluster) {
  if (!cmd.spp_map.empty() && !is_supported_output(cmd.spp_map))
    throw UsageError(fmt::format("--spp-map '{}': unsupported image format (use .exr, .png or .pfm)", cmd.spp_map));
  if (!cmd.spp_map.empty() && cluster.is_root()) check_can_write(cmd.spp_map, fmt::format("--spp-map '{}'", cmd.spp_map));
  if (cmd.checkpoint_every && cmd.checkpoint.empty()) throw UsageError("--checkpoint-every needs --checkpoint FILE");
  if (!cmd.frames.empty() && parse_frame_list(cmd.frames).size() > 1)
    for (const fs::path& f : plan.outputs)
      if (!has_frame_placeholder(f.string()))
        throw UsageError(fmt::format("output '{}': --frames writes one image per frame: name the frame number with "
                                     "a run of '#' (shot_####.exr)", f.string()));
  if (!cmd.part.empty() && (plan.outputs.size() != 1 || plan.outputs[0].extension() != ".exr"))
    throw UsageError("--part writes a part file for candela merge: give one output ending in .exr (-o part-K.exr)");
  if (!plan.render.one_pixel() && cluster.is_root()) check_outputs(plan.outputs);
  if (!cmd.checkpoint.empty() && cluster.is_root())
    check_can_write(cmd.checkpoint, fmt::format("--checkpoint '{}'", cmd.checkpoint));
}

// The one validator of the command: reads the scene, resolves the request (plan_render, where every
// capability of the integrator is checked) and checks what only the command line does.
CommandPlan plan_command(const RenderCommand& cmd, Cluster& cluster) {
  check_command_flags(cmd);
  CommandPlan plan;
  plan.desc = cmd.scene_file.empty() ? read_json_scene(builtin_scene_json(), "<built-in cornell-box.json>", ".")
                                     : read_scene_file(cmd.scene_file);
  // An animated scene rendered as one image: at its camera's shutter interval (--frames poses each frame).
  if (cmd.frames.empty() && is_animated(plan.desc))
    plan.desc = pose_scene(plan.desc, {plan.desc.camera.shutter_open, plan.desc.camera.shutter_close});
  if (cluster.distributed() || !cmd.checkpoint.empty() || !cmd.resume.empty() || !cmd.part.empty())
    plan.scene_bytes = cmd.scene_file.empty() ? std::string(builtin_scene_json()) : read_bytes(cmd.scene_file);
  plan.render = plan_render(cmd, plan.desc);
  if (plan.render.one_pixel() && cluster.distributed())
    throw UsageError("--pixel renders one pixel in one process: run it without mpirun");
  plan.outputs = output_files(cmd, plan.desc);
  plan.aovs = plan_aovs(cmd, plan, cluster);
  plan.film_aovs = plan.render.denoise ? with_denoise_features(plan.aovs) : plan.aovs;
  // The halves layer holds two independent estimates of each pixel: the sampler makes them.
  if (plan.aovs.wants(Aov::Halves)) plan.desc.settings.sampler.replicas = true;
  check_command_outputs(cmd, plan, cluster);
  // Refuse what cannot fit in memory before allocating the scene and the film.
  check_resources(plan.desc);
  return plan;
}

// Every rank must render the same scene: a file changed on one node is refused.
void check_same_scene(Cluster& cluster, const CommandPlan& plan, const std::string& scene_file) {
  std::vector<uint64_t> hashes = cluster.gather_values(scene_content_hash(plan.scene_bytes, plan.desc));
  for (size_t r = 1; r < hashes.size(); ++r)
    if (hashes[r] != hashes[0])
      throw UsageError(fmt::format("rank {} read a different scene than rank 0 ('{}' or its meshes differ between "
                                   "the nodes; hash {:016x} vs {:016x})",
                                   r, scene_file, hashes[r], hashes[0]));
}

// --resume: the checkpoint, read by the root and sent to the others (only it needs to see the file),
// made by the same scene and settings (`fingerprint`) for a film of the same size.
Checkpoint read_resumed(const std::string& file, Cluster& cluster, const RenderFingerprint& fingerprint,
                        const FilmDesc& film) {
  std::string checkpoint_bytes;
  on_every_rank(cluster, [&] {
    if (cluster.is_root()) checkpoint_bytes = read_checkpoint_bytes(file);
  });
  std::vector<std::byte> shared(reinterpret_cast<const std::byte*>(checkpoint_bytes.data()),
                                reinterpret_cast<const std::byte*>(checkpoint_bytes.data() + checkpoint_bytes.size()));
  cluster.broadcast(shared);
  Checkpoint resumed;
  on_every_rank(cluster, [&] {
    resumed = parse_checkpoint(std::string_view(reinterpret_cast<const char*>(shared.data()), shared.size()), file);
    std::string diff = resumed.fingerprint.difference(fingerprint);
    if (!diff.empty()) throw UsageError(fmt::format("cannot resume from '{}': {} (checkpoint vs now)", file, diff));
    if (resumed.width != film.width || resumed.height != film.height)
      throw UsageError(fmt::format("cannot resume from '{}': its film is {}x{}, not {}x{}", file, resumed.width,
                                   resumed.height, film.width, film.height));
  });
  return resumed;
}

// The film continues the checkpoint's; returns its non-finite samples (the root's alone: splats and
// counts are sums over the ranks, so the root alone carries the checkpoint's).
uint64_t restore(Checkpoint& resumed, Film& film, Cluster& cluster) {
  film.pixels() = std::move(resumed.pixels);
  if (!resumed.splats.empty()) {
    film.enable_splats();
    if (cluster.is_root()) {
      film.splats().sums() = std::move(resumed.splats);
      if (!resumed.half_splats.empty()) film.half_splats().sums() = std::move(resumed.half_splats);
    }
  }
  return cluster.is_root() ? resumed.non_finite_samples : 0;
}

// --checkpoint FILE: the film saved atomically by the root, between passes every --checkpoint-every
// seconds and when the render stops early.
class CheckpointWriter {
 public:
  CheckpointWriter(Cluster& cluster, std::string file, RenderFingerprint fingerprint, uint64_t earlier_non_finite)
      : cluster_(cluster), file_(std::move(file)), fingerprint_(std::move(fingerprint)),
        earlier_non_finite_(earlier_non_finite) {}

  // Called on every rank at the same moment; the root writes. `own_splats`: the film's splats are
  // still each rank's own (during the render), to be added up first.
  void save(const Film& f, uint64_t non_finite, bool own_splats) {
    Checkpoint cp;
    if (f.has_splats()) {
      cp.splats = f.splats().sums();
      cp.half_splats = f.half_splats().sums();
      if (own_splats) {
        cluster_.sum_int64(cp.splats);
        cluster_.sum_int64(cp.half_splats);
      }
    }
    on_every_rank(cluster_, [&] {
      if (!cluster_.is_root()) return;
      cp.fingerprint = fingerprint_;
      cp.width = f.width();
      cp.height = f.height();
      cp.non_finite_samples = non_finite;
      cp.pixels = f.pixels();
      write_checkpoint(file_, cp);
    });
  }

  // The render loop's after_pass hook: a checkpoint when `every` seconds have passed (the root's clock).
  std::function<void(const Film&, uint64_t)> every(double seconds) {
    return [this, seconds](const Film& f, uint64_t non_finite_so_far) {
      auto now = std::chrono::steady_clock::now();
      if (!cluster_.from_root(std::chrono::duration<double>(now - last_).count() >= seconds)) return;
      save(f, earlier_non_finite_ + non_finite_so_far, true);
      last_ = std::chrono::steady_clock::now();
    };
  }

 private:
  Cluster& cluster_;
  std::string file_;
  RenderFingerprint fingerprint_;
  uint64_t earlier_non_finite_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// Viewers of the render as it converges (the root's film: after each pass it holds every rank's
// tiles). They see the end once the images are written, or the command fails, before they close.
struct Viewers {
  std::unique_ptr<LiveFilm> live;
  std::unique_ptr<PreviewServer> preview;
  std::unique_ptr<TevClient> tev;
  LiveState end = LiveState::Stopped;
  Viewers() = default;
  Viewers(const Viewers&) = delete;
  Viewers& operator=(const Viewers&) = delete;
  ~Viewers() {
    if (live) live->finish(end);
  }
};

void start_preview(const RenderCommand& cmd, Viewers& viewers) {
  const PreviewAddress address = parse_preview_address(cmd.preview);
  viewers.preview = std::make_unique<PreviewServer>(
      address, *viewers.live,
      [] {
        g_stopped_from_page.store(true);
        g_stop.store(true);
      },
      cmd.preview_public);
  if (!address.loopback())
    std::fprintf(stderr, "candela: warning: the preview listens on %s, which other machines can reach: anyone who "
                         "sees its address (with the token) can watch the render and stop it, and it travels "
                         "unencrypted; an SSH tunnel to a loopback preview is safer (docs/preview.md)\n",
                 address.host.c_str());
  std::fprintf(stderr, "candela: preview at %s\n", viewers.preview->url().c_str());
  std::fflush(stderr);
}

// Starts the viewers asked for (--preview, --display-server) and hands the render their film.
void start_viewers(const RenderCommand& cmd, const CommandPlan& plan, const RenderOptions& options,
                   Cluster& cluster, Viewers& viewers) {
  if (!cluster.is_root() || (cmd.preview.empty() && cmd.display_server.empty())) return;
  const SceneDesc& desc = plan.desc;
  const RenderSettings& rs = desc.settings;
  viewers.live = std::make_unique<LiveFilm>(desc.film.width, desc.film.height);
  if (!cmd.display_server.empty())
    viewers.tev = std::make_unique<TevClient>(cmd.display_server, plan.outputs.front().filename().string(), *viewers.live);
  if (!cmd.preview.empty()) start_preview(cmd, viewers);
  const uint64_t spp = uint64_t(!rs.adaptive()          ? rs.spp
                                : rs.adaptive_spp > 0 ? rs.adaptive_spp
                                                      : std::max(rs.adaptive_spp_limit(), rs.adaptive_batch));
  viewers.live->start(fmt::format("{} ({})", cmd.scene_file.empty() ? "built-in cornell-box.json" : cmd.scene_file,
                                  rs.integrator),
                      spp, rs.adaptive(), options.time_limit_seconds, options.target_error);
}

// The render options: the plan's, and what the command line adds (threads per rank, progress on the
// root, the stop flag, the cluster, the AOV film, the integrator's outputs).
RenderOptions command_options(const RenderCommand& cmd, const CommandPlan& plan, Cluster& cluster, AovFilm* aovs,
                              IntegratorOutputs* integrator_outputs) {
  RenderOptions options = plan.render.options();
  options.threads = cmd.threads.value_or(cluster.default_threads());
  options.progress = !cmd.quiet && cluster.is_root();
  options.cancel = &g_stop;
  options.cluster = &cluster;
  options.aovs = aovs;
  options.integrator_outputs = integrator_outputs;
  return options;
}

void warn_non_finite(const RenderStats& stats, uint64_t non_finite, bool pixel_mode) {
  if (non_finite == 0) return;
  std::string where;
  for (const auto& n : stats.first_non_finite)
    where += fmt::format("{}pixel ({}, {}) sample {}", where.empty() ? "" : ", ", n.x, n.y, n.sample);
  std::fprintf(stderr, "candela: warning: %llu samples were NaN or infinite and counted as black%s%s\n",
               (unsigned long long)non_finite, where.empty() ? "" : "; first: ",
               (where + (where.empty() || pixel_mode ? "" : " (reproduce one with --pixel X,Y)")).c_str());
}

// --pixel: its value and its non-finite samples, instead of an image.
int report_pixel(const RenderPlan& plan, const Film& film, const RenderStats& stats, uint64_t non_finite) {
  const int px = plan.pixel_x, py = plan.pixel_y;
  const PixelSums& p = film.pixel(px, py);
  RGB v = film.mean_image().at(px, py);
  std::printf("pixel (%d, %d): %.9g %.9g %.9g (%llu samples)\n", px, py, v.r, v.g, v.b, (unsigned long long)p.count);
  std::string idx;
  for (const auto& n : stats.first_non_finite) idx += fmt::format("{}{}", idx.empty() ? "" : " ", n.sample);
  std::printf("non-finite samples: %s\n", idx.empty() ? "none" : idx.c_str());
  warn_non_finite(stats, non_finite, true);
  return stats.cancelled ? kExitInterrupted : 0;
}

// The images: the part file (--part), else every output (with the AOVs in .exr ones); the
// integrator's own outputs; the spp map. With --denoise (`denoised`) the outputs get the denoised
// image, and .exr ones the raw image as the layer Noisy.
// `made_by` and `non_finite` go into a part file.
void write_images(const RenderCommand& cmd, const CommandPlan& plan, const Scene& scene, Film& film,
                  const AovFilm* aov_film, const IntegratorOutputs* integrator_outputs,
                  const RenderFingerprint& made_by, uint64_t non_finite,
                  const std::map<std::string, std::string>& metadata, const DenoisedRender* denoised) {
  if (!cmd.part.empty()) {
    FilmPart part{plan.render.part_index, plan.render.part_count, made_by,
                  double(scene.camera().importance_film_pixels()), non_finite, std::move(film)};
    write_part(plan.outputs[0], part, metadata);
    film = std::move(part.film);
  } else {
    Image image = denoised ? denoised->result.image : film.mean_image();
    if (const auto& crop = plan.desc.film.crop) {
      image.x = crop->x;
      image.y = crop->y;
      image.full_width = crop->full_width;
      image.full_height = crop->full_height;
    }
    // The layers asked for (the AOV film may hold the denoiser's features besides), then Noisy.
    std::vector<AovLayer> layers = aov_film ? aov_film->images(film) : std::vector<AovLayer>{};
    std::erase_if(layers, [&](const AovLayer& layer) {
      return std::find(plan.aovs.layers.begin(), plan.aovs.layers.end(), layer.aov) == plan.aovs.layers.end();
    });
    FloatChannels aov_channels = exr_channels(layers);
    if (denoised) aov_channels = append_channels(aov_channels, noisy_layer(film.mean_image()));
    // The spectral layer's EXRs say so as the OpenEXR spectral layout asks (and pbrt-v4 writes).
    std::map<std::string, std::string> exr_metadata = metadata;
    if (aov_film && aov_film->spectral().count > 0) {
      exr_metadata["spectralLayoutVersion"] = "1.0";
      exr_metadata["emissiveUnits"] = "W.m^-2.sr^-1";
    }
    for (const auto& f : plan.outputs) {
      if (aov_channels.names.empty() || !is_exr(f))
        write_image(f, image, metadata);
      else
        write_image(f, image, exr_metadata, aov_channels);
    }
  }
  if (integrator_outputs) integrator_outputs->write(film, metadata);
  if (!cmd.spp_map.empty()) write_image(cmd.spp_map, spp_heat_map(film, fs::path(cmd.spp_map)), metadata);
}

// The closing lines: size, samples, time and speed; the error estimate; an MPI job's efficiency.
void print_summary(const RenderCommand& cmd, const CommandPlan& plan, const RenderOutcome& outcome,
                   const RenderOptions& options, const SampleCountText& samples, Cluster& cluster,
                   const std::vector<Cluster::Traffic>& traffic, const DenoisedRender* denoised) {
  const RenderStats& stats = outcome.stats;
  const double seconds = std::max(stats.seconds, 1e-9);
  std::string written;
  for (const auto& f : plan.outputs) written += (written.empty() ? "" : ", ") + f.string();
  std::printf("%dx%d, %s%s in %.2f s: %.3f Msamples/s, %.2f Mrays/s (%.3g rays/sample) -> %s\n",
              plan.desc.film.width, plan.desc.film.height, samples.text.c_str(), samples.spp_unit, stats.seconds,
              double(stats.samples) / seconds * 1e-6, double(stats.rays.total()) / seconds * 1e-6,
              double(stats.rays.total()) / double(std::max<uint64_t>(stats.samples, 1)), written.c_str());
  if (outcome.error.valid || options.target_error > 0 || cmd.estimate_error || denoised)
    std::printf("estimated error: %s%s\n", describe(outcome.error).c_str(),
                options.target_error <= 0 ? ""
                : stats.reached_target
                    ? fmt::format("; target {} reached", options.target_error).c_str()
                    : fmt::format("; target {} not reached (stopped at the {})", options.target_error,
                                  stats.time_limited ? "time limit" : stats.cancelled ? "interruption" : "spp limit").c_str());
  if (denoised) std::printf("%s\n", describe_denoised(denoised->result, denoised->seconds).c_str());
  if (!cluster.mpi_job()) return;
  // The job's parallel efficiency: the thread-seconds spent rendering over all threads x wall time.
  uint64_t most_sent = 0;
  for (const Cluster::Traffic& t : traffic) most_sent = std::max(most_sent, t.bytes_sent);
  double busy = 0;
  std::string per_rank;
  for (double b : stats.rank_busy_seconds) {
    busy += b;
    per_rank += fmt::format("{}{:.2f}", per_rank.empty() ? "" : " ", b);
  }
  std::printf("%d ranks, %d threads: parallel efficiency %.1f%% (busy thread-seconds per rank: %s); "
              "sent per rank: at most %.2f MB, rank 0 %.2f MB; rank 0 in collectives %.2f s\n",
              cluster.size(), stats.threads, 100 * busy / (double(stats.threads) * seconds), per_rank.c_str(),
              double(most_sent) * 1e-6, double(traffic[0].bytes_sent) * 1e-6, traffic[0].collective_seconds);
}

// Why the render stopped early, if it did, and the exit status.
int finish_message(const RenderCommand& cmd, const RenderStats& stats, const SampleCountText& samples) {
  if (stats.time_limited)
    std::fprintf(stderr, "candela: time limit reached: wrote the image with %s%s\n", samples.text.c_str(),
                 samples.spp_unit);
  if (!stats.cancelled) return 0;
  std::fprintf(stderr, "candela: %s: wrote the image with %s%s%s\n",
               g_stopped_from_page.load() ? "stopped from the preview page" : "interrupted", samples.text.c_str(),
               samples.spp_unit, cmd.checkpoint.empty() ? "" : fmt::format(" and checkpoint {}", cmd.checkpoint).c_str());
  return kExitInterrupted;
}

// Renders the planned scene (its description is consumed) and writes its images. `frame`: the
// frame of a sequence (--frames) it is, or -1; an interrupted frame is not written, so that a
// restarted job (--skip-existing) renders it again rather than keep a half-converged image.
int render_planned(const RenderCommand& cmd, CommandPlan& plan, Cluster& cluster, int frame = -1) {
  // What made the image, for checkpoints and parts; a checkpoint also names its part, as it resumes only that.
  const RenderFingerprint made_by = render_fingerprint(plan.scene_bytes, plan.desc, cmd);
  RenderFingerprint fingerprint = made_by;
  if (plan.render.part_count > 1) fingerprint.settings.push_back({"part", cmd.part});
  std::optional<Checkpoint> resumed;
  if (!cmd.resume.empty()) resumed = read_resumed(cmd.resume, cluster, fingerprint, plan.desc.film);

  // The meshes move into the scene: every triangle is held once.
  g_phase.store(kBuildingScene);
  SceneDesc& desc = plan.desc;
  Scene scene(desc, Scene::MeshData::Take);
  Film film(desc.film.width, desc.film.height);
  const uint64_t earlier_non_finite = resumed ? restore(*resumed, film, cluster) : 0;
  std::optional<AovFilm> aov_film;
  if (!plan.film_aovs.empty() && !plan.render.one_pixel())
    aov_film.emplace(film.width(), film.height(), plan.film_aovs, aov_camera_frame(scene.camera()));
  const std::unique_ptr<IntegratorOutputs> integrator_outputs =
      plan.render.make_integrator_outputs(desc.settings, film.width(), film.height());
  RenderOptions options =
      command_options(cmd, plan, cluster, aov_film ? &*aov_film : nullptr, integrator_outputs.get());
  CheckpointWriter checkpoints(cluster, cmd.checkpoint, fingerprint, earlier_non_finite);
  if (!cmd.checkpoint.empty() && cmd.checkpoint_every) options.after_pass = checkpoints.every(*cmd.checkpoint_every);
  Viewers viewers;
  start_viewers(cmd, plan, options, cluster, viewers);
  if (viewers.live) {
    options.live = viewers.live.get();
    if (!options.progress_fraction) options.progress_fraction = &viewers.live->progress_fraction();
  }

  g_phase.store(kRendering);
  const RenderOutcome outcome =
      render_requested(scene, desc.settings, film, plan.render, options, [&](const std::string& summary) {
        if (cluster.is_root()) std::printf("auto: %s\n", summary.c_str());
      });
  const RenderStats& stats = outcome.stats;
  g_phase.store(kWriting);  // a signal from here on lets the (complete or partial) images be written
  const uint64_t non_finite = earlier_non_finite + stats.non_finite_samples;
  if (frame >= 0 && stats.cancelled) {
    if (cluster.is_root())
      std::fprintf(stderr, "candela: interrupted in frame %d: its images are not written (the frames before it are)\n",
                   frame);
    return kExitInterrupted;
  }
  if (plan.render.one_pixel()) return report_pixel(plan.render, film, stats, non_finite);

  if ((stats.cancelled || stats.time_limited) && !cmd.checkpoint.empty()) checkpoints.save(film, non_finite, false);
  // The root writes the images and reports; the other ranks are done.
  const std::vector<Cluster::Traffic> traffic = cluster.gather_values(cluster.traffic());
  if (!cluster.is_root()) return stats.cancelled ? kExitInterrupted : 0;

  const SampleCountText samples = describe_samples(desc.settings, film, outcome);
  std::map<std::string, std::string> metadata =
      image_metadata(cmd.scene_file.empty() ? "<built-in cornell-box.json>" : cmd.scene_file, desc.settings, film,
                     outcome, options, cluster.size(), non_finite);
  if (frame >= 0) {
    metadata["candela:frame"] = std::to_string(frame);
    metadata["candela:shutter"] = fmt::format("{} {}", desc.camera.shutter_open, desc.camera.shutter_close);
  }
  // --denoise: the root alone denoises the gathered film (denoise/denoised_render.h).
  std::optional<DenoisedRender> denoised;
  if (plan.render.denoise) {
    denoised = denoise_render(film, *aov_film);
    add_denoise_metadata(metadata, denoised->result, denoised->seconds);
  }
  write_images(cmd, plan, scene, film, aov_film ? &*aov_film : nullptr, integrator_outputs.get(), made_by, non_finite,
               metadata, denoised ? &*denoised : nullptr);
  warn_non_finite(stats, non_finite, false);
  if (frame >= 0) std::printf("frame %d: ", frame);
  print_summary(cmd, plan, outcome, options, samples, cluster, traffic, denoised ? &*denoised : nullptr);
  viewers.end = stats.cancelled ? LiveState::Stopped : LiveState::Finished;
  return finish_message(cmd, stats, samples);
}

// --frames: the scene read once, then each frame posed (animation/pose.h), rendered and written in
// turn; with --part K/N only every N-th frame of the list (a job array's share), with --skip-existing
// only the frames whose images are not all there yet.
int run_frames(RenderCommand cmd, Cluster& cluster) {
  std::vector<int> frames;
  on_every_rank(cluster, [&] {
    frames = parse_frame_list(cmd.frames);
    if (!cmd.part.empty()) {
      const auto [part_index, part_count] = parse_part(cmd.part);
      frames = frames_of_part(frames, part_index, part_count);
      cmd.part.clear();  // the part is of the frames, not of each image
    }
  });
  CommandPlan plan;
  on_every_rank(cluster, [&] { plan = plan_command(cmd, cluster); });
  if (cluster.distributed()) on_every_rank(cluster, [&] { check_same_scene(cluster, plan, cmd.scene_file); });
  const SceneDesc animated = std::move(plan.desc);
  const std::vector<fs::path> patterns = plan.outputs;
  const auto started = std::chrono::steady_clock::now();
  int rendered = 0, skipped = 0;
  for (int frame : frames) {
    // Interrupted between frames (while the last one was written): the next one is not begun.
    if (g_stop.load()) {
      if (cluster.is_root()) std::fprintf(stderr, "candela: interrupted before frame %d: it is not written\n", frame);
      return kExitInterrupted;
    }
    plan.outputs.clear();
    for (const fs::path& pattern : patterns) plan.outputs.push_back(frame_file_name(pattern.string(), frame));
    RenderCommand frame_cmd = cmd;
    if (!cmd.spp_map.empty()) frame_cmd.spp_map = frame_file_name(cmd.spp_map, frame);
    // A frame is finished when all its images exist: each is written to a temporary name and renamed.
    bool exists = cmd.skip_existing;
    for (const fs::path& f : plan.outputs) exists = exists && fs::exists(f);
    if (cluster.from_root(exists)) {
      if (cluster.is_root()) std::printf("frame %d: skipped (%s exists)\n", frame, plan.outputs.front().c_str());
      ++skipped;
      continue;
    }
    const FrameTime time = frame_time(frame, cmd.fps, cmd.shutter);
    on_every_rank(cluster, [&] {
      plan.desc = pose_scene(animated, time);
      check_resources(plan.desc);
    });
    const int status = render_planned(frame_cmd, plan, cluster, frame);
    if (status != 0) return status;
    ++rendered;
  }
  if (cluster.is_root())
    std::printf("%zu frames: %d rendered, %d skipped, in %.2f s\n", frames.size(), rendered, skipped,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  return 0;
}

int run_render(const RenderCommand& cmd, Cluster& cluster) {
  if (!cmd.frames.empty()) return run_frames(cmd, cluster);
  CommandPlan plan;
  on_every_rank(cluster, [&] { plan = plan_command(cmd, cluster); });
  if (cluster.distributed()) on_every_rank(cluster, [&] { check_same_scene(cluster, plan, cmd.scene_file); });
  return render_planned(cmd, plan, cluster);
}

// `candela convert IN OUT.json`: any scene candela reads, in its JSON format.
int run_convert(const std::string& in, const std::string& out) {
  const std::filesystem::path output(out);
  if (output.extension() != ".json")
    throw UsageError(fmt::format("convert writes candela's JSON format: the output must end in .json, got \"{}\"", out));
  check_can_write(output, fmt::format("output '{}'", out));
  SceneDesc scene = read_scene_file(in);
  g_phase.store(kWriting);
  write_json_scene(scene, output);
  std::fprintf(stderr, "%s -> %s: %zu shapes, %zu instances, %zu materials, %zu textures, %zu lights\n", in.c_str(),
               out.c_str(), scene.shapes.size(), scene.instances.size(), scene.materials.size(), scene.textures.size(),
               scene.lights.size());
  return 0;
}

// `candela merge PARTS... -o OUT`: parts of one render (--part K/N) put back together, and sample
// sets of other seeds added (render/film_part.h).
int run_merge(const std::vector<std::string>& inputs, const std::string& output) {
  check_outputs({output});
  std::vector<fs::path> files(inputs.begin(), inputs.end());
  MergedRender merged = merge_parts(files);
  g_phase.store(kWriting);
  const Film& film = merged.film;
  const double pixels = double(film.width()) * film.height();
  const uint64_t min_spp = film.min_samples(), max_spp = film.max_samples();
  std::string spp_text = min_spp == max_spp ? std::to_string(min_spp)
                                            : fmt::format("min {}, mean {:.2f}", min_spp, double(film.total_samples()) / pixels);
  std::string seeds;
  for (const std::string& seed : merged.seeds) seeds += (seeds.empty() ? "" : ",") + seed;
  auto setting = [&](const std::string& key) {
    for (const auto& [k, v] : merged.fingerprint.settings)
      if (k == key) return v;
    return std::string();
  };
  std::map<std::string, std::string> metadata = {
      {"candela:merged", merged.description},
      {"candela:spp", spp_text},
      {"candela:spp_min", std::to_string(min_spp)},
      {"candela:spp_mean", fmt::format("{:.4f}", double(film.total_samples()) / pixels)},
      {"candela:integrator", setting("integrator")},
      {"candela:transport", setting("transport")},
      {"candela:max_depth", setting("max-depth")},
      {"candela:seed", seeds},
      {"Software", "candela " CANDELA_VERSION}};
  if (merged.non_finite_samples > 0) metadata["candela:non_finite_samples"] = std::to_string(merged.non_finite_samples);
  write_image(output, film.mean_image(), metadata);
  std::printf("merged %zu files (%s): %dx%d, %s spp -> %s\n", files.size(), merged.description.c_str(), film.width(),
              film.height(), spp_text.c_str(), output.c_str());
  return 0;
}

// `candela denoise IN.exr -o OUT`: the image of a render written with --aov halves,
// denoised (denoise/denoiser.h); an .exr output keeps the input's layers and the raw image as Noisy.
int run_denoise(const std::string& input, const std::string& output) {
  check_outputs({output});
  const DenoiseFile file = read_denoise_file(input);
  const DenoiseInput& in = file.input;
  std::map<std::string, std::string> metadata;
  for (const auto& [key, value] : read_image_metadata(input))
    if (key.rfind("candela:", 0) == 0 || key == "Software") metadata[key] = value;
  const DenoisedRender denoised = denoise_render(in);
  const DenoiseResult& result = denoised.result;
  const double seconds = denoised.seconds;
  add_denoise_metadata(metadata, result, seconds);
  g_phase.store(kWriting);
  if (is_exr(output)) {
    // The input's layers, then the raw image as Noisy.
    write_image(output, result.image, metadata, append_channels(file.layers, noisy_layer(in.raw())));
  } else {
    write_image(output, result.image, metadata);
  }
  std::printf("%s -> %s: %dx%d\n%s\n", input.c_str(), output.c_str(), in.width, in.height,
              describe_denoised(result, seconds).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  install_signal_handlers();
  // Under mpirun this process is one rank of a job (render/cluster.h); otherwise it is alone.
  std::unique_ptr<Cluster> cluster;
  try {
    cluster = join_cluster(argc, argv);
  } catch (const std::exception& e) {
    if (*e.what()) std::fprintf(stderr, "candela: error: %s\n", e.what());  // empty: another rank says it
    return exit_code_for(e);
  }
  CLI::App app{"candela: a physically based Monte Carlo path tracer.\n"
               "With no arguments, renders the built-in Cornell box to cornell-box.png and cornell-box.exr."};
  app.set_version_flag("--version", "candela " CANDELA_VERSION " (" + mpi_support() + ")");
  RenderCommand cmd;
  CLI::App* render_cmd = app.add_subcommand("render", "Render a scene file to an image");
  render_cmd->add_option("scene", cmd.scene_file, "Scene file: .json (candela's format), .pbrt (pbrt-v4), .xml (Mitsuba 3), .gltf/.glb, .obj")
      ->required();
  render_cmd->add_option("-o,--output", cmd.output,
                         "Output image; the extension picks the format: .exr (linear HDR, with metadata), "
                         ".png (sRGB 8-bit), .pfm (linear). Default: the scene's film file name, else SCENE.exr");
  // The render options, from their table (description/render_options.h); then the command's own.
  for (const RenderOption& option : render_options())
    std::visit(
        [&](auto member) {
          if constexpr (std::is_same_v<decltype(cmd.*member), bool&>)
            render_cmd->add_flag(option.flag(), cmd.*member, option.help);
          else
            render_cmd->add_option(option.flag(), cmd.*member, option.help);
        },
        option.field);
  render_cmd->add_option("--preview", cmd.preview,
                         "Serve a page showing the render as it converges at [HOST:]PORT (default host 127.0.0.1; "
                         "port 0 = any free port, printed); open it in a browser (docs/preview.md)");
  render_cmd->add_flag("--preview-public", cmd.preview_public,
                       "Allow --preview on an address other machines can reach (the token is still needed; a "
                       "warning is printed)");
  render_cmd->add_option("--spp-map", cmd.spp_map,
                         "Also write the per-pixel sample counts: a heat map (.png) or raw counts (.exr, .pfm)");
  render_cmd->add_option("--display-server", cmd.display_server,
                         "Show the image as it renders in the tev viewer listening at HOST:PORT (tev's default: "
                         "127.0.0.1:14158); reconnects if tev is not there yet or restarts");
  render_cmd->add_option("--aov", cmd.aov,
                         "Also write AOV layers into the .exr output, comma-separated: albedo, normal, depth, "
                         "position, spp, variance, geometric_normal, uv, depth_derivatives, relative_variance, "
                         "or all; camera_space for camera-space positions and normals; gbuffer for pbrt-v4's "
                         "gbuffer film's layers and names (docs/cli.md)");
  render_cmd->add_flag("-q,--quiet", cmd.quiet, "No progress bar");
  render_cmd->add_option("--checkpoint", cmd.checkpoint,
                         "Write the render state to FILE (atomically) every --checkpoint-every seconds "
                         "between passes, and when interrupted or out of time");
  render_cmd->add_option("--checkpoint-every", cmd.checkpoint_every,
                         "Seconds between checkpoints (fractions allowed); needs --checkpoint");
  render_cmd->add_option("--resume", cmd.resume,
                         "Continue from a checkpoint made with the same scene file and settings; the result "
                         "equals an uninterrupted render bit for bit");
  render_cmd->add_option("--part", cmd.part,
                         "Render part K of N of the image (every N-th tile; for job arrays) and write it, with "
                         "its exact sums, to the .exr output for candela merge");
  render_cmd->add_option("--frames", cmd.frames,
                         "Render an animation's frames: FIRST-LAST, FIRST-LASTxSTEP, or frames separated by commas "
                         "(1-240, 1-240x4, 1,5,9); frame F is at time F / --fps; -o names the frame number with a run "
                         "of '#' (shot_####.exr; docs/animation.md)");
  render_cmd->add_option("--fps", cmd.fps, "Frames per second of --frames (default 24)");
  render_cmd->add_option("--shutter", cmd.shutter,
                         "With --frames: the fraction of a frame the shutter is open, centred on the frame's time "
                         "(motion blur; default 0.5, 0 = none)");
  render_cmd->add_flag("--skip-existing", cmd.skip_existing,
                       "With --frames: skip the frames whose images all exist (a restarted job renders only the "
                       "missing ones; images are written to a temporary name and renamed, so a file is never half a frame)");
  render_cmd->add_option("--pixel", cmd.pixel,
                         "Render only pixel X,Y (all its samples), print its value and its NaN/inf sample "
                         "indices; writes no image");

  std::string convert_in, convert_out;
  CLI::App* convert_cmd = app.add_subcommand(
      "convert", "Write a scene (.json, .pbrt, .xml, .obj, .gltf, .glb) in candela's JSON format");
  convert_cmd->add_option("scene", convert_in, "The scene file to read")->required();
  convert_cmd->add_option("output", convert_out, "The JSON file to write (replaced atomically)")->required();

  std::string denoise_input_file, denoise_output;
  CLI::App* denoise_cmd = app.add_subcommand(
      "denoise", "Denoise an .exr written with --aov halves (docs/denoising.md): the output's "
                 "colour is denoised, the raw image kept as its layer Noisy, the denoised image's estimated relMSE reported");
  denoise_cmd->add_option("input", denoise_input_file, "The render (an .exr written with --aov halves)")
      ->required();
  denoise_cmd->add_option("-o,--output", denoise_output, "The image to write (.exr, .png or .pfm)")->required();
  std::vector<std::string> merge_inputs;
  std::string merge_output;
  CLI::App* merge_cmd = app.add_subcommand(
      "merge", "Put the parts of a render made with --part K/N back together (the image one process renders, bit "
               "for bit), and add up renders of the same scene with other seeds");
  merge_cmd->add_option("parts", merge_inputs, "The part files (.exr written with --part)")->required();
  merge_cmd->add_option("-o,--output", merge_output, "The image to write (.exr, .png or .pfm)")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; flags that cannot be parsed are a usage error.
    int code;
    if (!cluster->is_root()) {  // every rank parsed the same words: the root alone says what is wrong
      std::ostringstream ignored;
      code = app.exit(e, ignored, ignored);
    } else {
      code = app.exit(e);
    }
    return code == 0 ? 0 : kExitUsage;
  }
  try {
    if (convert_cmd->parsed()) return cluster->is_root() ? run_convert(convert_in, convert_out) : 0;
    if (denoise_cmd->parsed()) return cluster->is_root() ? run_denoise(denoise_input_file, denoise_output) : 0;
    if (merge_cmd->parsed()) return cluster->is_root() ? run_merge(merge_inputs, merge_output) : 0;
    return run_render(cmd, *cluster);
  } catch (const AgreedError& e) {  // every rank has it: one message
    if (cluster->is_root()) std::fprintf(stderr, "candela: error: %s\n", e.what());
    return e.exit_code;
  } catch (const std::exception& e) {  // a CandelaError (base/error.h), or a bug: one message
    const int code = exit_code_for(e);
    if (!cluster->distributed()) {
      std::fprintf(stderr, "candela: error: %s\n", e.what());
    } else {
      // Past the point where the ranks agree: the others may be waiting on this one, so end the job.
      std::fprintf(stderr, "candela: error (rank %d): %s\n", cluster->rank(), e.what());
      std::fflush(stderr);
      cluster->abort(code);
    }
    return code;
  }
}
