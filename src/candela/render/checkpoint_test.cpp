// Checkpoint files: exact round trip of the film sums, fingerprints naming what differs, and
// truncated or corrupt files refused with a clear message.
#include "candela/render/checkpoint.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>

#include "candela/base/error.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

Checkpoint sample_checkpoint() {
  Checkpoint cp;
  cp.fingerprint.scene_hash = fnv1a64("scene", 5);
  cp.fingerprint.settings = {{"resolution", "3x2"}, {"spp", "64"}, {"seed", "7"}};
  cp.width = 3;
  cp.height = 2;
  cp.non_finite_samples = 11;
  cp.pixels.resize(6);
  for (size_t i = 0; i < 6; ++i) {
    PixelSums& p = cp.pixels[i];
    for (int c = 0; c < 3; ++c) {
      p.weighted[c] = std::nextafter(0.1 * double(i + c), 1.0);
      p.weighted_sq[c] = 1.0 / 3.0 + double(i);
    }
    p.weight = 0.7 * double(i);
    p.count = 4 * i;
  }
  return cp;
}

struct CheckpointFile : ::testing::Test {
  void SetUp() override {
    file = fs::temp_directory_path() / ("candela_checkpoint_test_" + std::to_string(getpid()) + ".ckpt");
  }
  void TearDown() override { fs::remove(file); }
  std::string bytes() const {
    std::ifstream in(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  void put(const std::string& b) const { std::ofstream(file, std::ios::binary) << b; }
  std::string error() const {
    try {
      read_checkpoint(file);
    } catch (const FileContentError& e) {
      return e.what();
    }
    return "";
  }
  fs::path file;
};

TEST_F(CheckpointFile, RoundTripIsExact) {
  Checkpoint cp = sample_checkpoint();
  write_checkpoint(file, cp);
  Checkpoint back = read_checkpoint(file);
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 2);
  EXPECT_EQ(back.non_finite_samples, 11u);
  EXPECT_EQ(back.fingerprint.difference(cp.fingerprint), "");
  ASSERT_EQ(back.pixels.size(), cp.pixels.size());
  EXPECT_EQ(std::memcmp(back.pixels.data(), cp.pixels.data(), cp.pixels.size() * sizeof(PixelSums)), 0);
  // No temporary left beside it.
  int files = 0;
  for (const auto& e : fs::directory_iterator(file.parent_path()))
    if (e.path().filename().string().rfind(file.filename().string(), 0) == 0) ++files;
  EXPECT_EQ(files, 1);
}

TEST_F(CheckpointFile, SplatSumsRoundTripAndMustMatchTheSize) {
  // Bidirectional renders keep their light-path splats (fixed-point sums) in the checkpoint.
  Checkpoint cp = sample_checkpoint();
  cp.splats.resize(18);
  for (size_t i = 0; i < cp.splats.size(); ++i) cp.splats[i] = int64_t(i * i) * (i % 2 ? -1 : 1) + (int64_t(1) << 40);
  cp.half_splats.assign(cp.splats.rbegin(), cp.splats.rend());
  cp.pixels[4].half_weighted[2] = 0.25;
  cp.pixels[4].half_count = 3;
  write_checkpoint(file, cp);
  Checkpoint back = read_checkpoint(file);
  EXPECT_EQ(back.splats, cp.splats);
  EXPECT_EQ(back.half_splats, cp.half_splats);  // the first half's, for error estimates
  EXPECT_EQ(back.pixels[4].half_weighted[2], 0.25);
  EXPECT_EQ(back.pixels[4].half_count, 3u);
  EXPECT_EQ(back.pixels.size(), 6u);
  // A checkpoint without splats reads back without them.
  write_checkpoint(file, sample_checkpoint());
  EXPECT_TRUE(read_checkpoint(file).splats.empty());
  // A splat array that does not fit the film is refused before anything is written.
  cp.splats.resize(5);
  EXPECT_THROW(write_checkpoint(file, cp), InternalError);
}

TEST_F(CheckpointFile, TruncatedCorruptAndForeignFilesAreRefused) {
  write_checkpoint(file, sample_checkpoint());
  std::string good = bytes();
  put(good.substr(0, good.size() - 9));
  EXPECT_NE(error().find("truncated"), std::string::npos) << error();
  put(good.substr(0, 12));
  EXPECT_NE(error().find("truncated"), std::string::npos) << error();
  std::string flipped = good;
  flipped[flipped.size() - 20] ^= 0x10;
  put(flipped);
  EXPECT_NE(error().find("checksum"), std::string::npos) << error();
  put("hello world, not a checkpoint at all");
  EXPECT_NE(error().find("not a candela checkpoint"), std::string::npos) << error();
  std::string other_version = good;
  other_version[8] = 9;
  put(other_version);
  EXPECT_NE(error().find("version"), std::string::npos) << error();
  fs::remove(file);
  EXPECT_NE(error().find("cannot open"), std::string::npos) << error();
}

// Hostile inputs (docs/reliability.md): the file cut at every 64th of its length, and one bit flipped
// at every 64th, is refused each time with one message naming the file and what is wrong; never read.
TEST_F(CheckpointFile, EveryTruncationAndBitFlipIsRefused) {
  write_checkpoint(file, sample_checkpoint());
  const std::string good = bytes();
  ASSERT_GT(good.size(), 64u * 8);
  const auto refusal = [](const std::string& damaged) {
    try {
      parse_checkpoint(damaged, "render.ckpt");
    } catch (const FileContentError& e) {
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  const std::regex expected(
      R"(checkpoint 'render\.ckpt': (truncated|corrupt|not a candela checkpoint|unsupported version) .*)");
  for (size_t k = 0; k < 64; ++k) {
    const size_t at = good.size() * k / 64;
    const std::string cut = refusal(good.substr(0, at));
    EXPECT_TRUE(std::regex_match(cut, expected)) << "cut at " << at << ": " << cut;
    std::string flipped = good;
    flipped[at] = char(flipped[at] ^ (1 << (k % 8)));
    const std::string flip = refusal(flipped);
    EXPECT_TRUE(std::regex_match(flip, expected)) << "bit " << k % 8 << " of byte " << at << " flipped: " << flip;
  }
}

// Found by fuzz/checkpoint_reader_fuzz.cpp's input (docs/reliability.md): a version 1 checkpoint
// of 2^30 x 2^30 pixels and no pixel data. 2^60 pixels of 64 bytes wrap to 0 bytes, which matched
// the empty payload left, and the reader then asked for 2^60 pixels (std::length_error).
TEST(CheckpointBytes, SizeWhosePixelBytesPass2To64IsCorrupt) {
  std::string payload(8 + 4, '\0');  // scene hash, no settings
  for (int32_t side : {1 << 30, 1 << 30}) payload.append(reinterpret_cast<const char*>(&side), 4);
  payload.append(8, '\0');  // no non-finite samples
  const uint32_t version = 1;
  const uint64_t size = payload.size(), hash = fnv1a64(payload.data(), payload.size());
  std::string bytes = "CNDLCKPT";
  bytes.append(reinterpret_cast<const char*>(&version), 4);
  bytes.append(reinterpret_cast<const char*>(&size), 8);
  bytes.append(reinterpret_cast<const char*>(&hash), 8);
  try {
    parse_checkpoint(bytes + payload, "big.ckpt");
    FAIL() << "read";
  } catch (const FileContentError& e) {
    EXPECT_STREQ(e.what(), "checkpoint 'big.ckpt': corrupt (pixel data does not match the size)");
  }
}

TEST(RenderFingerprint, NamesWhatDiffers) {
  RenderFingerprint a = sample_checkpoint().fingerprint, b = a;
  EXPECT_EQ(a.difference(b), "");
  b.settings[1].second = "128";
  EXPECT_EQ(a.difference(b), "settings differ: spp 64 vs 128");
  b = a;
  b.scene_hash ^= 1;
  EXPECT_EQ(a.difference(b), "scene file differs");
  b.settings[2].second = "8";
  EXPECT_EQ(a.difference(b), "scene file differs; settings differ: seed 7 vs 8");
}

}  // namespace
}  // namespace candela
