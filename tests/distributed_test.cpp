// Rendering past one process (docs/distributed.md), end to end through the command line: the image
// rendered across MPI ranks, resumed under another rank count, or put together from job-array parts
// is byte for byte the image one process renders (compared as .pfm files, which hold nothing but
// the pixels); failures end the whole job with one message and leave the output untouched.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "candela/film/image_io.h"
#include "candela/testing/command_line.h"

namespace fs = std::filesystem;

namespace candela {
namespace {

using RunResult = testing::CommandResult;
using testing::file_bytes;

// Runs a bash command line in `dir`, with $CANDELA the CLI and $MPIRUN mpirun as root may run it.
RunResult sh(const fs::path& dir, const std::string& script) {
  return testing::run_command("cd '" + dir.string() + "' && CANDELA='" + CANDELA_CLI_PATH +
                              "' MPIRUN='mpirun --oversubscribe' OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
                              "OMPI_MCA_btl_vader_single_copy_mechanism=none bash -c '" + script + "'");
}

// Shell: wait (up to 60 s) until ck.bin exists.
const std::string kWaitForCheckpoint = "for i in $(seq 1200); do [ -e ck.bin ] && break; sleep 0.05; done; ";

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

class Distributed : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_directory("candela_distributed_test");
    scene_ = std::string(CANDELA_SOURCE_DIR) + "/scenes/cornell-box.json";
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Skips (with the reason) where this build or machine cannot run MPI jobs.
  void need_mpi() {
    if (sh(dir_, "$CANDELA --version").output.find("MPI ranks") == std::string::npos)
      GTEST_SKIP() << "candela was built without MPI";
    if (sh(dir_, "command -v mpirun").exit_code != 0) GTEST_SKIP() << "mpirun is not installed";
  }
  // `candela render` of the Cornell box with `args`, in one process or under mpirun -np `ranks`.
  RunResult render(int ranks, const std::string& args) {
    std::string launch = ranks > 0 ? "$MPIRUN -np " + std::to_string(ranks) + " $CANDELA" : "$CANDELA";
    return sh(dir_, launch + " render " + scene_ + " -q " + args);
  }
  void expect_same_image(const std::string& a, const std::string& b) {
    std::string x = file_bytes(dir_ / a), y = file_bytes(dir_ / b);
    ASSERT_FALSE(x.empty()) << a << " was not written";
    EXPECT_TRUE(x == y) << a << " and " << b << " differ";
  }
  // One process, then 2 and 3 ranks, with the same settings: the same bytes.
  void expect_ranks_agree(const std::string& settings) {
    need_mpi();
    if (IsSkipped()) return;
    RunResult one = render(0, settings + " -o one.pfm");
    ASSERT_EQ(one.exit_code, 0) << one.output;
    for (int ranks : {2, 3}) {
      std::string out = "ranks" + std::to_string(ranks) + ".pfm";
      RunResult r = render(ranks, settings + " -o " + out);
      ASSERT_EQ(r.exit_code, 0) << r.output;
      EXPECT_EQ(count(r.output, "parallel efficiency"), 1) << "one closing line, from rank 0:\n" << r.output;
      expect_same_image("one.pfm", out);
    }
  }

