#include "candela/film/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "candela/base/error.h"

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

// Debian's OpenImageIO 2.4 reads PFM but its PNM writer only writes 8/16-bit PPM, so PFM is written
// here: the header "PF\n<w> <h>\n-1.0\n" (negative scale = little-endian), then rows bottom to top.
bool write_pfm(const std::filesystem::path& file, const Image& image) {
  FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) return false;
  bool ok = std::fprintf(f, "PF\n%d %d\n-1.0\n", image.width, image.height) > 0;
  static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian machine");
  for (int y = image.height - 1; y >= 0 && ok; --y)
    ok = std::fwrite(&image.rgb[size_t(y) * image.width * 3], sizeof(float), size_t(image.width) * 3, f) ==
         size_t(image.width) * 3;
  return std::fclose(f) == 0 && ok;
}

}  // namespace

bool is_supported_output(const std::filesystem::path& file) {
  std::string ext = lower_extension(file);
  return ext == ".exr" || ext == ".png" || ext == ".pfm";
}

namespace {

// An 8-bit sRGB PNG (values clipped to [0,1]) through `out`, opened as `name`.
bool write_png(OIIO::ImageOutput& out, const std::string& name, const Image& image) {
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  std::vector<uint8_t> pixels(image.rgb.size());
  std::transform(image.rgb.begin(), image.rgb.end(), pixels.begin(), encode_srgb8);
  return out.open(name, spec) && out.write_image(OIIO::TypeDesc::UINT8, pixels.data());
}

}  // namespace

std::vector<unsigned char> encode_png(const Image& image) {
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput memory(bytes);
  auto out = OIIO::ImageOutput::create("image.png", &memory);
  if (!out) throw InternalError("cannot create a PNG writer: " + OIIO::geterror());
  bool ok = write_png(*out, "image.png", image);
  std::string error = ok ? "" : out->geterror();
  if (!out->close() || !ok) throw InternalError("cannot encode PNG: " + (error.empty() ? out->geterror() : error));
  return bytes;
}

namespace {

// Channels after R, G, B, every value 4 bytes (float or uint32): names->size() per pixel, row-major.
struct ExtraChannels {
  const std::vector<std::string>* names = nullptr;
  OIIO::TypeDesc format = OIIO::TypeDesc::FLOAT;
  const void* values = nullptr;
  bool empty() const { return !names || names->empty(); }
};

// Writes with OpenImageIO; returns an error message, empty on success.
std::string write_with_oiio(const std::filesystem::path& tmp, const std::string& ext, const Image& image,
                            const std::map<std::string, std::string>& metadata, const ExtraChannels& extra) {
  auto out = OIIO::ImageOutput::create(tmp.string());
  if (!out) return "cannot create image writer: " + OIIO::geterror();
  bool ok;
  if (ext == ".png") {
    ok = write_png(*out, tmp.string(), image);
  } else {
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    if (ext == ".exr" && image.full_width > 0) {  // a crop: its data window in the display window
      spec.x = image.x;
      spec.y = image.y;
      spec.full_width = image.full_width;
      spec.full_height = image.full_height;
    }
    spec.attribute("oiio:ColorSpace", "Linear");
    spec.attribute("compression", "zip");
    for (const auto& [key, value] : metadata) spec.attribute(key, value);
    if (extra.empty()) {
      ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, image.rgb.data());
    } else {
      // R, G, B as float, then the extra channels in their format, interleaved per pixel (all 4 bytes).
      static_assert(sizeof(float) == sizeof(uint32_t));
      const size_t n = extra.names->size(), per_pixel = 3 + n;
      spec.nchannels = int(per_pixel);
      spec.channelformats.assign(3, OIIO::TypeDesc::FLOAT);
      spec.channelformats.resize(per_pixel, extra.format);
      spec.channelnames = {"R", "G", "B"};
      spec.channelnames.insert(spec.channelnames.end(), extra.names->begin(), extra.names->end());
      std::vector<uint32_t> pixels(size_t(image.width) * size_t(image.height) * per_pixel);
      const auto* values = static_cast<const std::byte*>(extra.values);
      for (size_t i = 0; i < size_t(image.width) * size_t(image.height); ++i) {
        std::memcpy(&pixels[i * per_pixel], &image.rgb[i * 3], 3 * sizeof(float));
        std::memcpy(&pixels[i * per_pixel + 3], values + i * n * sizeof(uint32_t), n * sizeof(uint32_t));
      }
      ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::UNKNOWN, pixels.data());
    }
  }
  std::string error = ok ? "" : out->geterror();
  if (!out->close() && error.empty()) error = out->geterror();
  return ok && error.empty() ? "" : (error.empty() ? "write failed" : error);
}

