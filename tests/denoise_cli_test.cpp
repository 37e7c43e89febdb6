// `candela render --denoise` end to end (denoise/denoised_render.h): the outputs get the denoised
// image, an .exr keeps the raw one as the layer Noisy and the AOV layers asked for alone, the
// metadata and the closing lines report both estimates; what cannot be denoised is refused.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "candela/base/error.h"
#include "candela/film/image_io.h"
#include "candela/testing/command_line.h"

namespace fs = std::filesystem;

namespace candela {
namespace {

testing::CommandResult denoise_cli(const std::string& args) {
  return testing::run_command(std::string(CANDELA_CLI_PATH) + " " + args);
}

// A sphere on a plane under a sky: texture-free, with edges for the features to find.
const char* kDenoiseCliScene = R"({
  "camera": {"position": [0, 1, -4], "look_at": [0, 0.5, 0], "fov": 40, "width": 32, "height": 32},
  "render": {"spp": 16, "seed": 3},
  "materials": {"grey": {"type": "diffuse", "reflectance": 0.5}},
  "shapes": [{"type": "sphere", "center": [0, 0.7, 0], "radius": 0.7, "material": "grey"},
             {"type": "rectangle", "corner": [-3, 0, -3], "edge_u": [0, 0, 6], "edge_v": [6, 0, 0],
              "material": "grey"}],
  "lights": [{"type": "sky", "radiance": 1}, {"type": "sphere", "center": [1.5, 3, -1], "radius": 0.3, "radiance": 40}]
})";

