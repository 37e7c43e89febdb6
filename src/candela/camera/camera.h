#pragma once
// Perspective camera, pinhole or thin lens. Film coordinates are in pixels: x to the right, y down,
// (0,0) the top-left corner of the image; a pixel (i, j) covers [i, i+1) x [j, j+1) (the paper's eq. 9).
// With a lens, rays start on a disk of radius lens_radius around the camera position and pass
// through the point the pinhole ray reaches at depth focus_distance (pbrt's thin lens).
#include "candela/geometry/ray.h"
#include "candela/scene/description.h"

namespace candela {

class PerspectiveCamera {
 public:
  PerspectiveCamera() = default;
  PerspectiveCamera(const CameraDesc& desc, int width, int height);

  // `lens` in [0,1)^2 picks the point on the lens (ignored for a pinhole); `time` is the ray's time.
  Ray generate_ray(Vec2 film, Vec2 lens, float time) const;
  float shutter_open() const { return shutter_open_; }
  float shutter_close() const { return shutter_close_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  Transform world_from_camera_;
  Point3 origin_;
  float tan_half_x_ = 1, tan_half_y_ = 1;
  float lens_radius_ = 0, focus_distance_ = 1;
  float shutter_open_ = 0, shutter_close_ = 1;
  int width_ = 1, height_ = 1;
};

}  // namespace candela
