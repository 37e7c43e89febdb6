#pragma once
// The processes that render one image together: one process (a plain run), or the ranks of an Open
// MPI job (`mpirun -np N candela render ...`, render/mpi_cluster.cpp). The render loops use only
// this interface, so the same code renders in one process and across ranks, and the image is the
// same bit for bit either way (docs/distributed.md):
//   - work is handed out dynamically (share_work), but a pixel's samples are always computed as a
//     function of (pixel, sample index, seed) and added to its sums in sample order;
//   - every rank holds the whole film, and after each pass the ranks exchange the tiles they
//     rendered (all_gather), so all replicas stay identical and every decision taken from the film
//     (adaptive sampling, the next pass) is the same on every rank;
//   - splats are fixed-point integer sums, added across ranks exactly (sum_int64).
// Only the calling thread of each rank talks MPI (MPI_THREAD_FUNNELED): render threads ask for work
// through share_work's `next` function, which never calls MPI itself.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace candela {

class Cluster {
 public:
  virtual ~Cluster() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  bool is_root() const { return rank() == 0; }
  bool distributed() const { return size() > 1; }
  // Started by an MPI launcher (even as a job of one rank).
  virtual bool mpi_job() const = 0;
  // Render threads this rank uses by default: its share of the node's cores.
  virtual int default_threads() const = 0;

  // Hands out the items [0, items) across the ranks, dynamically: `work(next)` runs on every rank
  // (in another thread where the rank must keep serving requests) and calls `next()`, from any of
  // its threads, until it returns nothing. Every item goes to exactly one rank. On the root,
  // `granted(first, count)` is called (on the calling thread) for each run of items handed to
  // another rank, e.g. to advance a progress bar. `threads`: the rank asks for more items when it has
  // no more than this many queued, and for up to twice this many at a time.
  using NextItem = std::function<std::optional<uint64_t>()>;
  virtual void share_work(uint64_t items, int threads, const std::function<void(const NextItem&)>& work,
                          const std::function<void(uint64_t first, uint64_t count)>& granted) = 0;

  // Every rank's `mine`, in rank order, on every rank (collective): rank r's bytes are
  // all[offsets[r], offsets[r + 1]). The caller's buffers are reused, so that gathering a film's
  // worth of bytes every pass does not allocate (and page in) a new one each time.
  virtual void all_gather(std::span<const std::byte> mine, std::vector<std::byte>& all,
                          std::vector<uint64_t>& offsets) = 0;
  // The same into new vectors, one per rank.
  std::vector<std::vector<std::byte>> all_gather(std::span<const std::byte> mine);
  // Adds `values` element by element across the ranks; every rank gets the sums (collective).
  virtual void sum_int64(std::vector<int64_t>& values) = 0;
  // The root's `bytes` on every rank (collective).
  virtual void broadcast(std::vector<std::byte>& bytes) = 0;
  // What this rank has sent (bytes it contributed to messages and collectives) and the seconds its
  // calling thread spent in collectives (waiting for the others included): for the closing line and
  // the scaling model of docs/distributed.md.
  struct Traffic {
    uint64_t bytes_sent = 0;
    double collective_seconds = 0;
  };
  virtual Traffic traffic() const { return {}; }
  // Ends every rank of the job at once with `exit_code` (a failure after the ranks agreed to
  // render, where waiting for the others could hang).
  [[noreturn]] virtual void abort(int exit_code) = 0;

  // Helpers over the above for plain values.
  template <typename T>
  std::vector<T> gather_values(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    std::vector<T> out;
    for (const auto& bytes : all_gather(std::as_bytes(std::span(&value, 1)))) {
      T v;
      std::memcpy(&v, bytes.data(), sizeof(T));
      out.push_back(v);
    }
    return out;
  }
  // True on every rank when `flag` is true on any.
  bool any(bool flag);
  // The root's `value` on every rank (collective): a decision taken by the root's clock.
  template <typename T>
  T from_root(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!distributed()) return value;
    std::vector<std::byte> bytes(sizeof(T));
    std::memcpy(bytes.data(), &value, sizeof(T));
    broadcast(bytes);
    std::memcpy(&value, bytes.data(), sizeof(T));
    return value;
  }
  // On every rank (collective), the lowest failing rank's error: its message, prefixed with
  // "rank K: " when that is not the root, and its `exit_code` (base/error.h's exit_code_for), so that
  // every rank exits as that rank's error says. An empty message (and 0) when every rank's `error`
  // is empty.
  struct RankError {
    std::string message;
    int exit_code = 0;
  };
  RankError first_error(const std::string& error, int exit_code);
};

// The process on its own.
class LocalCluster final : public Cluster {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  int default_threads() const override { return 0; }
  bool mpi_job() const override { return false; }
  void share_work(uint64_t items, int threads, const std::function<void(const NextItem&)>& work,
                  const std::function<void(uint64_t, uint64_t)>& granted) override;
  using Cluster::all_gather;
  void all_gather(std::span<const std::byte> mine, std::vector<std::byte>& all, std::vector<uint64_t>& offsets) override;
  void sum_int64(std::vector<int64_t>&) override {}
  void broadcast(std::vector<std::byte>&) override {}
  [[noreturn]] void abort(int exit_code) override;
};

// The one LocalCluster, for callers that render alone.
Cluster& local_cluster();

// The cluster this process belongs to: an MPI job when launched by mpirun (and built with MPI),
// initialising MPI, else the process alone. MPI is finalised when the returned object is destroyed.
// A build without MPI started by mpirun throws (the message is empty on ranks other than 0, so that
// the job prints it once).
std::unique_ptr<Cluster> join_cluster(int& argc, char**& argv);

// The rank an MPI launcher (mpirun, srun) gave this process in its environment, or null when no
// launcher started it.
const char* mpi_launcher_rank();

// For --version: the MPI library this build renders across ranks with, or that it has none.
std::string mpi_support();

}  // namespace candela
