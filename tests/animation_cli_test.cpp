// Animation from the command line (docs/animation.md): --frames renders a glTF sample's keyframed
// motion (the moving object's pixel centroid follows the projection of its keyframed position), a
// sequence interrupted and restarted with --skip-existing gives the same pixels, bit for bit, as one
// uninterrupted run (an interrupted frame is never written), and --part K/N shares the frames out to a
// job array with the same pixels again.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "candela/animation/pose.h"
#include "candela/camera/camera.h"
#include "candela/film/image_io.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/command_line.h"

namespace fs = std::filesystem;

namespace candela {
namespace {

const std::string kBoxAnimated = std::string(CANDELA_SHARED_DIR) + "/meshes/gltf-animated/BoxAnimated/BoxAnimated.gltf";
const std::string kCli = CANDELA_CLI_PATH;

class AnimationCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kBoxAnimated)) GTEST_SKIP() << "no " << kBoxAnimated;
    dir_ = testing::fresh_test_directory("candela_animation_cli");
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  testing::CommandResult candela(const std::string& args) {
    return testing::run_command("cd '" + dir_.string() + "' && " + kCli + " render " + args);
  }
  fs::path dir_;
};

// BoxAnimated (Khronos): node 0 carries the inner box up along +y, linearly from 0 at t = 0 to 2.52
// at t = 1.25 s, holds it to 2.5 s and brings it back to 0 at 3.708 s (the file's keyframes); the
// outer box stays in [-0.5, 0.5]^3.
float box_height(float t) {
  if (t <= 1.25f) return 2.52f * t / 1.25f;
  if (t <= 2.5f) return 2.52f;
  return 2.52f * (1 - (t - 2.5f) / (3.708329916f - 2.5f));
}

// The renders that check what a sequence shows (keyframed motion, job-array parts): a suite of their own,
// which the sanitizer run leaves out (its frame loop runs instrumented in AnimationCli).
using AnimationFrames = AnimationCli;

TEST_F(AnimationFrames, TheMovingBoxFollowsItsKeyframes) {
  const int size = 96, fps = 4;
  const std::string frames = "3-11x2,12";  // t = 0.75 ... 3 s: the inner box clear of the outer one
  const auto r = candela(kBoxAnimated + " --frames " + frames + " --fps 4 --shutter 0 --spp 4 --resolution 96x96 "
                         "--aov position -q -o box_##.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The camera the reader frames the model with (it does not move).
  SceneDesc desc = read_scene_file(kBoxAnimated);
  const SceneDesc still = pose_scene(desc, frame_time(0, fps, 0));
  const Camera camera(still.camera, size, size);
  const Point3 eye = still.camera.world_from_camera.point({0, 0, 0});
  for (int frame : {3, 5, 7, 9, 11, 12}) {
    const float t = float(frame) / fps, height = box_height(t);
    ASSERT_GT(height, 1.1f) << "frame " << frame << " has the boxes overlapping";
    const FloatChannels p = read_float_channels(path(fmt::format("box_{:02d}.exr", frame)), "Position.");
    ASSERT_EQ(p.names.size(), 3u);
    // The inner box's pixels: first hits above the outer box.
    double sx = 0, sy = 0, n = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        if (p.values[3 * (size_t(y) * size + x) + 1] > 0.6f) {
          sx += x + 0.5;
          sy += y + 0.5;
          ++n;
        }
    ASSERT_GT(n, 20) << "frame " << frame;
    Vec2 raster;
    ASSERT_GT(camera.importance(eye, normalize(Point3(0, height, 0) - eye), &raster), 0);
    EXPECT_NEAR(sx / n, raster.x, 1.0) << "frame " << frame << ", t = " << t;
    EXPECT_NEAR(sy / n, raster.y, 1.0) << "frame " << frame << ", t = " << t;
  }
}

// The same pixels, bit for bit (the files' bytes differ only in the render time and date metadata).
bool same_pixels(const std::string& a, const std::string& b) {
  if (!fs::exists(a) || !fs::exists(b)) return false;
  const Image ia = read_image(a), ib = read_image(b);
  return ia.width == ib.width && ia.height == ib.height &&
         std::memcmp(ia.rgb.data(), ib.rgb.data(), ia.rgb.size() * sizeof(float)) == 0;
}

std::vector<std::string> sequence_files(const std::string& dir, int first, int last) {
  std::vector<std::string> files;
  for (int f = first; f <= last; ++f) files.push_back(fmt::format("{}/seq_{:03d}.exr", dir, f));
  return files;
}

TEST_F(AnimationCli, AnInterruptedSequenceRestartsWhereItStopped) {
  const std::string args = kBoxAnimated + " --frames 0-7 --fps 3 --spp 96 --resolution 96x96 -q";
  fs::create_directories(dir_ / "whole");
  fs::create_directories(dir_ / "restarted");
  const auto whole = candela(args + " -o whole/seq_###.exr");
  ASSERT_EQ(whole.exit_code, 0) << whole.output;

  // Interrupted once its third frame is written, then restarted with --skip-existing.
  const std::string log = path("interrupted.log");
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    if (chdir(dir_.c_str()) != 0) _exit(126);
    execl(kCli.c_str(), kCli.c_str(), "render", kBoxAnimated.c_str(), "--frames", "0-7", "--fps", "3", "--spp", "96",
          "--resolution", "96x96", "-q", "-o", "restarted/seq_###.exr", (char*)nullptr);
    _exit(127);
  }
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(dir_ / "restarted/seq_002.exr") && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string interrupted = testing::file_bytes(log);
  ASSERT_TRUE(WIFEXITED(status)) << interrupted;
  ASSERT_EQ(WEXITSTATUS(status), 3) << interrupted;  // interrupted
  // Stopped in a frame's render ("... not written") or while its scene was built ("... nothing written").
  EXPECT_TRUE(interrupted.find("not written") != std::string::npos ||
              interrupted.find("nothing written") != std::string::npos)
      << interrupted;
  int written = 0;
  for (const std::string& f : sequence_files(path("restarted"), 0, 7)) written += fs::exists(f);
  ASSERT_GE(written, 3);
  ASSERT_LT(written, 8) << "the sequence finished before the interruption: make its frames slower";
  for (const auto& entry : fs::directory_iterator(dir_ / "restarted"))  // nothing half-written is left
    EXPECT_EQ(entry.path().extension(), ".exr") << entry.path();

  const auto restarted = candela(args + " --skip-existing -o restarted/seq_###.exr");
  ASSERT_EQ(restarted.exit_code, 0) << restarted.output;
  EXPECT_NE(restarted.output.find(fmt::format("8 frames: {} rendered, {} skipped", 8 - written, written)),
            std::string::npos)
      << restarted.output;
  const std::vector<std::string> a = sequence_files(path("whole"), 0, 7), b = sequence_files(path("restarted"), 0, 7);
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(same_pixels(a[i], b[i])) << b[i] << " differs from " << a[i];
  // The frames differ from each other: the box moves.
  EXPECT_FALSE(same_pixels(a[0], a[4]));
}

