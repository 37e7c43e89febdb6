#include "candela/spectral/rgb_to_spectrum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "candela/spectral/cie.h"
#include "candela/spectral/rgb_to_spectrum_table.h"

namespace candela {

float SigmoidPolynomial::operator()(float lambda) const {
  float t = (lambda - cie::kLambdaMin) * (1.0f / (cie::kLambdaMax - cie::kLambdaMin));
  float x = (c0 * t + c1) * t + c2;
  if (std::isinf(x)) return x > 0 ? 1.0f : 0.0f;
  return 0.5f + x / (2 * std::sqrt(1 + x * x));
}

namespace {

constexpr int kRes = kRgbToSpectrumResolution;

// The grid's z values, for the lookup's search.
constexpr std::array<float, kRes> kZNodes = [] {
  std::array<float, kRes> z{};
  for (int k = 0; k < kRes; ++k) z[size_t(k)] = rgb_to_spectrum_z_node(k);
  return z;
}();

SigmoidPolynomial table_lookup(const RGB& in) {
  float rgb[3] = {std::clamp(in.r, 0.0f, 1.0f), std::clamp(in.g, 0.0f, 1.0f), std::clamp(in.b, 0.0f, 1.0f)};
  // Grey: the constant S(c2) = v.
  if (rgb[0] == rgb[1] && rgb[1] == rgb[2]) {
    float v = rgb[0];
    if (v <= 0) return {0, 0, -std::numeric_limits<float>::infinity()};
    if (v >= 1) return {0, 0, std::numeric_limits<float>::infinity()};
    return {0, 0, (v - 0.5f) / std::sqrt(v * (1 - v))};
  }
  const std::array<float, kRes>& nodes = kZNodes;
  int l = rgb[0] > rgb[1] ? (rgb[0] > rgb[2] ? 0 : 2) : (rgb[1] > rgb[2] ? 1 : 2);
  float z = rgb[l];
  float x = rgb[(l + 1) % 3] / z * (kRes - 1), y = rgb[(l + 2) % 3] / z * (kRes - 1);
  int xi = std::min(int(x), kRes - 2), yi = std::min(int(y), kRes - 2);
  int zi = int(std::upper_bound(nodes.begin(), nodes.end(), z) - nodes.begin()) - 1;
  zi = std::clamp(zi, 0, kRes - 2);
  float dx = x - float(xi), dy = y - float(yi);
  float dz = (z - nodes[size_t(zi)]) / (nodes[size_t(zi) + 1] - nodes[size_t(zi)]);
  float c[3];
  for (int k = 0; k < 3; ++k) {
    auto co = [&](int a, int b, int d) {
      return kRgbToSpectrumTable[rgb_to_spectrum_index(l, zi + a, yi + b, xi + d) + size_t(k)];
    };
    auto lerp1 = [](float t, float a, float b) { return a + t * (b - a); };
    c[k] = lerp1(dz, lerp1(dy, lerp1(dx, co(0, 0, 0), co(0, 0, 1)), lerp1(dx, co(0, 1, 0), co(0, 1, 1))),
                 lerp1(dy, lerp1(dx, co(1, 0, 0), co(1, 0, 1)), lerp1(dx, co(1, 1, 0), co(1, 1, 1))));
  }
  return {c[0], c[1], c[2]};
}

}  // namespace

SigmoidPolynomial rgb_to_sigmoid(const RGB& rgb) {
  // Scenes use a few colours at most hits (constant materials, lights): a small per-thread cache
  // keyed by the colour's bits skips the table for them.
  struct Entry {
    bool valid = false;
    RGB rgb;
    SigmoidPolynomial s;
  };
  thread_local std::array<Entry, 64> cache;
  uint32_t bits[3];
  std::memcpy(bits, &rgb, sizeof bits);
  uint32_t h = (bits[0] * 0x9E3779B1u) ^ (bits[1] * 0x85EBCA77u) ^ (bits[2] * 0xC2B2AE3Du);
  Entry& e = cache[h >> 26];
  if (e.valid && std::memcmp(&e.rgb, &rgb, sizeof bits) == 0) return e.s;
  e = {true, rgb, table_lookup(rgb)};
  return e.s;
}

}  // namespace candela
