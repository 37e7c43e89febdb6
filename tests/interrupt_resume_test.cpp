// The command line under interruption: SIGINT writes the partial image (exit 3), a second SIGINT
// leaves at once (exit 130), checkpoints survive kill -9 and resume to the bitwise-same image as an
// uninterrupted render, resuming with another scene or settings (or from a damaged checkpoint) is
// refused, --time-limit and --clamp do what they say.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "candela/base/error.h"
#include "candela/testing/command_line.h"
#include "candela/film/image_io.h"

namespace fs = std::filesystem;

namespace candela {
namespace {

const std::string kScene = std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-box.json";

class InterruptResume : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_directory("candela_interrupt_test");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Starts the CLI with `args`; its stdout and stderr go to a log file.
  pid_t start(const std::vector<std::string>& args) {
    std::string log = path("log" + std::to_string(runs_++) + ".txt");
    last_log_ = log;
    pid_t pid = fork();
    if (pid == 0) {
      int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      std::vector<char*> argv;
      static std::string cli = CANDELA_CLI_PATH;
      argv.push_back(cli.data());
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(cli.c_str(), argv.data());
      _exit(127);
    }
    return pid;
  }
  // Exit status, or 1000 + signal number when killed.
  static int wait_exit(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
  }
  int run(const std::vector<std::string>& args) { return wait_exit(start(args)); }
  std::string log() const {
    std::ifstream in(last_log_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  // Waits (up to 60 s) until `file` exists.
  static bool wait_for(const std::string& file) {
    auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!fs::exists(file)) {
      if (std::chrono::steady_clock::now() > until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }
  static bool same_pixels(const std::string& a, const std::string& b) {
    Image ia = read_image(a), ib = read_image(b);
    return ia.width == ib.width && ia.height == ib.height &&
           std::memcmp(ia.rgb.data(), ib.rgb.data(), ia.rgb.size() * sizeof(float)) == 0;
  }

  fs::path dir_;
  int runs_ = 0;
  std::string last_log_;
};

std::vector<std::string> operator+(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

TEST_F(InterruptResume, SigintWritesThePartialImageAndExits3) {
  std::string out = path("partial.exr"), ckpt = path("ck.bin");
  pid_t pid = start({"render", kScene, "-o", out, "--resolution", "256x256", "--spp", "100000", "-q", "--checkpoint",
                     ckpt, "--checkpoint-every", "0.2"});
  ASSERT_TRUE(wait_for(ckpt));  // rendering has begun: at least one pass is done
  const auto sent = std::chrono::steady_clock::now();
  kill(pid, SIGINT);
  ASSERT_EQ(wait_exit(pid), 3) << log();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count(), 1.0);
  EXPECT_NE(log().find("interrupted"), std::string::npos) << log();
  ASSERT_TRUE(fs::exists(out));
  auto meta = read_image_metadata(out);
  EXPECT_EQ(meta["candela:interrupted"], "true");
  long long least = std::stoll(meta["candela:spp_min"]);
  double mean = std::stod(meta["candela:spp_mean"]);
  EXPECT_GT(least, 0);
  EXPECT_GT(mean, 0);
  EXPECT_LT(mean, 100000);
  EXPECT_FALSE(meta["candela:spp"].empty());
  for (float v : read_image(out).rgb) ASSERT_TRUE(std::isfinite(v));
}

TEST_F(InterruptResume, SigtermAlsoInterrupts) {
  std::string out = path("partial.exr"), ckpt = path("ck.bin");
  pid_t pid = start({"render", kScene, "-o", out, "--resolution", "64x64", "--spp", "100000", "-q", "--checkpoint",
                     ckpt, "--checkpoint-every", "0.1"});
  ASSERT_TRUE(wait_for(ckpt));
  kill(pid, SIGTERM);
  ASSERT_EQ(wait_exit(pid), 3) << log();
  EXPECT_EQ(read_image_metadata(out)["candela:interrupted"], "true");
}

TEST_F(InterruptResume, SecondSigintExitsAtOnceWithoutWriting) {
  std::string out = path("never.exr"), ckpt = path("ck.bin");
  pid_t pid = start({"render", kScene, "-o", out, "--resolution", "256x256", "--spp", "100000", "-q", "--checkpoint",
                     ckpt, "--checkpoint-every", "0.2"});
  ASSERT_TRUE(wait_for(ckpt));
  kill(pid, SIGINT);
  kill(pid, SIGINT);
  int code = wait_exit(pid);
  // Almost always 130; 3 only if the whole partial write finished between the two signals.
  ASSERT_TRUE(code == 130 || code == 3) << code << "\n" << log();
  if (code == 130) {
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST_F(InterruptResume, ResumeAfterKillAndAfterSigintIsBitwiseTheUninterruptedRender) {
  const std::vector<std::string> common = {"--resolution", "128x128", "--spp", "64", "--seed", "7", "--threads", "2",
                                           "-q"};
  std::string ref = path("ref.exr");
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "-o", ref} + common), 0) << log();

  // kill -9 after the first checkpoint; resume.
  std::string ckpt = path("ck.bin"), out = path("resumed.exr");
  pid_t pid = start(std::vector<std::string>{"render", kScene, "-o", out, "--checkpoint", ckpt, "--checkpoint-every",
                                             "0.2"} + common);
  ASSERT_TRUE(wait_for(ckpt));
  kill(pid, SIGKILL);
  ASSERT_EQ(wait_exit(pid), 1000 + SIGKILL) << "the render finished before it could be killed";
  ASSERT_FALSE(fs::exists(out));
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "-o", out, "--resume", ckpt} + common), 0) << log();
  EXPECT_TRUE(same_pixels(out, ref));

