// The ranks of an Open MPI job as a Cluster (render/cluster.h). Compiled only when CMake finds MPI.
//
// Work is handed out by the root: its calling thread serves requests (MPI_Iprobe) while a render
// thread takes items from a local queue; every other rank's calling thread keeps its own queue
// topped up by asking the root for more, guided-self-scheduling style (a run of up to `threads`
// items, shorter as the items run out), so the ranks finish within about one item of each other
// whatever the items cost. Only the calling thread makes MPI calls (MPI_THREAD_FUNNELED).
#include <mpi.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "candela/base/error.h"
#include "candela/render/cluster.h"

namespace candela {
namespace {

constexpr int kTagRequest = 1;  // payload: int64, how many items the asking rank keeps queued
constexpr int kTagGrant = 2;    // payload: uint64 first, uint64 count (0 = no more)
// How often a calling thread that waits for a message looks for it. Each look wakes a core that render
// threads are using and runs Open MPI's progress engine: looking every 50 us made two ranks render
// 15-20% slower on 2 cores. So the root looks every millisecond, the other ranks only while a request
// is out, and otherwise sleep until their queue runs low. Ranks ask for more while they still have
// some queued, so the wait is hidden.
constexpr auto kPoll = std::chrono::milliseconds(1);

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw InternalError(std::string("MPI call failed: ") + what);
}

// The items a rank has been given and not yet started, shared by its render threads.
class ItemQueue {
 public:
  void push(uint64_t first, uint64_t count) {
    std::lock_guard lock(mutex_);
    for (uint64_t i = first; i < first + count; ++i) items_.push_back(i);
    ready_.notify_all();
  }
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    ready_.notify_all();
  }
  size_t size() {
    std::lock_guard lock(mutex_);
    return items_.size();
  }
  // The next item; waits while the queue is empty and still open.
  std::optional<uint64_t> pop() {
    std::unique_lock lock(mutex_);
    ready_.wait(lock, [&] { return !items_.empty() || closed_; });
    if (items_.empty()) return std::nullopt;
    uint64_t i = items_.front();
    items_.pop_front();
    taken_.notify_all();
    return i;
  }
  // Waits until at most `low` items are left, or for `timeout`.
  void wait_until_at_most(size_t low, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    taken_.wait_for(lock, timeout, [&] { return items_.size() <= low; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable ready_, taken_;
  std::deque<uint64_t> items_;
  bool closed_ = false;
};

class MpiCluster final : public Cluster {
 public:
  MpiCluster(int& argc, char**& argv) {
    int provided = 0;
    check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    if (provided < MPI_THREAD_FUNNELED) {
      MPI_Finalize();
      throw InternalError("the MPI library does not provide MPI_THREAD_FUNNELED");
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
    MPI_Comm_size(node, &ranks_on_node_);
    MPI_Comm_free(&node);
    // A rank alone on its node but bound to fewer of its cores renders slower than it could: say so.
    const int cores = std::max(1, int(std::thread::hardware_concurrency()));
    if (rank_ == 0 && ranks_on_node_ == 1 && allowed_cores() < cores)
      std::fprintf(stderr,
                   "candela: note: rank 0 may run on %d of its node's %d cores (mpirun bound it); to use them all, "
                   "run mpirun with --bind-to none (or --map-by ppr:1:node:pe=%d)\n",
                   allowed_cores(), cores, cores);
  }
  ~MpiCluster() override { MPI_Finalize(); }

  bool mpi_job() const override { return true; }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  // The cores this rank may run on (mpirun binds ranks to cores by default when it starts two or
  // fewer), shared with the other ranks on the node when it may run on all of them.
  int default_threads() const override {
    int cores = std::max(1, int(std::thread::hardware_concurrency()));
    int allowed = allowed_cores();
    if (allowed < cores) return allowed;
    return std::max(1, cores / std::max(1, ranks_on_node_));
  }

  void share_work(uint64_t items, int threads, const std::function<void(const NextItem&)>& work,
                  const std::function<void(uint64_t, uint64_t)>& granted) override {
    if (size_ == 1) return LocalCluster().share_work(items, threads, work, granted);
    threads = std::max(threads, 1);
    ItemQueue queue;
    std::exception_ptr failure;
    std::thread render([&] {
      try {
        work([&] { return queue.pop(); });
      } catch (...) {
        failure = std::current_exception();
      }
    });
    if (rank_ == 0)
      serve(items, threads, queue, granted);
    else
      ask(threads, queue);
    render.join();
    if (failure) std::rethrow_exception(failure);
  }

  Traffic traffic() const override { return traffic_; }

  using Cluster::all_gather;
  void all_gather(std::span<const std::byte> mine, std::vector<std::byte>& all,
                  std::vector<uint64_t>& offsets) override {
    CollectiveTimer timer(traffic_);
    const uint64_t length = mine.size();
    traffic_.bytes_sent += length + sizeof length;
    std::vector<uint64_t> lengths(static_cast<size_t>(size_), 0);
    check(MPI_Allgather(&length, 1, MPI_UINT64_T, lengths.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD), "MPI_Allgather");
    offsets.assign(static_cast<size_t>(size_) + 1, 0);
    for (int r = 0; r < size_; ++r) offsets[size_t(r) + 1] = offsets[size_t(r)] + lengths[size_t(r)];
    all.resize(offsets.back());
    if (offsets.back() <= uint64_t(INT_MAX)) {
      // One round, straight into place.
      std::vector<int> counts(static_cast<size_t>(size_)), displacements(static_cast<size_t>(size_));
      for (int r = 0; r < size_; ++r) {
        counts[size_t(r)] = int(lengths[size_t(r)]);
        displacements[size_t(r)] = int(offsets[size_t(r)]);
      }
      check(MPI_Allgatherv(mine.data(), int(length), MPI_BYTE, all.data(), counts.data(), displacements.data(),
                           MPI_BYTE, MPI_COMM_WORLD),
            "MPI_Allgatherv");
      return;
    }
    // MPI counts are ints: in rounds of at most INT_MAX bytes in all.
    const uint64_t slice = std::max<uint64_t>(1, uint64_t(INT_MAX) / uint64_t(size_));
    const uint64_t longest = *std::max_element(lengths.begin(), lengths.end());
    std::vector<int> counts(static_cast<size_t>(size_)), displacements(static_cast<size_t>(size_));
    std::vector<std::byte> received;
    for (uint64_t start = 0; start < longest; start += slice) {
      int total = 0;
      for (int r = 0; r < size_; ++r) {
        uint64_t len = lengths[size_t(r)];
        counts[size_t(r)] = int(start < len ? std::min(slice, len - start) : 0);
        displacements[size_t(r)] = total;
        total += counts[size_t(r)];
      }
      received.resize(size_t(total));
      check(MPI_Allgatherv(mine.data() + std::min<uint64_t>(start, length), counts[size_t(rank_)], MPI_BYTE,
                           received.data(), counts.data(), displacements.data(), MPI_BYTE, MPI_COMM_WORLD),
            "MPI_Allgatherv");
      for (int r = 0; r < size_; ++r)
        std::copy_n(received.begin() + displacements[size_t(r)], counts[size_t(r)],
                    all.begin() + long(offsets[size_t(r)] + start));
    }
  }

  void sum_int64(std::vector<int64_t>& values) override {
    CollectiveTimer timer(traffic_);
    traffic_.bytes_sent += values.size() * sizeof(int64_t);
    constexpr size_t kSlice = size_t(1) << 26;
    for (size_t start = 0; start < values.size(); start += kSlice)
      check(MPI_Allreduce(MPI_IN_PLACE, values.data() + start, int(std::min(kSlice, values.size() - start)),
                          MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD),
            "MPI_Allreduce");
  }

  void broadcast(std::vector<std::byte>& bytes) override {
    CollectiveTimer timer(traffic_);
    uint64_t length = bytes.size();
    if (rank_ == 0) traffic_.bytes_sent += length + sizeof length;
    check(MPI_Bcast(&length, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
    bytes.resize(length);
    constexpr uint64_t kSlice = uint64_t(1) << 30;
    for (uint64_t start = 0; start < length; start += kSlice)
      check(MPI_Bcast(bytes.data() + start, int(std::min(kSlice, length - start)), MPI_BYTE, 0, MPI_COMM_WORLD),
            "MPI_Bcast");
  }

  void abort(int exit_code) override {
    MPI_Abort(MPI_COMM_WORLD, exit_code);
    std::_Exit(exit_code);
  }

 private:
  // The root: hands out runs of items to the ranks that ask, and to its own queue, until every
  // rank has been told there are no more.
  void serve(uint64_t items, int threads, ItemQueue& queue, const std::function<void(uint64_t, uint64_t)>& granted) {
    uint64_t next = 0;
    auto grant = [&](int64_t want) {
      uint64_t left = items - next;
      uint64_t count = std::min<uint64_t>({uint64_t(std::max<int64_t>(want, 1)), left,
                                           std::max<uint64_t>(1, left / (2 * uint64_t(size_)))});
      uint64_t first = next;
      next += count;
      return std::pair{first, count};
    };
    int told_done = 0;
    bool own_closed = false;
    while (!own_closed || told_done < size_ - 1) {
      bool busy = false;
      for (;;) {
        int waiting = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &waiting, &status);
        if (!waiting) break;
        int64_t want = 0;
        MPI_Recv(&want, 1, MPI_INT64_T, status.MPI_SOURCE, kTagRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        auto [first, count] = grant(want);
        uint64_t reply[2] = {first, count};
        MPI_Send(reply, 2, MPI_UINT64_T, status.MPI_SOURCE, kTagGrant, MPI_COMM_WORLD);
        traffic_.bytes_sent += sizeof reply;
        if (count == 0)
          ++told_done;
        else if (granted)
          granted(first, count);
        busy = true;
      }
      if (!own_closed && queue.size() <= size_t(threads)) {
        auto [first, count] = grant(2 * int64_t(threads));
        if (count == 0) {
          queue.close();
          own_closed = true;
        } else {
          queue.push(first, count);
        }
        busy = true;
      }
      // Sleep until the own queue runs low, or the next look for requests.
      if (busy) continue;
      if (own_closed)
        std::this_thread::sleep_for(kPoll);
      else
        queue.wait_until_at_most(size_t(threads), kPoll);
    }
  }

  // Any other rank: keeps its queue topped up from the root until the root has no more. A reply
  // that finds the queue already empty means the items go faster than a request goes round (cheap
  // tiles of empty sky): ask for twice as many from then on, so the rank does not sit idle while the
  // root, which needs no messages for its own queue, takes the rest.
  void ask(int threads, ItemQueue& queue) {
    uint64_t reply[2] = {0, 0};
    MPI_Request pending = MPI_REQUEST_NULL;
    int64_t want = 2 * int64_t(threads);
    for (;;) {
      if (pending == MPI_REQUEST_NULL && queue.size() > size_t(want / 2)) {
        queue.wait_until_at_most(size_t(want / 2), std::chrono::milliseconds(100));
        continue;
      }
      if (pending == MPI_REQUEST_NULL) {
        MPI_Send(&want, 1, MPI_INT64_T, 0, kTagRequest, MPI_COMM_WORLD);
        traffic_.bytes_sent += sizeof want;
        MPI_Irecv(reply, 2, MPI_UINT64_T, 0, kTagGrant, MPI_COMM_WORLD, &pending);
      }
      int arrived = 0;
      if (pending != MPI_REQUEST_NULL) MPI_Test(&pending, &arrived, MPI_STATUS_IGNORE);  // sets it null when done
      if (arrived) {
        if (reply[1] == 0) {
          queue.close();
          return;
        }
        if (queue.size() == 0) want = std::min<int64_t>(2 * want, 1024);
        queue.push(reply[0], reply[1]);
        continue;
      }
      std::this_thread::sleep_for(kPoll);
    }
  }

  // Adds the time from its construction to its destruction to Traffic::collective_seconds.
  struct CollectiveTimer {
    explicit CollectiveTimer(Traffic& t) : traffic(t), start(std::chrono::steady_clock::now()) {}
    ~CollectiveTimer() {
      traffic.collective_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    Traffic& traffic;
    std::chrono::steady_clock::time_point start;
  };

  static int allowed_cores() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) != 0) return std::max(1, int(std::thread::hardware_concurrency()));
    return std::max(1, CPU_COUNT(&set));
  }

  int rank_ = 0, size_ = 1, ranks_on_node_ = 1;
  Traffic traffic_;
};

}  // namespace

std::unique_ptr<Cluster> join_cluster(int& argc, char**& argv) {
  // Only a process an MPI launcher started initialises MPI, so a plain run never pays for it.
  if (!mpi_launcher_rank()) return std::make_unique<LocalCluster>();
  return std::make_unique<MpiCluster>(argc, argv);
}

std::string mpi_support() {
  char version[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(version, &length);
  std::string text(version, size_t(length));
  text = text.substr(0, text.find_first_of(",\n"));
  return "renders across MPI ranks with " + text;
}

}  // namespace candela
