#pragma once
// How fuzz/part_reader_fuzz.cpp (and tests/fuzz_regression_test.cpp, replaying its findings) turn an
// input into a part file. An input that starts with OpenEXR's magic (76 2f 31 01) is the file as it
// is. Any other describes a part as text, which is written as an EXR by candela's own write_image
// (R, G, B and the exact channels, as write_part writes them), so that mutations reach candela's
// checks of well-formed files and not only OpenEXR's parsing:
//   the first line: the width and height ("4 4"; each from 1 to 16, taken modulo 16),
//   "name=value" attribute lines ("\n" in a value stands for a newline), up to a line "--",
//   the exact channels' names, one a line, up to a line "--" or the end,
//   then bytes that fill the channels' 32-bit values (repeated; zeros when there are none).
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "candela/film/image_io.h"

namespace candela_fuzz {

// Writes the part file of `input` to `file`; false when the writer refuses the described image (an
// empty channel name, say): there is then nothing to read.
inline bool write_part_input(std::string_view input, const std::filesystem::path& file) {
  if (input.starts_with("\x76\x2f\x31\x01")) {
    std::ofstream(file, std::ios::binary) << input;
    return true;
  }
  // The lines up to a line "--" or the end of the input.
  auto section = [&input]() {
    std::vector<std::string> lines;
    while (!input.empty()) {
      const size_t end = std::min(input.find('\n'), input.size());
      std::string line(input.substr(0, end));
      input.remove_prefix(std::min(end + 1, input.size()));
      if (line == "--") break;
      lines.push_back(std::move(line));
    }
    return lines;
  };
  const size_t size_end = std::min(input.find('\n'), input.size());
  unsigned width = 1, height = 1;
  std::sscanf(std::string(input.substr(0, size_end)).c_str(), "%u %u", &width, &height);
  input.remove_prefix(std::min(size_end + 1, input.size()));
  width = (width - 1) % 16 + 1;
  height = (height - 1) % 16 + 1;
  std::map<std::string, std::string> metadata;
  for (const std::string& line : section()) {
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    std::string value = line.substr(eq + 1);
    for (size_t at = value.find("\\n"); at != std::string::npos; at = value.find("\\n", at + 1)) value.replace(at, 2, "\n");
    metadata[line.substr(0, eq)] = value;
  }
  candela::ExactChannels channels;
  channels.names = section();
  channels.values.resize(size_t(width) * height * channels.names.size());
  const size_t words = input.size() / 4;
  for (size_t i = 0; words > 0 && i < channels.values.size(); ++i)
    std::memcpy(&channels.values[i], input.data() + 4 * (i % words), 4);
  try {
    candela::write_image(file, candela::Image(int(width), int(height)), metadata, channels);
  } catch (const std::exception&) {  // OpenEXR's own exceptions too (an empty channel name): not what is fuzzed
    return false;
  }
  return true;
}

}  // namespace candela_fuzz
