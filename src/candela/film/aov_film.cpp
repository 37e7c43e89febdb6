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

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string_view aov_name(Aov aov) { return names_of(aov).option; }

std::string aov_names() {
  std::string names;
  for (Aov aov : kAllAovs) names += std::string(aov_name(aov)) + ", ";
  return names + "all, gbuffer, camera_space, world_space";
}

AovSelection parse_aov_selection(std::string_view list) {
  std::vector<bool> chosen(std::size(kAllAovs), false);
  bool gbuffer = false, any_layer_name = false;
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
      chosen.assign(chosen.size(), true);
      any_layer_name = true;
    } else if (name == "gbuffer") {
      gbuffer = true;
    } else if (name == "camera_space") {
      set_space(AovSpace::Camera);
    } else if (name == "world_space") {
      set_space(AovSpace::World);
    } else {
      auto it = std::find_if(std::begin(kAllAovs), std::end(kAllAovs), [&](Aov a) { return aov_name(a) == name; });
      if (it == std::end(kAllAovs))
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
    if (any_layer_name)
      throw UsageError(fmt::format("'{}': gbuffer (pbrt-v4's gbuffer film) is a fixed set of layers; only "
                                   "camera_space or world_space can be given beside it", list));
    selection.layers.assign(std::begin(kPbrtGbufferAovs), std::end(kPbrtGbufferAovs));
    selection.naming = AovNaming::PbrtGbuffer;
    selection.space = space.value_or(AovSpace::Camera);  // pbrt-v4's default "coordinatesystem"
    return selection;
  }
  if (!any_layer_name)
    throw UsageError(fmt::format("'{}' names no AOV layer (valid: {})", list, aov_names()));
  for (Aov aov : kAllAovs)
    if (chosen[size_t(aov)]) selection.layers.push_back(aov);
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
  const auto order_begin = pbrt ? std::begin(kPbrtGbufferAovs) : std::begin(kAllAovs);
  const auto order_end = pbrt ? std::end(kPbrtGbufferAovs) : std::end(kAllAovs);
  for (auto it = order_begin; it != order_end; ++it)
    if (std::find(selection.layers.begin(), selection.layers.end(), *it) != selection.layers.end())
      layers_.push_back(*it);
  auto keep = [&](int& offset, size_t n) {
    offset = int(stride_);
    stride_ += n;
  };
  if (wants(Aov::Albedo)) keep(albedo_, 3);
  if (wants(Aov::Normal)) keep(normal_, 3);
  if (wants(Aov::Depth) || wants(Aov::Position) || wants(Aov::Uv) || wants(Aov::DepthDerivatives))
    keep(hit_weight_, 1);
  if (wants(Aov::Depth)) keep(depth_, 1);
  if (wants(Aov::Position)) keep(position_, 3);
  if (wants(Aov::GeometricNormal)) keep(geometric_normal_, 3);
  if (wants(Aov::Uv)) keep(uv_, 2);
  if (wants(Aov::DepthDerivatives)) keep(depth_derivatives_, 2);
  sums_.assign(size_t(width) * size_t(height) * stride_, 0.0);
}

bool AovFilm::wants(Aov aov) const { return std::find(layers_.begin(), layers_.end(), aov) != layers_.end(); }

void AovFilm::add_sample(int x, int y, const AovSample& s, float weight) {
  double* px = sums(x, y);
  const double w = weight;
  px[0] += w;
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

bool AovFilm::empty() const {
  for (size_t i = 0; i < sums_.size(); i += stride_)
    if (sums_[i] != 0) return false;
  return true;
}

void AovFilm::clear() { std::fill(sums_.begin(), sums_.end(), 0.0); }

std::vector<AovLayer> AovFilm::images(const Film& film) const {
  if (film.width() != width_ || film.height() != height_)
    throw InternalError(fmt::format("AovFilm::images: the film is {}x{}, the AOVs {}x{}", film.width(), film.height(),
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
  std::vector<AovLayer> result;
  for (Aov aov : layers_) {
    const LayerNames& names = pbrt ? pbrt_gbuffer_names_of(aov) : names_of(aov);
    AovLayer layer{aov, std::string(names.layer), names.channels, width_, height_, {}};
    const size_t n = names.channels.size();
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
        }
      }
    result.push_back(std::move(layer));
  }
  return result;
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
