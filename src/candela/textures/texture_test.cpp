#include "candela/textures/texture.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "candela/film/image_io.h"
#include "candela/base/error.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

// The exact sRGB decoding curve, in double, for expected values.
float srgb_to_linear(double v) { return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4)); }

ColorInput color_ref(int texture) {
  ColorInput in;
  in.texture = texture;
  return in;
}

FloatInput float_ref(int texture) {
  FloatInput in;
  in.texture = texture;
  return in;
}

RGB at(const TextureSet& set, int texture, float s, float t) {
  return set.eval(color_ref(texture), TextureEvalContext{Point3(0.0f), Vec2(s, t)});
}

void expect_rgb_near(const RGB& actual, const RGB& expected, float tolerance = 1e-5f) {
  EXPECT_NEAR(actual.r, expected.r, tolerance);
  EXPECT_NEAR(actual.g, expected.g, tolerance);
  EXPECT_NEAR(actual.b, expected.b, tolerance);
}

// Writes pixels (top row first, interleaved channels) exactly as given, with OpenImageIO.
void write_pixels(const fs::path& file, int width, int height, int channels, OIIO::TypeDesc type,
                  const void* pixels) {
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out) throw std::runtime_error("no writer for " + file.string());
  OIIO::ImageSpec spec(width, height, channels, type);
  spec.attribute("oiio:UnassociatedAlpha", 1);  // store colours as given, not un-premultiplied
  if (!out->open(file.string(), spec) || !out->write_image(type, pixels) || !out->close())
    throw std::runtime_error("cannot write " + file.string() + ": " + out->geterror());
}

ImageTexture image_desc(const fs::path& file, TextureWrap wrap = TextureWrap::Repeat, bool bilinear = false,
                        ColorEncoding encoding = ColorEncoding::Auto) {
  ImageTexture desc;
  desc.filename = file.string();
  desc.wrap = wrap;
  desc.filter = bilinear ? TextureFilter::Bilinear : TextureFilter::Nearest;
  desc.encoding = encoding;
  return desc;
}

// A distinct, exactly representable value for texel (x, y), y counted from the top row of the file.
RGB texel_value(int x, int y) { return RGB(float(x), float(y), float(10 * x + y + 1)); }

class TextureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / fmt::format("candela_texture_test_{}_{}", getpid(), info->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // A float EXR holding texel_value(x, y).
  fs::path write_pattern_exr(int width, int height, const std::string& name = "pattern.exr") {
    Image image(width, height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) image.set(x, y, texel_value(x, y));
    fs::path file = dir_ / name;
    write_image(file, image);
    return file;
  }

  fs::path write_u8(const std::string& name, int width, int height, int channels, const std::vector<uint8_t>& pixels) {
    fs::path file = dir_ / name;
    write_pixels(file, width, height, channels, OIIO::TypeDesc::UINT8, pixels.data());
    return file;
  }

  fs::path dir_;
};

// ---------------------------------------------------------------- decoding

TEST_F(TextureTest, Srgb8BitPngIsDecodedWithTheExactCurve) {
  fs::path png = write_u8("grey128.png", 1, 1, 3, {128, 128, 128});
  TextureSet set({image_desc(png, TextureWrap::Repeat, false, ColorEncoding::Auto),
                  image_desc(png, TextureWrap::Repeat, false, ColorEncoding::SRGB),
                  image_desc(png, TextureWrap::Repeat, false, ColorEncoding::Linear)});
  EXPECT_NEAR(at(set, 0, 0.5f, 0.5f).r, 0.2158605f, 1e-5f);
  expect_rgb_near(at(set, 1, 0.5f, 0.5f), RGB(0.2158605f));
  expect_rgb_near(at(set, 2, 0.5f, 0.5f), RGB(128.0f / 255.0f), 1e-7f);
}

