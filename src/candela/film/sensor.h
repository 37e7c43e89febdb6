#pragma once
// The sensor between the light arriving at the film and the film's sums: pbrt-v4's PixelSensor with
// its CIE 1931 sensor (FilmDesc::Sensor). A sample's radiance, in candela's linear sRGB, becomes the
// sensor's response (CIE XYZ times the exposure), is scaled down where its largest component exceeds
// the sensor's limit, and is turned back into linear sRGB through the white balance. Applied to every
// camera sample and every splat, before the film adds it (pbrt-v4 applies it in the same place).
#include <array>

#include "candela/description/camera_film.h"
#include "candela/math/color.h"

namespace candela {

// A chromaticity (CIE 1931 xy).
struct Chromaticity {
  double x = 0, y = 0;
};

// The chromaticity of the CIE daylight illuminant of correlated colour temperature `kelvin`, as
// pbrt-v4 makes it: the temperature is first rescaled to the revised second radiation constant
// (x 1.4388 / 1.4380); below 4000 K, where the daylight series is not defined, a blackbody's.
Chromaticity daylight_chromaticity(double kelvin);

// The 3x3 matrix, row-major, that white-balances CIE XYZ from white `from` to white `to`: von Kries
// scaling of Bradford's cone responses (the adapted `from` white has `to`'s chromaticity).
std::array<double, 9> white_balance_matrix(Chromaticity from, Chromaticity to);

class FilmSensor {
 public:
  FilmSensor() = default;
  explicit FilmSensor(const FilmDesc::Sensor& desc);
  // The default sensor: every sample passes unchanged.
  bool changes_nothing() const { return changes_nothing_; }
  // The value the film adds for a sample (or splat) of radiance `L`.
  RGB respond(const RGB& L) const {
    if (changes_nothing_) return L;
    return respond_slow(L);
  }
  // pbrt-v4's maxcomponentvalue (0: no limit); a spectral film's buckets apply it too (aov_film.h).
  float max_component() const { return max_component_; }

 private:
  RGB respond_slow(const RGB& L) const;
  bool changes_nothing_ = true;
  float max_component_ = 0;
  std::array<float, 9> sensor_from_rgb_{};  // exposure x XYZ from linear sRGB
  std::array<float, 9> rgb_from_sensor_{};  // linear sRGB from white-balanced XYZ
};

}  // namespace candela
