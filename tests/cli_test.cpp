// The command line end to end: bad input exits non-zero with one message naming the file and place,
// and leaves an existing output file untouched; good input writes the image with its metadata.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <set>
#include <sstream>

#include "candela/base/error.h"
#include "candela/film/image_io.h"
#include "candela/testing/command_line.h"
#include "candela/testing/gzip_bytes.h"

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
  RunResult expect_failure(const std::string& args, const std::string& pattern) {
    RunResult r = run_cli(args);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_THAT_MATCHES(r.output, pattern);
    EXPECT_EQ(previous_output(), "previous render");
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one message expected:\n" << r.output;
    return r;
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
  expect_failure("render " + scene + " -o " + out() + " --adaptive-spp 64 --max-spp 32", "--max-spp: must be at least the mean spp \\(64\\), got 32");
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

TEST_F(CommandLine, PhotonMappingIntegrator) {
  std::string scene = write("good.json", kGoodJson);
  RunResult sppm = run_cli("render " + scene + " -o " + out() + " --integrator sppm --spp 3 --sppm-photons 500 "
                           "--sppm-radius 0.2 -q");
  ASSERT_EQ(sppm.exit_code, 0) << sppm.output;
  EXPECT_THAT_MATCHES(sppm.output, "16x12, 3 iterations in");
  auto meta = read_image_metadata(out());
  EXPECT_EQ(meta["candela:integrator"], "sppm");
  EXPECT_EQ(meta["candela:sppm"], "photons-per-iteration 500 radius 0.2");
  write("out.exr", "previous render");
  expect_failure("render " + scene + " -o " + out() + " --integrator sppm --target-error 0.01",
                 "--target-error: the sppm integrator gives no error estimate");
  expect_failure("render " + scene + " -o " + out() + " --sppm-radius 0.2",
                 "--sppm-radius: the path integrator does not read sppm");
  expect_failure("render " + scene + " -o " + out() + " --integrator sppm --sppm-radius 0",
                 "--sppm-radius");
}

TEST_F(CommandLine, IntegratorOptionsAreChecked) {
  std::string scene = write("good.json", kGoodJson);
  expect_failure("render " + scene + " -o " + out() + " --integrator whitted", "unknown integrator 'whitted' \\(known: path, bdpt, mlt, volpath, ambient_occlusion, light_path, sppm, auto\\)");
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
      {"--adaptive-spp 32", "adaptive", "mlt", "path, bdpt, volpath, ambient_occlusion"},
      {"--adaptive-batch 8", "adaptive", "mlt", "path, bdpt, volpath, ambient_occlusion"},
      {"--max-spp 64", "adaptive", "mlt", "path, bdpt, volpath, ambient_occlusion"},
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

// One exit status per kind of error (base/error.h, docs/cli.md "Exit status"), with the one-line message.
TEST_F(CommandLine, ExitStatusNamesTheKindOfError) {
  const std::string scene = write("good.json", kGoodJson);
  const std::string render = "render " + scene + " -o " + out() + " -q";
  // 1: the scene (or a file it names) is bad.
  EXPECT_EQ(expect_failure("render " + write("bad.json", "{\"camera\": ") + " -o " + out(), "^candela: error: .*bad\\.json")
                .exit_code,
            kExitBadInput);
  // 2: a request refused: a value out of range, flags that exclude each other, a flag CLI11 does not know or
  // cannot read, a missing argument.
  EXPECT_EQ(expect_failure(render + " --spp 0", "^candela: error: --spp").exit_code, kExitUsage);
  EXPECT_EQ(expect_failure(render + " --pixel 1,1 --part 1/2", "^candela: error: --part cannot be combined with --pixel")
                .exit_code,
            kExitUsage);
  RunResult unknown = run_cli(render + " --no-such-flag");
  EXPECT_EQ(unknown.exit_code, kExitUsage) << unknown.output;
  EXPECT_THAT_MATCHES(unknown.output, "--no-such-flag");
  EXPECT_EQ(run_cli(render + " --spp many").exit_code, kExitUsage);
  EXPECT_EQ(run_cli("render").exit_code, kExitUsage);
  EXPECT_EQ(previous_output(), "previous render");
  // 0: --help and --version are not errors.
  EXPECT_EQ(run_cli("--help").exit_code, 0);
  EXPECT_EQ(run_cli("render --help").exit_code, 0);
  EXPECT_EQ(run_cli("--version").exit_code, 0);
  // 4: a file that cannot be written once rendered: bdpt's strategy images into /sys, which takes no new
  // files even from root (the directory itself is only checked to exist before rendering).
  if (testing::run_command("touch /sys/candela-probe").exit_code == 0) GTEST_SKIP() << "/sys is writable here";
  const std::string ok = (dir_ / "ok.exr").string();
  RunResult unwritable = run_cli("render " + scene + " -o " + ok + " -q --integrator bdpt --spp 1 --bdpt-strategies /sys");
  EXPECT_EQ(unwritable.exit_code, kExitOutput) << unwritable.output;
  EXPECT_THAT_MATCHES(unwritable.output, "^candela: error: /sys/bdpt_d0_s0_t2\\.exr: cannot write image: ");
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

// ---------------------------------------------------------------- hostile inputs

// The table "Hostile inputs" of docs/reliability.md: each input is refused with one message naming the
// file (and line) and the limit, exit status 1 (2 for a flag's value or an output refused before the
// scene is read), no crash, and no file written or left behind.
class HostileInput : public CommandLine {
 protected:
  void expect_refused(const std::string& args, const std::string& pattern, int exit_code = kExitBadInput) {
    const std::set<std::string> before = files();
    EXPECT_EQ(expect_failure(args, "^candela: error: " + pattern).exit_code, exit_code);
    EXPECT_EQ(files(), before);
  }
  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.insert(entry.path().filename().string());
    return names;
  }
  // `text` as a regular expression that matches it literally.
  static std::string quoted(const std::string& text) {
    return std::regex_replace(text, std::regex(R"([.^$|()\[\]*+?{}\\])"), R"(\$&)");
  }
};

TEST_F(HostileInput, GzipBombInAnInclude) {
  const std::string bomb = write("bomb.pbrt.gz", testing::gzip_bomb(1025));  // 1 MB, 1025 MiB inflated
  const std::string scene = write("scene.pbrt", "WorldBegin\nInclude \"bomb.pbrt.gz\"\n");
  expect_refused("render " + scene + " -o " + out(),
                 quoted(scene + ":2:9: cannot read \"" + bomb + "\": gzip: it decompresses to more than 1.0 GiB, the "
                        "limit for a gzipped file (a gzip bomb?); gunzip it to read it without this limit"));
}

TEST_F(HostileInput, DeepIncludesAndInstancing) {
  // pbrt: a file including itself; a chain of 100 files; objects inside objects.
  const std::string self = write("self.pbrt", "WorldBegin\nInclude \"self.pbrt\"\n");
  expect_refused("render " + self + " -o " + out(), quoted(self + ":2:9: \"" + self + "\" includes itself"));
  for (int k = 1; k < 100; ++k) write(fmt::format("f{}.pbrt", k), fmt::format("Include \"f{}.pbrt\"\n", k + 1));
  write("f100.pbrt", "Shape \"sphere\"\n");
  const std::string chain = write("chain.pbrt", "WorldBegin\nInclude \"f1.pbrt\"\n");
  expect_refused("render " + chain + " -o " + out(), ".*f63\\.pbrt:1:9: files are included more than 64 deep \\(in the "
                 "file included at .*f62\\.pbrt:1:9, included at .*f61\\.pbrt:1:9, \\.\\.\\. 60 more Includes "
                 "\\.\\.\\., included at .*chain\\.pbrt:2:9\\)\n");
  const std::string nested = write("nested.pbrt", "WorldBegin\nObjectBegin \"a\"\nObjectBegin \"b\"\n");
  expect_refused("render " + nested + " -o " + out(),
                 ".*nested\\.pbrt:3:1: ObjectBegin inside the definition of \"a\"");
  const std::string instance = write("instance.pbrt", "WorldBegin\nObjectBegin \"a\"\nObjectInstance \"a\"\n");
  expect_refused("render " + instance + " -o " + out(), ".*instance\\.pbrt:3:1: ObjectInstance inside the definition");
  // Mitsuba: objects nested 100,000 deep; a file including itself.
  std::string deep = "<scene version=\"3.0.0\">\n";
  for (int k = 0; k < 100000; ++k) deep += "<bsdf type=\"twosided\">";
  for (int k = 0; k < 100000; ++k) deep += "</bsdf>";
  const std::string xml = write("deep.xml", deep + "\n</scene>\n");
  expect_refused("render " + xml + " -o " + out(), quoted(xml + ":2: <bsdf> is nested more than 100 objects deep"));
  const std::string self_xml = write("self.xml", "<scene version=\"3.0.0\"><include filename=\"self.xml\"/></scene>");
  expect_refused("render " + self_xml + " -o " + out(), ".*self\\.xml:1: more than 15 nested <include>s");
}

TEST_F(HostileInput, AbsurdResolution) {
  const std::string scene = write("good.json", kGoodJson);
  expect_refused("render " + scene + " -o " + out() + " --resolution 1000000000x1000000000",
                 quoted("resolution 1000000000x1000000000 is out of range (each side 1..65536, at most 268435456 "
                        "pixels)"),
                 kExitUsage);
  const std::string pbrt = write("wide.pbrt", "Film \"rgb\" \"integer xresolution\" 1000000000\nWorldBegin\n");
  expect_refused("render " + pbrt + " -o " + out(),
                 quoted(pbrt + ":1:12: Film \"rgb\": \"xresolution\" must be between 1 and 65536, got 1000000000"));
  const std::string json = write("wide.json", R"({"camera": {"width": 1000000000, "height": 1000000000}})");
  expect_refused("render " + json + " -o " + out(),
                 quoted(json) + ":1:13: at /camera/width: expected an integer in \\[1, 65536\\], got 1000000000");
}

TEST_F(HostileInput, TextureHeaderClaimingTenBillionTexels) {
  // A PFM of a few bytes whose header says 100000 x 100000.
  const std::string pfm = write("huge.pfm", "PF\n100000 100000\n-1.0\n" + std::string(1200, '\0'));
  const std::string scene =
      write("texture.json", R"({"textures": {"wood": {"type": "image", "filename": ")" + pfm + R"("}},
  "materials": {"m": {"type": "diffuse", "reflectance": "wood"}},
  "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  expect_refused("render " + scene + " -o " + out(),
                 quoted(scene + ":1:15: at /textures/wood: " + pfm + ": the image is 100000 x 100000 texels, more "
                        "than candela reads (at most 65536 on a side and 536870912 = 2^29 in all)"));
}

TEST_F(HostileInput, MeshIndicesAndCountsNearTwoToThe32) {
  const std::string obj = write("big.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2147483648\n");
  expect_refused("render " + obj + " -o " + out(),
                 quoted(obj + ": cannot read mesh '" + obj + "': malformed OBJ: line 4: face index '2147483648' is out "
                        "of range (at most 2147483647 in size)"));
  const std::string ply = write("big.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\n"
                                           "property float x\nproperty float y\nproperty float z\nend_header\n" +
                                               std::string(36, '\0'));
  expect_refused("render " + ply + " -o " + out(),
                 quoted(ply + ": cannot read mesh '" + ply + "': corrupt PLY header") + ".*4294967295 'vertex'");
}

TEST_F(HostileInput, NonFinitePlyVertices) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string nan = write("nan.ply", header + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n");
  expect_refused("render " + nan + " -o " + out(), quoted(nan + ": cannot read mesh '" + nan +
                                                          "': malformed PLY: line 11: 'nan' is not a finite number"));
  std::string binary = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float vertices[9] = {0, 0, 0, std::numeric_limits<float>::infinity(), 0, 0, 0, 1, 0};
  const int32_t face[3] = {0, 1, 2};
  binary.append(reinterpret_cast<const char*>(vertices), sizeof vertices).append(1, '\3');
  binary.append(reinterpret_cast<const char*>(face), sizeof face);
  const std::string inf = write("inf.ply", binary);
  expect_refused("render " + inf + " -o " + out(),
                 quoted(inf + ": cannot read mesh '" + inf + "': vertex 1 has a non-finite position (inf, 0, 0)"));
}

TEST_F(HostileInput, DamagedCheckpoint) {
  // (Every 64th truncation and bit flip: CheckpointFile.EveryTruncationAndBitFlipIsRefused.)
  const std::string scene = write("good.json", kGoodJson);
  const std::string checkpoint = (dir_ / "render.ckpt").string(), image = (dir_ / "image.exr").string();
  ASSERT_EQ(run_cli("render " + scene + " -o " + image + " --spp 8 --checkpoint " + checkpoint +
                    " --checkpoint-every 0.000001 -q").exit_code, 0);
  const std::string good = testing::file_bytes(checkpoint);
  ASSERT_GT(good.size(), 1000u);
  write("render.ckpt", good.substr(0, good.size() / 2));
  expect_refused("render " + scene + " -o " + out() + " --spp 16 --resume " + checkpoint,
                 quoted("checkpoint '" + checkpoint + "': truncated (") + ".*");
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x08;
  write("render.ckpt", flipped);
  expect_refused("render " + scene + " -o " + out() + " --spp 16 --resume " + checkpoint,
                 quoted("checkpoint '" + checkpoint + "': corrupt (checksum mismatch)"));
}

TEST_F(HostileInput, OutputsThatCannotBeWritten) {
  const std::string scene = write("good.json", kGoodJson);
  // Found before the scene is read: a usage error (status 2), as any refused flag.
  expect_refused("render " + scene + " -o /dev/full/x.png",
                 quoted("output '/dev/full/x.png': '/dev/full' is not a directory"), kExitUsage);
  fs::create_directory(dir_ / "folder.exr");
  const std::string folder = (dir_ / "folder.exr").string();
  expect_refused("render " + scene + " -o " + folder, quoted("output '" + folder + "': it is a directory"), kExitUsage);
  // /sys takes no new files, even from root (for whom permissions do not stop a write).
  if (testing::run_command("touch /sys/candela-probe").exit_code == 0) GTEST_SKIP() << "/sys is writable here";
  const std::string in_sys = ": cannot write in directory '/sys': .+";
  expect_refused("render " + scene + " -o /sys/x.png", quoted("output '/sys/x.png'") + in_sys, kExitUsage);
  const std::string render = "render " + scene + " -o " + out();
  expect_refused(render + " --checkpoint /sys/x.ckpt", quoted("--checkpoint '/sys/x.ckpt'") + in_sys, kExitUsage);
  expect_refused(render + " --spp-map /sys/x.png", quoted("--spp-map '/sys/x.png'") + in_sys, kExitUsage);
  expect_refused("convert " + scene + " /sys/x.json", quoted("output '/sys/x.json'") + in_sys, kExitUsage);
  expect_refused("merge " + out() + " -o /sys/x.exr", quoted("output '/sys/x.exr'") + in_sys, kExitUsage);
}

// A full disk: a 64 KiB tmpfs mounted in a mount namespace of its own (root with CAP_SYS_ADMIN only; the
// mount goes with the namespace). The image and the checkpoint fail to write (an output error, status
// 4); the earlier files are left as they were and no temporary file is left beside them.
TEST_F(HostileInput, FullDisk) {
  const std::string scene = write("good.json", kGoodJson);
  const fs::path disk = dir_ / "disk";
  fs::create_directory(disk);
  const std::string mount = "unshare -m sh -c 'mount -t tmpfs -o size=64k tmpfs " + disk.string();
  const auto on_full_disk = [&](const std::string& args) {
    return testing::run_command(mount + " && cd " + disk.string() + " && printf previous > out.pfm && " +
                                "printf previous > render.ckpt && " + CANDELA_CLI_PATH + " render " + scene + " " +
                                args + "; echo \"status $?\"; ls -A; cat out.pfm render.ckpt'");
  };
  const RunResult probe = testing::run_command(mount + "'");
  if (probe.exit_code != 0) GTEST_SKIP() << "cannot mount a tmpfs here: " << probe.output;
  // 512 x 512 float RGB is 3 MiB.
  RunResult image = on_full_disk("-o out.pfm --resolution 512x512 --spp 1 -q");
  EXPECT_THAT_MATCHES(image.output, "^candela: error: out\\.pfm: cannot write image: No space left on device\n"
                                    "status 4\nout\\.pfm\nrender\\.ckpt\npreviousprevious$");
  RunResult checkpoint =
      on_full_disk("-o out.pfm --resolution 512x512 --spp 8 --checkpoint render.ckpt --checkpoint-every 0.000001 -q");
  EXPECT_THAT_MATCHES(checkpoint.output, "^candela: error: checkpoint 'render\\.ckpt': cannot write: No space left on "
                                         "device\nstatus 4\nout\\.pfm\nrender\\.ckpt\npreviousprevious$");
}

}  // namespace
}  // namespace candela