  // SIGINT (mid-pass: pixels stop at different counts) writes a checkpoint too; resume from it.
  std::string ckpt2 = path("ck2.bin"), partial = path("partial.exr"), out2 = path("resumed2.exr");
  pid = start(std::vector<std::string>{"render", kScene, "-o", partial, "--checkpoint", ckpt2, "--checkpoint-every",
                                       "0.2"} + common);
  ASSERT_TRUE(wait_for(ckpt2));
  kill(pid, SIGINT);
  ASSERT_EQ(wait_exit(pid), 3) << log();
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "-o", out2, "--resume", ckpt2, "--checkpoint", ckpt2} +
                common),
            0)
      << log();
  EXPECT_TRUE(same_pixels(out2, ref));
}

TEST_F(InterruptResume, ResumeWithAnotherSceneOrSettingsOrDamagedCheckpointIsRefused) {
  std::string ckpt = path("ck.bin"), out = path("out.exr");
  const std::vector<std::string> common = {"--resolution", "32x32", "--seed", "3", "-q"};
  // A time-limited render writes its checkpoint when it stops.
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "-o", out, "--spp", "100000", "--time-limit", "0.01",
                                         "--checkpoint", ckpt} + common),
            0)
      << log();
  ASSERT_TRUE(fs::exists(ckpt));

  // Another request than the checkpoint's: a usage error (2); a damaged checkpoint: bad input (1).
  EXPECT_EQ(run(std::vector<std::string>{"render", kScene, "-o", out, "--spp", "128", "--resume", ckpt} + common),
            kExitUsage);
  EXPECT_NE(log().find("settings differ: spp 100000 vs 128"), std::string::npos) << log();

  // A copy of the scene with one number changed.
  std::ifstream in(kScene);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  size_t at = text.find_first_of("123456789");
  ASSERT_NE(at, std::string::npos);
  text[at] = text[at] == '9' ? '8' : char(text[at] + 1);
  std::string changed = path("changed.json");
  std::ofstream(changed) << text;
  EXPECT_EQ(run(std::vector<std::string>{"render", changed, "-o", out, "--spp", "100000", "--resume", ckpt} + common),
            kExitUsage);
  EXPECT_NE(log().find("scene file differs"), std::string::npos) << log();

  // Truncated and corrupted checkpoints.
  std::ifstream cin(ckpt, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(cin)), std::istreambuf_iterator<char>());
  std::string bad = path("bad.bin");
  std::ofstream(bad, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_EQ(run(std::vector<std::string>{"render", kScene, "-o", out, "--spp", "100000", "--resume", bad} + common),
            kExitBadInput);
  EXPECT_NE(log().find("truncated"), std::string::npos) << log();
  bytes[bytes.size() / 2] ^= 0x40;
  std::ofstream(bad, std::ios::binary) << bytes;
  EXPECT_EQ(run(std::vector<std::string>{"render", kScene, "-o", out, "--spp", "100000", "--resume", bad} + common),
            kExitBadInput);
  EXPECT_NE(log().find("corrupt (checksum mismatch)"), std::string::npos) << log();

  // Adaptive sampling does not checkpoint.
  EXPECT_EQ(run(std::vector<std::string>{"render", kScene, "-o", out, "--adaptive-threshold", "0.1", "--checkpoint",
                                         ckpt} + common),
            kExitUsage);
  EXPECT_NE(log().find("adaptive"), std::string::npos) << log();
}

TEST_F(InterruptResume, TimeLimitWritesTheImageAndExits0) {
  std::string out = path("limited.exr");
  ASSERT_EQ(run({"render", kScene, "-o", out, "--resolution", "64x64", "--spp", "100000", "--time-limit", "0.3", "-q"}),
            0)
      << log();
  auto meta = read_image_metadata(out);
  EXPECT_EQ(meta["candela:time-limited"], "true");
  EXPECT_EQ(meta.count("candela:interrupted"), 0u);
  long long spp = std::stoll(meta["candela:spp"]);
  EXPECT_GT(spp, 0);
  EXPECT_LT(spp, 100000);  // the last pass cut to what fitted: any count, the same in every pixel
}

