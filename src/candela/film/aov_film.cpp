#include "candela/film/aov_film.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "candela/base/error.h"

namespace candela {
namespace {

struct LayerNames {
  std::string_view option;  // --aov
  std::string_view layer;   // the EXR layer
  std::vector<std::string> channels;
};

const LayerNames& names_of(Aov aov) {
  static const LayerNames table[] = {
      {"albedo", "Albedo", {"R", "G", "B"}},
      {"normal", "Normal", {"X", "Y", "Z"}},
      {"depth", "Depth", {"Z"}},
      {"position", "Position", {"X", "Y", "Z"}},
      // Blender names the one channel of its value passes (object index, sample count) X.
      {"spp", "SampleCount", {"X"}},
      {"variance", "Variance", {"R", "G", "B"}},
      {"geometric_normal", "GeometricNormal", {"X", "Y", "Z"}},
      {"uv", "UV", {"U", "V"}},
      {"depth_derivatives", "DepthDerivatives", {"X", "Y"}},
      {"relative_variance", "RelativeVariance", {"R", "G", "B"}},
      {"halves", "Halves", {"A.R", "A.G", "A.B", "B.R", "B.G", "B.B", "ShareA",
                            "A.Albedo.R", "A.Albedo.G", "A.Albedo.B", "A.Normal.X", "A.Normal.Y", "A.Normal.Z", "A.Depth.Z",
                            "B.Albedo.R", "B.Albedo.G", "B.Albedo.B", "B.Normal.X", "B.Normal.Y", "B.Normal.Z", "B.Depth.Z"}},
      // The OpenEXR spectral layout's emissive layer; its channels are the buckets (SpectralBuckets).
      {"spectral", "S0", {}},
  };
  return table[size_t(aov)];
}

// pbrt-v4's GBufferFilm's channel names (an empty layer name: the channels stand alone).
const LayerNames& pbrt_gbuffer_names_of(Aov aov) {
  static const LayerNames albedo{"albedo", "Albedo", {"R", "G", "B"}};
  static const LayerNames shading_normal{"normal", "Ns", {"X", "Y", "Z"}};
  static const LayerNames position{"position", "P", {"X", "Y", "Z"}};
  static const LayerNames geometric_normal{"geometric_normal", "N", {"X", "Y", "Z"}};
  static const LayerNames uv{"uv", "", {"u", "v"}};
  static const LayerNames depth_derivatives{"depth_derivatives", "", {"dzdx", "dzdy"}};
  switch (aov) {
    case Aov::Albedo: return albedo;
    case Aov::Normal: return shading_normal;
    case Aov::Position: return position;
    case Aov::GeometricNormal: return geometric_normal;
    case Aov::Uv: return uv;
    case Aov::DepthDerivatives: return depth_derivatives;
    default: return names_of(aov);  // Variance, RelativeVariance: the same names
  }
}

// The unit vector along a sum of normals, or 0 for a zero sum (pbrt-v4's gbuffer normals).
Vec3 normalized_or_zero(double x, double y, double z) {
  const double length = std::sqrt(x * x + y * y + z * z);
  if (!(length > 0)) return {0, 0, 0};
  return {float(x / length), float(y / length), float(z / length)};
}

// "spectral", "spectral:N" or "spectral:N:MIN:MAX" (nullopt for a name that is not spectral).
std::optional<SpectralBuckets> parse_spectral_buckets(std::string_view name) {
  constexpr std::string_view kName = "spectral";
  if (name.substr(0, kName.size()) != kName || (name.size() > kName.size() && name[kName.size()] != ':'))
    return std::nullopt;
  SpectralBuckets buckets;
  buckets.count = 16;  // pbrt-v4's default "nbuckets"
  if (name.size() == kName.size()) return buckets;
  std::vector<double> numbers;
  std::string_view rest = name.substr(kName.size() + 1);
  while (true) {
    const size_t colon = rest.find(':');
    const std::string part(rest.substr(0, colon));
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (part.empty() || used != part.size() || !std::isfinite(v))
      throw UsageError(fmt::format("'{}': '{}' is not a number (spectral, spectral:N or spectral:N:MIN:MAX)", name, part));
    numbers.push_back(v);
    if (colon == std::string_view::npos) break;
    rest = rest.substr(colon + 1);
  }
  if (numbers.size() != 1 && numbers.size() != 3)
    throw UsageError(fmt::format("'{}': give spectral, spectral:N or spectral:N:MIN:MAX", name));
  if (numbers[0] != std::floor(numbers[0]) || numbers[0] < 1 || numbers[0] > 1000)
    throw UsageError(fmt::format("'{}': the number of buckets must be a whole number from 1 to 1000", name));
  buckets.count = int(numbers[0]);
  if (numbers.size() == 3) {
    buckets.lambda_min = float(numbers[1]);
    buckets.lambda_max = float(numbers[2]);
    if (!(buckets.lambda_min >= cie::kLambdaMin && buckets.lambda_max <= cie::kLambdaMax &&
          buckets.lambda_min < buckets.lambda_max))
      throw UsageError(fmt::format("'{}': the wavelength range must lie in [{}, {}] nm with MIN < MAX (candela's "
                                   "spectral transport samples no others)",
                                   name, cie::kLambdaMin, cie::kLambdaMax));
  }
  return buckets;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

int SpectralBuckets::bucket_of(float lambda) const {
  if (!(lambda >= lambda_min && lambda <= lambda_max)) return -1;
  return std::min(count - 1, int(float(count) * (lambda - lambda_min) / (lambda_max - lambda_min)));
}

std::string SpectralBuckets::channel_name(int i) const {
  // The layout names a channel by its bucket's centre ("S0.<lambda>nm", OpenEXR's '.' as a decimal
  // comma), as pbrt-v4 writes it (three decimals).
  std::string centre = fmt::format("{:.3f}", lambda_min + (float(i) + 0.5f) / float(count) * (lambda_max - lambda_min));
  std::replace(centre.begin(), centre.end(), '.', ',');
  return centre + "nm";
}

std::string_view aov_name(Aov aov) { return names_of(aov).option; }

std::string aov_names() {
  std::string names;
  for (Aov aov : kNamedAovs) names += std::string(aov_name(aov)) + ", ";
  return names + "spectral[:N[:MIN:MAX]], all, gbuffer, camera_space, world_space";
}

AovSelection parse_aov_selection(std::string_view list) {
  std::vector<bool> chosen(std::size(kNamedAovs), false);
  bool gbuffer = false, any_layer_name = false;
  SpectralBuckets spectral;
  std::optional<AovSpace> space;
  auto set_space = [&](AovSpace s) {
    if (space && *space != s)
      throw UsageError(fmt::format("'{}': camera_space and world_space cannot both be given", list));
    space = s;
  };
  size_t start = 0;
  while (true) {
    const size_t comma = list.find(',', start);
    const std::string_view name = trim(list.substr(start, comma == std::string_view::npos ? list.npos : comma - start));
    if (name == "all") {
      for (Aov aov : kAllAovs) chosen[size_t(aov)] = true;
      any_layer_name = true;
    } else if (name == "gbuffer") {
      gbuffer = true;
    } else if (name == "camera_space") {
      set_space(AovSpace::Camera);
    } else if (name == "world_space") {
      set_space(AovSpace::World);
    } else if (std::optional<SpectralBuckets> buckets = parse_spectral_buckets(name)) {
      if (spectral.count > 0) throw UsageError(fmt::format("'{}': the spectral layer is given twice", list));
      spectral = *buckets;
    } else {
      auto it = std::find_if(std::begin(kNamedAovs), std::end(kNamedAovs), [&](Aov a) { return aov_name(a) == name; });
      if (it == std::end(kNamedAovs))
        throw UsageError(name.empty() ? fmt::format("empty AOV name in '{}' (valid: {})", list, aov_names())
                                                 : fmt::format("unknown AOV '{}' (valid: {})", name, aov_names()));
      chosen[size_t(*it)] = true;
      any_layer_name = true;
    }
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  AovSelection selection;
  if (gbuffer) {
    // pbrt-v4's gbuffer film is a fixed set: layer names beside it would leave its layout.
    if (any_layer_name || spectral.count > 0)
      throw UsageError(fmt::format("'{}': gbuffer (pbrt-v4's gbuffer film) is a fixed set of layers; only "
                                   "camera_space or world_space can be given beside it", list));
    selection.layers.assign(std::begin(kPbrtGbufferAovs), std::end(kPbrtGbufferAovs));
    selection.naming = AovNaming::PbrtGbuffer;
    selection.space = space.value_or(AovSpace::Camera);  // pbrt-v4's default "coordinatesystem"
    return selection;
  }
  if (!any_layer_name && spectral.count == 0)
    throw UsageError(fmt::format("'{}' names no AOV layer (valid: {})", list, aov_names()));
  for (Aov aov : kNamedAovs)
    if (chosen[size_t(aov)]) selection.layers.push_back(aov);
  if (spectral.count > 0) {
    selection.layers.push_back(Aov::Spectral);
    selection.spectral = spectral;
  }
  selection.space = space.value_or(AovSpace::World);
  return selection;
}

std::vector<Aov> parse_aovs(std::string_view list) { return parse_aov_selection(list).layers; }

std::string describe_aovs(const std::vector<Aov>& layers) {
  std::string s;
  for (Aov aov : layers) {
    if (!s.empty()) s += ',';
    s += aov_name(aov);
  }
  return s;
}

AovFilm::AovFilm(int width, int height, std::vector<Aov> layers)
    : AovFilm(width, height, AovSelection{std::move(layers), AovSpace::World, AovNaming::Candela}, AovCameraFrame{}) {}

AovFilm::AovFilm(int width, int height, const AovSelection& selection, const AovCameraFrame& camera)
    : width_(width), height_(height), space_(selection.space), naming_(selection.naming), camera_(camera) {
  // The written order, each once: candela's canonical order, or pbrt-v4's channel order.
  const bool pbrt = naming_ == AovNaming::PbrtGbuffer;
  const auto order_begin = pbrt ? std::begin(kPbrtGbufferAovs) : std::begin(kNamedAovs);
  const auto order_end = pbrt ? std::end(kPbrtGbufferAovs) : std::end(kNamedAovs);
  for (auto it = order_begin; it != order_end; ++it)
    if (std::find(selection.layers.begin(), selection.layers.end(), *it) != selection.layers.end())
      layers_.push_back(*it);
  if (selection.wants_spectral()) {
    layers_.push_back(Aov::Spectral);  // last: after R, G, B and the others, as pbrt-v4's film writes them
    spectral_ = selection.spectral;
  }
  auto keep = [&](int& offset, size_t n) {
    offset = int(stride_);
    stride_ += n;
  };
  const bool halves = wants(Aov::Halves);  // the denoiser's features, per half
  if (wants(Aov::Albedo) || halves) keep(albedo_, 3);
  if (wants(Aov::Normal) || halves) keep(normal_, 3);
  if (wants(Aov::Depth) || wants(Aov::Position) || wants(Aov::Uv) || wants(Aov::DepthDerivatives) || halves)
    keep(hit_weight_, 1);
  if (wants(Aov::Depth) || halves) keep(depth_, 1);
  if (halves) keep(half_features_, 9);
  if (wants(Aov::Position)) keep(position_, 3);
  if (wants(Aov::GeometricNormal)) keep(geometric_normal_, 3);
  if (wants(Aov::Uv)) keep(uv_, 2);
  if (wants(Aov::DepthDerivatives)) keep(depth_derivatives_, 2);
  if (spectral_.count > 0) keep(spectral_offset_, 2 * size_t(spectral_.count));
  sums_.assign(size_t(width) * size_t(height) * stride_, 0.0);
}

bool AovFilm::wants(Aov aov) const { return std::find(layers_.begin(), layers_.end(), aov) != layers_.end(); }

void AovFilm::add_sample(int x, int y, const AovSample& s, float weight, bool first_half) {
  double* px = sums(x, y);
  const double w = weight;
  px[0] += w;
  if (half_features_ >= 0 && first_half) {
    double* half = px + half_features_;
    half[0] += w;
    for (int c = 0; c < 3; ++c) half[1 + c] += w * s.albedo[c];
    half[4] += w * s.normal.x;
    half[5] += w * s.normal.y;
    half[6] += w * s.normal.z;
    if (s.hit) {
      half[7] += w;
      half[8] += w * s.depth;
    }
  }
  if (albedo_ >= 0)
    for (int c = 0; c < 3; ++c) px[albedo_ + c] += w * s.albedo[c];
  const bool camera_space = space_ == AovSpace::Camera;
  auto add3 = [&](int offset, const Vec3& v) {
    px[offset] += w * v.x;
    px[offset + 1] += w * v.y;
    px[offset + 2] += w * v.z;
  };
  if (normal_ >= 0) add3(normal_, camera_space ? camera_.vector_to_camera(s.normal) : s.normal);
  if (geometric_normal_ >= 0 && s.hit)
    add3(geometric_normal_, camera_space ? camera_.vector_to_camera(s.geometric_normal) : s.geometric_normal);
  if (hit_weight_ >= 0 && s.hit) {
    px[hit_weight_] += w;
    if (depth_ >= 0) px[depth_] += w * s.depth;
    if (position_ >= 0) {
      const Point3 p = camera_space ? camera_.point_to_camera(s.position) : s.position;
      add3(position_, Vec3(p.x, p.y, p.z));
    }
    if (uv_ >= 0) {
      px[uv_] += w * s.uv.x;
      px[uv_ + 1] += w * s.uv.y;
    }
    if (depth_derivatives_ >= 0) {
      // z of the hit's per-pixel change: along the viewing axis in camera space, world z otherwise
      // (pbrt-v4 takes the output space's z either way).
      const float dzdx = camera_space ? dot(s.dpdx, camera_.z) : s.dpdx.z;
      const float dzdy = camera_space ? dot(s.dpdy, camera_.z) : s.dpdy.z;
      px[depth_derivatives_] += w * dzdx;
      px[depth_derivatives_ + 1] += w * dzdy;
    }
  }
}

void AovFilm::add_spectral_sample(int x, int y, const RGB& values, const Wavelengths& wl, float weight,
                                  float max_component) {
  double* px = sums(x, y) + spectral_offset_;
  // pbrt-v4 compares the radiance in its own units (luminance over the CIE Y integral) with the limit.
  double scale = 1;
  if (max_component > 0) {
    float largest = 0;
    for (int i = 0; i < Wavelengths::kCount; ++i) largest = std::max(largest, values[i]);
    const double in_pbrt_units = double(largest) / cie::y_integral();
    if (in_pbrt_units > max_component) scale = max_component / in_pbrt_units;
  }
  for (int i = 0; i < Wavelengths::kCount; ++i) {
    const int b = spectral_.bucket_of(wl.lambda[i]);
    if (b < 0 || !(wl.pdf[i] > 0)) continue;
    const double w = double(weight) / wl.pdf[i];
    px[2 * b] += w * scale * values[i];
    px[2 * b + 1] += w;
  }
}

bool AovSelection::wants(Aov aov) const { return std::find(layers.begin(), layers.end(), aov) != layers.end(); }

bool AovFilm::empty() const {
  // Every layer's sums are weights or weighted values: nothing added leaves them all 0.
  return std::all_of(sums_.begin(), sums_.end(), [](double v) { return v == 0; });
}

void AovFilm::clear() { std::fill(sums_.begin(), sums_.end(), 0.0); }

std::vector<AovLayer> AovFilm::images(const Film& film) const {
  std::vector<AovLayer> result;
  for (Aov aov : layers_) result.push_back(image(film, aov));
  return result;
}

AovLayer AovFilm::image(const Film& film, Aov aov) const {
  if (std::find(layers_.begin(), layers_.end(), aov) == layers_.end())
    throw InternalError("AovFilm::image: the film does not collect that layer");
  if (film.width() != width_ || film.height() != height_)
    throw InternalError(fmt::format("AovFilm::image: the film is {}x{}, the AOVs {}x{}", film.width(), film.height(),
                                    width_, height_));
  const bool pbrt = naming_ == AovNaming::PbrtGbuffer;
  // The variance a pixel's layers report: of the mean (candela's), or of the samples themselves
  // (pbrt-v4's VarianceEstimator: the samples' spread, the mean's times the sample count).
  auto pixel_variance = [&](int x, int y) {
    const PixelSums& sums = film.pixel(x, y);
    const RGB se = sums.standard_error();
    RGB v = se * se;
    if (pbrt) v = v * float(sums.count);
    return v;
  };
  const LayerNames& names = pbrt ? pbrt_gbuffer_names_of(aov) : names_of(aov);
  AovLayer layer{aov, std::string(names.layer), names.channels, width_, height_, {}};
  if (aov == Aov::Spectral)
    for (int i = 0; i < spectral_.count; ++i) layer.channels.push_back(spectral_.channel_name(i));
  const size_t n = layer.channels.size();
  layer.values.resize(size_t(width_) * size_t(height_) * n);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const double* px = sums(x, y);
      float* out = &layer.values[(size_t(y) * size_t(width_) + size_t(x)) * n];
      // Means over all samples, or over those that hit a surface (none: the miss values).
      const double weight = px[0];
      const double hit_weight = hit_weight_ >= 0 ? px[hit_weight_] : 0;
      auto mean = [&](int offset, int count) {
        for (int c = 0; c < count; ++c) out[c] = weight != 0 ? float(px[offset + c] / weight) : 0.0f;
      };
      auto hit_mean = [&](int offset, int count, float miss) {
        for (int c = 0; c < count; ++c) out[c] = hit_weight > 0 ? float(px[offset + c] / hit_weight) : miss;
      };
      auto normalized = [&](int offset) {
        const Vec3 n = normalized_or_zero(px[offset], px[offset + 1], px[offset + 2]);
        out[0] = n.x, out[1] = n.y, out[2] = n.z;
      };
      switch (aov) {
        case Aov::Albedo: mean(albedo_, 3); break;
        case Aov::Normal:
          if (pbrt)
            normalized(normal_);
          else
            mean(normal_, 3);
          break;
        case Aov::Depth: hit_mean(depth_, 1, kAovMissDepth); break;
        case Aov::Position: hit_mean(position_, 3, 0.0f); break;
        case Aov::SampleCount: out[0] = float(film.pixel(x, y).count); break;
        case Aov::Variance: {
          const RGB v = pixel_variance(x, y);
          for (int c = 0; c < 3; ++c) out[c] = v[c];
          break;
        }
        case Aov::GeometricNormal: normalized(geometric_normal_); break;
        case Aov::Uv: hit_mean(uv_, 2, 0.0f); break;
        case Aov::DepthDerivatives: {
          hit_mean(depth_derivatives_, 2, 0.0f);
          // pbrt-v4 scales camera ray differentials by max(1/8, 1/sqrt(spp)) before the first hit
          // takes them (a pixel's samples then cover about its own footprint).
          const float scale =
              pbrt ? std::max(0.125f, 1.0f / std::sqrt(float(std::max<uint64_t>(1, film.pixel(x, y).count)))) : 1.0f;
          for (int c = 0; c < 2; ++c) out[c] = std::abs(out[c]) * scale;
          break;
        }
        case Aov::RelativeVariance: {
          // pbrt-v4's VarianceEstimator::RelativeVariance: the variance over the mean (0 for a zero mean).
          const RGB v = pixel_variance(x, y);
          const RGB m = film.pixel(x, y).mean();
          for (int c = 0; c < 3; ++c) out[c] = m[c] != 0 ? v[c] / m[c] : 0.0f;
          break;
        }
        case Aov::Halves: {
          // A pixel without both halves: its mean twice.
          PixelHalves halves;
          if (!film.pixel_halves(x, y, halves)) {
            const RGB m = film.pixel(x, y).mean();
            for (int c = 0; c < 3; ++c) halves.a[c] = halves.b[c] = m[c];
          }
          for (int c = 0; c < 3; ++c) {
            out[c] = float(halves.a[c]);
            out[3 + c] = float(halves.b[c]);
          }
          out[6] = float(halves.share_a);
          // Each half's features: A's sums, and B's as the totals less A's (a half without samples,
          // as where the AOVs had a pass of their own: the pixel's).
          const double* half = px + half_features_;
          const double weight_b = weight - half[0], hit_b = hit_weight - half[7];
          const bool split = half[0] > 0 && weight_b > 0;
          for (int h = 0; h < 2; ++h) {
            float* f = out + 7 + 7 * h;
            const double wsum = !split ? weight : h == 0 ? half[0] : weight_b;
            const double hsum = !split ? hit_weight : h == 0 ? half[7] : hit_b;
            for (int c = 0; c < 6; ++c) {
              const double total = px[(c < 3 ? albedo_ : normal_) + c % 3];
              const double v = !split ? total : h == 0 ? half[1 + c] : total - half[1 + c];
              f[c] = wsum > 0 ? float(v / wsum) : 0.0f;
            }
            const double depth = !split ? px[depth_] : h == 0 ? half[8] : px[depth_] - half[8];
            f[6] = hsum > 0 ? float(depth / hsum) : kAovMissDepth;
          }
          break;
        }
        case Aov::Spectral:
          // A bucket no wavelength fell in stays 0, as in pbrt-v4.
          for (int b = 0; b < spectral_.count; ++b) {
            const double w = px[spectral_offset_ + 2 * b + 1];
            out[b] = w > 0 ? float(px[spectral_offset_ + 2 * b] / w) : 0.0f;
          }
          break;
      }
    }
  return layer;
}

FloatChannels exr_channels(const std::vector<AovLayer>& layers) {
  FloatChannels channels;
  if (layers.empty()) return channels;
  const size_t pixels = size_t(layers[0].width) * size_t(layers[0].height);
  for (const AovLayer& layer : layers)
    for (const std::string& c : layer.channels) channels.names.push_back(layer.name.empty() ? c : layer.name + "." + c);
  const size_t per_pixel = channels.names.size();
  channels.values.resize(pixels * per_pixel);
  for (size_t i = 0; i < pixels; ++i) {
    size_t k = i * per_pixel;
    for (const AovLayer& layer : layers) {
      const size_t n = layer.channels.size();
      std::copy_n(&layer.values[i * n], n, &channels.values[k]);
      k += n;
    }
  }
  return channels;
}

}  // namespace candela
