#include "candela/camera/camera.h"

#include <cmath>

#include "candela/sampling/warp.h"

namespace candela {

Camera::Camera(const CameraDesc& desc, int width, int height, Vec2 margin)
    : world_from_camera_(desc.world_from_camera),
      projection_(desc.projection),
      near_clip_(std::max(0.0f, desc.near_clip)),
      lens_radius_(desc.projection == Projection::Perspective ? desc.lens_radius : 0.0f),
      focus_distance_(desc.focus_distance),
      shutter_open_(desc.shutter_open),
      shutter_close_(desc.shutter_close),
      width_(width),
      height_(height),
      margin_(margin) {
  origin_ = world_from_camera_.point(Point3(0.0f));
  camera_from_world_ = world_from_camera_.inverse();
  forward_ = normalize(world_from_camera_.vector(Vec3(0, 0, 1)));
  // The screen spans [-tan_half_x, tan_half_x] x [-tan_half_y, tan_half_y] at unit distance; the fov
  // fixes one axis and the aspect ratio (square pixels) the other. An orthographic film spans
  // [-1, 1] x [-1 / aspect, 1 / aspect]. A screen window replaces either.
  float aspect = float(width) / float(height);
  float t = std::tan(radians(desc.fov_degrees) / 2);
  const bool orthographic = is_orthographic();
  if (orthographic) {
    screen_half_ = {1, 1 / aspect};
  } else {
    FovAxis axis = desc.fov_axis;
    if (axis == FovAxis::Smaller) axis = width < height ? FovAxis::X : FovAxis::Y;
    if (axis == FovAxis::Larger) axis = width < height ? FovAxis::Y : FovAxis::X;
    switch (axis) {
      case FovAxis::X: screen_half_ = {t, t / aspect}; break;
      case FovAxis::Y: screen_half_ = {t * aspect, t}; break;
      case FovAxis::Smaller:  // resolved to X or Y above
      case FovAxis::Larger:
      case FovAxis::Diagonal: {
        float diag = std::sqrt(aspect * aspect + 1);
        screen_half_ = {t * aspect / diag, t / diag};
      }
    }
  }
  if (desc.screen_window && is_spherical()) {
    uv_window_ = *desc.screen_window;
  } else if (desc.screen_window) {
    const auto [x0, x1, y0, y1] = *desc.screen_window;
    const float unit = orthographic ? 1.0f : t;  // screen space to camera space at unit distance
    screen_center_ = {unit * 0.5f * (x0 + x1), unit * 0.5f * (y0 + y1)};
    screen_half_ = {unit * 0.5f * (x1 - x0), unit * 0.5f * (y1 - y0)};
  }
  // A pinhole ray's world direction is linear in the film position: precompute it as
  // pinhole_dir0_ + film.x * pinhole_dx_ + film.y * pinhole_dy_ (no matrix product per camera ray).
  pinhole_dir0_ = world_from_camera_.vector(
      Vec3(screen_center_.x - screen_half_.x, screen_center_.y + screen_half_.y, 1));
  pinhole_dx_ = world_from_camera_.vector(Vec3(2 * screen_half_.x / float(width), 0, 0));
  pinhole_dy_ = world_from_camera_.vector(Vec3(0, -2 * screen_half_.y / float(height), 0));
}

float Camera::near_t(const Point3& o, const Vec3& d) const {
  if (!(near_clip_ > o.z) || !(d.z > 0)) return 0;
  Point3 on_plane = o + d * ((near_clip_ - o.z) / d.z);
  return length(world_from_camera_.point(on_plane) - world_from_camera_.point(o));
}

Vec3 Camera::spherical_direction(Vec2 film) const {
  // The full image's (u, v) = (x, y) over its size; a screen window is the part the film covers.
  Vec2 uv{lerp(film.x / float(width_), uv_window_[0], uv_window_[1]),
          lerp(film.y / float(height_), uv_window_[2], uv_window_[3])};
  if (projection_ == Projection::Equirectangular) {
    const float theta = kPi * uv.y, phi = 2 * kPi * uv.x;
    const float sin_theta = std::sin(theta);
    return {sin_theta * std::cos(phi), std::cos(theta), sin_theta * std::sin(phi)};
  }
  // Film positions beyond the image's edges (the reconstruction filter's margin) continue across the
  // square's folded edges, as pbrt-v4's WrapEqualAreaSquare continues them.
  if (uv.x < 0) uv = {-uv.x, 1 - uv.y};
  if (uv.x > 1) uv = {2 - uv.x, 1 - uv.y};
  if (uv.y < 0) uv = {1 - uv.x, -uv.y};
  if (uv.y > 1) uv = {1 - uv.x, 2 - uv.y};
  const Vec3 d = equal_area_square_to_sphere(uv);
  return {d.x, d.z, d.y};  // pbrt-v4 swaps y and z: the square's +z hemisphere looks up
}

Ray Camera::generate_ray(Vec2 film, Vec2 lens, float time) const {
  const float inf = std::numeric_limits<float>::infinity();
  if (is_spherical()) {
    // The near clip is a sphere of that radius (in camera space) around the origin.
    const Vec3 w = world_from_camera_.vector(spherical_direction(film));
    Ray ray{origin_, normalize(w), inf, time};
    if (near_clip_ > 0) ray.t_min = near_clip_ * length(w);
    return ray;
  }
  if (is_orthographic()) {
    Point3 o((2 * film.x / float(width_) - 1) * screen_half_.x + screen_center_.x,
             (1 - 2 * film.y / float(height_)) * screen_half_.y + screen_center_.y, 0);
    Vec3 d(0, 0, 1);
    Ray ray{world_from_camera_.point(o), normalize(world_from_camera_.vector(d)), inf, time};
    ray.t_min = near_t(o, d);
    return ray;
  }
  if (lens_radius_ <= 0) {
    // The world image of the camera-space direction at depth z = 1, so the near plane (z = near_clip)
    // is near_clip times its length away along the ray.
    const Vec3 w = pinhole_dir0_ + film.x * pinhole_dx_ + film.y * pinhole_dy_;
    Ray ray{origin_, normalize(w), inf, time};
    if (near_clip_ > 0) ray.t_min = near_clip_ * length(w);
    return ray;
  }
  Vec3 dir = camera_direction(film);
  // Thin lens: start on the lens disk and aim at the point of the pinhole ray on the plane of focus.
  Vec2 d = square_to_concentric_disk(lens);
  Point3 lens_point(lens_radius_ * d.x, lens_radius_ * d.y, 0);
  Point3 focus_point = dir * focus_distance_;
  Point3 o = world_from_camera_.point(lens_point);
  Vec3 w = normalize(world_from_camera_.vector(focus_point - lens_point));
  Ray ray{o, w, inf, time};
  ray.t_min = near_t(lens_point, focus_point - lens_point);
  return ray;
}

float Camera::importance(const Point3& lens_point, const Vec3& w, Vec2* raster) const {
  if (is_delta_direction()) return 0;  // orthographic: a delta in direction; spherical: no importance
  float cos_theta = dot(w, forward_);
  if (!(cos_theta > 0)) return 0;
  // Where the ray meets the plane of focus (the unit plane for a pinhole), in camera space: that
  // point fixes the raster position, as in generate_ray.
  Vec3 wc = camera_from_world_.vector(w);
  Point3 oc = camera_from_world_.point(lens_point);
  if (!(wc.z > 0)) return 0;
  float depth = lens_radius_ > 0 ? focus_distance_ : 1.0f;
  Point3 focus = oc + wc * ((depth - oc.z) / wc.z);
  float sx = (focus.x / depth - screen_center_.x) / screen_half_.x;
  float sy = (focus.y / depth - screen_center_.y) / screen_half_.y;
  Vec2 r{(sx + 1) * 0.5f * float(width_), (1 - sy) * 0.5f * float(height_)};
  if (!(r.x >= -margin_.x && r.x < float(width_) + margin_.x && r.y >= -margin_.y && r.y < float(height_) + margin_.y))
    return 0;
  if (raster) *raster = r;
  float film_area = importance_film_area();
  float cos2 = cos_theta * cos_theta;
  return 1 / (film_area * lens_area() * cos2 * cos2);
}

Camera::ImportancePdf Camera::pdf_importance(const Point3& lens_point, const Vec3& w) const {
  if (is_delta_direction()) return {};  // see is_delta_direction
  if (importance(lens_point, w, nullptr) == 0) return {};
  float cos_theta = dot(w, forward_);
  float film_area = importance_film_area();
  return {1 / lens_area(), 1 / (film_area * cos_theta * cos_theta * cos_theta)};
}

std::optional<Camera::LensSample> Camera::sample_lens(const Point3& ref, Vec2 u) const {
  if (is_delta_direction()) return std::nullopt;  // no point is connected to these cameras
  Point3 p = origin_;
  if (lens_radius_ > 0) {
    Vec2 d = square_to_concentric_disk(u);
    p = world_from_camera_.point(Point3(lens_radius_ * d.x, lens_radius_ * d.y, 0));
  }
  Vec3 to_lens = p - ref;
  float dist2 = length_squared(to_lens);
  if (!(dist2 > 0)) return std::nullopt;
  LensSample s;
  s.p = p;
  s.distance = std::sqrt(dist2);
  s.wi = to_lens / s.distance;
  float cos_lens = std::abs(dot(forward_, s.wi));
  if (!(cos_lens > 0)) return std::nullopt;
  s.pdf = dist2 / (cos_lens * lens_area());
  s.importance = importance(p, -s.wi, &s.raster);
  if (s.importance == 0) return std::nullopt;
  s.p_visible = p;
  if (near_clip_ > 0) {
    // Nothing in front of the near plane is seen: ref must lie beyond it, and visibility is
    // tested from where the segment crosses it.
    Point3 rc = camera_from_world_.point(ref), lc = camera_from_world_.point(p);
    if (!(rc.z > near_clip_)) return std::nullopt;
    s.p_visible = world_from_camera_.point(lc + (rc - lc) * ((near_clip_ - lc.z) / (rc.z - lc.z)));
  }
  return s;
}

}  // namespace candela