TEST_F(AnimationFrames, JobArrayPartsRenderTheSameFrames) {
  const std::string args = kBoxAnimated + " --frames 0-23x3 --fps 8 --spp 4 --resolution 48x48 -q";
  fs::create_directories(dir_ / "one");
  fs::create_directories(dir_ / "parts");
  ASSERT_EQ(candela(args + " -o one/f_##.exr").exit_code, 0);
  for (int k = 1; k <= 3; ++k) {
    const auto r = candela(args + fmt::format(" --part {}/3 -o parts/f_##.exr", k));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  for (int f = 0; f <= 21; f += 3) {
    const std::string name = fmt::format("f_{:02d}.exr", f);
    EXPECT_TRUE(same_pixels(path("one/" + name), path("parts/" + name))) << name;
  }
}

// Under mpirun the ranks render each frame together: the frames of one process, bit for bit. (A suite
// of its own: the sanitizer run leaves MPI jobs out, as Open MPI never frees some of its memory.)
using DistributedFrames = AnimationCli;
TEST_F(DistributedFrames, RanksRenderTheFramesOfOneProcess) {
  if (testing::run_command("command -v mpirun").exit_code != 0) GTEST_SKIP() << "mpirun is not installed";
  const std::string args = kBoxAnimated + " --frames 2-8x3 --fps 4 --spp 8 --resolution 48x48 -q";
  fs::create_directories(dir_ / "one");
  fs::create_directories(dir_ / "ranks");
  ASSERT_EQ(candela(args + " -o one/f_#.exr").exit_code, 0);
  const auto r = testing::run_command("cd '" + dir_.string() +
                                      "' && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
                                      "OMPI_MCA_btl_vader_single_copy_mechanism=none mpirun --oversubscribe -np 2 " +
                                      kCli + " render " + args + " -o ranks/f_#.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("3 frames: 3 rendered, 0 skipped"), std::string::npos) << r.output;
  for (int f : {2, 5, 8}) {
    const std::string name = fmt::format("f_{}.exr", f);
    EXPECT_TRUE(same_pixels(path("one/" + name), path("ranks/" + name))) << name;
  }
}

TEST_F(AnimationCli, RefusesWhatASequenceCannotDo) {
  struct Case {
    std::string args, expected;
  };
  for (const Case& c : std::vector<Case>{
           {"--frames 1-3 -o still.exr", "run of '#'"},
           {"--frames 3-1 -o f_#.exr", "runs backwards"},
           {"--frames 1-3 --fps 0 -o f_#.exr", "--fps"},
           {"--frames 1-3 --shutter 2 -o f_#.exr", "--shutter"},
           {"--skip-existing -o f.exr", "needs --frames"},
           {"--frames 1-3 --checkpoint c.bin -o f_#.exr", "--checkpoint"},
           {"--frames 1-3 --pixel 1,1", "--pixel"}}) {
    const auto r = candela(kBoxAnimated + " --resolution 16x16 --spp 1 -q " + c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args << "\n" << r.output;
  }
}

}  // namespace
}  // namespace candela
