#pragma once
// The camera and the film: projection, lens, shutter, image size, outputs. Part of the format-neutral scene description (description/scene_desc.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "candela/animation/keyframes.h"
#include "candela/base/enum_names.h"
#include "candela/base/error.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"

namespace candela {

enum class FovAxis { X, Y, Smaller, Larger, Diagonal };
enum class Projection {
  Perspective,
  // Parallel rays along +z; the film covers camera-space x in [-1, 1] and y in [-1 / aspect,
  // 1 / aspect] (aspect = width / height), as Mitsuba's orthographic sensor; world_from_camera
  // scales it.
  Orthographic,
  // pbrt-v4's spherical camera: every direction around the camera's origin, the whole image being
  // the sphere. Equirectangular: film (x, y) / (width, height) = (phi / 2 pi, theta / pi), the
  // direction (sin theta cos phi, cos theta, sin theta sin phi) in camera space (theta from +y, up;
  // +z, the view, at a quarter of the width). EqualArea: the image is Clarberg's equal-area square
  // (sampling/warp.h), its +z hemisphere turned to +y (pbrt-v4 swaps y and z). No fov, lens or screen
  // window; light paths cannot be joined to it (no t = 1 strategy).
  Equirectangular,
  EqualArea
};
constexpr std::string_view enum_name(FovAxis v) {
  switch (v) {
    case FovAxis::X: return "x";
    case FovAxis::Y: return "y";
    case FovAxis::Smaller: return "smaller";
    case FovAxis::Larger: return "larger";
    case FovAxis::Diagonal: return "diagonal";
  }
  return {};
}
constexpr std::string_view enum_name(Projection v) {
  switch (v) {
    case Projection::Perspective: return "perspective";
    case Projection::Orthographic: return "orthographic";
    case Projection::Equirectangular: return "equirectangular";
    case Projection::EqualArea: return "equal_area";
  }
  return {};
}

struct CameraDesc {
  // Maps camera space (+x image right, +y image up, +z forward) to world space. It may scale
  // (orthographic cameras); directions are normalised after it.
  Transform world_from_camera;
  Projection projection = Projection::Perspective;
  // Nothing nearer than this (along +z, in camera space) is seen by camera rays (Mitsuba's near_clip).
  float near_clip = 0;
  float fov_degrees = 40;
  FovAxis fov_axis = FovAxis::Y;  // JSON gives a vertical fov; pbrt-v4 gives it on the smaller axis
  // pbrt-v4's screen window: the rectangle [x0, x1] x [y0, y1] of screen space the film covers, where
  // screen space is camera space for orthographic cameras, and camera space at unit distance over
  // tan(fov / 2) for perspective ones. An off-centre window shifts the view without tilting the film.
  // Unset: the film is centred and framed by the fov (perspective) or spans x in [-1, 1] (orthographic).
  // Spherical projections: the part [u0, u1] x [v0, v1] of the full image's (u, v) = (x / width,
  // y / height) the film covers, v down the image's rows (a cropped spherical image); unset: all of it.
  std::optional<std::array<float, 4>> screen_window;
  // Thin lens (depth of field): 0 = pinhole. Points at focus_distance along +z are sharp.
  float lens_radius = 0;
  float focus_distance = 1e6f;
  // Each camera path gets a time uniformly in [shutter_open, shutter_close] (motion blur).
  float shutter_open = 0, shutter_close = 1;
  // The participating medium the camera sits in (index into SceneDesc::media; -1 = vacuum).
  int medium = -1;
  // Animation (SceneDesc::animation): the node whose world transform places the camera
  // (world_from_camera is then relative to it; -1 = none), and keyframed lens values (none: constant).
  int animation_node = -1;
  std::optional<Keyframes> fov_keys, focus_distance_keys, lens_radius_keys;
};

// For models that bring no camera (OBJ, glTF): a perspective camera looking along -z at the box
// [lo, hi] from its +z side, up +y, `fov_degrees` across the smaller image axis, far enough back that
// the box's bounding sphere fits, times `margin`.
inline CameraDesc camera_framing(const Point3& lo, const Point3& hi, float fov_degrees = 40, float margin = 1) {
  const Point3 center = (lo + hi) * 0.5f;
  const float radius = std::max(0.5f * length(hi - lo), 1e-3f);
  const float distance = radius / std::sin(0.5f * fov_degrees * 3.14159265f / 180) * margin;
  CameraDesc camera;
  camera.world_from_camera = Transform::look_at_right_handed(center + Vec3(0, 0, distance), center, {0, 1, 0});
  camera.fov_degrees = fov_degrees;
  camera.fov_axis = FovAxis::Smaller;
  return camera;
}

// The largest film any front end accepts: each side, and pixels in all.
inline constexpr int kMaxResolution = 65536;
inline constexpr long long kMaxPixels = 1LL << 28;

struct FilmDesc {
  int width = 512;
  int height = 512;
  std::string filename;  // empty = the command line's default
  // The AOV layers written beside the colour in an EXR output, as --aov takes them ("albedo,normal";
  // film/aov_film.h); empty = none. The command line's --aov replaces it.
  std::string aovs;
  // Where the image lies in a larger one (pbrt-v4's cropwindow and pixelbounds): its top-left pixel is
  // (x, y) of a full_width x full_height image, whose view the camera's screen window was narrowed
  // from. EXR outputs record it as their data window inside that display window; --resolution drops it.
  struct Crop {
    int x = 0, y = 0, full_width = 0, full_height = 0;
  };
  std::optional<Crop> crop;
  // The sensor every sample passes on its way to the film (pbrt-v4's PixelSensor with its CIE 1931
  // sensor; film/sensor.h applies it). The default changes nothing.
  struct Sensor {
    // pbrt-v4's imaging ratio: the exposure time (the shutter interval) x ISO / 100; scales every sample.
    float exposure = 1;
    // Kelvin, 0 = none: light is white-balanced from the CIE daylight illuminant of this correlated
    // colour temperature to the output's white (D65), by von Kries adaptation in Bradford's cone space.
    float white_balance = 0;
    // > 0: a sample whose largest sensor component (CIE XYZ x exposure) is above it is scaled down
    // to it (pbrt-v4's maxcomponentvalue: less energy, fewer fireflies); 0 = no limit.
    float max_component = 0;
    bool changes_nothing() const { return exposure == 1 && white_balance == 0 && max_component == 0; }
  };
  Sensor sensor;
};

}  // namespace candela
