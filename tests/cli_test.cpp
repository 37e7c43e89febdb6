// The command line end to end: bad input exits non-zero with one message naming the file and place,
// and leaves an existing output file untouched; good input writes the image with its metadata.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "candela/film/image_io.h"
#include "candela/testing/command_line.h"

namespace fs = std::filesystem;

namespace candela {
namespace {

using RunResult = testing::CommandResult;

RunResult run_cli(const std::string& args) { return testing::run_command(std::string(CANDELA_CLI_PATH) + " " + args); }

class CommandLine : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_directory("candela_cli_test");
    // An existing output that must survive every failed run.
    std::ofstream(dir_ / "out.exr") << "previous render";
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  std::string out() const { return (dir_ / "out.exr").string(); }
  std::string previous_output() const {
    std::ifstream in(dir_ / "out.exr");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  // Runs and expects failure with a message matching `pattern`, and the old output untouched.
  void expect_failure(const std::string& args, const std::string& pattern) {
    RunResult r = run_cli(args);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_THAT_MATCHES(r.output, pattern);
    EXPECT_EQ(previous_output(), "previous render");
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one message expected:\n" << r.output;
  }
  static void EXPECT_THAT_MATCHES(const std::string& text, const std::string& pattern) {
    EXPECT_TRUE(std::regex_search(text, std::regex(pattern))) << "output:\n" << text << "\ndoes not match: " << pattern;
  }
  fs::path dir_;
};

const char* kGoodJson = R"({
  "camera": {"position": [0, 0, -3], "look_at": [0, 0, 0], "fov": 40, "width": 16, "height": 12},
  "render": {"spp": 2},
  "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}],
  "lights": [{"type": "sky", "radiance": 1}]
})";