void write_image_with(const std::filesystem::path& file, const Image& image,
                      const std::map<std::string, std::string>& metadata, const ExtraChannels& extra) {
  if (!extra.empty() && lower_extension(file) != ".exr")
    throw InternalError(fmt::format("{}: only .exr files keep extra channels", file.string()));
  if (!is_supported_output(file))
    throw OutputError(fmt::format("{}: unsupported image format (use .exr, .png or .pfm)", file.string()));
  std::string ext = lower_extension(file);
  std::filesystem::path dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::filesystem::path tmp = dir / fmt::format(".{}.{}.tmp{}", file.stem().string(), getpid(), ext);

  std::string error = ext == ".pfm" ? (write_pfm(tmp, image) ? "" : std::string(std::strerror(errno)))
                                    : write_with_oiio(tmp, ext, image, metadata, extra);
  std::error_code ec;
  if (error.empty()) {
    std::filesystem::rename(tmp, file, ec);
    if (ec) error = ec.message();
  }
  if (!error.empty()) {
    std::filesystem::remove(tmp, ec);
    throw OutputError(fmt::format("{}: cannot write image: {}", file.string(), error));
  }
}

// OIIO::ImageInput::open after check_exr_header; throws naming the file when the file cannot be opened.
std::unique_ptr<OIIO::ImageInput> open_image(const std::filesystem::path& file, const OIIO::ImageSpec* config = nullptr) {
  check_exr_header(file);
  auto in = OIIO::ImageInput::open(file.string(), config);
  if (!in) throw FileContentError(fmt::format("{}: cannot read image: {}", file.string(), OIIO::geterror()));
  return in;
}

// check_image_size, and for a PFM (uncompressed) that the file holds the pixels its header claims:
// OpenImageIO would allocate them all before finding the file cut short.
void check_image_header(const std::filesystem::path& file, const OIIO::ImageInput& in) {
  const OIIO::ImageSpec& spec = in.spec();
  check_image_size(file, spec.width, spec.height);
  // OpenImageIO reads PFM with its PNM reader; PFM is the PNM with float pixels.
  if (std::string_view(in.format_name()) != "pnm" || spec.format != OIIO::TypeDesc::FLOAT) return;
  std::error_code ec;
  const uint64_t file_bytes = std::filesystem::file_size(file, ec);
  const uint64_t pixel_bytes = uint64_t(spec.width) * uint64_t(spec.height) * spec.pixel_bytes();
  if (!ec && file_bytes < pixel_bytes)
    throw FileContentError(fmt::format("{}: cannot read image: the file has {} bytes, too few for the {} x {} pixels "
                                         "its header claims (cut short?)",
                                         file.string(), file_bytes, spec.width, spec.height));
}

// The channels of `file` whose names start with `prefix` (together), each checked by `check`
// (which throws) and read as `format` into `values`.
template <typename T, typename Check>
std::vector<std::string> read_channels(const std::filesystem::path& file, const std::string& prefix,
                                       OIIO::TypeDesc format, Check check, std::vector<T>& values) {
  auto in = open_image(file);
  check_image_header(file, *in);
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<std::string> names;
  int first = -1, last = -1;
  for (int c = 0; c < spec.nchannels; ++c)
    if (spec.channelnames[size_t(c)].rfind(prefix, 0) == 0) {
      if (first >= 0 && c != last + 1)
        throw FileContentError(fmt::format("{}: the {}* channels are not together", file.string(), prefix));
      check(spec, c);
      if (first < 0) first = c;
      last = c;
      names.push_back(spec.channelnames[size_t(c)]);
    }
  values.clear();
  if (first >= 0) {
    values.resize(size_t(spec.width) * size_t(spec.height) * names.size());
    if (!in->read_image(0, 0, first, last + 1, format, values.data()))
      throw FileContentError(fmt::format("{}: cannot read image: {}", file.string(), in->geterror()));
  }
  in->close();
  return names;
}

}  // namespace

