#pragma once
// How fuzz/checkpoint_reader_fuzz.cpp (and tests/fuzz_regression_test.cpp, replaying its findings)
// turn an input into checkpoint bytes. Bit 0 of the first byte set: the rest is the whole file.
// Clear: the rest is a payload, which gets a valid header (magic, version 1, 2 or 3 by bits 1-2,
// size, FNV-1a hash), so that mutations reach the payload's parsing past the checksum.
#include <cstdint>
#include <string>
#include <string_view>

#include "candela/render/checkpoint.h"

namespace candela_fuzz {

inline std::string checkpoint_bytes_of(std::string_view input) {
  if (input.empty()) return {};
  const std::string_view rest = input.substr(1);
  if (input[0] & 1) return std::string(rest);
  const uint32_t version = 1 + (uint8_t(input[0]) >> 1) % 3;
  const uint64_t size = rest.size(), hash = candela::fnv1a64(rest.data(), rest.size());
  std::string file = "CNDLCKPT";
  file.append(reinterpret_cast<const char*>(&version), sizeof version);
  file.append(reinterpret_cast<const char*>(&size), sizeof size);
  file.append(reinterpret_cast<const char*>(&hash), sizeof hash);
  file.append(rest);
  return file;
}

}  // namespace candela_fuzz