TEST_F(TextureTest, SixteenBitPngIsDecodedWithTheExactCurve) {
  std::vector<uint16_t> pixels = {0, 1000, 32768, 65535};  // a 2x2 grey image
  fs::path png = dir_ / "grey16.png";
  write_pixels(png, 2, 2, 1, OIIO::TypeDesc::UINT16, pixels.data());
  TextureSet set({image_desc(png), image_desc(png, TextureWrap::Repeat, false, ColorEncoding::Linear)});
  expect_rgb_near(at(set, 0, 0.25f, 0.25f), RGB(srgb_to_linear(32768.0 / 65535)), 1e-6f);  // bottom-left
  expect_rgb_near(at(set, 0, 0.75f, 0.75f), RGB(srgb_to_linear(1000.0 / 65535)), 1e-7f);   // top-right
  expect_rgb_near(at(set, 1, 0.25f, 0.25f), RGB(32768.0f / 65535), 1e-7f);
  expect_rgb_near(at(set, 1, 0.75f, 0.25f), RGB(1.0f), 0);
}

TEST_F(TextureTest, FloatExrIsLinear) {
  Image image(1, 1);
  image.set(0, 0, RGB(0.5f, 2.0f, 0.25f));
  fs::path exr = dir_ / "value.exr";
  write_image(exr, image);
  // pbrt-v4 and Mitsuba ignore the encoding for float images, and so does candela.
  TextureSet set({image_desc(exr), image_desc(exr, TextureWrap::Repeat, false, ColorEncoding::SRGB),
                  image_desc(exr, TextureWrap::Repeat, false, ColorEncoding::Linear)});
  for (int i = 0; i < 3; ++i) EXPECT_EQ(at(set, i, 0.5f, 0.5f), RGB(0.5f, 2.0f, 0.25f));
}

TEST_F(TextureTest, LuminanceReadsEachColourAsItsGreyLuminance) {
  Image image(1, 1);
  image.set(0, 0, RGB(0.5f, 2.0f, 0.25f));
  fs::path exr = dir_ / "colour.exr";
  write_image(exr, image);
  ImageTexture grey = image_desc(exr);
  grey.luminance = true;
  TextureSet set({image_desc(exr), grey});
  const float y = RGB(0.5f, 2.0f, 0.25f).luminance();
  expect_rgb_near(at(set, 1, 0.5f, 0.5f), RGB(y), 1e-6f);
  FloatInput as_float;
  as_float.texture = 1;
  EXPECT_NEAR(set.eval(as_float, TextureEvalContext{{0, 0, 0}, {0.5f, 0.5f}, {}}), y, 1e-6f);
}

TEST_F(TextureTest, GreyscaleIsReplicatedToRgb) {
  fs::path grey = write_u8("grey.png", 1, 1, 1, {200});
  fs::path grey_alpha = write_u8("grey_alpha.png", 1, 1, 2, {200, 0});
  TextureSet set({image_desc(grey, TextureWrap::Repeat, false, ColorEncoding::Linear),
                  image_desc(grey_alpha, TextureWrap::Repeat, false, ColorEncoding::Linear)});
  expect_rgb_near(at(set, 0, 0.5f, 0.5f), RGB(200.0f / 255), 1e-7f);
  expect_rgb_near(at(set, 1, 0.5f, 0.5f), RGB(200.0f / 255), 1e-7f);
}

TEST_F(TextureTest, AlphaIsIgnoredAndColoursAreNotPremultiplied) {
  fs::path png = write_u8("rgba.png", 2, 1, 4, {200, 100, 50, 64, 10, 20, 30, 0});
  fs::path tga = write_u8("rgba.tga", 2, 1, 4, {200, 100, 50, 64, 10, 20, 30, 0});
  TextureSet set({image_desc(png, TextureWrap::Repeat, false, ColorEncoding::Linear),
                  image_desc(tga, TextureWrap::Repeat, false, ColorEncoding::Linear)});
  for (int i = 0; i < 2; ++i) {
    expect_rgb_near(at(set, i, 0.25f, 0.5f), RGB(200.0f / 255, 100.0f / 255, 50.0f / 255), 1e-7f);
    expect_rgb_near(at(set, i, 0.75f, 0.5f), RGB(10.0f / 255, 20.0f / 255, 30.0f / 255), 1e-7f);
  }
}

