#include "candela/lights/goniometric_light.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>

#include "candela/base/error.h"
#include "candela/film/image_io.h"

namespace candela {

GoniometricLightSource make_goniometric_light(const GoniometricLight& desc, const Image& image) {
  if (image.width <= 0 || image.height <= 0) throw SceneError("goniometric light: the image is empty");
  // The equal-area octahedral square needs a square image (as pbrt-v4 requires).
  if (image.width != image.height)
    throw SceneError(fmt::format("goniometric light: the image must be square (an equal-area map of the "
                                 "directions), not {}x{}",
                                 image.width, image.height));
  auto texels = std::make_shared<GoniometricLightSource::Texels>();
  const int n = image.width;
  texels->resolution = n;
  texels->values.resize(size_t(n) * size_t(n));
  // One channel per texel, the mean of R, G and B as pbrt-v4 makes it; NaN and negative values
  // count as zero (no negative intensity).
  double sum = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const RGB c = image.at(x, y);
      const float mean = (c.r + c.g + c.b) / 3;
      const float value = mean > 0 ? mean : 0.0f;
      texels->values[size_t(y) * size_t(n) + size_t(x)] = value;
      sum += value;
    }
  texels->mean = float(sum / double(texels->values.size()));
  // Equal areas of the square are equal solid angles, so sampling texels in proportion to their
  // values samples directions in proportion to the intensity.
  texels->distribution = Distribution2D(texels->values, n, n);

  GoniometricLightSource light;
  light.to_world = desc.to_world;
  light.position = desc.to_world.point(Point3(0.0f));
  light.intensity = desc.intensity;
  // pbrt-v4's "power": the intensity times power / (4 pi mean), so that unit intensity emits `power`.
  if (desc.power > 0) {
    if (!(texels->mean > 0))
      throw SceneError(fmt::format("goniometric light: \"power\" {} cannot be met: the image is black", desc.power));
    light.intensity = light.intensity * (desc.power / (4 * kPi * texels->mean));
  }
  light.texels = std::move(texels);
  return light;
}

GoniometricLightSource make_goniometric_light(const GoniometricLight& desc) {
  std::shared_ptr<const Image> image;
  try {
    image = read_image_shared(desc.filename, IntegerEncoding::SRGB);
  } catch (const std::exception& e) {
    // read_image's message names the file already.
    throw SceneError(fmt::format("goniometric light: {}", e.what()));
  }
  try {
    return make_goniometric_light(desc, *image);
  } catch (const SceneError& e) {
    throw SceneError(fmt::format("{}: {}", desc.filename, e.what()));
  }
}

}  // namespace candela
