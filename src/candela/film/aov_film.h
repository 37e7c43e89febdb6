#pragma once
// AOVs (arbitrary output variables): per-pixel images beside the colour, written as extra layers of
// the EXR (image_io.h's FloatChannels), for denoisers (Intel Open Image Denoise's albedo and normal
// inputs) and compositors (Blender's Depth and Position passes). The layers, in the order they are
// written, with their EXR channels:
//   albedo            Albedo.R, Albedo.G, Albedo.B       first non-delta hit's reflectance, in [0, 1]
//   normal            Normal.X, Normal.Y, Normal.Z       first non-delta hit's shading normal
//   depth             Depth.Z                            distance along the camera's viewing axis
//   position          Position.X, Position.Y, Position.Z first-hit position
//   spp               SampleCount.X                      the film's per-pixel sample count
//   variance          Variance.R, Variance.G, Variance.B the film's per-pixel variance of the mean
//   geometric_normal  GeometricNormal.X, .Y, .Z          first hit's geometric normal (unit length)
//   uv                UV.U, UV.V                         first hit's surface (u, v)
//   depth_derivatives DepthDerivatives.X, .Y             |dz/dx|, |dz/dy|: how the first hit's z changes
//                                                        per pixel step right and down (on its tangent plane)
//   relative_variance RelativeVariance.R, .G, .B         the variance layer over the pixel's mean
//   halves            Halves.A.R, .A.G, .A.B, .B.R, .B.G, .B.B, Halves.ShareA, and per half
//                     Halves.A.Albedo.R/G/B, Halves.A.Normal.X/Y/Z, Halves.A.Depth.Z (and B.)
//                                                        the pixel's two independent estimates (the halves
//                                                        of its samples: Film::pixel_halves), half A's share
//                                                        of its weight, and each half's albedo, normal and
//                                                        depth, for the denoiser (denoise/denoiser.h); asking
//                                                        for it renders with two independent halves
//   spectral:N[:MIN:MAX] S0.389,375nm, ...             pbrt-v4's Film "spectral": the radiance in N equal
//                                                        wavelength buckets over [MIN, MAX] nm (16 over
//                                                        [360, 830] by default), in the OpenEXR spectral
//                                                        layout of Fichet et al. 2021 (JCGT 10(3)); needs
//                                                        spectral transport
// Positions, normals and z are in world space, or with camera_space in the camera's frame: x to the
// image's right, y up, z along the viewing direction, origin at the camera (pbrt-v4's camera space).
// "gbuffer" asks for pbrt-v4's Film "gbuffer" instead: its layers, definitions and channel names
// (R G B beside Albedo.R/G/B, P.X/Y/Z, dzdx, dzdy, N.X/Y/Z, Ns.X/Y/Z, u, v, Variance.R/G/B,
// RelativeVariance.R/G/B), in camera space unless world_space is given. Its definitions differ from
// candela's own where pbrt-v4's do: normals are the normalised sum of the samples' normals; the
// variance is the variance of the pixel's samples (not of their mean); dz/dx and dz/dy are scaled as
// pbrt-v4 scales camera ray differentials, by max(1/8, 1/sqrt(samples per pixel)).
// What a camera sample sees first is computed by render/first_hit_aovs.h; AovFilm adds it up per
// pixel with the sample's filter weight, as Film adds the colour. Albedo and normal are averaged over
// all of a pixel's samples (a miss counts as 0: OIDN's "no surface"); depth, position, uv and the
// depth derivatives over the samples that hit a surface (averaging a background depth into an edge
// pixel would give neither), and a pixel none of whose samples hit gets kAovMissDepth and position,
// uv and derivatives 0. The sample count and the variance are the film's own
// (Film::sample_count_image, PixelSums::standard_error). A pixel is only ever written by one thread
// at a time, so the sums are plain doubles.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "candela/film/film.h"
#include "candela/film/image_io.h"
#include "candela/math/color.h"
#include "candela/math/vec.h"
#include "candela/spectral/cie.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

enum class Aov : uint8_t {
  Albedo,
  Normal,
  Depth,
  Position,
  SampleCount,
  Variance,
  GeometricNormal,
  Uv,
  DepthDerivatives,
  RelativeVariance,
  Halves,   // not in kAllAovs: it changes the sampler (two independent halves)
  Spectral  // not in kAllAovs: "all" stays renderable without spectral transport
};
inline constexpr Aov kAllAovs[] = {Aov::Albedo,   Aov::Normal,          Aov::Depth, Aov::Position,
                                   Aov::SampleCount, Aov::Variance,      Aov::GeometricNormal, Aov::Uv,
                                   Aov::DepthDerivatives, Aov::RelativeVariance};
