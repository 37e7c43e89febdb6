// The error types and the exit status of each (docs/cli.md, "Exit status").
#include "candela/base/error.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <new>
#include <stdexcept>

#include "candela/render/cluster.h"

namespace candela {
namespace {

TEST(ErrorTypes, EachTypeHasItsExitStatus) {
  EXPECT_EQ(exit_code_for(SceneError("scene.json: at /shapes/0: bad")), 1);
  EXPECT_EQ(exit_code_for(FileContentError("mesh.ply: corrupt")), 1);
  EXPECT_EQ(exit_code_for(UsageError("--spp: 0 is out of range")), 2);
  EXPECT_EQ(exit_code_for(UnknownParameterError("no scene parameter 'x'")), 2);
  EXPECT_EQ(exit_code_for(OutputError("out.exr: cannot write image: No space left on device")), 4);
  EXPECT_EQ(exit_code_for(InternalError("a broken invariant")), 70);
  // Anything else that reaches the command line is a bug too.
  EXPECT_EQ(exit_code_for(std::runtime_error("bare")), 70);
  EXPECT_EQ(exit_code_for(std::invalid_argument("bare")), 70);
  EXPECT_EQ(exit_code_for(std::bad_alloc()), 70);
  // Every code is one of the documented ones, and they differ from the interruption's.
  EXPECT_EQ(kExitBadInput, 1);
  EXPECT_EQ(kExitUsage, 2);
  EXPECT_EQ(kExitInterrupted, 3);
  EXPECT_EQ(kExitOutput, 4);
  EXPECT_EQ(kExitInternal, 70);
  EXPECT_EQ(kExitSecondSignal, 130);
}

TEST(ErrorTypes, AllDeriveFromCandelaError) {
  auto is_candela_error = [](auto&& error) {
    try {
      throw error;
    } catch (const CandelaError&) {
      return true;
    } catch (...) {
      return false;
    }
  };
  EXPECT_TRUE(is_candela_error(SceneError("")));
  EXPECT_TRUE(is_candela_error(FileContentError("")));
  EXPECT_TRUE(is_candela_error(UsageError("")));
  EXPECT_TRUE(is_candela_error(UnknownParameterError("")));
  EXPECT_TRUE(is_candela_error(OutputError("")));
  EXPECT_TRUE(is_candela_error(InternalError("")));
  EXPECT_FALSE(is_candela_error(std::runtime_error("")));
}

// The ranks of a job agree on the first error and its exit status (render/cluster.h); alone, a process
// gets its own back.
TEST(ErrorTypes, TheFirstErrorCarriesItsExitStatus) {
  const Cluster::RankError none = local_cluster().first_error("", 0);
  EXPECT_EQ(none.message, "");
  EXPECT_EQ(none.exit_code, 0);
  const Cluster::RankError failed = local_cluster().first_error("out.exr: cannot write image: gone", kExitOutput);
  EXPECT_EQ(failed.message, "out.exr: cannot write image: gone");
  EXPECT_EQ(failed.exit_code, kExitOutput);
}

// Three ranks where rank 0 has no error and ranks 1 and 2 send this rank's: rank 1's is the first.
class ThreeRanks final : public Cluster {
 public:
  int rank() const override { return 0; }
  int size() const override { return 3; }
  bool mpi_job() const override { return true; }
  int default_threads() const override { return 1; }
  void share_work(uint64_t, int, const std::function<void(const NextItem&)>&,
                  const std::function<void(uint64_t, uint64_t)>&) override {}
  using Cluster::all_gather;
  void all_gather(std::span<const std::byte> mine, std::vector<std::byte>& all, std::vector<uint64_t>& offsets) override {
    all.assign(mine.begin(), mine.end());
    all.insert(all.end(), mine.begin(), mine.end());
    offsets = {0, 0, mine.size(), 2 * mine.size()};
  }
  void sum_int64(std::vector<int64_t>&) override {}
  void broadcast(std::vector<std::byte>&) override {}
  [[noreturn]] void abort(int) override { std::abort(); }
};

TEST(ErrorTypes, TheFirstFailingRankNamesItselfAndGivesItsExitStatus) {
  ThreeRanks ranks;
  const Cluster::RankError first = ranks.first_error("scene.json: at /camera: bad", kExitBadInput);
  EXPECT_EQ(first.message, "rank 1: scene.json: at /camera: bad");
  EXPECT_EQ(first.exit_code, kExitBadInput);
  EXPECT_EQ(ranks.first_error("", 0).message, "");
}

}  // namespace
}  // namespace candela
