#include "candela/render/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace candela {
namespace {

std::string format_duration(double seconds) {
  long s = long(seconds + 0.5);
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60);
  return fmt::format("{:02}:{:02}", s / 60, s % 60);
}

}  // namespace

ProgressBar::ProgressBar(uint64_t total_work, bool enabled, std::atomic<double>* fraction_out)
    : total_(total_work ? total_work : 1), enabled_(enabled && isatty(fileno(stderr))), fraction_out_(fraction_out),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

void ProgressBar::advance(uint64_t work) {
  uint64_t done = done_.fetch_add(work) + work;
  if (fraction_out_) fraction_out_->store(std::min(1.0, double(done) / double(total_)), std::memory_order_relaxed);
  if (!enabled_) return;
  auto now = std::chrono::steady_clock::now();
  std::unique_lock lock(draw_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(done, false);
}

void ProgressBar::set_label(std::string label) {
  std::lock_guard lock(draw_mutex_);
  label_ = std::move(label);
  if (enabled_) draw(done_.load(), false);
}

void ProgressBar::finish() {
  if (fraction_out_) fraction_out_->store(1.0, std::memory_order_relaxed);
  if (!enabled_) return;
  std::lock_guard lock(draw_mutex_);
  draw(total_, true);
  std::fputc('\n', stderr);
}

void ProgressBar::draw(uint64_t done, bool final) {
  double fraction = std::min(1.0, double(done) / double(total_));
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  constexpr int kWidth = 40;
  int filled = int(fraction * kWidth);
  std::string bar(size_t(filled), '=');
  if (filled < kWidth) bar += '>' + std::string(size_t(kWidth - filled - 1), ' ');
  std::string eta = fraction > 0 && !final ? format_duration(elapsed * (1 - fraction) / fraction) : "00:00";
  std::fprintf(stderr, "\r%s%s[%s] %5.1f%%  elapsed %s  ETA %s \033[K", label_.c_str(), label_.empty() ? "" : " ",
               bar.c_str(), 100 * fraction, format_duration(elapsed).c_str(), eta.c_str());
  std::fflush(stderr);
}

}  // namespace candela