// Every layer with a name of its own, in the order written (the spectral one comes last).
inline constexpr Aov kNamedAovs[] = {Aov::Albedo,   Aov::Normal,          Aov::Depth, Aov::Position,
                                     Aov::SampleCount, Aov::Variance,      Aov::GeometricNormal, Aov::Uv,
                                     Aov::DepthDerivatives, Aov::RelativeVariance, Aov::Halves};
// pbrt-v4's Film "gbuffer": its layers, in the order it lists its channels.
inline constexpr Aov kPbrtGbufferAovs[] = {Aov::Albedo, Aov::Position, Aov::DepthDerivatives, Aov::GeometricNormal,
                                           Aov::Normal, Aov::Uv,       Aov::Variance,         Aov::RelativeVariance};

// The space positions, normals and depth derivatives are given in.
enum class AovSpace : uint8_t {
  World,
  Camera  // x to the image's right, y up, z along the viewing direction, origin at the camera
};
// Whose layer definitions and EXR channel names: candela's ("Normal.X") or pbrt-v4's gbuffer film's ("Ns.X").
enum class AovNaming : uint8_t { Candela, PbrtGbuffer };

// pbrt-v4's spectral film's buckets: `count` equal wavelength intervals over [lambda_min, lambda_max]
// nm. Each bucket's value is the filter-weighted mean of the radiance at the pixel's sampled
// wavelengths that fall in it (each wavelength weighted by one over its density, so that candela's
// importance-sampled wavelengths give the bucket's plain mean, as pbrt-v4's uniform ones do), in
// the spectral values' units: a constant spectrum of luminance Y reads Y in every bucket.
struct SpectralBuckets {
  int count = 0;  // 0: no spectral layer
  float lambda_min = cie::kLambdaMin, lambda_max = cie::kLambdaMax;  // within what spectral transport samples
  // The bucket of `lambda`, or -1 outside [lambda_min, lambda_max].
  int bucket_of(float lambda) const;
  // The EXR channel name of bucket i: "S0." and its centre with a decimal comma, "S0.389,375nm".
  std::string channel_name(int i) const;
};

// What an AOV list asks for.
struct AovSelection {
  std::vector<Aov> layers;  // in the order written, each once (Aov::Spectral: see `spectral`)
  AovSpace space = AovSpace::World;
  AovNaming naming = AovNaming::Candela;
  SpectralBuckets spectral;  // with Aov::Spectral in `layers`
  bool empty() const { return layers.empty(); }
  bool wants(Aov aov) const;
  bool wants_spectral() const { return spectral.count > 0; }
};

// The name --aov and the scene's "aovs" take: "albedo", "normal", "depth", "position", "spp",
// "variance", "geometric_normal", "uv", "depth_derivatives", "relative_variance", "halves", "spectral".
std::string_view aov_name(Aov aov);
// The names above (and "all", "gbuffer", "camera_space", "world_space"), for messages.
std::string aov_names();
// Comma-separated names (spaces around them ignored) as layers in the order above, each once. "all"
// is every layer but the spectral one; "camera_space" or "world_space" (the default) sets the space;
// "gbuffer" is pbrt-v4's gbuffer film (kPbrtGbufferAovs, pbrt's names, camera space unless
// world_space is given) and takes no layer names beside it; "spectral", "spectral:N" or
// "spectral:N:MIN:MAX" is the spectral layer (N in 1..1000, 360 <= MIN < MAX <= 830). Throws
// UsageError naming an unknown or empty name and the valid ones, or what is wrong with a spectral one.
AovSelection parse_aov_selection(std::string_view list);
// parse_aov_selection's layers.
std::vector<Aov> parse_aovs(std::string_view list);
// The layers as a list parse_aovs reads back: "albedo,normal".
std::string describe_aovs(const std::vector<Aov>& layers);

