#include "candela/textures/noise.h"

#include <cmath>
#include <cstdint>

namespace candela {
namespace {

// Ken Perlin's permutation of 0..255 ("Improved Noise", 2002), which hashes the lattice points.
constexpr uint8_t kPerlinPermutation[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,  69,  142,
    8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,  94,  252, 219, 203,
    117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165,
    71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,
    55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,
    18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250,
    124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189,
    28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,
    129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,
    242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,
    181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114,
    67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180};

int lattice_hash(int x, int y, int z) {
  return kPerlinPermutation[(kPerlinPermutation[(kPerlinPermutation[x & 255] + y) & 255] + z) & 255];
}

// The dot product of the lattice point's gradient (one of 12 edge directions of a cube, 4 of them
// repeated: pbrt-v4's choice of which by the hash's low 4 bits) with the offset (dx, dy, dz) from it.
float lattice_gradient_dot(int h, float dx, float dy, float dz) {
  h &= 15;
  const float u = (h < 8 || h == 12 || h == 13) ? dx : dy;
  const float v = (h < 4 || h == 12 || h == 13) ? dy : dz;
  return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

// 6t^5 - 15t^4 + 10t^3: zero first and second derivatives at 0 and 1.
float quintic_fade(float t) { return t * t * t * (t * (t * 6 - 15) + 10); }

}  // namespace

float perlin_noise(Point3 p) {
  // Keep the cell index far inside int's range; coordinates that large have no fraction left.
  constexpr float kPeriod = float(1 << 30);
  const float x = std::fmod(p.x, kPeriod), y = std::fmod(p.y, kPeriod), z = std::fmod(p.z, kPeriod);
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return 0;
  const int ix = int(std::floor(x)), iy = int(std::floor(y)), iz = int(std::floor(z));
  const float dx = x - float(ix), dy = y - float(iy), dz = z - float(iz);
  // The eight corners' contributions, blended trilinearly with faded weights.
  auto corner = [&](int cx, int cy, int cz) {
    return lattice_gradient_dot(lattice_hash(ix + cx, iy + cy, iz + cz), dx - float(cx), dy - float(cy), dz - float(cz));
  };
  const float wx = quintic_fade(dx), wy = quintic_fade(dy), wz = quintic_fade(dz);
  const float y0 = lerp(wy, lerp(wx, corner(0, 0, 0), corner(1, 0, 0)), lerp(wx, corner(0, 1, 0), corner(1, 1, 0)));
  const float y1 = lerp(wy, lerp(wx, corner(0, 0, 1), corner(1, 0, 1)), lerp(wx, corner(0, 1, 1), corner(1, 1, 1)));
  return lerp(wz, y0, y1);
}

float fbm(Point3 p, float omega, int octaves) {
  float sum = 0, frequency = 1, amplitude = 1;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * perlin_noise(p * frequency);
    frequency *= 1.99f;
    amplitude *= omega;
  }
  return sum;
}

float turbulence(Point3 p, float omega, int octaves) {
  float sum = 0, frequency = 1, amplitude = 1;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * std::abs(perlin_noise(p * frequency));
    frequency *= 1.99f;
    amplitude *= omega;
  }
  return sum + 0.2f * amplitude;
}

}  // namespace candela
