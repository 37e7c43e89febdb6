// Gzipped input (io/gzip.h): whole files and concatenated members read back exactly; damaged data,
// data cut short and data inflating past the limit refused with one message each.
#include "candela/io/gzip.h"

#include <gtest/gtest.h>

#include <string>

#include "candela/base/error.h"
#include "candela/testing/gzip_bytes.h"

namespace candela {
namespace {

using testing::gzip_bomb;
using testing::gzip_bytes;

std::string gunzip_error(std::string_view bytes, uint64_t max_bytes = kMaxGunzippedBytes) {
  try {
    gunzip(bytes, max_bytes);
  } catch (const FileContentError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Gzip, RecognisedByItsMagicBytes) {
  EXPECT_TRUE(is_gzip(gzip_bytes("WorldBegin\n")));
  EXPECT_FALSE(is_gzip("WorldBegin\n"));
  EXPECT_FALSE(is_gzip("\x1f"));
  EXPECT_FALSE(is_gzip(""));
  EXPECT_EQ(gunzip_if_gzip("ply\n"), "ply\n");
}

TEST(Gzip, ReadsWholeFilesAndConcatenatedMembers) {
  std::string text;
  for (int k = 0; k < 100000; ++k) text += "Shape \"sphere\" \"float radius\" " + std::to_string(k) + "\n";
  EXPECT_EQ(gunzip(gzip_bytes(text)), text);
  EXPECT_EQ(gunzip(gzip_bytes("first\n") + gzip_bytes("second\n")), "first\nsecond\n");
  EXPECT_EQ(gunzip(gzip_bytes("")), "");
  EXPECT_EQ(gunzip_if_gzip(gzip_bytes(text)), text);
}

TEST(Gzip, DamagedOrCutShortDataIsAnError) {
  const std::string whole = gzip_bytes(std::string(5000, 'x') + "the end");
  EXPECT_EQ(gunzip_error(whole.substr(0, whole.size() / 2)), "gzip: the compressed data is cut short");
  EXPECT_EQ(gunzip_error(whole.substr(0, whole.size() - 1)), "gzip: the compressed data is cut short");
  std::string flipped = whole;
  flipped[flipped.size() - 6] ^= 0x10;  // in the CRC-32 of the trailer
  EXPECT_NE(gunzip_error(flipped).find("gzip: corrupt compressed data"), std::string::npos) << gunzip_error(flipped);
  EXPECT_EQ(gunzip_error(whole + "trailing"),
            "gzip: 8 bytes after the end of the compressed data are not gzip data");
}

TEST(Gzip, InflatingPastTheLimitIsRefused) {
  const std::string bomb = gzip_bomb(8);  // about 8 KB inflating to 8 MiB
  EXPECT_LT(bomb.size(), 10000u);
  EXPECT_EQ(gunzip_error(bomb, uint64_t(4) << 20),
            "gzip: it decompresses to more than 4.0 MiB, the limit for a gzipped file (a gzip bomb?); gunzip it to read "
            "it without this limit");
  EXPECT_EQ(gunzip(bomb, uint64_t(8) << 20).size(), size_t(8) << 20);  // exactly at the limit is read
  EXPECT_EQ(kMaxGunzippedBytes, uint64_t(1) << 30);
}

}  // namespace
}  // namespace candela