TEST_F(CommandLine, RendersAndWritesMetadata) {
  std::string scene = write("good.json", kGoodJson);
  RunResult r = run_cli("render " + scene + " -o " + out() + " --spp 3 --threads 2 --seed 5 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT_MATCHES(r.output, "16x12, 3 spp in .* s: .* Msamples/s, .* Mrays/s");
  auto meta = read_image_metadata(out());
  EXPECT_EQ(meta["candela:spp"], "3");
  EXPECT_EQ(meta["candela:seed"], "5");
  EXPECT_EQ(meta["candela:scene"], scene);
  EXPECT_EQ(meta["candela:transport"], "rgb");
  EXPECT_TRUE(meta.count("candela:render_time_seconds"));
  Image img = read_image(out());
  EXPECT_EQ(img.width, 16);
  EXPECT_EQ(img.height, 12);
}

TEST_F(CommandLine, ResolutionAndFormatFromOptions) {
  std::string scene = write("good.json", kGoodJson);
  std::string png = (dir_ / "small.png").string(), pfm = (dir_ / "small.pfm").string();
  ASSERT_EQ(run_cli("render " + scene + " -o " + png + " --resolution 20x10 -q").exit_code, 0);
  ASSERT_EQ(run_cli("render " + scene + " -o " + pfm + " --resolution 20x10 -q").exit_code, 0);
  EXPECT_EQ(read_image(png).width, 20);
  EXPECT_EQ(read_image(pfm).height, 10);
}

TEST_F(CommandLine, AdaptiveSamplingWritesTheSppMap) {
  std::string scene = write("good.json", kGoodJson);
  std::string map = (dir_ / "spp.exr").string(), heat = (dir_ / "spp.png").string();
  std::string image = (dir_ / "adaptive.exr").string();
  RunResult r = run_cli("render " + scene + " -o " + image + " --adaptive-threshold 0.05 --adaptive-batch 4 " +
                        "--max-spp 64 --sampler stratified --spp-map " + map + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image counts = read_image(map);
  float least = 1e9f, most = 0;
  for (float c : counts.rgb) {
    EXPECT_EQ(std::fmod(c, 4.0f), 0.0f);
    least = std::min(least, c);
    most = std::max(most, c);
  }
  EXPECT_EQ(least, 4.0f);  // the sky: one batch
  EXPECT_GT(most, 16.0f);  // the sphere's edge: many more
  EXPECT_LE(most, 64.0f);
  EXPECT_NE(read_image_metadata(image)["candela:spp"].find("adaptive"), std::string::npos);
  ASSERT_EQ(run_cli("render " + scene + " -o " + image + " --adaptive-threshold 0.05 --spp-map " + heat + " -q").exit_code, 0);
  EXPECT_EQ(read_image(heat).width, 16);
  expect_failure("render " + scene + " -o " + out() + " --adaptive-threshold 0.05 --adaptive-batch 6", "power of two");
  expect_failure("render " + scene + " -o " + out() + " --sampler sobolev", "sobolev");

  // A budget: exactly 8 samples per pixel on average, the sky's pixels fewer than the sphere's.
  ASSERT_EQ(run_cli("render " + scene + " -o " + image + " --adaptive-spp 8 --adaptive-batch 2 --spp-map " + map + " -q")
                .exit_code,
            0);
  counts = read_image(map);
  double total = 0;
  least = 1e9f, most = 0;
  for (size_t i = 0; i < counts.rgb.size(); i += 3) {
    total += counts.rgb[i];
    least = std::min(least, counts.rgb[i]);
    most = std::max(most, counts.rgb[i]);
  }
  EXPECT_EQ(total, 8.0 * counts.width * counts.height);
  EXPECT_EQ(least, 2.0f);
  EXPECT_GT(most, 8.0f);
  EXPECT_LE(most, 64.0f);
  expect_failure("render " + scene + " -o " + out() + " --adaptive-spp 8 --adaptive-batch 16", "at least the batch size");
  expect_failure("render " + scene + " -o " + out() + " --adaptive-spp 64 --max-spp 32", "must be at least --adaptive-spp");
}

TEST_F(CommandLine, HelpDocumentsEveryOption) {
  RunResult r = run_cli("render --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--output", "--spp", "--threads", "--seed", "--max-depth", "--resolution", "--integrator",
                          "--sampler", "--filter", "--direction-sampling", "--no-mis", "--light-selection",
                          "--shadow-rays", "--adaptive-threshold", "--adaptive-spp", "--adaptive-batch", "--max-spp", "--spp-map",
                          "--checkpoint", "--checkpoint-every", "--resume", "--time-limit", "--clamp", "--pixel",
                          "--bdpt-strategies", "--bdpt-unweighted", "--mlt-bootstrap", "--mlt-chains", "--mlt-sigma",
                          "--mlt-large-step", "--mlt-lens", "--mlt-caustic", "--transport", "--part"})
    EXPECT_NE(r.output.find(opt), std::string::npos) << opt;
}

TEST_F(CommandLine, TransportOption) {
  // JSON scenes render in RGB unless asked; --transport overrides the scene either way.
  std::string scene = write("good.json", kGoodJson);
  expect_failure("render " + scene + " -o " + out() + " --transport hyperspectral",
                 "--transport: unknown value 'hyperspectral' \\(expected one of: rgb, spectral\\)");
  ASSERT_EQ(run_cli("render " + scene + " -o " + out() + " --spp 2 -q --transport spectral").exit_code, 0);
  EXPECT_EQ(read_image_metadata(out())["candela:transport"], "spectral");
  const std::string pbrt = std::string(CANDELA_SHARED_DIR) + "/scenes/cornell-box/cornell-box.pbrt";
  ASSERT_EQ(run_cli("render " + pbrt + " -o " + out() + " --spp 1 --resolution 8x8 -q").exit_code, 0);
  EXPECT_EQ(read_image_metadata(out())["candela:transport"], "spectral") << "pbrt-v4 files render spectrally";
  ASSERT_EQ(run_cli("render " + pbrt + " -o " + out() + " --spp 1 --resolution 8x8 -q --transport rgb").exit_code, 0);
  EXPECT_EQ(read_image_metadata(out())["candela:transport"], "rgb");
}

TEST_F(CommandLine, RenderControlOptionsAreChecked) {
  std::string scene = write("good.json", kGoodJson);
  expect_failure("render " + scene + " -o " + out() + " --checkpoint-every 1", "--checkpoint-every needs --checkpoint");
  expect_failure("render " + scene + " -o " + out() + " --resume " + (dir_ / "none.ckpt").string(), "none\\.ckpt.*cannot open");
  expect_failure("render " + scene + " -o " + out() + " --pixel 3", "--pixel");
  expect_failure("render " + scene + " -o " + out() + " --pixel 99,1", "outside");
  for (const char* bad : {"10x", "m", "1m30", "0", "0s", "-5", "2h1h"})
    expect_failure("render " + scene + " -o " + out() + " --time-limit " + bad, "--time-limit: (expected seconds or a duration|must be more than 0)");
  // Values out of range, refused before the scene is read (the file need not exist).
  expect_failure("render none.json --spp 0", "--spp: 0 is out of range \\(1 to 16777216\\)");
  expect_failure("render none.json --mlt-sigma 2", "--mlt-sigma: 2 is out of range");
  expect_failure("render none.json --clamp nan", "--clamp: must be a positive number");
  expect_failure("render none.json --checkpoint-every -1", "--checkpoint-every: must be a positive number");
  // Durations: a limit far beyond the render does not cut it short.
  for (const char* limit : {"90", "2.5", "90s", "10m", "2h", "1h30m", "1m0.5s"}) {
    RunResult r = run_cli("render " + scene + " -o " + out() + " --spp 2 -q --time-limit " + limit);
    ASSERT_EQ(r.exit_code, 0) << limit << ": " << r.output;
    EXPECT_EQ(read_image_metadata(out()).count("candela:time-limited"), 0u) << limit;
  }
}

TEST_F(CommandLine, BidirectionalAndMetropolisIntegrators) {
  std::string scene = write("good.json", kGoodJson);
  RunResult bdpt = run_cli("render " + scene + " -o " + out() + " --integrator bdpt --spp 4 -q --bdpt-strategies " +
                           dir_.string());
  ASSERT_EQ(bdpt.exit_code, 0) << bdpt.output;
  EXPECT_EQ(read_image_metadata(out())["candela:integrator"], "bdpt");
  EXPECT_TRUE(fs::exists(dir_ / "bdpt_d0_s0_t2.exr"));
  EXPECT_TRUE(fs::exists(dir_ / "bdpt_d1_s2_t1.exr"));
  RunResult mlt = run_cli("render " + scene + " -o " + out() + " --integrator mlt --spp 8 --mlt-bootstrap 500 "
                          "--mlt-chains 16 --mlt-sigma 0.02 --mlt-large-step 0.5 --mlt-lens 0.2 --mlt-caustic 0.1 -q");
  ASSERT_EQ(mlt.exit_code, 0) << mlt.output;
  EXPECT_THAT_MATCHES(mlt.output, "16x12, 8.00 mutations per pixel in");
  auto meta = read_image_metadata(out());
  EXPECT_EQ(meta["candela:integrator"], "mlt");
  EXPECT_EQ(meta["candela:mlt"], "bootstrap 500 chains 16 sigma 0.02 large-step 0.5 lens 0.2 caustic 0.1");
}

TEST_F(CommandLine, IntegratorOptionsAreChecked) {
  std::string scene = write("good.json", kGoodJson);
  expect_failure("render " + scene + " -o " + out() + " --integrator whitted", "unknown integrator 'whitted' \\(known: path, bdpt, mlt, volpath, auto\\)");
  expect_failure("render " + scene + " -o " + out() + " --bdpt-strategies " + dir_.string(),
                 "--bdpt-strategies: the path integrator writes no strategy images \\(bdpt does\\)");
  expect_failure("render " + scene + " -o " + out() + " --integrator bdpt --bdpt-strategies " + (dir_ / "nope").string(),
                 "not a directory");
  expect_failure("render " + scene + " -o " + out() + " --integrator mlt --checkpoint " + (dir_ / "c.ckpt").string(),
                 "not supported with the mlt integrator");
  expect_failure("render " + scene + " -o " + out() + " --integrator mlt --adaptive-threshold 0.1",
                 "--adaptive-threshold: the mlt integrator does not read adaptive");
  RunResult range = run_cli("render " + scene + " -o " + out() + " --integrator mlt --mlt-large-step 2");
  EXPECT_NE(range.exit_code, 0);
  EXPECT_THAT_MATCHES(range.output, "--mlt-large-step");
  expect_failure("render " + scene + " -o " + out() + " --integrator mlt --mlt-large-step 0.5 --mlt-lens 0.4 --mlt-caustic 0.2",
                 "must be at most 1, got 1.1");
  EXPECT_EQ(previous_output(), "previous render");
}

// --estimate-error, --target-error and --integrator auto (docs/error-estimates.md): the estimate in
// the closing lines and the metadata, the target reached, the auto choice reported; what cannot go
// with them refused with one message.
TEST_F(CommandLine, ErrorEstimatesTargetsAndTheAutoIntegrator) {
  std::string scene = write("good.json", kGoodJson);
  const std::string ok = (dir_ / "ok.exr").string();  // out() must survive the refused runs below
  RunResult plain = run_cli("render " + scene + " -o " + ok + " --spp 16 -q");  // one ZSobol net: no estimate
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_EQ(plain.output.find("estimated error"), std::string::npos) << plain.output;
  RunResult estimated = run_cli("render " + scene + " -o " + ok + " --spp 16 --estimate-error -q");
  ASSERT_EQ(estimated.exit_code, 0) << estimated.output;
  EXPECT_THAT_MATCHES(estimated.output, "estimated error: relMSE [0-9.e-]+ \\(95% interval [0-9.e-]+-[0-9.e-]+, eps 0.01\\)");
  EXPECT_TRUE(read_image_metadata(ok).count("candela:relmse_estimate"));

  RunResult target = run_cli("render " + scene + " -o " + ok + " --target-error 0.02 --resolution 32x24 -q");
  ASSERT_EQ(target.exit_code, 0) << target.output;
  EXPECT_THAT_MATCHES(target.output, "; target 0.02 reached");
  auto meta = read_image_metadata(ok);
  EXPECT_EQ(meta["candela:target_reached"], "true");
  EXPECT_LE(std::stod(meta["candela:relmse_estimate"]), 0.02);
  RunResult capped = run_cli("render " + scene + " -o " + ok + " --target-error 1e-9 --spp 32 -q");
  ASSERT_EQ(capped.exit_code, 0) << capped.output;
  EXPECT_THAT_MATCHES(capped.output, "target 1e-09 not reached \\(stopped at the spp limit\\)");
  EXPECT_EQ(read_image_metadata(ok)["candela:spp"], "32");

  RunResult chosen = run_cli("render " + scene + " -o " + ok + " --integrator auto --time-limit 3 -q");
  ASSERT_EQ(chosen.exit_code, 0) << chosen.output;
  EXPECT_THAT_MATCHES(chosen.output, "auto: path: relMSE .* bdpt: relMSE .* mlt: .*; chose (path|bdpt|mlt) \\(pilots");
  meta = read_image_metadata(ok);
  EXPECT_TRUE(meta["candela:integrator"] == "path" || meta["candela:integrator"] == "bdpt" || meta["candela:integrator"] == "mlt");
  EXPECT_NE(meta["candela:auto"].find("chose " + meta["candela:integrator"]), std::string::npos);

  expect_failure("render " + scene + " -o " + out() + " --target-error 0.01 --adaptive-spp 16",
                 "--target-error: adaptive sampling .* has its own stopping rule");
  expect_failure("render " + scene + " -o " + out() + " --integrator auto --checkpoint " + (dir_ / "c.ckpt").string(),
                 "--integrator auto cannot be combined with --checkpoint");
  expect_failure("render " + scene + " -o " + out() + " --target-error 0.01 --part 1/2", "--part cannot be combined with --target-error");
  RunResult negative = run_cli("render " + scene + " -o " + out() + " --target-error -1");
  EXPECT_NE(negative.exit_code, 0);
  EXPECT_EQ(previous_output(), "previous render");
}

// Every flag of a setting only some integrators read (integrators/integrator.h) is an error with an
// integrator that does not read it, naming both; the integrators that do read it accept it.
TEST_F(CommandLine, AFlagTheIntegratorDoesNotReadIsAnError) {
  std::string scene = write("good.json", kGoodJson);
  struct Case {
    const char* flag;
    const char* key;
    const char* refused_by;
    const char* read_by;
  };
  const Case cases[] = {
      {"--direction-sampling cosine", "direction_sampling", "bdpt", "path"},
      {"--no-mis", "mis", "mlt", "path"},
      {"--shadow-rays 4", "shadow_rays", "bdpt", "path"},
      {"--light-selection paper", "light_selection=paper", "bdpt", "path"},
      {"--adaptive-spp 32", "adaptive", "mlt", "path, bdpt, volpath"},
      {"--adaptive-batch 8", "adaptive", "mlt", "path, bdpt, volpath"},
      {"--max-spp 64", "adaptive", "mlt", "path, bdpt, volpath"},
      {"--mlt-bootstrap 100", "mlt", "path", "mlt"},
      {"--mlt-chains 10", "mlt", "bdpt", "mlt"},
      {"--mlt-sigma 0.1", "mlt", "path", "mlt"},
      {"--mlt-large-step 0.2", "mlt", "bdpt", "mlt"},
      {"--mlt-lens 0.1", "mlt", "path", "mlt"},
      {"--mlt-caustic 0.1", "mlt", "path", "mlt"},
  };
  for (const Case& c : cases) {
    std::string flag_name = std::string(c.flag).substr(0, std::string(c.flag).find(' ', 2));
    expect_failure("render " + scene + " -o " + out() + " --integrator " + c.refused_by + " " + c.flag,
                   flag_name + ".*: the " + c.refused_by + " integrator does not read " + c.key + " \\(.*; read by: " +
                       c.read_by + "\\)");
  }
  // Light selection by power, uniformly or through the light BVH: every integrator reads it.
  for (std::string integrator : {"path", "volpath", "bdpt", "mlt"})
    for (std::string selection : {"uniform", "bvh"}) {
      RunResult r = run_cli("render " + scene + " -o " + out() + " --integrator " + integrator +
                            " --light-selection " + selection + " --spp 1 --max-depth 2 -q" +
                            (integrator == "mlt" ? " --mlt-bootstrap 100" : ""));
      EXPECT_EQ(r.exit_code, 0) << integrator << " " << selection << ": " << r.output;
    }
}

TEST_F(CommandLine, ConvertWritesJsonThatRendersTheSameImage) {
  const std::string pbrt = std::string(CANDELA_SHARED_DIR) + "/scenes/cornell-box/cornell-box.pbrt";
  const std::string json = (dir_ / "box.json").string();
  RunResult convert = run_cli("convert " + pbrt + " " + json);
  ASSERT_EQ(convert.exit_code, 0) << convert.output;
  const std::string a = (dir_ / "a.exr").string(), b = (dir_ / "b.exr").string();
  ASSERT_EQ(run_cli("render " + pbrt + " -o " + a + " --resolution 24x24 --spp 2 -q").exit_code, 0);
  ASSERT_EQ(run_cli("render " + json + " -o " + b + " --resolution 24x24 --spp 2 -q").exit_code, 0);
  Image ia = read_image(a), ib = read_image(b);
  EXPECT_EQ(ia.rgb, ib.rgb);
}

TEST_F(CommandLine, ConvertRefusesOtherOutputsAndBadScenes) {
  std::string scene = write("good.json", kGoodJson);
  RunResult r = run_cli("convert " + scene + " " + out());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT_MATCHES(r.output, "must end in \\.json");
  EXPECT_EQ(previous_output(), "previous render");
  std::string bad = write("bad.json", "{ \"shapes\": [ { \"type\": \"torus\" } ] }");
  std::string target = write("target.json", "previous");
  RunResult refused = run_cli("convert " + bad + " " + target);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_THAT_MATCHES(refused.output, "bad\\.json.*torus");
  std::ifstream in(target);
  std::string kept((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(kept, "previous");
}

TEST_F(CommandLine, MissingSceneFile) { expect_failure("render " + (dir_ / "nope.json").string() + " -o " + out(), "nope\\.json"); }

TEST_F(CommandLine, MalformedJsonNamesLine) {
  std::string scene = write("bad.json", "{\n  \"camera\": {\n    \"fov\": 40,\n  }\n}\n");
  expect_failure("render " + scene + " -o " + out(), "bad\\.json:4:");
}

TEST_F(CommandLine, UnknownJsonKeyNamesPath) {
  std::string scene = write("bad.json", R"({"camera": {"fov": 40}, "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "colour": 1}]})");
  expect_failure("render " + scene + " -o " + out(), "bad\\.json.*/shapes/0/colour");
}

