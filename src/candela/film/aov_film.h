#pragma once
// AOVs (arbitrary output variables): per-pixel images beside the colour, written as extra layers of
// the EXR (image_io.h's FloatChannels), for denoisers (Intel Open Image Denoise's albedo and normal
// inputs) and compositors (Blender's Depth and Position passes). The layers, in the order they are
// written, with their EXR channels:
//   albedo    Albedo.R, Albedo.G, Albedo.B       first non-delta hit's reflectance, in [0, 1]
//   normal    Normal.X, Normal.Y, Normal.Z       first non-delta hit's world-space shading normal
//   depth     Depth.Z                            distance along the camera's viewing axis
//   position  Position.X, Position.Y, Position.Z world-space first-hit position
//   spp       SampleCount.X                      the film's per-pixel sample count
//   variance  Variance.R, Variance.G, Variance.B the film's per-pixel variance of the mean
// What a camera sample sees first is computed by render/first_hit_aovs.h; AovFilm adds it up per
// pixel with the sample's filter weight, as Film adds the colour. Albedo and normal are averaged over
// all of a pixel's samples (a miss counts as 0: OIDN's "no surface"); depth and position over the
// samples that hit a surface (averaging a background depth into an edge pixel would give neither),
// and a pixel none of whose samples hit gets kAovMissDepth and position 0. The sample count and the
// variance are the film's own (Film::sample_count_image, Film::variance_of_mean_image). A pixel is
// only ever written by one thread at a time, so the sums are plain doubles.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "candela/film/film.h"
#include "candela/film/image_io.h"
#include "candela/math/color.h"
#include "candela/math/vec.h"

namespace candela {

enum class Aov : uint8_t { Albedo, Normal, Depth, Position, SampleCount, Variance };
inline constexpr Aov kAllAovs[] = {Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Position, Aov::SampleCount, Aov::Variance};

// The name --aov and the scene's "aovs" take: "albedo", "normal", "depth", "position", "spp", "variance".
std::string_view aov_name(Aov aov);
// "albedo, normal, depth, position, spp, variance" (and "all"), for messages.
std::string aov_names();
// Comma-separated names (spaces around them ignored; "all" for every layer) as layers in the order
// above, each once. Throws UsageError naming an unknown or empty name and the valid ones.
std::vector<Aov> parse_aovs(std::string_view list);
// The layers as a list parse_aovs reads back: "albedo,normal".
std::string describe_aovs(const std::vector<Aov>& layers);

// Blender's depth for the background: pixels where no sample hit a surface.
inline constexpr float kAovMissDepth = 1e10f;

// What one camera sample sees (render/first_hit_aovs.h).
struct AovSample {
  bool hit = false;  // the ray met a surface: depth and position are set
  RGB albedo{0.0f};
  Vec3 normal{0, 0, 0};
  float depth = 0;
  Point3 position{0, 0, 0};
};

// One layer of the output: its EXR layer name, channel names, and channels.size() floats per pixel.
struct AovLayer {
  Aov aov = Aov::Albedo;
  std::string name;                   // "Albedo"
  std::vector<std::string> channels;  // "R", "G", "B"
  int width = 0, height = 0;
  std::vector<float> values;  // row-major, channels.size() per pixel
  float at(int x, int y, int channel) const {
    return values[(size_t(y) * size_t(width) + size_t(x)) * channels.size() + size_t(channel)];
  }
};

class AovFilm {
 public:
  AovFilm(int width, int height, std::vector<Aov> layers);
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<Aov>& layers() const { return layers_; }
  bool wants(Aov aov) const;
  // Whether the layers need the surface's BSDF and shading frame (albedo, normal), or only the hit.
  bool needs_shading() const { return wants(Aov::Albedo) || wants(Aov::Normal); }
  // Whether any layer is added up from camera samples (albedo, normal, depth, position).
  bool has_sample_layers() const { return stride_ > 1; }

  void add_sample(int x, int y, const AovSample& s, float weight);
  // No sample added to any pixel yet.
  bool empty() const;
  // Clears every sum.
  void clear();

  // The sums, doubles_per_pixel() per pixel, row-major: for exchanging tiles between MPI ranks.
  size_t doubles_per_pixel() const { return stride_; }
  double* sums(int x, int y) { return &sums_[(size_t(y) * size_t(width_) + size_t(x)) * stride_]; }
  const double* sums(int x, int y) const { return &sums_[(size_t(y) * size_t(width_) + size_t(x)) * stride_]; }

  // The layers as images, in the order of layers(); the sample count and the variance from `film`
  // (the film these samples went with).
  std::vector<AovLayer> images(const Film& film) const;

 private:
  int width_, height_;
  std::vector<Aov> layers_;
  // Offsets into a pixel's sums (-1: not kept). [0] is always the sum of the weights.
  int albedo_ = -1, normal_ = -1, hit_weight_ = -1, depth_ = -1, position_ = -1;
  size_t stride_ = 1;
  std::vector<double> sums_;
};

// The layers as EXR channels "Albedo.R", ..., interleaved per pixel, for write_image.
FloatChannels exr_channels(const std::vector<AovLayer>& layers);

}  // namespace candela
