#pragma once
// Image files through OpenImageIO. The format follows the extension: .exr (linear float, with
// metadata), .pfm (linear float), .png (sRGB-encoded 8-bit, values clipped to [0,1]).
#include <filesystem>
#include <map>
#include <memory>
#include <cstdint>
#include <string>
#include <vector>

#include "candela/film/image.h"

namespace candela {

// True for the extensions write_image accepts (case-insensitive).
bool is_supported_output(const std::filesystem::path& file);

// Writes atomically: to a temporary file beside the target, then renamed over it, so an existing
// file is never left half-written. `metadata` goes into EXR headers (string attributes; keys such
// as "candela:spp"). Throws OutputError naming the file when it cannot be written (or has an
// extension other than is_supported_output's).
void write_image(const std::filesystem::path& file, const Image& image,
                 const std::map<std::string, std::string>& metadata = {});

// The bytes of an 8-bit sRGB PNG of `image` (as write_image writes a .png), e.g. to show it inline
// in a notebook. Throws InternalError if OpenImageIO fails.
std::vector<unsigned char> encode_png(const Image& image);

// 32-bit unsigned integer channels kept exactly beside an EXR's RGB (a render part's sums, bit for
// bit): names.size() values per pixel in `values`, row-major.
struct ExactChannels {
  std::vector<std::string> names;
  std::vector<uint32_t> values;
};
// write_image for an .exr with `extra` after its R, G, B channels.
void write_image(const std::filesystem::path& file, const Image& image, const std::map<std::string, std::string>& metadata,
                 const ExactChannels& extra);
// The channels of `file` whose names start with `prefix`, which must be 32-bit unsigned integers
// (an empty ExactChannels when there are none). Throws FileContentError naming the file.
ExactChannels read_exact_channels(const std::filesystem::path& file, const std::string& prefix);

// 32-bit float channels beside an EXR's RGB, named as layers ("Albedo.R", "Depth.Z": film/aov_film.h):
// names.size() values per pixel in `values`, row-major.
struct FloatChannels {
  std::vector<std::string> names;
  std::vector<float> values;
  int width = 0, height = 0;  // the image's, where read from a file (read_float_channels)
};
// write_image for an .exr with `extra` after its R, G, B channels.
void write_image(const std::filesystem::path& file, const Image& image, const std::map<std::string, std::string>& metadata,
                 const FloatChannels& extra);
// The channels of `file` whose names start with `prefix`, read as 32-bit floats (an empty
// FloatChannels when there are none). Throws FileContentError naming the file.
FloatChannels read_float_channels(const std::filesystem::path& file, const std::string& prefix);
// The names of all channels of `file`, in the order the reader gives them.
std::vector<std::string> read_channel_names(const std::filesystem::path& file);

// The largest image read (a texture, an environment map, a part file): at most kMaxImageSide texels
// on a side and kMaxImageTexels in all (6 GiB as float RGB; a 32768 x 16384 environment map fits).
// Checked from the header, before the pixels are allocated, so that a small file whose header claims
// 100000 x 100000 is refused at once.
inline constexpr int64_t kMaxImageSide = 65536;
inline constexpr int64_t kMaxImageTexels = int64_t(1) << 29;
// Throws FileContentError "FILE: the image is W x H texels, more than candela reads (...)" for an
// image beyond those limits.
void check_image_size(const std::filesystem::path& file, int64_t width, int64_t height);

// OpenEXR (3.1) allocates each header attribute's declared size before it reads the value, so a
// 500-byte file declaring a 2 GB attribute costs 2 GB and seconds before it fails. For an OpenEXR file
// (its first bytes are OpenEXR's magic number), walks every header (name, type, 4-byte size, value) and
// throws FileContentError "FILE: cannot read image: its OpenEXR header attribute 'NAME' claims N
// bytes, more than the M left in the file" (or "...: its OpenEXR header is malformed") before anything
// reads it. Every reader here calls it; returns the flags byte of the file's version field (0x08 deep,
// 0x10 multi-part), or -1 for a file that is not an OpenEXR file.
int check_exr_header(const std::filesystem::path& file);

// How 8- and 16-bit pixel values become linear: the exact sRGB decoding curve, or value / max.
// Float pixels (EXR, HDR, PFM) are linear either way, as in pbrt-v4 and Mitsuba, whose encoding
// options also only apply to integer images.
enum class IntegerEncoding { SRGB, Linear };

// Reads any image OpenImageIO reads as linear RGB float, top row first. Greyscale is replicated to
// RGB; alpha and further channels are dropped, and colours are read as stored (not premultiplied).
// Throws FileContentError naming the file on failure.
Image read_image(const std::filesystem::path& file, IntegerEncoding encoding);
// The same with 8- and 16-bit data sRGB-decoded.
Image read_image(const std::filesystem::path& file);

// read_image, shared: while anything holds the image of a file (the same path and encoding), reading
// it again returns that image instead of reading the file, unless the file has changed since (its
// size or modification time; a file removed since is not read again). A scene built
// again from the same description (the Python module builds one per render) then reads no image
// file again while its loaded scene keeps the images (python/module.cpp).
std::shared_ptr<const Image> read_image_shared(const std::filesystem::path& file, IntegerEncoding encoding);

// The metadata attributes of an image file (for tests and tools). Throws FileContentError.
std::map<std::string, std::string> read_image_metadata(const std::filesystem::path& file);

}  // namespace candela