TEST_F(InterruptResume, ClampBoundsEveryPixel) {
  std::string plain = path("plain.exr"), clamped = path("clamped.exr");
  const std::vector<std::string> common = {"--resolution", "48x48", "--spp", "16", "--filter", "box", "-q"};
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "-o", plain} + common), 0) << log();
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "-o", clamped, "--clamp", "0.5"} + common), 0) << log();
  float most = 0;
  for (float v : read_image(plain).rgb) most = std::max(most, v);
  EXPECT_GT(most, 0.5f);  // the light and bright walls exceed it unclamped
  for (float v : read_image(clamped).rgb) ASSERT_LE(v, 0.5f * (1 + 1e-5f));
  EXPECT_EQ(read_image_metadata(clamped)["candela:clamp"], "0.5");
}

TEST_F(InterruptResume, PixelRendersOnePixelAsInTheFullImage) {
  std::string full = path("full.exr");
  const std::vector<std::string> common = {"--resolution", "32x32", "--spp", "8", "--seed", "2", "-q"};
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "-o", full} + common), 0) << log();
  ASSERT_EQ(run(std::vector<std::string>{"render", kScene, "--pixel", "20,11"} + common), 0) << log();
  std::string text = log();
  float r, g, b;
  unsigned long long n;
  ASSERT_EQ(std::sscanf(text.c_str(), "pixel (20, 11): %g %g %g (%llu samples)", &r, &g, &b, &n), 4) << text;
  EXPECT_EQ(n, 8u);
  EXPECT_NE(text.find("non-finite samples: none"), std::string::npos) << text;
  RGB expected = read_image(full).at(20, 11);
  EXPECT_EQ(r, expected.r);
  EXPECT_EQ(g, expected.g);
  EXPECT_EQ(b, expected.b);
  EXPECT_EQ(run(std::vector<std::string>{"render", kScene, "--pixel", "40,1"} + common), kExitUsage);
}

}  // namespace
}  // namespace candela

namespace candela {
namespace {

// Signals sent to a running render: after the handler is installed, with a bound on the wait.
class SignalledRender : public InterruptResume {
 protected:
  // Sends `sig`, waits up to `limit` seconds for the exit; returns the status (-1 if it had to be
  // killed) and the seconds from the signal to the exit.
  static std::pair<int, double> signal_and_wait(pid_t pid, int sig, double limit = 5.0) {
    const auto sent = std::chrono::steady_clock::now();
    kill(pid, sig);
    for (;;) {
      int status = 0;
      if (waitpid(pid, &status, WNOHANG) == pid) {
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
        return {WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status), seconds};
      }
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count() > limit) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        return {-1, limit};
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  // Waits until the process catches SIGTERM (/proc/PID/status SigCgt): its handler is installed at the
  // start of main, and a signal before that (while the shared libraries load) would simply kill it.
  static void wait_until_handling_signals(pid_t pid) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < until) {
      std::ifstream in("/proc/" + std::to_string(pid) + "/status");
      std::string line;
      while (std::getline(in, line))
        if (line.starts_with("SigCgt:") && (std::stoull(line.substr(7), nullptr, 16) >> (SIGTERM - 1) & 1)) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
};

class MltInterrupt : public SignalledRender {};

TEST_F(MltInterrupt, SigtermDuringTheBootstrapOfADeepRenderIsAnsweredWithinASecond) {
  // MLT's bootstrap and normalisation take one batch of paths per depth: at max depth 400 they run
  // for many seconds before the first chain. A signal must still stop the render within a second,
  // writing the image so far (the directly seen emission).
  std::string out = path("mlt.exr");
  pid_t pid = start({"render", kScene, "-o", out, "--integrator", "mlt", "--max-depth", "400", "--resolution",
                     "32x32", "--spp", "64", "-q"});
  wait_until_handling_signals(pid);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the scene is read, the bootstrap runs
  const auto [code, seconds] = signal_and_wait(pid, SIGTERM);
  ASSERT_EQ(code, 3) << log();
  EXPECT_LT(seconds, 1.0) << log();
  EXPECT_EQ(read_image_metadata(out)["candela:interrupted"], "true");
}

}  // namespace
}  // namespace candela