class DenoiseCommandLine : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_directory("candela_denoise_cli_test");
    std::ofstream(dir_ / "scene.json") << kDenoiseCliScene;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string scene() const { return (dir_ / "scene.json").string(); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

bool denoise_cli_has_channel(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

TEST_F(DenoiseCommandLine, WritesTheDenoisedImageTheNoisyLayerAndBothEstimates) {
  const testing::CommandResult r = denoise_cli("render " + scene() + " --denoise -o " + file("d.exr") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The raw image's estimate, then the denoised one's.
  const std::regex lines(
      "estimated error: relMSE [0-9.e-]+ \\(95% interval [0-9.e-]+-[0-9.e-]+, eps 0.01\\)\n"
      "denoised: relMSE [0-9.e-]+ \\(95% interval [0-9.e-]+-[0-9.e-]+, eps 0.01\\) in [0-9.]+ s\n");
  EXPECT_TRUE(std::regex_search(r.output, lines)) << r.output;

  std::map<std::string, std::string> meta = read_image_metadata(file("d.exr"));
  EXPECT_EQ(meta["candela:denoised"], "true");
  ASSERT_TRUE(meta.count("candela:relmse_estimate") && meta.count("candela:denoised_relmse_estimate")) << r.output;
  const double raw = std::stod(meta["candela:relmse_estimate"]);
  const double denoised = std::stod(meta["candela:denoised_relmse_estimate"]);
  double low = 0, high = 0;
  ASSERT_EQ(std::sscanf(meta["candela:denoised_relmse_interval95"].c_str(), "%lf %lf", &low, &high), 2);
  EXPECT_LE(low, denoised);
  EXPECT_GE(high, denoised);
  // Both are estimates of a noisy image (how much the filters gain is the denoiser's tests' to check).
  EXPECT_GT(raw, 0);
  EXPECT_GT(denoised, 0);
  EXPECT_GE(std::stod(meta["candela:denoise_seconds"]), 0);

  // RGB and Noisy alone: the halves layer the denoiser read is not written unless asked for.
  const std::vector<std::string> names = read_channel_names(file("d.exr"));
  for (const char* c : {"R", "G", "B", "Noisy.R", "Noisy.G", "Noisy.B"})
    EXPECT_TRUE(denoise_cli_has_channel(names, c)) << c;
  EXPECT_EQ(names.size(), 6u);

  // Noisy is the raw image: the render with the same two halves and no denoising, bit for bit.
  const testing::CommandResult plain =
      denoise_cli("render " + scene() + " --estimate-error -o " + file("raw.exr") + " -q");
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  const Image raw_image = read_image(file("raw.exr"));
  const FloatChannels noisy = read_float_channels(file("d.exr"), "Noisy.");
  ASSERT_EQ(noisy.names.size(), 3u);
  ASSERT_EQ(noisy.values.size(), raw_image.rgb.size());
  for (size_t i = 0; i < noisy.values.size(); i += 3)
    for (size_t c = 0; c < 3; ++c) {
      // read_float_channels gives the channels in the file's (alphabetical) order: B, G, R.
      const size_t k = size_t(std::find(noisy.names.begin(), noisy.names.end(),
                                        std::string("Noisy.") + "RGB"[c]) - noisy.names.begin());
      ASSERT_EQ(noisy.values[i + k], raw_image.rgb[i + c]) << "pixel " << i / 3;
    }
  EXPECT_EQ(meta["candela:relmse_estimate"], read_image_metadata(file("raw.exr"))["candela:relmse_estimate"]);
  const Image denoised_image = read_image(file("d.exr"));
  EXPECT_NE(denoised_image.rgb, raw_image.rgb);
}

// The layers asked for are written beside Noisy, and `candela denoise` of a file with the halves
// gives the very image --denoise wrote (one denoiser, one input).
TEST_F(DenoiseCommandLine, AskedForLayersAreKeptAndMatchTheDenoiseSubcommand) {
  const testing::CommandResult r = denoise_cli("render " + scene() + " --denoise --aov halves,albedo,position -o " +
                                               file("d.exr") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<std::string> names = read_channel_names(file("d.exr"));
  EXPECT_TRUE(denoise_cli_has_channel(names, "Albedo.R"));
  EXPECT_TRUE(denoise_cli_has_channel(names, "Position.X"));
  EXPECT_TRUE(denoise_cli_has_channel(names, "Halves.ShareA"));
  EXPECT_TRUE(denoise_cli_has_channel(names, "Noisy.G"));
  EXPECT_FALSE(denoise_cli_has_channel(names, "Normal.X"));
  EXPECT_FALSE(denoise_cli_has_channel(names, "Depth.Z"));

  const testing::CommandResult again = denoise_cli("denoise " + file("d.exr") + " -o " + file("again.exr"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(read_image(file("again.exr")).rgb, read_image(file("d.exr")).rgb);
}

TEST_F(DenoiseCommandLine, PngAndPfmOutputsGetTheDenoisedImage) {
  const testing::CommandResult exr = denoise_cli("render " + scene() + " --denoise -o " + file("d.exr") + " -q");
  ASSERT_EQ(exr.exit_code, 0) << exr.output;
  const testing::CommandResult pfm = denoise_cli("render " + scene() + " --denoise -o " + file("d.pfm") + " -q");
  ASSERT_EQ(pfm.exit_code, 0) << pfm.output;
  EXPECT_NE(pfm.output.find("denoised: relMSE"), std::string::npos) << pfm.output;
  const Image a = read_image(file("d.exr")), b = read_image(file("d.pfm"));
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  EXPECT_EQ(a.rgb, b.rgb);
  const testing::CommandResult png = denoise_cli("render " + scene() + " --denoise -o " + file("d.png") + " -q");
  ASSERT_EQ(png.exit_code, 0) << png.output;
  EXPECT_TRUE(fs::file_size(file("d.png")) > 0);
}

// Under mpirun the root alone denoises the gathered film: the same bytes and lines as one process,
// once, and every rank ends with status 0. A suite of its own, which the sanitizer run leaves out with
// the other MPI jobs (.ci/sanitizers: Open MPI's own allocations fail LeakSanitizer).
class DenoiseUnderMpirun : public DenoiseCommandLine {};

TEST_F(DenoiseUnderMpirun, TheRootDenoisesTheGatheredFilm) {
  const std::string env = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
                          "OMPI_MCA_btl_vader_single_copy_mechanism=none ";
  if (denoise_cli("--version").output.find("MPI ranks") == std::string::npos)
    GTEST_SKIP() << "candela was built without MPI";
  if (testing::run_command("command -v mpirun").exit_code != 0) GTEST_SKIP() << "mpirun is not installed";
  const testing::CommandResult one = denoise_cli("render " + scene() + " --denoise -o " + file("one.exr") + " -q");
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const testing::CommandResult two =
      testing::run_command(env + "mpirun --oversubscribe -np 2 " + std::string(CANDELA_CLI_PATH) + " render " +
                           scene() + " --denoise -o " + file("two.exr") + " -q");
  ASSERT_EQ(two.exit_code, 0) << two.output;
  const size_t first = two.output.find("denoised: relMSE");
  ASSERT_NE(first, std::string::npos) << two.output;
  EXPECT_EQ(two.output.find("denoised: relMSE", first + 1), std::string::npos) << "one report:\n" << two.output;
  EXPECT_EQ(one.output.substr(one.output.find("estimated error"), 40), two.output.substr(two.output.find("estimated error"), 40));
  EXPECT_EQ(read_image(file("one.exr")).rgb, read_image(file("two.exr")).rgb);
  EXPECT_EQ(read_float_channels(file("one.exr"), "Noisy.").values, read_float_channels(file("two.exr"), "Noisy.").values);
}

TEST_F(DenoiseCommandLine, WhatCannotBeDenoisedIsRefusedBeforeRendering) {
  struct Case {
    std::string flags, message;
  };
  const Case cases[] = {
      {"--part 1/2", "--denoise cannot be combined with --part \\(parts do not keep the AOVs"},
      {"--pixel 3,4", "--denoise cannot be combined with --pixel"},
      {"--resume " + file("none.ckpt"), "--denoise cannot be combined with --resume \\(checkpoints do not keep"},
      {"--integrator sppm", "--denoise: the sppm integrator's pixels have no two independent halves"},
      {"--aov gbuffer", "--denoise cannot be combined with pbrt-v4's gbuffer AOVs"},
  };
  for (const Case& c : cases) {
    const testing::CommandResult r =
        denoise_cli("render " + scene() + " --denoise " + c.flags + " -o " + file("refused.exr"));
    EXPECT_EQ(r.exit_code, kExitUsage) << c.flags << ":\n" << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex(c.message))) << c.flags << ":\n" << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << c.flags << ": one message expected:\n"
                                                                      << r.output;
    EXPECT_FALSE(fs::exists(file("refused.exr"))) << c.flags;
  }
}

}  // namespace
}  // namespace candela
