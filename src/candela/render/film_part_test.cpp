// Render parts (candela render --part K/N) refused with a message naming the file when their header,
// attributes or channels are not a part's: found by fuzz/part_reader_fuzz.cpp (docs/reliability.md).
#include "candela/render/film_part.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>

#include "candela/base/error.h"
#include "candela/film/image_io.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

struct PartFile : ::testing::Test {
  void SetUp() override {
    file = fs::temp_directory_path() / ("candela_film_part_test_" + std::to_string(getpid()) + ".exr");
    FilmPart part;
    part.fingerprint.scene_hash = 0x0123456789abcdefULL;
    part.fingerprint.settings = {{"resolution", "2x2"}, {"spp", "1"}, {"seed", "1"}};
    part.film = Film(2, 2);
    part.film.add_sample(1, 0, RGB(1, 2, 3));
    write_part(file, part, {});
  }
  void TearDown() override { fs::remove(file); }
  // The part written again with `key` set to `value` (the pixels as they are).
  void set_attribute(const std::string& key, const std::string& value) const {
    std::map<std::string, std::string> metadata = read_image_metadata(file);
    metadata[key] = value;
    const ExactChannels channels = read_exact_channels(file, "candela.");
    write_image(file, read_image(file), metadata, channels);
  }
  std::string merge_error() const {
    try {
      merge_parts({file});
    } catch (const FileContentError& e) {
      return e.what();
    }
    return "";
  }
  fs::path file;
};

TEST_F(PartFile, ReadsBackAsWritten) {
  EXPECT_EQ(merge_error(), "");
  EXPECT_EQ(read_part(file).film.pixel(1, 0).count, 1u);
}

// A 484-byte file whose header declared an attribute of 1.8 GB: OpenEXR allocated it all before
// failing, 18 s under ASan (fuzz/regressions/part_reader/timeout-header-attribute-of-1.8-gb).
TEST_F(PartFile, HeaderAttributeLargerThanTheHeaderIsRefused) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const size_t size_at = bytes.find(std::string("candela:part\0string\0", 20)) + 20;
  const int32_t huge = 1800000000;
  std::memcpy(bytes.data() + size_at, &huge, 4);
  std::ofstream(file, std::ios::binary) << bytes;
  const std::string message = merge_error();
  EXPECT_EQ(message.rfind(file.string() + ": cannot read image: its OpenEXR header attribute 'candela:part' claims "
                                          "1800000000 bytes, more than the ", 0), 0u) << message;
  // A texture of the same file, through read_image (textures, environment maps): the same refusal,
  // before OpenEXR allocates the attribute.
  try {
    (void)read_image(file);
    ADD_FAILURE() << "read";
  } catch (const FileContentError& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

// std::stoull threw std::invalid_argument ("stoull"), naming neither the file nor the attribute.
TEST_F(PartFile, AttributeThatIsNotANumberIsRefusedNamingIt) {
  set_attribute("candela:scene_hash", "hello");
  EXPECT_EQ(merge_error(), file.string() + ": candela:scene_hash 'hello' is not a hexadecimal number below 2^64");
  set_attribute("candela:scene_hash", "0123456789abcdef");
  set_attribute("candela:non_finite_samples", "18446744073709551616");
  EXPECT_EQ(merge_error(),
            file.string() + ": candela:non_finite_samples '18446744073709551616' is not a decimal number below 2^64");
}

// -2 x -2 passed the pixel count check (4 pixels) and made a film of negative width.
TEST_F(PartFile, NegativeResolutionIsRefused) {
  set_attribute("candela:settings", "resolution=-2x-2\nspp=1\nseed=1\n");
  EXPECT_EQ(merge_error(), file.string() + ": its pixels do not match its resolution setting '-2x-2'");
}

// Part 1 of 2147483647 made merge allocate a vector of 2147483647 part holders (8 GB) before it
// found the others missing.
TEST_F(PartFile, OnePartOfVeryManyIsFoundMissingTheOthers) {
  set_attribute("candela:part", "1/2147483647");
  EXPECT_EQ(merge_error(), "merge: part 2/2147483647 of seed 1 is missing (have " + file.string() + ")");
}

}  // namespace
}  // namespace candela