TEST_F(TextureTest, TgaJpegAndHdrLoad) {
  fs::path tga = write_u8("texel.tga", 1, 1, 3, {128, 64, 255});
  fs::path jpg = write_u8("texel.jpg", 8, 8, 3, std::vector<uint8_t>(8 * 8 * 3, 128));
  Image image(1, 1);
  image.set(0, 0, RGB(0.5f, 4.0f, 0.125f));  // exactly representable in RGBE
  fs::path hdr = dir_ / "texel.hdr";
  write_pixels(hdr, 1, 1, 3, OIIO::TypeDesc::FLOAT, image.rgb.data());
  TextureSet set({image_desc(tga), image_desc(jpg), image_desc(hdr)});
  expect_rgb_near(at(set, 0, 0.5f, 0.5f), RGB(srgb_to_linear(128 / 255.0), srgb_to_linear(64 / 255.0), 1.0f), 1e-6f);
  expect_rgb_near(at(set, 1, 0.5f, 0.5f), RGB(0.2158605f), 0.01f);  // lossy, but a flat image stays close
  expect_rgb_near(at(set, 2, 0.5f, 0.5f), RGB(0.5f, 4.0f, 0.125f), 1e-6f);
}

TEST(ReadImage, DefaultReadStillDecodesSrgbAndLinearIsOptIn) {
  fs::path png = fs::temp_directory_path() / fmt::format("candela_read_image_test_{}.png", getpid());
  std::vector<uint8_t> pixels = {128, 0, 255};
  write_pixels(png, 1, 1, 3, OIIO::TypeDesc::UINT8, pixels.data());
  Image srgb = read_image(png), linear = read_image(png, IntegerEncoding::Linear);
  fs::remove(png);
  ASSERT_EQ(srgb.width, 1);
  ASSERT_EQ(srgb.height, 1);
  EXPECT_NEAR(srgb.at(0, 0).r, 0.2158605f, 1e-6f);
  EXPECT_EQ(srgb.at(0, 0).g, 0.0f);
  EXPECT_EQ(srgb.at(0, 0).b, 1.0f);
  EXPECT_FLOAT_EQ(linear.at(0, 0).r, 128.0f / 255);
}

// ---------------------------------------------------------------- lookup

TEST_F(TextureTest, NearestAtATexelCentreReturnsThatTexelWithTheTopRowNearTOne) {
  const int w = 4, h = 3;
  TextureSet set({image_desc(write_pattern_exr(w, h), TextureWrap::Repeat, false)});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      EXPECT_EQ(at(set, 0, (x + 0.5f) / w, 1 - (y + 0.5f) / h), texel_value(x, y)) << x << "," << y;
  // The file's first row is at the top of (s, t) space, its last at the bottom.
  EXPECT_EQ(at(set, 0, 0.01f, 0.99f), texel_value(0, 0));
  EXPECT_EQ(at(set, 0, 0.99f, 0.01f), texel_value(w - 1, h - 1));
}

TEST_F(TextureTest, BilinearAtATexelCentreReturnsThatTexel) {
  const int w = 4, h = 3;
  TextureSet set({image_desc(write_pattern_exr(w, h), TextureWrap::Clamp, true)});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) expect_rgb_near(at(set, 0, (x + 0.5f) / w, 1 - (y + 0.5f) / h), texel_value(x, y));
}

TEST_F(TextureTest, BilinearMidpointBetweenTexelCentresIsTheirAverage) {
  const int w = 4, h = 3;
  TextureSet set({image_desc(write_pattern_exr(w, h), TextureWrap::Clamp, true)});
  auto average = [](RGB a, RGB b) { return 0.5f * (a + b); };
  // Horizontal neighbours (1,1)-(2,1), vertical (2,0)-(2,1), and the four around a texel corner.
  expect_rgb_near(at(set, 0, 2.0f / w, 1 - 1.5f / h), average(texel_value(1, 1), texel_value(2, 1)));
  expect_rgb_near(at(set, 0, 2.5f / w, 1 - 1.0f / h), average(texel_value(2, 0), texel_value(2, 1)));
  expect_rgb_near(at(set, 0, 3.0f / w, 1 - 2.0f / h),
                  average(average(texel_value(2, 1), texel_value(3, 1)),
                          average(texel_value(2, 2), texel_value(3, 2))));
  // A quarter of the way from (0,0) to (1,0).
  expect_rgb_near(at(set, 0, 0.75f / w, 1 - 0.5f / h), 0.75f * texel_value(0, 0) + 0.25f * texel_value(1, 0));
}