namespace candela {
namespace {

// Before rendering begins there is nothing worth keeping: the first SIGINT/SIGTERM while the scene is
// read or built (the BVH of a big mesh can take many seconds) leaves at once with status 3 and writes
// nothing. Each test sends the signal, requires the exit within a second of it, and kills the child
// after a few seconds so that a regression fails instead of hanging.
class PrepareInterrupt : public SignalledRender {
 protected:
  // Bytes the process has read so far (/proc/PID/io rchar).
  static long long bytes_read(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/io");
    std::string key;
    long long value = 0;
    while (in >> key >> value)
      if (key == "rchar:") return value;
    return -1;
  }
  // A binary PLY of an n x n grid of bumpy quads (2 n^2 triangles): quick to read, seconds of BVH build.
  void write_grid_ply(const std::string& file, int n) {
    std::ofstream out(file, std::ios::binary);
    const int v = n + 1;
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << v * v
        << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << 2LL * n * n
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    std::vector<float> xyz;
    xyz.reserve(size_t(v) * v * 3);
    for (int j = 0; j < v; ++j)
      for (int i = 0; i < v; ++i) {
        const float x = float(i) / n - 0.5f, z = float(j) / n - 0.5f;
        xyz.insert(xyz.end(), {x, 0.05f * std::sin(40 * x) * std::cos(37 * z), z});
      }
    out.write(reinterpret_cast<const char*>(xyz.data()), std::streamsize(xyz.size() * sizeof(float)));
    std::vector<char> faces(size_t(2) * n * n * 13);
    char* p = faces.data();
    auto face = [&](int a, int b, int c) {
      *p++ = 3;
      for (int index : {a, b, c}) {
        std::memcpy(p, &index, 4);
        p += 4;
      }
    };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = j * v + i;
        face(a, a + 1, a + v + 1);
        face(a, a + v + 1, a + v);
      }
    out.write(faces.data(), std::streamsize(faces.size()));
  }
  void write_mesh_scene(const std::string& file, const std::string& mesh) {
    std::ofstream(file) << R"({ "camera": { "position": [0, 2, -2], "look_at": [0, 0, 0], "fov": 40, "width": 32, "height": 32 },
  "materials": { "white": { "type": "diffuse", "reflectance": [0.7, 0.7, 0.7] } },
  "shapes": [ { "type": "mesh", "file": ")" << mesh << R"(", "material": "white" } ],
  "lights": [ { "type": "sky", "zenith": [1, 1, 1], "horizon": [1, 1, 1] } ] })";
  }
  static std::string file_text(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
};

TEST_F(PrepareInterrupt, SigtermWhileTheSceneFileIsStillBeingReadLeavesAtOnceWritingNothing) {
  // A scene file that never finishes arriving (a FIFO nobody writes: a stalled network share): the
  // reader blocks and looks at no flag; the signal must still end the command at once.
  const std::string scene = path("stalled.json"), out = path("out.exr");
  ASSERT_EQ(mkfifo(scene.c_str(), 0644), 0) << std::strerror(errno);
  std::ofstream(out) << "an earlier image";
  pid_t pid = start({"render", scene, "-o", out, "-q"});
  wait_until_handling_signals(pid);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto [code, seconds] = signal_and_wait(pid, SIGTERM);
  ASSERT_EQ(code, 3) << log();
  EXPECT_LT(seconds, 1.0);
  EXPECT_NE(log().find("interrupted while reading the scene: nothing written"), std::string::npos) << log();
  EXPECT_EQ(file_text(out), "an earlier image");  // the existing output is left as it was
  for (const auto& entry : fs::directory_iterator(dir_))  // no temporaries either
    EXPECT_TRUE(entry.path() == scene || entry.path() == out || entry.path().filename().string().starts_with("log"))
        << entry.path();
}

TEST_F(PrepareInterrupt, SigintWhileABigMeshIsReadOrItsBvhBuiltLeavesAtOnceWritingNothing) {
  // About a million triangles: seconds of reading (the PLY's conversion) and of (high-quality) BVH
  // build, neither of which looks at a flag. The signal goes once the file's bytes are in, normally
  // during the BVH build; under load it may still be converting, equally before rendering.
  const std::string mesh = path("grid.ply"), scene = path("grid.json"), out = path("out.exr"),
                    ckpt = path("ck.bin");
  write_grid_ply(mesh, 700);
  write_mesh_scene(scene, mesh);
  const long long mesh_bytes = (long long)fs::file_size(mesh);
  pid_t pid = start({"render", scene, "-o", out, "-q", "--checkpoint", ckpt});
  wait_until_handling_signals(pid);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (bytes_read(pid) < mesh_bytes && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto [code, seconds] = signal_and_wait(pid, SIGINT);
  ASSERT_EQ(code, 3) << log();
  EXPECT_LT(seconds, 1.0);
  EXPECT_TRUE(log().find("interrupted while building the scene (textures, BVH): nothing written") != std::string::npos ||
              log().find("interrupted while reading the scene: nothing written") != std::string::npos)
      << log();
  std::printf("phase interrupted: %s", log().c_str());
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(ckpt));
}

}  // namespace
}  // namespace candela