int check_exr_header(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char start[8] = {};
  if (!in.read(start, 8) || std::memcmp(start, "\x76\x2f\x31\x01", 4) != 0) return -1;
  std::error_code ec;
  const uint64_t file_bytes = std::filesystem::file_size(file, ec);
  const auto malformed = [&] {
    throw FileContentError(fmt::format("{}: cannot read image: its OpenEXR header is malformed or cut short", file.string()));
  };
  // A name or type of at most 255 bytes (OpenEXR's long names) ended by a NUL byte; "" ends a header.
  const auto read_string = [&] {
    std::string text;
    for (char c; text.size() <= 255;) {
      if (!in.get(c)) malformed();
      if (c == '\0') return text;
      text += c;
    }
    malformed();
    return text;
  };
  const int flags = uint8_t(start[5]);
  // A multi-part file holds a header per part, then an empty one.
  for (;;) {
    std::string name = read_string();
    if (name.empty()) return flags;
    for (; !name.empty(); name = read_string()) {
      (void)read_string();  // the attribute's type
      int32_t size = 0;
      if (!in.read(reinterpret_cast<char*>(&size), 4)) malformed();
      const uint64_t left = file_bytes - uint64_t(in.tellg());
      if (size < 0 || uint64_t(size) > left)
        throw FileContentError(fmt::format("{}: cannot read image: its OpenEXR header attribute '{}' claims {} bytes, "
                                             "more than the {} left in the file",
                                             file.string(), name, size, left));
      in.seekg(size, std::ios::cur);
    }
    if (!(flags & 0x10)) return flags;
  }
}

void check_image_size(const std::filesystem::path& file, int64_t width, int64_t height) {
  if (width > kMaxImageSide || height > kMaxImageSide || width * height > kMaxImageTexels)
    throw FileContentError(fmt::format("{}: the image is {} x {} texels, more than candela reads (at most {} on a "
                                         "side and {} = 2^29 in all)",
                                         file.string(), width, height, kMaxImageSide, kMaxImageTexels));
}

void write_image(const std::filesystem::path& file, const Image& image,
                 const std::map<std::string, std::string>& metadata) {
  write_image_with(file, image, metadata, ExtraChannels{});
}

void write_image(const std::filesystem::path& file, const Image& image, const std::map<std::string, std::string>& metadata,
                 const ExactChannels& extra) {
  write_image_with(file, image, metadata, {&extra.names, OIIO::TypeDesc::UINT32, extra.values.data()});
}

void write_image(const std::filesystem::path& file, const Image& image, const std::map<std::string, std::string>& metadata,
                 const FloatChannels& extra) {
  write_image_with(file, image, metadata, {&extra.names, OIIO::TypeDesc::FLOAT, extra.values.data()});
}

namespace {

// Integer value -> linear float for every value of a `max_value`-bit-depth image: a table keeps the
// exact curve (computed in double) off the per-pixel path.
std::vector<float> decode_table(int max_value, IntegerEncoding encoding) {
  std::vector<float> table(size_t(max_value) + 1);
  for (int i = 0; i <= max_value; ++i) {
    double v = double(i) / max_value;
    if (encoding == IntegerEncoding::SRGB) v = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
    table[size_t(i)] = float(v);
  }
  return table;
}

// Reads all pixels as T and converts them to RGB with `to_linear`; one or two channels are grey
// (plus alpha), so channel 0 fills R, G and B.
template <typename T, typename ToLinear>
bool read_pixels(OIIO::ImageInput& in, OIIO::TypeDesc type, ToLinear to_linear, Image& img) {
  const OIIO::ImageSpec& spec = in.spec();
  int channels = spec.nchannels;
  std::vector<T> data(size_t(spec.width) * size_t(spec.height) * size_t(channels));
  if (!in.read_image(0, 0, 0, channels, type, data.data())) return false;
  const int source[3] = {0, channels < 3 ? 0 : 1, channels < 3 ? 0 : 2};
  size_t n = size_t(spec.width) * size_t(spec.height);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = to_linear(data[i * channels + source[c]]);
  return true;
}

}  // namespace