TEST_F(TextureTest, WrapModesPickTheExpectedTexelOutsideTheUnitSquare) {
  const int w = 4;
  fs::path row = write_pattern_exr(w, 1, "row.exr");
  fs::path column = write_pattern_exr(1, w, "column.exr");
  struct Case {
    TextureWrap wrap;
    int at_minus_quarter, at_one_and_quarter, at_minus_one_point_one, at_two_point_six;  // texel; -1 = black
  };
  // s = -0.25 is texel -1, s = 1.25 is texel 5, s = -1.1 is texel -5, s = 2.6 is texel 10.
  const Case cases[] = {{TextureWrap::Repeat, 3, 1, 3, 2},
                        {TextureWrap::Clamp, 0, 3, 0, 3},
                        {TextureWrap::Black, -1, -1, -1, -1},
                        {TextureWrap::Mirror, 0, 2, 3, 2}};
  for (const Case& c : cases) {
    SCOPED_TRACE(int(c.wrap));
    TextureSet set({image_desc(row, c.wrap, false), image_desc(column, c.wrap, false)});
    const float coords[] = {-0.25f, 1.25f, -1.1f, 2.6f};
    const int expected[] = {c.at_minus_quarter, c.at_one_and_quarter, c.at_minus_one_point_one, c.at_two_point_six};
    for (int k = 0; k < 4; ++k) {
      RGB horizontal = expected[k] < 0 ? RGB(0.0f) : texel_value(expected[k], 0);
      EXPECT_EQ(at(set, 0, coords[k], 0.5f), horizontal) << "s = " << coords[k];
      // Vertically the same texel index is counted from the top, i.e. at t = 1 - coordinate.
      RGB vertical = expected[k] < 0 ? RGB(0.0f) : texel_value(0, expected[k]);
      EXPECT_EQ(at(set, 1, 0.5f, 1 - coords[k]), vertical) << "t = " << 1 - coords[k];
    }
    // Inside the unit square every mode is the plain lookup.
    EXPECT_EQ(at(set, 0, 0.6f, 0.5f), texel_value(2, 0));
  }
}

TEST_F(TextureTest, WrapModesApplyToEachTexelOfTheBilinearFootprint) {
  const int w = 4;
  fs::path row = write_pattern_exr(w, 1);
  auto at_left_edge = [&](TextureWrap wrap) {
    TextureSet set({image_desc(row, wrap, true)});
    return at(set, 0, 0.0f, 0.5f);  // halfway between texel -1 and texel 0
  };
  RGB first = texel_value(0, 0), last = texel_value(w - 1, 0);
  expect_rgb_near(at_left_edge(TextureWrap::Repeat), 0.5f * (first + last));
  expect_rgb_near(at_left_edge(TextureWrap::Clamp), first);
  expect_rgb_near(at_left_edge(TextureWrap::Black), 0.5f * first);
  expect_rgb_near(at_left_edge(TextureWrap::Mirror), first);
}

TEST_F(TextureTest, ScaleIsAppliedBeforeInvertAndResultsAreClampedAtZero) {
  fs::path png = write_u8("values.png", 2, 1, 3, {51, 51, 51, 255, 255, 255});  // 0.2 and 1.0 linear
  ImageTexture scaled = image_desc(png, TextureWrap::Repeat, false, ColorEncoding::Linear);
  scaled.scale = 2;
  ImageTexture inverted = scaled;
  inverted.invert = true;
  TextureSet set({scaled, inverted});
  expect_rgb_near(at(set, 0, 0.25f, 0.5f), RGB(0.4f));
  expect_rgb_near(at(set, 1, 0.25f, 0.5f), RGB(0.6f));  // 1 - 2 * 0.2
  expect_rgb_near(at(set, 1, 0.75f, 0.5f), RGB(0.0f));  // 1 - 2 * 1 < 0
}

