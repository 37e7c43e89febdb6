#pragma once
// How fuzz/nanovdb_reader_fuzz.cpp (and tests/fuzz_regression_test.cpp, replaying its findings)
// turn an input into a .nvdb file. Bit 0 of the first byte clear: the rest is the whole file. Set:
// the rest is patches to a valid file of a 2 x 2 x 2 float grid "density" (written by candela's
// write_grid_file), each 4 bytes of offset (little-endian, modulo the file's size), a length byte,
// and that many bytes written over the file there. A NanoVDB grid holds its nodes at full size (this
// one is 613 KB), too big for seed files, so the fuzzer reaches the internal and leaf nodes through
// patches.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

#include "candela/io/grid_files.h"

namespace candela_fuzz {

// The dense samples the target reads a grid into at most: a few bytes of a sparse grid can span the
// reader's own limit (kMaxDenseGridSamples, 4 GiB of floats), more than libFuzzer's 2 GiB.
inline constexpr uint64_t kMaxFuzzedDenseSamples = uint64_t(1) << 20;

// The file the patches apply to, written once into `dir` and kept in memory.
inline const std::string& nanovdb_template(const std::filesystem::path& dir) {
  static const std::string bytes = [&] {
    const std::filesystem::path file = dir / "template.nvdb";
    candela::write_grid_file(file, "density", {2, 2, 2}, {0, 1, 0.5f, 0, 0, 0.25f, 1, 2}, 0.5f, {-1, 0, 3});
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }();
  return bytes;
}

inline std::string nanovdb_file_of(std::string_view input, const std::filesystem::path& dir) {
  if (input.empty()) return {};
  std::string_view rest = input.substr(1);
  if (!(input[0] & 1)) return std::string(rest);
  std::string file = nanovdb_template(dir);
  while (rest.size() >= 5) {
    uint32_t offset;
    std::memcpy(&offset, rest.data(), 4);
    offset %= uint32_t(file.size());
    const size_t length = std::min<size_t>({uint8_t(rest[4]), rest.size() - 5, file.size() - offset});
    file.replace(offset, length, rest.substr(5, length));
    rest.remove_prefix(5 + length);
  }
  return file;
}

}  // namespace candela_fuzz
