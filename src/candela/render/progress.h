#pragma once
// A progress bar with percentage, elapsed time and ETA on stderr, drawn only when stderr is a
// terminal, at most ten times a second, from whichever worker thread finishes a piece of work.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace candela {

class ProgressBar {
 public:
  // `fraction_out`: also stores the fraction done there (RenderOptions::progress_fraction).
  ProgressBar(uint64_t total_work, bool enabled, std::atomic<double>* fraction_out = nullptr);
  void advance(uint64_t work);  // thread-safe
  void finish();
  // A word on the phase under way, drawn before the bar (thread-safe).
  void set_label(std::string label);
  // Whether it draws at all (stderr is a terminal and it was asked to).
  bool enabled() const { return enabled_; }

 private:
  void draw(uint64_t done, bool final);

  std::string label_;
  uint64_t total_;
  bool enabled_;
  std::atomic<double>* fraction_out_;
  std::atomic<uint64_t> done_{0};
  std::mutex draw_mutex_;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace candela