TEST_F(TextureTest, UvMappingScalesAndOffsetsBeforeTheLookup) {
  const int w = 4, h = 3;
  ImageTexture desc = image_desc(write_pattern_exr(w, h), TextureWrap::Clamp, false);
  desc.mapping = UVMapping{2, 3, 0.25f, -1};  // s = 2u + 0.25, t = 3v - 1
  TextureSet set({desc});
  // (u, v) = (0.1, 0.5) -> (s, t) = (0.45, 0.5): texel x = 1, row from top 1.
  EXPECT_EQ(at(set, 0, 0.1f, 0.5f), texel_value(1, 1));
  // (u, v) = (0.3, 0.6) -> (0.85, 0.8): x = 3, row 0.
  EXPECT_EQ(at(set, 0, 0.3f, 0.6f), texel_value(3, 0));
}

TEST_F(TextureTest, TexturesOfOneFileShareTheImageButNotAcrossEncodings) {
  fs::path png = write_u8("grey128.png", 1, 1, 3, {128, 128, 128});
  TextureSet set({image_desc(png), image_desc(png, TextureWrap::Clamp, true),
                  image_desc(png, TextureWrap::Repeat, false, ColorEncoding::Linear)});
  EXPECT_EQ(set.size(), 3u);
  EXPECT_NEAR(at(set, 0, 0.5f, 0.5f).g, 0.2158605f, 1e-5f);
  EXPECT_NEAR(at(set, 1, 0.5f, 0.5f).g, 0.2158605f, 1e-5f);
  EXPECT_NEAR(at(set, 2, 0.5f, 0.5f).g, 128.0f / 255, 1e-7f);
}

TEST_F(TextureTest, CopiesStayValidAfterTheOriginalIsGone) {
  fs::path exr = write_pattern_exr(4, 3);
  TextureSet copy;
  {
    TextureSet original({image_desc(exr)});
    copy = original;
  }
  EXPECT_EQ(at(copy, 0, 0.6f, 0.5f), texel_value(2, 1));
}

TEST_F(TextureTest, ConcurrentEvaluationMatchesSequential) {
  ImageTexture image = image_desc(write_pattern_exr(16, 16), TextureWrap::Mirror, true);
  MixTexture mix;
  mix.tex1 = color_ref(0);
  mix.tex2 = RGB(0.5f);
  mix.amount = 0.25f;
  TextureSet set({image, mix});
  // Points over [-1, 2)^2, so that the wrap mode matters too.
  auto sample_point = [](int i) {
    return Vec2(std::fmod(i * 0.6180339f, 3.0f) - 1, std::fmod(i * 0.4142135f, 3.0f) - 1);
  };
  const int n = 20000;
  std::vector<RGB> expected(n);
  for (int i = 0; i < n; ++i) expected[i] = set.eval(color_ref(1), {Point3(0.0f), sample_point(i)});
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> threads;
  for (int k = 0; k < 4; ++k)
    threads.emplace_back([&, k] {
      for (int i = 0; i < n; ++i)
        if (!(set.eval(color_ref(1), {Point3(0.0f), sample_point(i)}) == expected[i])) ++mismatches[k];
    });
  for (auto& t : threads) t.join();
  for (int k = 0; k < 4; ++k) EXPECT_EQ(mismatches[k], 0);
}

// ---------------------------------------------------------------- procedural and composite textures

