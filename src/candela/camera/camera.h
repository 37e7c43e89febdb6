#pragma once
// Pinhole perspective camera. Film coordinates are in pixels: x to the right, y down, (0,0) the
// top-left corner of the image; a pixel (i, j) covers [i, i+1) x [j, j+1) (the paper's eq. 9).
#include "candela/geometry/ray.h"
#include "candela/scene/description.h"

namespace candela {

class PerspectiveCamera {
 public:
  PerspectiveCamera() = default;
  PerspectiveCamera(const CameraDesc& desc, int width, int height);

  Ray generate_ray(Vec2 film, float time) const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  Transform world_from_camera_;
  Point3 origin_;
  float tan_half_x_ = 1, tan_half_y_ = 1;
  int width_ = 1, height_ = 1;
};

}  // namespace candela
