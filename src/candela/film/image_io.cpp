#include "candela/film/image_io.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace candela {
namespace {

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

uint8_t encode_srgb8(float linear) {
  if (!(linear > 0)) return 0;  // also maps NaN to black
  float v = linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1 / 2.4f) - 0.055f;
  return uint8_t(std::clamp(std::lround(v * 255.0f), 0L, 255L));
}

}  // namespace

bool is_supported_output(const std::filesystem::path& file) {
  std::string ext = lower_extension(file);
  return ext == ".exr" || ext == ".png" || ext == ".pfm";
}

void write_image(const std::filesystem::path& file, const Image& image,
                 const std::map<std::string, std::string>& metadata) {
  if (!is_supported_output(file))
    throw std::runtime_error(fmt::format("{}: unsupported image format (use .exr, .png or .pfm)", file.string()));
  std::string ext = lower_extension(file);
  std::filesystem::path dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::filesystem::path tmp = dir / fmt::format(".{}.{}.tmp{}", file.stem().string(), getpid(), ext);

  auto out = OIIO::ImageOutput::create(tmp.string());
  if (!out) throw std::runtime_error(fmt::format("{}: cannot create image writer: {}", file.string(), OIIO::geterror()));
  bool ok;
  if (ext == ".png") {
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    std::vector<uint8_t> pixels(image.rgb.size());
    std::transform(image.rgb.begin(), image.rgb.end(), pixels.begin(), encode_srgb8);
    ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
  } else {
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    spec.attribute("oiio:ColorSpace", "Linear");
    if (ext == ".exr") {
      spec.attribute("compression", "zip");
      for (const auto& [key, value] : metadata) spec.attribute(key, value);
    }
    ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, image.rgb.data());
  }
  std::string error = ok ? "" : out->geterror();
  ok = out->close() && ok;
  if (!ok) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(fmt::format("{}: cannot write image: {}", file.string(), error));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(fmt::format("{}: cannot write image: {}", file.string(), ec.message()));
  }
}

Image read_image(const std::filesystem::path& file) {
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read image: {}", file.string(), OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  int channels = spec.nchannels;
  std::vector<float> data(size_t(spec.width) * spec.height * channels);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data()))
    throw std::runtime_error(fmt::format("{}: cannot read image: {}", file.string(), in->geterror()));
  bool srgb = spec.format == OIIO::TypeDesc::UINT8 || spec.format == OIIO::TypeDesc::UINT16;
  Image img(spec.width, spec.height);
  for (size_t i = 0; i < size_t(spec.width) * spec.height; ++i)
    for (int c = 0; c < 3; ++c) {
      float v = data[i * channels + std::min(c, channels - 1)];
      if (srgb) v = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
      img.rgb[i * 3 + c] = v;
    }
  in->close();
  return img;
}

std::map<std::string, std::string> read_image_metadata(const std::filesystem::path& file) {
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read image: {}", file.string(), OIIO::geterror()));
  std::map<std::string, std::string> result;
  for (const auto& attr : in->spec().extra_attribs) result[attr.name().string()] = attr.get_string();
  in->close();
  return result;
}

}  // namespace candela
