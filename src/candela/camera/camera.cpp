#include "candela/camera/camera.h"

#include <cmath>

#include "candela/sampling/warp.h"

namespace candela {

PerspectiveCamera::PerspectiveCamera(const CameraDesc& desc, int width, int height)
    : world_from_camera_(desc.world_from_camera),
      lens_radius_(desc.lens_radius),
      focus_distance_(desc.focus_distance),
      shutter_open_(desc.shutter_open),
      shutter_close_(desc.shutter_close),
      width_(width),
      height_(height) {
  origin_ = world_from_camera_.point(Point3(0.0f));
  // The screen spans [-tan_half_x, tan_half_x] x [-tan_half_y, tan_half_y] at unit distance; the fov
  // fixes one axis and the aspect ratio (square pixels) the other.
  float aspect = float(width) / float(height);
  float t = std::tan(radians(desc.fov_degrees) / 2);
  FovAxis axis = desc.fov_axis;
  if (axis == FovAxis::Smaller) axis = width < height ? FovAxis::X : FovAxis::Y;
  if (axis == FovAxis::Larger) axis = width < height ? FovAxis::Y : FovAxis::X;
  switch (axis) {
    case FovAxis::X: tan_half_x_ = t; tan_half_y_ = t / aspect; break;
    case FovAxis::Y: tan_half_y_ = t; tan_half_x_ = t * aspect; break;
    default: {  // diagonal
      float diag = std::sqrt(aspect * aspect + 1);
      tan_half_x_ = t * aspect / diag;
      tan_half_y_ = t / diag;
    }
  }
}

Ray PerspectiveCamera::generate_ray(Vec2 film, Vec2 lens, float time) const {
  float sx = (2 * film.x / float(width_) - 1) * tan_half_x_;
  float sy = (1 - 2 * film.y / float(height_)) * tan_half_y_;
  Vec3 dir(sx, sy, 1);  // camera space, z = 1
  if (lens_radius_ <= 0)
    return Ray{origin_, normalize(world_from_camera_.vector(dir)), std::numeric_limits<float>::infinity(), time};
  // Thin lens: start on the lens disk and aim at the point of the pinhole ray on the plane of focus.
  Vec2 d = square_to_concentric_disk(lens);
  Point3 lens_point(lens_radius_ * d.x, lens_radius_ * d.y, 0);
  Point3 focus_point = dir * focus_distance_;
  Point3 o = world_from_camera_.point(lens_point);
  Vec3 w = normalize(world_from_camera_.vector(focus_point - lens_point));
  return Ray{o, w, std::numeric_limits<float>::infinity(), time};
}

}  // namespace candela
