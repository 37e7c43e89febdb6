#pragma once
#include <limits>

#include "candela/math/color.h"
#include "candela/math/vec.h"

namespace candela {

// Where light is gathered: a surface point and the normal of the side that gathers (zero vector
// when any direction may receive light).
struct LightSampleContext {
  Point3 p;
  Normal3 n;
};

struct LightSample {
  RGB radiance;    // arriving at ctx.p along wi, before visibility
  Vec3 wi;         // unit direction from ctx.p towards the light
  float distance = std::numeric_limits<float>::infinity();  // to the light point; infinite for the sky
  float pdf = 0;   // solid angle (1 for delta lights); 0 = no sample
  Point3 p_light;  // the sampled point on the light (for shadow rays)
  Normal3 n_light;
  bool is_delta = false;
};

}  // namespace candela