  fs::path dir_;
  std::string scene_;
};

TEST_F(Distributed, PathTracingAcrossRanksIsTheOneProcessImage) {
  expect_ranks_agree("--resolution 40x30 --spp 24");
}

TEST_F(Distributed, BidirectionalSplatsAcrossRanksAreTheOneProcessImage) {
  expect_ranks_agree("--integrator bdpt --resolution 40x30 --spp 8");
}

TEST_F(Distributed, MetropolisChainsAcrossRanksAreTheOneProcessImage) {
  expect_ranks_agree("--integrator mlt --resolution 40x30 --spp 4 --mlt-bootstrap 3000 --mlt-chains 48");
}

// With an error target the render stops where the film's estimate says, the same for any number of
// ranks (passes and rounds do not grow with the clock then).
TEST_F(Distributed, AnErrorTargetAcrossRanksIsTheOneProcessImage) {
  expect_ranks_agree("--integrator bdpt --resolution 40x30 --target-error 0.02");
  expect_ranks_agree("--integrator mlt --resolution 40x30 --target-error 0.05 --mlt-bootstrap 3000 --mlt-chains 48");
}

TEST_F(Distributed, AdaptiveSamplingWithAThresholdAcrossRanksIsTheOneProcessImage) {
  expect_ranks_agree("--resolution 40x30 --adaptive-threshold 0.08 --max-spp 64");
}

TEST_F(Distributed, AdaptiveSamplingWithABudgetAcrossRanksIsTheOneProcessImage) {
  expect_ranks_agree("--resolution 40x30 --adaptive-spp 24");
}

TEST_F(Distributed, ACheckpointOfThreeRanksResumesUnderTwoToTheOneProcessImage) {
  need_mpi();
  if (IsSkipped()) return;
  const std::string settings = "--integrator bdpt --resolution 48x48 --spp 512";
  ASSERT_EQ(render(0, settings + " -o one.pfm").exit_code, 0);
  RunResult cut = render(3, settings + " -o cut.pfm --checkpoint ck.bin --time-limit 0.3");
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  ASSERT_NE(cut.output.find("time limit reached"), std::string::npos) << "must stop early to test resuming:\n"
                                                                         << cut.output;
  RunResult resumed = render(2, settings + " -o resumed.pfm --resume ck.bin");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  expect_same_image("one.pfm", "resumed.pfm");
}

TEST_F(Distributed, InterruptingMpirunWritesTheImageAndACheckpointThatResumes) {
  need_mpi();
  if (IsSkipped()) return;
  const std::string settings = "--resolution 48x48 --spp 100000";
  // Once the render is under way (its first checkpoint is written), Ctrl-C to mpirun.
  RunResult r = sh(dir_, "$MPIRUN -np 2 $CANDELA render " + scene_ + " -q " + settings +
                             " -o cut.pfm --checkpoint ck.bin --checkpoint-every 0.2 & p=$!; " + kWaitForCheckpoint +
                             "kill -INT $p; wait $p; echo exit=$?");
  EXPECT_NE(r.output.find("interrupted: wrote the image"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "cut.pfm") && fs::exists(dir_ / "ck.bin")) << r.output;
  EXPECT_EQ(r.output.find("exit=0"), std::string::npos) << "an interrupted job exits non-zero:\n" << r.output;
}

TEST_F(Distributed, ARankKilledOutrightEndsTheJobAndItsCheckpointResumesInOneProcess) {
  need_mpi();
  if (IsSkipped()) return;
  const std::string settings = "--resolution 64x64 --spp 1024";
  ASSERT_EQ(render(0, settings + " -o one.pfm").exit_code, 0);
  RunResult r = sh(dir_, "$MPIRUN -np 3 $CANDELA render " + scene_ + " -q " + settings +
                             " -o killed.pfm --checkpoint ck.bin --checkpoint-every 0.1 & p=$!; "
                             + kWaitForCheckpoint +
                             "pkill -9 -n -P $p; wait $p; echo exit=$?");  // the newest rank of this job
  EXPECT_EQ(r.output.find("exit=0"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "killed.pfm")) << "nothing is written when a rank dies";
  RunResult resumed = render(0, settings + " -o resumed.pfm --resume ck.bin");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  expect_same_image("one.pfm", "resumed.pfm");
}

TEST_F(Distributed, ABadSceneEndsTheJobWithOneMessageAndTheOutputUntouched) {
  need_mpi();
  if (IsSkipped()) return;
  std::ofstream(dir_ / "bad.json") << "{\"camera\": ";
  std::ofstream(dir_ / "out.pfm") << "previous render";
  RunResult r = sh(dir_, "$MPIRUN -np 3 $CANDELA render bad.json -o out.pfm");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(count(r.output, "candela: error:"), 1) << r.output;
  EXPECT_NE(r.output.find("bad.json:"), std::string::npos) << r.output;
  EXPECT_EQ(file_bytes(dir_ / "out.pfm"), "previous render");
}

TEST_F(Distributed, RanksThatReadDifferentScenesAreRefused) {
  need_mpi();
  if (IsSkipped()) return;
  // Two nodes whose copies of the scene differ: here, two files, one per rank (MPMD launch).
  std::string text = file_bytes(scene_);
  std::ofstream(dir_ / "a.json") << text;
  std::ofstream(dir_ / "b.json") << text << "\n";
  RunResult r = sh(dir_, "$MPIRUN -np 1 $CANDELA render a.json -q --resolution 8x8 --spp 1 -o out.pfm : "
                         "-np 1 $CANDELA render b.json -q --resolution 8x8 --spp 1 -o out.pfm");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("rank 1 read a different scene than rank 0"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
}

class JobArrayParts : public Distributed {};

TEST_F(JobArrayParts, MergedPartsAreTheOneProcessImage) {
  for (const char* integrator : {"path", "bdpt"}) {
    const std::string settings = std::string("--integrator ") + integrator + " --resolution 70x40 --spp 8";
    ASSERT_EQ(render(0, settings + " -o one.pfm").exit_code, 0);
    for (int k = 1; k <= 3; ++k) {
      RunResult r = render(0, settings + " --part " + std::to_string(k) + "/3 -o part" + std::to_string(k) + ".exr");
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    RunResult merged = sh(dir_, "$CANDELA merge part3.exr part1.exr part2.exr -o merged.pfm");
    ASSERT_EQ(merged.exit_code, 0) << merged.output;
    SCOPED_TRACE(integrator);
    expect_same_image("one.pfm", "merged.pfm");
  }
}

TEST_F(JobArrayParts, AMissingDuplicatedOrForeignPartIsAnErrorNamingTheFile) {
  const std::string settings = "--resolution 40x30 --spp 2";
  for (int k = 1; k <= 3; ++k)
    ASSERT_EQ(render(0, settings + " --part " + std::to_string(k) + "/3 -o p" + std::to_string(k) + ".exr").exit_code, 0);
  ASSERT_EQ(render(0, "--resolution 40x30 --spp 2 --max-depth 3 --part 2/3 -o other.exr").exit_code, 0);
  ASSERT_EQ(render(0, settings + " -o plain.exr").exit_code, 0);
  std::ofstream(dir_ / "out.exr") << "previous render";
  struct Case {
    std::string files, message;
  } cases[] = {
      {"p1.exr p3.exr", "part 2/3 of seed 0 is missing"},
      {"p1.exr p2.exr p2.exr p3.exr", "p2.exr: is part 2/3 of seed 0, as p2.exr is"},
      {"p1.exr other.exr p3.exr", "other.exr: does not belong with p1.exr: settings differ: max-depth"},
      {"p1.exr plain.exr", "plain.exr: not a candela part"},
      {"p1.exr p2.exr p3.exr nothere.exr", "nothere.exr: no such file"},
  };
  for (const Case& c : cases) {
    RunResult r = sh(dir_, "$CANDELA merge " + c.files + " -o out.exr");
    EXPECT_EQ(r.exit_code, 1) << c.files;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.files << ":\n" << r.output;
    EXPECT_EQ(count(r.output, "candela: error:"), 1) << r.output;
    EXPECT_EQ(file_bytes(dir_ / "out.exr"), "previous render");
  }
}

TEST_F(JobArrayParts, RendersWithOtherSeedsAddUpWeightedBySampleCount) {
  const std::string settings = "--resolution 32x24 --filter box --spp 16 --part 1/1";
  ASSERT_EQ(render(0, settings + " --seed 1 -o s1.exr").exit_code, 0);
  ASSERT_EQ(render(0, "--resolution 32x24 --filter box --spp 48 --part 1/1 --seed 2 -o s2.exr").exit_code, 0);
  RunResult r = sh(dir_, "$CANDELA merge s1.exr s2.exr -o sum.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("64 spp"), std::string::npos) << r.output;
  // The merged mean is the sample-weighted mean of the two (box filter: every sample weighs 1).
  Image a = read_image(dir_ / "s1.exr"), b = read_image(dir_ / "s2.exr"), sum = read_image(dir_ / "sum.exr");
  ASSERT_EQ(sum.rgb.size(), a.rgb.size());
  for (size_t i = 0; i < sum.rgb.size(); ++i)
    ASSERT_NEAR(sum.rgb[i], 0.25f * a.rgb[i] + 0.75f * b.rgb[i], 1e-5f * (1 + sum.rgb[i])) << i;
  EXPECT_EQ(read_image_metadata(dir_ / "sum.exr").at("candela:seed"), "1,2");
}

}  // namespace
}  // namespace candela
