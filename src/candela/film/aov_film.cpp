#include "candela/film/aov_film.h"

#include <fmt/format.h>

#include <algorithm>
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
  };
  return table[size_t(aov)];
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
  return names + "all";
}

std::vector<Aov> parse_aovs(std::string_view list) {
  std::vector<bool> chosen(std::size(kAllAovs), false);
  size_t start = 0;
  while (true) {
    const size_t comma = list.find(',', start);
    const std::string_view name = trim(list.substr(start, comma == std::string_view::npos ? list.npos : comma - start));
    if (name == "all") {
      chosen.assign(chosen.size(), true);
    } else {
      auto it = std::find_if(std::begin(kAllAovs), std::end(kAllAovs), [&](Aov a) { return aov_name(a) == name; });
      if (it == std::end(kAllAovs))
        throw UsageError(name.empty() ? fmt::format("empty AOV name in '{}' (valid: {})", list, aov_names())
                                                 : fmt::format("unknown AOV '{}' (valid: {})", name, aov_names()));
      chosen[size_t(*it)] = true;
    }
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  std::vector<Aov> layers;
  for (Aov aov : kAllAovs)
    if (chosen[size_t(aov)]) layers.push_back(aov);
  return layers;
}

std::string describe_aovs(const std::vector<Aov>& layers) {
  std::string s;
  for (Aov aov : layers) {
    if (!s.empty()) s += ',';
    s += aov_name(aov);
  }
  return s;
}

AovFilm::AovFilm(int width, int height, std::vector<Aov> layers) : width_(width), height_(height) {
  for (Aov aov : kAllAovs)  // the canonical order, each once
    if (std::find(layers.begin(), layers.end(), aov) != layers.end()) layers_.push_back(aov);
  auto keep = [&](int& offset, size_t n) {
    offset = int(stride_);
    stride_ += n;
  };
  if (wants(Aov::Albedo)) keep(albedo_, 3);
  if (wants(Aov::Normal)) keep(normal_, 3);
  if (wants(Aov::Depth) || wants(Aov::Position)) keep(hit_weight_, 1);
  if (wants(Aov::Depth)) keep(depth_, 1);
  if (wants(Aov::Position)) keep(position_, 3);
  sums_.assign(size_t(width) * size_t(height) * stride_, 0.0);
}

bool AovFilm::wants(Aov aov) const { return std::find(layers_.begin(), layers_.end(), aov) != layers_.end(); }

void AovFilm::add_sample(int x, int y, const AovSample& s, float weight) {
  double* px = sums(x, y);
  const double w = weight;
  px[0] += w;
  if (albedo_ >= 0)
    for (int c = 0; c < 3; ++c) px[albedo_ + c] += w * s.albedo[c];
  if (normal_ >= 0) {
    px[normal_] += w * s.normal.x;
    px[normal_ + 1] += w * s.normal.y;
    px[normal_ + 2] += w * s.normal.z;
  }
  if (hit_weight_ >= 0 && s.hit) {
    px[hit_weight_] += w;
    if (depth_ >= 0) px[depth_] += w * s.depth;
    if (position_ >= 0) {
      px[position_] += w * s.position.x;
      px[position_ + 1] += w * s.position.y;
      px[position_ + 2] += w * s.position.z;
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
  const Image variance = wants(Aov::Variance) ? film.variance_of_mean_image() : Image();
  std::vector<AovLayer> result;
  for (Aov aov : layers_) {
    const LayerNames& names = names_of(aov);
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
        switch (aov) {
          case Aov::Albedo: mean(albedo_, 3); break;
          case Aov::Normal: mean(normal_, 3); break;
          case Aov::Depth: hit_mean(depth_, 1, kAovMissDepth); break;
          case Aov::Position: hit_mean(position_, 3, 0.0f); break;
          case Aov::SampleCount: out[0] = float(film.pixel(x, y).count); break;
          case Aov::Variance: {
            const RGB v = variance.at(x, y);
            for (int c = 0; c < 3; ++c) out[c] = v[c];
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
    for (const std::string& c : layer.channels) channels.names.push_back(layer.name + "." + c);
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