TEST(TextureSet, ConstantInputsNeedNoTextures) {
  TextureSet set;
  EXPECT_EQ(set.size(), 0u);
  TextureEvalContext ctx{Point3(1, 2, 3), Vec2(0.3f, 0.7f)};
  EXPECT_EQ(set.eval(ColorInput(RGB(0.1f, 0.2f, 0.3f)), ctx), RGB(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(set.eval(FloatInput(0.75f), ctx), 0.75f);
}

TEST(TextureSet, RotatedMappingTurnsTheSquares) {
  // s = -v, t = u (a quarter turn), scaled by 2: a point lands on the square its rotated
  // coordinates name, which an axis-aligned map would get wrong.
  CheckerboardTexture checker;
  checker.tex1 = RGB(1, 0, 0);
  checker.tex2 = RGB(0, 0, 1);
  checker.mapping.su = 0;
  checker.mapping.sv = 0;
  checker.mapping.s_from_v = -2;
  checker.mapping.t_from_u = 2;
  TextureSet set({checker});
  const RGB red(1, 0, 0), blue(0, 0, 1);
  EXPECT_EQ(at(set, 0, 0.25f, 0.25f), blue);  // (s, t) = (-0.5, 0.5): floor -1 + 0
  EXPECT_EQ(at(set, 0, 0.75f, 0.25f), red);   // (-0.5, 1.5): -1 + 1
  EXPECT_EQ(at(set, 0, 0.25f, 0.75f), red);   // (-1.5, 0.5): -2 + 0
  EXPECT_EQ(at(set, 0, 0.6f, 0.6f), blue);    // (-1.2, 1.2): -2 + 1
}

TEST(TextureSet, CheckerboardAlternatesOnUnitSquares) {
  CheckerboardTexture checker;
  checker.tex1 = RGB(1, 0, 0);
  checker.tex2 = RGB(0, 0, 1);
  CheckerboardTexture scaled = checker;
  scaled.mapping = UVMapping{4, 4, 0, 0};
  TextureSet set({checker, scaled});
  const RGB red(1, 0, 0), blue(0, 0, 1);
  EXPECT_EQ(at(set, 0, 0.5f, 0.5f), red);      // 0 + 0
  EXPECT_EQ(at(set, 0, 1.5f, 0.5f), blue);     // 1 + 0
  EXPECT_EQ(at(set, 0, 1.5f, 1.5f), red);      // 1 + 1
  EXPECT_EQ(at(set, 0, -0.5f, 0.5f), blue);    // -1 + 0
  EXPECT_EQ(at(set, 0, -0.5f, -0.5f), red);    // -1 - 1
  EXPECT_EQ(at(set, 0, -2.5f, 0.25f), blue);   // -3 + 0
  EXPECT_EQ(at(set, 1, 0.1f, 0.1f), red);      // floor(0.4) + floor(0.4)
  EXPECT_EQ(at(set, 1, 0.3f, 0.1f), blue);     // floor(1.2) + floor(0.4)
  EXPECT_EQ(at(set, 1, 0.3f, 0.3f), red);      // floor(1.2) + floor(1.2)
}

TEST(TextureSet, ScaleMultipliesByAFloatInput) {
  CheckerboardTexture checker;  // white / black
  ScaleTexture constant_scale;
  constant_scale.tex = RGB(0.2f, 0.4f, 0.6f);
  constant_scale.scale = 0.5f;
  ScaleTexture textured_scale;  // the colour texture read as a float: the average of its channels
  textured_scale.tex = RGB(1, 2, 3);
  textured_scale.scale = float_ref(1);
  ScaleTexture textured_tex;
  textured_tex.tex = color_ref(0);
  textured_tex.scale = 3.0f;
  TextureSet set({checker, constant_scale, textured_scale, textured_tex});
  expect_rgb_near(at(set, 1, 0.5f, 0.5f), RGB(0.1f, 0.2f, 0.3f));
  expect_rgb_near(at(set, 2, 0.5f, 0.5f), RGB(0.2f, 0.4f, 0.6f));  // (1, 2, 3) * average(0.1, 0.2, 0.3)
  EXPECT_EQ(at(set, 3, 0.5f, 0.5f), RGB(3.0f));
  EXPECT_EQ(at(set, 3, 1.5f, 0.5f), RGB(0.0f));
}

TEST(TextureSet, MixBlendsByAmount) {
  CheckerboardTexture checker;  // amounts: 1 on even squares, 0 on odd ones
  MixTexture half;
  half.tex1 = RGB(0.2f, 0.4f, 0.6f);
  half.tex2 = RGB(1.0f, 0.0f, 0.0f);
  MixTexture quarter = half;
  quarter.amount = 0.25f;
  MixTexture textured = half;
  textured.amount = float_ref(0);
  TextureSet set({checker, half, quarter, textured});
  expect_rgb_near(at(set, 1, 0.5f, 0.5f), RGB(0.6f, 0.2f, 0.3f));  // default amount 0.5
  expect_rgb_near(at(set, 2, 0.5f, 0.5f), RGB(0.4f, 0.3f, 0.45f));
  EXPECT_EQ(at(set, 3, 0.5f, 0.5f), RGB(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(at(set, 3, 1.5f, 0.5f), RGB(0.2f, 0.4f, 0.6f));
}

TEST(TextureSet, FloatEvaluationAveragesTheChannels) {
  ScaleTexture colour;
  colour.tex = RGB(0.1f, 0.5f, 0.9f);
  TextureSet set({colour});
  EXPECT_NEAR(set.eval(float_ref(0), {Point3(0.0f), Vec2(0.5f, 0.5f)}), 0.5f, 1e-7f);
}

TEST(TextureSet, InvalidReferencesAreSceneErrors) {
  auto expect_error = [](const std::vector<TextureDesc>& descs, const std::string& fragment) {
    try {
      TextureSet set(descs);
      ADD_FAILURE() << "no SceneError; expected one mentioning \"" << fragment << "\"";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  CheckerboardTexture checker;
  ScaleTexture out_of_range;
  out_of_range.tex = color_ref(7);
  expect_error({checker, out_of_range}, "texture 1: refers to texture 7");
  MixTexture self;
  self.amount = float_ref(0);
  expect_error({self}, "texture 0: refers to itself");
  ScaleTexture forward;
  forward.scale = float_ref(1);
  expect_error({forward, checker}, "texture 0: refers to texture 1, which comes after it");
  // Two textures referring to each other: the cycle shows up as a forward reference.
  ScaleTexture a, b;
  a.tex = color_ref(1);
  b.tex = color_ref(0);
  expect_error({a, b}, "texture 0: refers to texture 1");
  // Backward references are fine.
  EXPECT_NO_THROW(TextureSet({checker, b}));
}

TEST_F(TextureTest, MissingOrUnreadableImagesAreSceneErrorsNamingTheFile) {
  fs::path missing = dir_ / "no-such-texture.png";
  fs::path garbage = dir_ / "garbage.png";
  { std::FILE* f = std::fopen(garbage.c_str(), "w"); std::fputs("not an image", f); std::fclose(f); }
  for (const fs::path& file : {missing, garbage}) {
    try {
      TextureSet set({CheckerboardTexture{}, image_desc(file)});
      ADD_FAILURE() << "no SceneError for " << file;
    } catch (const SceneError& e) {
      std::string message = e.what();
      EXPECT_NE(message.find(file.string()), std::string::npos) << message;
      EXPECT_NE(message.find("texture 1"), std::string::npos) << message;
    }
  }
}

// ---------------------------------------------------------------- real scene textures

TEST(TextureSet, SharedTgaTexturesLoad) {
#ifndef CANDELA_SHARED_DIR
  GTEST_SKIP() << "CANDELA_SHARED_DIR not defined";
#else
  fs::path dir = fs::path(CANDELA_SHARED_DIR) / "scenes/bitterli/veach-ajar/textures";
  fs::path file = dir / "cherry-wood-texture.tga";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not found";
  Image image = read_image(file);
  EXPECT_EQ(image.width, 1280);
  EXPECT_EQ(image.height, 1024);
  TextureSet set({image_desc(file, TextureWrap::Repeat, true), image_desc(dir / "landscape-with-a-lake.tga")});
  RGB sum(0.0f);
  for (int i = 0; i < 64; ++i)
    for (int k = 0; k < 2; ++k) {
      RGB c = at(set, k, (i % 8 + 0.5f) / 8, (i / 8 + 0.5f) / 8);
      EXPECT_TRUE(c.is_finite());
      EXPECT_GE(c.min_component(), 0.0f);
      EXPECT_LE(c.max_component(), 1.0f);
      sum += c;
    }
  EXPECT_GT(sum.average(), 1.0f);  // not a black image
#endif
}

}  // namespace
}  // namespace candela
