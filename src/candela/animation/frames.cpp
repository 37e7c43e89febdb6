#include "candela/animation/frames.h"

#include <fmt/format.h>

#include <charconv>
#include <set>

#include "candela/base/error.h"

namespace candela {

namespace {

int frame_number(std::string_view text, const std::string& item) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || value < 0 || value > kMaxFrameNumber)
    throw UsageError(fmt::format("--frames: '{}' in '{}' is not a frame number (0 to {})", text, item, kMaxFrameNumber));
  return value;
}

}  // namespace

std::vector<int> parse_frame_list(const std::string& text) {
  std::vector<int> frames;
  std::set<int> seen;
  auto add = [&](int frame, const std::string& item) {
    if (!seen.insert(frame).second) throw UsageError(fmt::format("--frames: frame {} ('{}') is listed twice", frame, item));
    if (frames.size() >= kMaxFrames) throw UsageError(fmt::format("--frames: more than {} frames", kMaxFrames));
    frames.push_back(frame);
  };
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    if (item.empty())
      throw UsageError(fmt::format("--frames: '{}' has an empty item (write FIRST-LASTxSTEP, or frames separated by "
                                   "commas: 1-240, 1-240x4, 1,5,9)", text));
    const size_t dash = item.find('-');
    if (dash == std::string::npos) {
      add(frame_number(item, item), item);
    } else {
      const size_t x = item.find('x', dash);
      const int first = frame_number(std::string_view(item).substr(0, dash), item);
      const int last = frame_number(std::string_view(item).substr(dash + 1, (x == std::string::npos ? item.size() : x) - dash - 1), item);
      const int step = x == std::string::npos ? 1 : frame_number(std::string_view(item).substr(x + 1), item);
      if (last < first) throw UsageError(fmt::format("--frames: the range '{}' runs backwards", item));
      if (step < 1) throw UsageError(fmt::format("--frames: the step of '{}' must be at least 1", item));
      if (frames.size() + size_t((last - first) / step) + 1 > kMaxFrames)
        throw UsageError(fmt::format("--frames: more than {} frames", kMaxFrames));
      for (long f = first; f <= last; f += step) add(int(f), item);
    }
    start = comma + 1;
  }
  return frames;
}

namespace {
// The file name's last run of '#': [begin, end) in the whole pattern, or begin == npos.
std::pair<size_t, size_t> placeholder(const std::string& pattern) {
  const size_t slash = pattern.find_last_of('/');
  const size_t name_start = slash == std::string::npos ? 0 : slash + 1;
  const size_t end = pattern.find_last_of('#');
  if (end == std::string::npos || end < name_start) return {std::string::npos, 0};
  size_t begin = end;
  while (begin > name_start && pattern[begin - 1] == '#') --begin;
  return {begin, end + 1};
}
}  // namespace

bool has_frame_placeholder(const std::string& pattern) { return placeholder(pattern).first != std::string::npos; }

std::string frame_file_name(const std::string& pattern, int frame) {
  const auto [begin, end] = placeholder(pattern);
  if (begin == std::string::npos) return pattern;
  return pattern.substr(0, begin) + fmt::format("{:0{}d}", frame, end - begin) + pattern.substr(end);
}

std::vector<int> frames_of_part(const std::vector<int>& frames, int part_index, int part_count) {
  std::vector<int> mine;
  for (size_t i = size_t(part_index); i < frames.size(); i += size_t(part_count)) mine.push_back(frames[i]);
  return mine;
}

}  // namespace candela