TEST_F(CommandLine, WrongJsonTypeNamesPath) {
  std::string scene = write("bad.json", R"({"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": "big"}]})");
  expect_failure("render " + scene + " -o " + out(), "bad\\.json.*/shapes/0/radius");
}

TEST_F(CommandLine, NegativeRadius) {
  std::string scene = write("bad.json", R"({"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": -1}]})");
  expect_failure("render " + scene + " -o " + out(), "bad\\.json.*/shapes/0/radius");
}

TEST_F(CommandLine, MissingMeshFile) {
  std::string scene = write("bad.json", R"({"shapes": [{"type": "mesh", "file": "missing.obj"}]})");
  expect_failure("render " + scene + " -o " + out(), "missing\\.obj");
}

TEST_F(CommandLine, UnknownPbrtDirectiveNamesLine) {
  std::string scene = write("bad.pbrt", "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"\nFrobnicate 3\n");
  expect_failure("render " + scene + " -o " + out(), "bad\\.pbrt:3:");
}

TEST_F(CommandLine, WrongPbrtParameterTypeNamesLine) {
  std::string scene = write("bad.pbrt", "WorldBegin\nShape \"sphere\"\n  \"string radius\" \"one\"\n");
  expect_failure("render " + scene + " -o " + out(), "bad\\.pbrt:[23]:");
}

TEST_F(CommandLine, MissingPbrtInclude) {
  std::string scene = write("bad.pbrt", "WorldBegin\nInclude \"nowhere.pbrt\"\n");
  expect_failure("render " + scene + " -o " + out(), "bad\\.pbrt:2.*nowhere\\.pbrt");
}

TEST_F(CommandLine, ZeroAndAbsurdResolution) {
  std::string scene = write("good.json", kGoodJson);
  expect_failure("render " + scene + " -o " + out() + " --resolution 0x0", "resolution");
  expect_failure("render " + scene + " -o " + out() + " --resolution 100000x100000", "resolution");
  std::string bad = write("bad.json", R"({"camera": {"width": 0, "height": 10}})");
  expect_failure("render " + bad + " -o " + out(), "bad\\.json.*/camera/width");
}

TEST_F(CommandLine, UnsupportedOutputAndIntegrator) {
  std::string scene = write("good.json", kGoodJson);
  expect_failure("render " + scene + " -o " + (dir_ / "out.bmp").string(), "out\\.bmp.*unsupported");
  expect_failure("render " + scene + " -o " + out() + " --integrator teleport", "teleport");
}

}  // namespace
}  // namespace candela
