#pragma once
// The camera: perspective (pinhole or thin lens) or orthographic. Film coordinates are in pixels: x
// to the right, y down, (0,0) the top-left corner of the image; a pixel (i, j) covers [i, i+1) x
// [j, j+1) (the paper's eq. 9). With a lens, rays start on a disk of radius lens_radius around the
// camera position and pass through the point the pinhole ray reaches at depth focus_distance
// (pbrt's thin lens). Orthographic rays are parallel to camera +z and start on the film rectangle
// [-1, 1] x [-1/aspect, 1/aspect] of the camera's z = 0 plane (Mitsuba's orthographic sensor), mapped
// by world_from_camera (which may scale it). With near_clip, camera rays start where they cross
// the camera-space plane z = near_clip (Ray::t_min), and t = 1 connections ignore everything nearer.
//
// An orthographic camera's importance is a delta in direction: no connection can reach it, so it
// has no importance() or sample_lens() (they return 0 and nothing), and bidirectional methods treat
// its vertex as delta (is_delta_direction()). Spherical cameras (pbrt-v4's, equirectangular or
// equal-area: CameraDesc's Projection) are not joined to light paths either, as pbrt-v4's are not:
// the same answers, so their light reaches the film through camera paths alone.
#include <array>
#include <optional>

#include "candela/geometry/ray.h"
#include "candela/description/scene_desc.h"

namespace candela {

class Camera {
 public:
  Camera() = default;
  // `margin`: how far (in pixels) beyond the image's edges camera rays reach, the reconstruction
  // filter's radius; the importance function covers that larger film so that light paths reaching
  // the margin still add to the pixels whose filter overlaps it.
  Camera(const CameraDesc& desc, int width, int height, Vec2 margin = {0, 0});

  bool is_orthographic() const { return projection_ == Projection::Orthographic; }
  bool is_spherical() const {
    return projection_ == Projection::Equirectangular || projection_ == Projection::EqualArea;
  }
  // Whether light paths cannot be connected to the camera (no t = 1 strategy): its rays come from a
  // delta distribution in direction (orthographic), or it has no importance function (spherical).
  bool is_delta_direction() const { return projection_ != Projection::Perspective; }
  float near_clip() const { return near_clip_; }
  const Transform& world_from_camera() const { return world_from_camera_; }

  // `lens` in [0,1)^2 picks the point on the lens (ignored for a pinhole); `time` is the ray's time.
  Ray generate_ray(Vec2 film, Vec2 lens, float time) const;
  // The camera as a sensor of importance (Veach's W_e, pbrt-v3 sec. 16.1.1), for paths traced from
  // lights. W_e is normalised so that it integrates to 1 over the lens and the whole film, with the
  // film area measured on the plane at unit distance: importance() of a ray leaving lens_point along
  // unit w, and the raster position it reaches, or 0 when it misses the film.
  float importance(const Point3& lens_point, const Vec3& w, Vec2* raster) const;
  // Densities with which generate_ray (with uniform film and lens samples) produces the ray from
  // lens_point along w: per area on the lens (1 for a pinhole) and per solid angle; 0 off the film.
  struct ImportancePdf {
    float pos = 0, dir = 0;
  };
  ImportancePdf pdf_importance(const Point3& lens_point, const Vec3& w) const;
  // A point on the lens seen from `ref` (the t = 1 strategy of bidirectional path tracing): the
  // direction wi from ref to it, the distance, the solid-angle pdf at ref, the importance arriving
  // there and the raster position it lands on.
  struct LensSample {
    Point3 p;
    Point3 p_visible;  // where the segment from ref meets the near clipping plane (p without one):
                       // visibility is tested from ref to here
    Vec3 wi;
    float distance = 0, pdf = 0, importance = 0;
    Vec2 raster;
  };
  std::optional<LensSample> sample_lens(const Point3& ref, Vec2 u) const;
  // The area of the importance function's film in pixels, (width + 2 margin) (height + 2 margin): a light
  // path's splat, over the number of light paths traced, times this is its contribution to a pixel.
  float importance_film_pixels() const {
    return (float(width_) + 2 * margin_.x) * (float(height_) + 2 * margin_.y);
  }
  Vec2 margin() const { return margin_; }
  // The viewing direction (the lens normal) in world space, and the lens area (1 for a pinhole).
  const Vec3& forward() const { return forward_; }
  bool has_lens() const { return lens_radius_ > 0; }
  float lens_area() const { return lens_radius_ > 0 ? kPi * lens_radius_ * lens_radius_ : 1.0f; }

  float shutter_open() const { return shutter_open_; }
  float shutter_close() const { return shutter_close_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  // The importance function's film on the plane at unit distance (margin included).
  float importance_film_area() const {
    return 4 * screen_half_.x * screen_half_.y * importance_film_pixels() / (float(width_) * float(height_));
  }

  // Ray::t_min for a ray from the camera-space point o along the camera-space direction d (d.z > 0)
  // whose world direction has length world_len: the near plane's distance along the world ray.
  float near_t(const Point3& o, const Vec3& d) const;

  // The pinhole ray through film position `film` in camera space, at depth z = 1.
  Vec3 camera_direction(Vec2 film) const {
    return {(2 * film.x / float(width_) - 1) * screen_half_.x + screen_center_.x,
            (1 - 2 * film.y / float(height_)) * screen_half_.y + screen_center_.y, 1};
  }

  // The spherical cameras' ray direction in camera space for film position `film`.
  Vec3 spherical_direction(Vec2 film) const;

  Transform world_from_camera_, camera_from_world_;
  Projection projection_ = Projection::Perspective;
  float near_clip_ = 0;
  Vec3 forward_{0, 0, 1};
  Point3 origin_;
  Vec3 pinhole_dir0_, pinhole_dx_, pinhole_dy_;  // see the constructor
  // The film's centre and half extents on the plane z = 1 (perspective) or z = 0 (orthographic), in
  // camera space.
  Vec2 screen_center_{0, 0}, screen_half_{1, 1};
  // Spherical cameras: the part [u0, u1] x [v0, v1] of the full image's (u, v) the film covers.
  std::array<float, 4> uv_window_{0, 1, 0, 1};
  float lens_radius_ = 0, focus_distance_ = 1;
  float shutter_open_ = 0, shutter_close_ = 1;
  int width_ = 1, height_ = 1;
  Vec2 margin_{0, 0};
};

// The name from before orthographic cameras.
using PerspectiveCamera = Camera;

}  // namespace candela
