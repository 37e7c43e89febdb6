#pragma once
// Lights that are not shapes (emissive shapes are ShapeDesc::emission), each with its schema
// (description/schema.h). Part of the format-neutral scene description (description/scene_desc.h).
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

#include "candela/base/enum_names.h"
#include "candela/base/error.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"
#include "candela/description/schema.h"
#include "candela/description/textures.h"

namespace candela {

struct PointLight {
  Point3 position{0.0f};
  RGB intensity{1.0f};  // W/sr
};
template <>
struct SchemaOf<PointLight> {
  static constexpr Field fields[] = {
      point_field<&PointLight::position>("position").required_field(),
      field<&PointLight::intensity>("intensity", kNonNegative, "W/sr").required_field(),
  };
  static constexpr TypeSchema schema{.name = "point", .fields = fields, .help = "a point light"};
};

// How a spot light falls off between its beam and its cutoff angle.
enum class SpotFalloff {
  Smoothstep,  // pbrt-v4's smoothstep in cos(angle)
  Linear,      // Mitsuba 3's: linear in the angle
};
constexpr std::string_view enum_name(SpotFalloff v) {
  switch (v) {
    case SpotFalloff::Smoothstep: return "smoothstep";
    case SpotFalloff::Linear: return "linear";
  }
  return {};
}

// Point light emitting into a cone around `direction`: full intensity inside cone_angle - cone_delta,
// falling off to zero at cone_angle with pbrt-v4's smoothstep in cos(angle), or (SpotFalloff::Linear)
// with Mitsuba 3's spot: linearly in the angle from beam width = cone_angle - cone_delta to cone_angle,
// times the image `texture` projected over the cone (-1 = none), as Mitsuba defines both.
struct SpotLight {
  Point3 position{0.0f};
  Vec3 direction{0, 0, 1};
  RGB intensity{1.0f};  // W/sr on the axis
  float cone_angle = 30;  // degrees from the axis where the light reaches zero
  float cone_delta = 5;   // degrees over which it falls off
  SpotFalloff falloff = SpotFalloff::Smoothstep;
  int texture = -1;      // index into SceneDesc::textures
  Vec3 up{0, 1, 0};      // with a texture: the image's up direction (the light frame's +y)
};
inline std::optional<SchemaViolation> check_spot(const void* object) {
  const auto& spot = *static_cast<const SpotLight*>(object);
  if (spot.cone_delta <= spot.cone_angle) return std::nullopt;
  return SchemaViolation{"cone_delta", fmt::format("cone_delta must be in [0, cone_angle] = [0, {}] degrees, got {}",
                                                   spot.cone_angle, spot.cone_delta)};
}
template <>
struct SchemaOf<SpotLight> {
  using L = SpotLight;
  static constexpr Field fields[] = {
      point_field<&L::position>("position").required_field(),
      direction_field<&L::direction>("direction", "the cone's axis"),
      field<&L::intensity>("intensity", kNonNegative, "W/sr on the axis").required_field(),
      field<&L::cone_angle>("cone_angle", ValueRange{.lo = 0, .hi = 180, .lo_open = true}, "degrees to zero"),
      field<&L::cone_delta>("cone_delta", ValueRange{.lo = 0, .hi = 180}, "degrees of falloff"),
      enum_field<&L::falloff>("falloff"),
      texture_ref<&L::texture>("texture", "an image projected over the cone"),
      direction_field<&L::up>("up", "the image's up direction"),
  };
  static constexpr TypeSchema schema{.name = "spot", .fields = fields, .check = &check_spot,
                                     .help = "a point light in a cone"};
};

// What a projector's image means.
enum class ProjectorRadiometry {
  // Mitsuba's projector: the image is the irradiance delivered to a surface one unit away facing the
  // projector, so the intensity is I = pi scale image(uv) / cos^3(theta), theta from the axis.
  Irradiance,
  // pbrt-v4's "projection" light: the image is the intensity itself, I = scale image(uv).
  Intensity,
};
constexpr std::string_view enum_name(ProjectorRadiometry v) {
  switch (v) {
    case ProjectorRadiometry::Irradiance: return "irradiance";
    case ProjectorRadiometry::Intensity: return "intensity";
  }
  return {};
}

// Which of the image's axes a projector's field of view spans (the other follows from the aspect ratio).
enum class ProjectorFovAxis {
  Larger,   // the image's longer side (Mitsuba's fov_axis is converted to it by the reader)
  Smaller,  // the image's shorter side (pbrt-v4's "projection" light; the camera's FovAxis::Smaller)
};
constexpr std::string_view enum_name(ProjectorFovAxis v) {
  switch (v) {
    case ProjectorFovAxis::Larger: return "larger";
    case ProjectorFovAxis::Smaller: return "smaller";
  }
  return {};
}

// A point light that projects an image (Mitsuba's "projector", pbrt-v4's "projection"): at the origin
// of to_world looking along its +z with the field of view `fov_degrees` on the image's `fov_axis`;
// `irradiance` is the image (index into SceneDesc::textures), scaled by `scale`, meaning what
// `radiometry` says. power > 0 (pbrt-v4's "power"): the emission is multiplied by power / (the power
// the projector would emit with scale 1, reckoned as pbrt-v4 does: cos^3 at each texel's centre).
struct ProjectorLight {
  Transform to_world;
  float fov_degrees = 90;
  int irradiance = -1;
  RGB scale{1.0f};
  ProjectorRadiometry radiometry = ProjectorRadiometry::Irradiance;
  ProjectorFovAxis fov_axis = ProjectorFovAxis::Larger;
  float power = 0;
};
template <>
struct SchemaOf<ProjectorLight> {
  using L = ProjectorLight;
  static constexpr Field fields[] = {
      field<&L::to_world>("transform", kAnyValue, "from the projector's frame (looking along +z) to the world"),
      field<&L::fov_degrees>("fov", ValueRange{.lo = 0, .hi = 180, .lo_open = true, .hi_open = true},
                             "degrees, on the image's fov_axis"),
      texture_ref<&L::irradiance>("irradiance").required_field(),
      field<&L::scale>("scale", kNonNegative),
      enum_field<&L::radiometry>("radiometry", "what the image means"),
      enum_field<&L::fov_axis>("fov_axis", "the image axis fov spans"),
      field<&L::power>("power", kNonNegative, "W with scale 1; 0 = not normalised"),
  };
  static constexpr TypeSchema schema{.name = "projector", .fields = fields, .help = "projects an image"};
};

// A point light whose intensity over directions is an image (pbrt-v4's "goniometric" light): at the
// origin of to_world, the intensity along the local unit direction d is
//   I(d) = intensity x image(equal_area_sphere_to_square(d.x, d.z, d.y)),
// Clarberg's equal-area square (sampling/warp.h) with the light's +y at the square's centre (pbrt-v4
// swaps y and z), read at the nearest texel (texel (x, y) covers [x, x+1) / width x [y, y+1) / height,
// row 0 the top); the image must be square, and each texel counts as the mean of its R, G and B
// (pbrt-v4 makes it one channel so), negative values as zero. power > 0 (pbrt-v4's "power"): the
// intensity is multiplied by power / (4 pi x the image's mean), so that an intensity of luminance 1
// emits `power`.
struct GoniometricLight {
  Transform to_world;
  std::string filename;  // resolved by the reader
  RGB intensity{1.0f};
  float power = 0;
};
template <>
struct SchemaOf<GoniometricLight> {
  using L = GoniometricLight;
  static constexpr Field fields[] = {
      field<&L::to_world>("transform", kAnyValue, "from the light's frame (+y at the image's centre) to the world"),
      field<&L::filename>("filename", kAnyValue, "square equal-area image of the directions").required_field(),
      field<&L::intensity>("intensity", kNonNegative, "W/sr, times the image"),
      field<&L::power>("power", kNonNegative, "W for unit intensity; 0 = not normalised"),
  };
  static constexpr TypeSchema schema{.name = "goniometric", .fields = fields,
                                     .help = "a point light shaped by an image"};
};

// Parallel light from infinitely far away, travelling along `direction`; `radiance` is the
// irradiance it delivers to a surface facing it (pbrt-v4's distant "L").
struct DistantLight {
  Vec3 direction{0, 0, 1};
  RGB radiance{1.0f};
};
template <>
struct SchemaOf<DistantLight> {
  static constexpr Field fields[] = {
      direction_field<&DistantLight::direction>("direction", "where the light travels").required_field(),
      field<&DistantLight::radiance>("radiance", kNonNegative, "irradiance on a facing surface").required_field(),
  };
  static constexpr TypeSchema schema{.name = "distant", .fields = fields, .help = "parallel light"};
};

// Light from infinitely far away in every direction. Constant when zenith == horizon == ground;
// otherwise radiance blends linearly in cos(theta) from horizon to zenith above the horizon and is
// `ground` below it.
struct SkyLight {
  RGB zenith{1.0f};
  RGB horizon{1.0f};
  RGB ground{1.0f};
  Vec3 up{0, 1, 0};
  bool is_constant() const { return zenith == horizon && horizon == ground; }
};
template <>
struct SchemaOf<SkyLight> {
  static constexpr Field fields[] = {
      field<&SkyLight::zenith>("zenith", kNonNegative),
      field<&SkyLight::horizon>("horizon", kNonNegative),
      field<&SkyLight::ground>("ground", kNonNegative),
      direction_field<&SkyLight::up>("up"),
  };
  static constexpr TypeSchema schema{.name = "sky", .fields = fields, .help = "a sky gradient, or constant"};
};

// How an environment image covers the sphere of directions, in the light's local frame.
enum class EnvironmentMapping {
  // Latitude-longitude with +y up (Mitsuba's orientation): image position (u, v) in [0,1]^2, v = 0 at
  // the top, is the direction (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi)), phi = 2 pi u,
  // theta = pi v. Texel (x, y) sits at ((x + 1/2) / width, (y + 1/2) / height), as most lat-long images
  // are made.
  Equirectangular,
  // The same directions with Mitsuba's envmap texel placement: texel (x, y) at ((x + 1/2) / width,
  // y / (height - 1)), so the first and last rows are the poles themselves.
  EquirectangularPoleRows,
  // Clarberg's equal-area octahedral square with +z up (pbrt-v4's "infinite" light with a filename).
  EqualAreaOctahedral
};
constexpr std::string_view enum_name(EnvironmentMapping v) {
  switch (v) {
    case EnvironmentMapping::Equirectangular: return "equirectangular";
    case EnvironmentMapping::EquirectangularPoleRows: return "equirectangular_pole_rows";
    case EnvironmentMapping::EqualAreaOctahedral: return "equal_area";
  }
  return {};
}

// An environment map: radiance from every direction read from an image, importance-sampled.
struct EnvironmentMap {
  std::string filename;  // resolved by the reader
  EnvironmentMapping mapping = EnvironmentMapping::Equirectangular;
  RGB scale{1.0f};
  Transform to_world;  // from the map's local frame to the world (rotations only are meaningful)
  bool mis_compensation = false;  // sample by luminance minus its mean (environment_light.h)
  // Between texel centres: bilinear (Mitsuba's envmap), or the nearest texel (pbrt-v4's image
  // infinite light, whose sampling density is then exactly proportional to the radiance).
  TextureFilter filter = TextureFilter::Bilinear;
};
template <>
struct SchemaOf<EnvironmentMap> {
  using L = EnvironmentMap;
  static constexpr Field fields[] = {
      field<&L::filename>("filename", kAnyValue, "environment map").required_field(),
      enum_field<&L::mapping>("mapping"),
      field<&L::scale>("scale", kNonNegative),
      field<&L::mis_compensation>("mis_compensation"),
      enum_field<&L::filter>("filter", "bilinear between texel centres, or the nearest texel"),
      field<&L::to_world>("transform", kAnyValue, "rotations only"),
  };
  static constexpr TypeSchema schema{.name = "environment", .fields = fields, .help = "an environment image"};
};

using LightDesc =
    std::variant<PointLight, SkyLight, SpotLight, DistantLight, EnvironmentMap, ProjectorLight, GoniometricLight>;

}  // namespace candela