// The camera's frame in world space, for camera-space AOVs and the first hit's depth derivatives
// (render/first_hit_aovs.h's aov_camera_frame makes it from the scene's camera).
struct AovCameraFrame {
  Point3 origin{0, 0, 0};  // the camera's position (the lens centre; an orthographic film's centre)
  Vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};  // unit axes: to the image's right, up, along the view
  // How a camera ray's point at unit depth along z moves for one pixel step right (film x + 1) and
  // down (film y + 1): a perspective ray's direction turns by it, an orthographic ray's origin moves by it.
  Vec3 pixel_dx{0, 0, 0}, pixel_dy{0, 0, 0};
  bool orthographic = false;
  Point3 point_to_camera(const Point3& p) const {
    const Vec3 d = p - origin;
    return {dot(d, x), dot(d, y), dot(d, z)};
  }
  Vec3 vector_to_camera(const Vec3& v) const { return {dot(v, x), dot(v, y), dot(v, z)}; }
};

// Blender's depth for the background: pixels where no sample hit a surface.
inline constexpr float kAovMissDepth = 1e10f;

// What one camera sample sees (render/first_hit_aovs.h).
struct AovSample {
  bool hit = false;  // the ray met a surface: depth, position, geometric_normal, uv, dpdx, dpdy are set
  RGB albedo{0.0f};
  Vec3 normal{0, 0, 0};  // shading normal, world space, facing the ray
  float depth = 0;
  Point3 position{0, 0, 0};           // world space
  Vec3 geometric_normal{0, 0, 0};     // world space, facing the ray (pbrt-v4's FaceForward(n, wo))
  Vec2 uv{0, 0};                      // the surface's parameterisation at the hit
  Vec3 dpdx{0, 0, 0}, dpdy{0, 0, 0};  // world-space change of the hit per pixel step right and down
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
  // Candela's definitions and names, world space.
  AovFilm(int width, int height, std::vector<Aov> layers);
  // `selection`'s layers, space and naming; `camera` maps world space to camera space (used with
  // AovSpace::Camera, and for pbrt-v4's camera-space dz/dx, dz/dy).
  AovFilm(int width, int height, const AovSelection& selection, const AovCameraFrame& camera);
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<Aov>& layers() const { return layers_; }
  AovSpace space() const { return space_; }
  AovNaming naming() const { return naming_; }
  bool wants(Aov aov) const;
  // Whether the layers need the surface's BSDF and shading frame (albedo, normal), or only the hit.
  bool needs_shading() const { return albedo_ >= 0 || normal_ >= 0; }
  // Whether any layer is added up from camera samples (all but spp, variance, relative_variance).
  bool has_sample_layers() const { return stride_ > 1; }
  // Whether any layer needs what the camera ray sees first (render/first_hit_aovs.h): all of those
  // but the spectral one.
  bool has_first_hit_layers() const { return stride_ - 2 * size_t(spectral_.count) > 1; }
  const SpectralBuckets& spectral() const { return spectral_; }

  // `first_half`: the sample is among the pixel's first half (Film::add_sample), which the halves
  // layer's features keep apart.
  void add_sample(int x, int y, const AovSample& s, float weight, bool first_half = true);
  // The spectral layer's share of a camera sample: `values` at the wavelengths `wl` (a spectral
  // render's sample before it becomes RGB), with the sample's filter weight; `max_component` > 0
  // scales values whose largest lane over the CIE Y integral exceeds it down to it (pbrt-v4's
  // spectral film applies maxcomponentvalue so).
  void add_spectral_sample(int x, int y, const RGB& values, const Wavelengths& wl, float weight,
                           float max_component);
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
  // One of them (one of layers()).
  AovLayer image(const Film& film, Aov aov) const;

 private:
  int width_, height_;
  std::vector<Aov> layers_;
  AovSpace space_ = AovSpace::World;
  AovNaming naming_ = AovNaming::Candela;
  AovCameraFrame camera_;
  // Offsets into a pixel's sums (-1: not kept). [0] is always the sum of the weights.
  int albedo_ = -1, normal_ = -1, hit_weight_ = -1, depth_ = -1, position_ = -1, geometric_normal_ = -1, uv_ = -1,
      depth_derivatives_ = -1;
  // The halves layer's sums of the first half's samples: weight, albedo, normal, hit weight, depth.
  int half_features_ = -1;
  // The spectral layer: per bucket the sums of w L / pdf and of w / pdf (their ratio is the bucket's mean).
  int spectral_offset_ = -1;
  SpectralBuckets spectral_;
  size_t stride_ = 1;
  std::vector<double> sums_;
};

// The layers as EXR channels "Albedo.R", ... (a layer with an empty name: its channels' names alone,
// pbrt-v4's "u", "dzdx"), interleaved per pixel, for write_image.
FloatChannels exr_channels(const std::vector<AovLayer>& layers);

}  // namespace candela