Image read_image(const std::filesystem::path& file, IntegerEncoding encoding) {
  // PNG and TGA readers premultiply colour by alpha unless told not to; alpha is ignored here, so
  // the stored colours are wanted.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = open_image(file, &config);
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw FileContentError(fmt::format("{}: cannot read image: empty image", file.string()));
  check_image_header(file, *in);
  Image img(spec.width, spec.height);
  bool ok;
  if (spec.format == OIIO::TypeDesc::UINT8) {
    std::vector<float> table = decode_table(255, encoding);
    ok = read_pixels<uint8_t>(*in, OIIO::TypeDesc::UINT8, [&](uint8_t v) { return table[v]; }, img);
  } else if (spec.format == OIIO::TypeDesc::UINT16) {
    std::vector<float> table = decode_table(65535, encoding);
    ok = read_pixels<uint16_t>(*in, OIIO::TypeDesc::UINT16, [&](uint16_t v) { return table[v]; }, img);
  } else {
    ok = read_pixels<float>(*in, OIIO::TypeDesc::FLOAT, [](float v) { return v; }, img);
  }
  if (!ok) throw FileContentError(fmt::format("{}: cannot read image: {}", file.string(), in->geterror()));
  in->close();
  return img;
}

Image read_image(const std::filesystem::path& file) { return read_image(file, IntegerEncoding::SRGB); }

ExactChannels read_exact_channels(const std::filesystem::path& file, const std::string& prefix) {
  ExactChannels result;
  result.names = read_channels(
      file, prefix, OIIO::TypeDesc::UINT32,
      [&](const OIIO::ImageSpec& spec, int c) {
        if (spec.channelformat(c) != OIIO::TypeDesc::UINT32)
          throw FileContentError(fmt::format("{}: channel {} is not 32-bit unsigned integer", file.string(),
                                               spec.channelnames[size_t(c)]));
      },
      result.values);
  return result;
}

FloatChannels read_float_channels(const std::filesystem::path& file, const std::string& prefix) {
  FloatChannels result;
  result.names = read_channels(
      file, prefix, OIIO::TypeDesc::FLOAT,
      [&](const OIIO::ImageSpec& spec, int) { result.width = spec.width, result.height = spec.height; }, result.values);
  return result;
}

std::vector<std::string> read_channel_names(const std::filesystem::path& file) {
  auto in = open_image(file);
  std::vector<std::string> names = in->spec().channelnames;
  in->close();
  return names;
}

std::map<std::string, std::string> read_image_metadata(const std::filesystem::path& file) {
  auto in = open_image(file);
  std::map<std::string, std::string> result;
  for (const auto& attr : in->spec().extra_attribs) result[attr.name().string()] = attr.get_string();
  in->close();
  return result;
}

std::shared_ptr<const Image> read_image_shared(const std::filesystem::path& file, IntegerEncoding encoding) {
  struct Entry {
    std::weak_ptr<const Image> image;
    std::uintmax_t size;
    std::filesystem::file_time_type modified;
  };
  static std::mutex mutex;
  static std::map<std::pair<std::string, IntegerEncoding>, Entry> images;
  std::error_code ec;
  const std::string path = std::filesystem::absolute(file, ec).string();
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  const std::filesystem::file_time_type modified = std::filesystem::last_write_time(file, ec);
  std::lock_guard lock(mutex);
  Entry& entry = images[{path, encoding}];
  // The image held: unless the file has changed since (a file removed since is not read again).
  if (auto live = entry.image.lock(); live && (ec || (entry.size == size && entry.modified == modified))) return live;
  auto image = std::make_shared<const Image>(read_image(file, encoding));
  entry = {image, size, modified};
  std::erase_if(images, [](const auto& e) { return e.second.image.expired(); });
  return image;
}

}  // namespace candela
