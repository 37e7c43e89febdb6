#include "candela/render/cluster.h"

#include <atomic>
#include <cstdlib>
#include <stdexcept>

#include "candela/base/error.h"

namespace candela {

bool Cluster::any(bool flag) {
  if (!distributed()) return flag;
  for (bool f : gather_values(flag))
    if (f) return true;
  return false;
}

Cluster::RankError Cluster::first_error(const std::string& error, int exit_code) {
  // Each rank sends nothing, or its exit code (4 bytes in the host's order: every rank runs the same
  // build) and then its message.
  std::string mine;
  if (!error.empty()) {
    const int32_t code = exit_code;
    mine.append(reinterpret_cast<const char*>(&code), sizeof code);
    mine += error;
  }
  std::vector<std::vector<std::byte>> all = all_gather(std::as_bytes(std::span(mine.data(), mine.size())));
  for (size_t r = 0; r < all.size(); ++r)
    if (all[r].size() > sizeof(int32_t)) {
      int32_t code = 0;
      std::memcpy(&code, all[r].data(), sizeof code);
      std::string message(reinterpret_cast<const char*>(all[r].data()) + sizeof code, all[r].size() - sizeof code);
      return {r == 0 ? message : "rank " + std::to_string(r) + ": " + message, code};
    }
  return {};
}

void LocalCluster::share_work(uint64_t items, int, const std::function<void(const NextItem&)>& work,
                              const std::function<void(uint64_t, uint64_t)>&) {
  std::atomic<uint64_t> next{0};
  work([&]() -> std::optional<uint64_t> {
    uint64_t i = next.fetch_add(1, std::memory_order_relaxed);
    if (i >= items) return std::nullopt;
    return i;
  });
}

std::vector<std::vector<std::byte>> Cluster::all_gather(std::span<const std::byte> mine) {
  std::vector<std::byte> all;
  std::vector<uint64_t> offsets;
  all_gather(mine, all, offsets);
  std::vector<std::vector<std::byte>> ranks;
  for (size_t r = 0; r + 1 < offsets.size(); ++r)
    ranks.emplace_back(all.begin() + long(offsets[r]), all.begin() + long(offsets[r + 1]));
  return ranks;
}

void LocalCluster::all_gather(std::span<const std::byte> mine, std::vector<std::byte>& all,
                              std::vector<uint64_t>& offsets) {
  all.assign(mine.begin(), mine.end());
  offsets = {0, mine.size()};
}

void LocalCluster::abort(int exit_code) { std::_Exit(exit_code); }

Cluster& local_cluster() {
  static LocalCluster alone;
  return alone;
}

const char* mpi_launcher_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
    if (const char* rank = std::getenv(name)) return rank;
  if (std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE")) return "0";
  return nullptr;
}

#ifndef CANDELA_HAVE_MPI
std::unique_ptr<Cluster> join_cluster(int&, char**&) {
  // Started by mpirun but unable to join: every process would render the whole image on its own.
  if (const char* rank = mpi_launcher_rank())
    throw UsageError(std::string(rank) != "0"
                         ? ""
                         : "this candela was built without MPI, but an MPI launcher started it: build it "
                           "where CMake finds MPI (Debian: libopenmpi-dev), or run it without mpirun");
  return std::make_unique<LocalCluster>();
}
std::string mpi_support() { return "built without MPI: renders in one process"; }
#endif

}  // namespace candela
