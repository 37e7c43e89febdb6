#pragma once
#include <cstdint>
#include <limits>

#include "candela/math/vec.h"

namespace candela {

// Rays traced, by kind, for the statistics line.
struct RayCounts {
  uint64_t camera = 0, bounce = 0, shadow = 0;
  uint64_t total() const { return camera + bounce + shadow; }
  RayCounts& operator+=(const RayCounts& o) {
    camera += o.camera;
    bounce += o.bounce;
    shadow += o.shadow;
    return *this;
  }
};

struct Ray {
  Point3 origin;
  Vec3 direction;  // not necessarily normalised; t is measured in its units
  float t_max = std::numeric_limits<float>::infinity();
  float time = 0;  // absolute, in [shutter open, shutter close]; moving shapes are seen at this time
  float t_min = 0;  // nothing nearer is hit (camera rays: the near clipping plane)
  Point3 at(float t) const { return origin + direction * t; }
};

// Offsets a ray origin off a surface along its geometric normal, to the side the new ray leaves
// towards, so the ray does not re-hit the surface it starts on. The offset grows with the magnitude
// of the coordinates because float error in hit points does.
inline Point3 offset_ray_origin(const Point3& p, const Normal3& ng, const Vec3& w) {
  float magnitude = std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z)));
  float eps = 2e-5f * (1.0f + magnitude);
  return p + (dot(w, ng) >= 0 ? ng : -ng) * eps;
}

}  // namespace candela
