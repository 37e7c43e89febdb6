#pragma once
// Which frames a command renders and what their files are called: `--frames 1-240`, `1-240x4`,
// `1,5,9` or any comma-separated mix; output names with the frame number in a run of '#'
// (`shot_####.exr` -> shot_0007.exr), as Blender and most farm tools name sequences.
#include <string>
#include <vector>

namespace candela {

inline constexpr int kMaxFrameNumber = 9999999;
inline constexpr size_t kMaxFrames = 1000000;

// The frames of `text` in the order given (a range counts up from its first frame by its step).
// Throws UsageError naming --frames for anything else: empty items, descending ranges, a step
// below 1, numbers outside [0, kMaxFrameNumber], the same frame twice, more than kMaxFrames.
std::vector<int> parse_frame_list(const std::string& text);

// Whether `pattern`'s file name holds a run of '#' for the frame number.
bool has_frame_placeholder(const std::string& pattern);
// `pattern` with its file name's last run of '#' replaced by `frame`, zero-padded to the run's
// length (longer numbers are written whole).
std::string frame_file_name(const std::string& pattern, int frame);

// The frames of `frames` that part `part_index` (0-based) of `part_count` renders: every
// part_count-th of the list, from the part_index-th (a job array hands each job its frames).
std::vector<int> frames_of_part(const std::vector<int>& frames, int part_index, int part_count);

}  // namespace candela
