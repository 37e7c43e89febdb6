#pragma once
// Shape descriptions: geometry, emission, media on either side; objects and their instances. Part of the format-neutral scene description (description/scene_desc.h).
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

namespace candela {

struct TriangleMesh {
  std::vector<Point3> positions;
  std::vector<Normal3> normals;  // empty or one per position (shading normals)
  std::vector<Vec2> uvs;         // empty or one per position
  std::vector<uint32_t> indices;  // three per triangle
  // Named per-vertex or per-face values (PLY's extra properties; Mitsuba's mesh_attribute), each
  // with 1 or 3 channels: values.size() == channels * (vertex count or triangle count).
  struct Attribute {
    std::string name;  // without the "vertex_" / "face_" prefix
    bool per_face = false;
    int channels = 1;
    std::vector<float> values;
  };
  std::vector<Attribute> attributes;
  size_t triangle_count() const { return indices.size() / 3; }
};

// Each geometry declares its parameters in a schema (description/schema.h). A mesh's and an SDF
// grid's data (a file, or arrays inline) are read and written beside their schemas' fields
// (io/json/shapes.cpp, io/json_writer.cpp).

// How a sphere's surface is parameterised, with phi the azimuth from +x towards +y and theta the
// angle from +z, both in its object space: u = phi / 2 pi, and v = theta / pi (Mitsuba's) or
// 1 - theta / pi (pbrt-v4's). Textures are placed by it.
enum class SphereUv { Mitsuba, Pbrt };
constexpr std::string_view enum_name(SphereUv v) {
  switch (v) {
    case SphereUv::Mitsuba: return "mitsuba";
    case SphereUv::Pbrt: return "pbrt";
  }
  return {};
}

// Sphere of `radius` around `center`, in object space (then to_world applies). It may be cut to a
// partial sphere (pbrt-v4's zmin, zmax, phimax): only the points at heights z_min <= z <= z_max above
// the centre along its z axis (each clamped to [-radius, radius]; absent: the whole height) and with
// azimuth phi <= phi_max degrees are kept. Through the cut its inside shows. With uv = pbrt, (u, v) are
// pbrt-v4's of the part kept: u = phi / phi_max, v = (theta - theta(z_min)) / (theta(z_max) - theta(z_min))
// with theta(z) = acos(z / radius), which is 1 - theta / pi for the whole sphere; with uv = mitsuba
// they stay (phi / 2 pi, theta / pi).
struct SphereShape {
  Point3 center{0.0f};
  float radius = 1;
  SphereUv uv = SphereUv::Mitsuba;
  float z_min = 0, z_max = 0;
  bool z_min_given = false, z_max_given = false;
  float phi_max = 360;  // degrees, in (0, 360]

  // The heights kept, clamped to the sphere (as pbrt-v4 clamps them).
  float z_lo() const { return z_min_given ? std::clamp(z_min, -radius, radius) : -radius; }
  float z_hi() const { return z_max_given ? std::clamp(z_max, -radius, radius) : radius; }
  bool partial() const { return z_lo() > -radius || z_hi() < radius || phi_max < 360; }
};
inline std::optional<SchemaViolation> check_sphere(const void* object) {
  const auto& s = *static_cast<const SphereShape*>(object);
  if (s.z_min_given && s.z_max_given && !(s.z_min < s.z_max))
    return SchemaViolation{"z_max", fmt::format("z_max must exceed z_min; z_min is {} and z_max is {}", s.z_min, s.z_max)};
  return std::nullopt;
}
template <>
struct SchemaOf<SphereShape> {
  using T = SphereShape;
  static constexpr Field fields[] = {
      point_field<&T::center>("center").required_field(),
      field<&T::radius>("radius", kPositive).required_field(),
      enum_field<&T::uv>("uv", "the (u, v) parameterisation: v = theta / pi or 1 - theta / pi"),
      number_if_given<&T::z_min, &T::z_min_given>("z_min", kAnyValue,
                                                  "cuts off what lies below this height above the centre"),
      number_if_given<&T::z_max, &T::z_max_given>("z_max", kAnyValue,
                                                  "cuts off what lies above this height above the centre"),
      field<&T::phi_max>("phi_max", ValueRange{.lo = 0, .hi = 360, .lo_open = true},
                         "keeps the azimuths up to this many degrees")};
  static constexpr TypeSchema schema{.name = "sphere", .fields = fields, .check = check_sphere, .help = "a sphere"};
};

// Infinite plane through `point` with normal `normal` (object space).
struct PlaneShape {
  Point3 point{0.0f};
  Normal3 normal{0, 1, 0};
};
template <>
struct SchemaOf<PlaneShape> {
  using T = PlaneShape;
  static constexpr Field fields[] = {point_field<&T::point>("point").required_field(),
                                     direction_field<&T::normal>("normal").required_field()};
  static constexpr TypeSchema schema{.name = "plane", .fields = fields, .help = "an infinite plane"};
};

// Axis-aligned box [lo, hi] in object space; to_world may rotate and scale it.
struct BoxShape {
  Point3 lo{-1.0f}, hi{1.0f};
};
inline std::optional<SchemaViolation> check_box(const void* object) {
  const auto& box = *static_cast<const BoxShape*>(object);
  for (int axis = 0; axis < 3; ++axis)
    if (!(box.lo[axis] < box.hi[axis]))
      return SchemaViolation{"max", fmt::format("max must exceed min on every axis; on axis {} min is {} and max is {}",
                                                "xyz"[axis], box.lo[axis], box.hi[axis])};
  return std::nullopt;
}
template <>
struct SchemaOf<BoxShape> {
  using T = BoxShape;
  static constexpr Field fields[] = {point_field<&T::lo>("min").required_field(),
                                     point_field<&T::hi>("max").required_field()};
  static constexpr TypeSchema schema{.name = "box", .fields = fields, .check = check_box, .help = "an axis-aligned box"};
};

// Parallelogram corner + s*edge_u + t*edge_v, (s,t) in [0,1]^2; normal = normalize(cross(edge_u, edge_v)).
struct RectangleShape {
  Point3 corner{-1, -1, 0};
  Vec3 edge_u{2, 0, 0}, edge_v{0, 2, 0};
};
inline std::optional<SchemaViolation> check_rectangle(const void* object) {
  const auto& r = *static_cast<const RectangleShape*>(object);
  if (length(cross(r.edge_u, r.edge_v)) > 1e-6f * length(r.edge_u) * length(r.edge_v)) return std::nullopt;
  return SchemaViolation{"edge_v", "edge_u and edge_v are parallel, so the rectangle has no area"};
}
template <>
struct SchemaOf<RectangleShape> {
  using T = RectangleShape;
  static constexpr Field fields[] = {point_field<&T::corner>("corner").required_field(),
                                     vector_field<&T::edge_u>("edge_u").required_field(),
                                     vector_field<&T::edge_v>("edge_v").required_field()};
  static constexpr TypeSchema schema{.name = "rectangle", .fields = fields, .check = check_rectangle,
                                     .help = "a parallelogram"};
};

// A triangle mesh: its data is read from a file or given inline, beside the schema.
struct MeshShape {
  TriangleMesh mesh;
  // A deforming mesh (animation/pose.h): its positions and normals at SceneDesc::transform_end_time
  // (mesh holds those at transform_start_time); empty when it keeps its shape.
  std::vector<Point3> positions_end;
  std::vector<Normal3> normals_end;
};
template <>
struct SchemaOf<MeshShape> {
  static constexpr TypeSchema schema{.name = "mesh", .help = "a triangle mesh (OBJ, PLY, glTF, ... or inline)"};
};

// Disk of radius 1 around the origin in the z = 0 plane, normal +z (Mitsuba's "disk"); to_world
// scales it. (u, v) = (r, phi / 2 pi), as Mitsuba parameterises it.
struct DiskShape {};
template <>
struct SchemaOf<DiskShape> {
  static constexpr TypeSchema schema{.name = "disk", .help = "the unit disk in the z = 0 plane"};
};

// Open tube (no caps) of `radius` around the segment p0-p1 (Mitsuba's "cylinder"), normals pointing
// outwards; (u, v) = (phi / phi_max, distance along the axis / its length), with phi the azimuth
// about the axis from the first vector of its frame (Frame(normalize(p1 - p0)).s: +x for an axis
// along +z, as pbrt-v4's). phi_max < 360 keeps only the azimuths up to it (pbrt-v4's phimax): through
// the cut its inside shows.
struct CylinderShape {
  Point3 p0{0.0f}, p1{0, 0, 1};
  float radius = 1;
  float phi_max = 360;  // degrees, in (0, 360]
};
inline std::optional<SchemaViolation> check_cylinder(const void* object) {
  const auto& c = *static_cast<const CylinderShape*>(object);
  if (length_squared(c.p1 - c.p0) > 0) return std::nullopt;
  return SchemaViolation{"p1", "p1 must differ from p0 (the axis)"};
}
template <>
struct SchemaOf<CylinderShape> {
  using T = CylinderShape;
  static constexpr Field fields[] = {point_field<&T::p0>("p0"), point_field<&T::p1>("p1"),
                                     field<&T::radius>("radius", kPositive),
                                     field<&T::phi_max>("phi_max", ValueRange{.lo = 0, .hi = 360, .lo_open = true},
                                                        "keeps the azimuths up to this many degrees")};
  static constexpr TypeSchema schema{.name = "cylinder", .fields = fields, .check = check_cylinder,
                                     .help = "an open tube"};
};

// How an SDF grid's shading normal is found (Mitsuba's sdfgrid "normals").
enum class SdfNormals {
  Smooth,   // Hansson-Söderlund et al.'s blend of the gradients of the voxels around the hit, continuous
            // across voxel faces (Mitsuba's default)
  Analytic  // the gradient of the hit voxel's trilinear interpolant, as the geometric normal
};
constexpr std::string_view enum_name(SdfNormals v) {
  switch (v) {
    case SdfNormals::Smooth: return "smooth";
    case SdfNormals::Analytic: return "analytic";
  }
  return {};
}

// A signed distance function sampled on a grid (Mitsuba's "sdfgrid"): the surface is the zero level
// set of the trilinear interpolation of the samples, positive outside; normals point outwards. The
// grid spans [0,1]^3 in object space, sample (i, j, k) at (i / (nx - 1), j / (ny - 1), k / (nz - 1)).
// It has no (u, v) (they are 0) and cannot emit light.
struct SdfGridShape {
  std::array<int, 3> resolution{2, 2, 2};  // samples along x, y and z, each >= 2
  // nx * ny * nz distances, x fastest, then y, then z; shared, so that copies of a SceneDesc are cheap.
  std::shared_ptr<const std::vector<float>> values;
  SdfNormals normals = SdfNormals::Smooth;
  std::string filename;  // the Mitsuba .vol file it was read from (empty: made in memory)
};
template <>
struct SchemaOf<SdfGridShape> {
  static constexpr Field fields[] = {enum_field<&SdfGridShape::normals>("normals", "how the shading normal is found")};
  static constexpr TypeSchema schema{.name = "sdfgrid", .fields = fields,
                                     .help = "a signed distance grid (a Mitsuba .vol file, or inline)"};
};

// How a curve's width is laid out across it (pbrt-v4's curve "type").
enum class CurveType {
  Flat,      // a ribbon that always faces the ray (Embree's flat curves)
  Cylinder,  // a round tube of the curve's width (Embree's round curves; pbrt-v4 fakes it with a ribbon
             // whose shading normal bends across it, which looks the same)
  Ribbon     // a flat band turned by the given normals (Embree's normal-oriented curves)
};
constexpr std::string_view enum_name(CurveType v) {
  switch (v) {
    case CurveType::Flat: return "flat";
    case CurveType::Cylinder: return "cylinder";
    case CurveType::Ribbon: return "ribbon";
  }
  return {};
}

// How a curve's points are read (pbrt-v4's curve "basis").
enum class CurveBasis {
  Bezier,  // Bézier segments sharing their end points: degree + 1 points, then degree more per segment
  BSpline  // a uniform B-spline: each point after the first degree + 1 adds a segment
};
constexpr std::string_view enum_name(CurveBasis v) {
  switch (v) {
    case CurveBasis::Bezier: return "bezier";
    case CurveBasis::BSpline: return "bspline";
  }
  return {};
}

// A curve (pbrt-v4's Shape "curve"): a chain of polynomial segments of degree 2 or 3 through object
// space, of width `width0` at its start and `width1` at its end (linear along the chain: segment k of
// n goes from lerp(k / n) to lerp((k + 1) / n), and linearly in its own parameter between), the width
// scaled by the transform as object-space lengths are (by |det|^(1/3), exact for similarity
// transforms). Each segment has its own parameter u in [0, 1]; v goes across the width from 0 to 1
// (pbrt-v4's: v grows towards cross(ray direction, tangent), 0.5 on the axis). A ribbon needs one
// normal per segment end (segment_count() + 1); the width lies along cross(normal, tangent), the
// normal between the ends turning as pbrt-v4 turns it (a spherical interpolation). Curves cannot emit
// light, and are no boundary between media.
struct CurveShape {
  std::vector<Point3> points;
  CurveBasis basis = CurveBasis::Bezier;
  int degree = 3;
  CurveType type = CurveType::Flat;
  float width0 = 1, width1 = 1;
  std::vector<Normal3> normals;  // ribbons only

  // The number of segments the points make, or 0 where their number does not fit the basis and degree.
  size_t segment_count() const {
    if ((degree != 2 && degree != 3) || points.size() < size_t(degree) + 1) return 0;
    if (basis == CurveBasis::BSpline) return points.size() - size_t(degree);
    return (points.size() - 1) % size_t(degree) == 0 ? (points.size() - 1) / size_t(degree) : 0;
  }
  // What the number of points must be, for messages: "3k + 1 (4, 7, 10, ...)" or "at least 4".
  std::string expected_point_count() const {
    if (basis == CurveBasis::BSpline) return fmt::format("at least {}", degree + 1);
    return fmt::format("{}k + 1 ({}, {}, {}, ...)", degree, degree + 1, 2 * degree + 1, 3 * degree + 1);
  }
};
inline std::optional<SchemaViolation> check_curve(const void* object) {
  const auto& c = *static_cast<const CurveShape*>(object);
  const size_t segments = c.segment_count();
  if (segments == 0)
    return SchemaViolation{"points", fmt::format("a degree {} {} curve needs {} points, got {}", c.degree,
                                                 c.basis == CurveBasis::BSpline ? "B-spline" : "Bézier",
                                                 c.expected_point_count(), c.points.size())};
  if (c.type == CurveType::Ribbon && c.normals.size() != segments + 1)
    return SchemaViolation{"normals", fmt::format("a ribbon of {} segments needs {} normals (one at each end of each "
                                                  "segment), got {}", segments, segments + 1, c.normals.size())};
  if (c.type != CurveType::Ribbon && !c.normals.empty())
    return SchemaViolation{"normals", fmt::format("only a ribbon has normals; this curve is {}", enum_name(c.type))};
  return std::nullopt;
}
template <>
struct SchemaOf<CurveShape> {
  using T = CurveShape;
  static constexpr Field fields[] = {
      enum_field<&T::basis>("basis", "how the points make segments: Bézier or uniform B-spline"),
      field<&T::degree>("degree", ValueRange{.lo = 2, .hi = 3}, "2 (quadratic) or 3 (cubic) segments"),
      enum_field<&T::type>("curve_type", "flat (facing the ray), cylinder (a round tube) or ribbon (turned by normals)"),
      field<&T::width0>("width0", kNonNegative, "the width at the curve's start"),
      field<&T::width1>("width1", kNonNegative, "the width at the curve's end")};
  static constexpr TypeSchema schema{.name = "curve", .fields = fields, .check = check_curve,
                                     .help = "a curve of Bézier or B-spline segments (hair, fur, grass)"};
};

using ShapeGeometry = std::variant<SphereShape, PlaneShape, BoxShape, RectangleShape, MeshShape, DiskShape,
                                   CylinderShape, SdfGridShape, CurveShape>;

// Diffuse emission attached to a shape (an area light). One-sided: emits on the side the surface
// normal points to, unless two_sided.
struct AreaEmission {
  RGB radiance{1.0f};
  bool two_sided = false;
  // A textured emitter (Mitsuba's area light with a texture as "radiance"): radiance *
  // SceneDesc::textures[texture] evaluated at the hit's uv (-1 = none).
  int texture = -1;
};

struct ShapeDesc {
  ShapeGeometry geometry;
  Transform to_world;
  int material = -1;  // index into SceneDesc::materials; -1 = the default diffuse 0.5
  std::optional<AreaEmission> emission;
  // A moving shape: its transform at SceneDesc::transform_times[1] (to_world holds the one at
  // transform_times[0]); in between the matrix is interpolated linearly, as Embree does.
  std::optional<Transform> to_world_end;
  // Flips the surface normal (pbrt's ReverseOrientation): which side a one-sided emitter lights.
  // Independently of this, a to_world that swaps handedness keeps normals equal to the object-space
  // normals transformed as normals (pbrt-v4's convention).
  bool reverse_orientation = false;
  // The participating media on either side (indices into SceneDesc::media; -1 = vacuum): interior on
  // the side opposite the surface normal. A ray crossing a shape whose two differ enters the one on
  // the side it goes to; where they are equal the ray keeps the medium it has (pbrt-v4's
  // MediumInterface, Mitsuba's interior/exterior).
  int interior_medium = -1, exterior_medium = -1;
  bool is_medium_transition() const { return interior_medium != exterior_medium; }
  // Animation (SceneDesc::animation): the node whose world transform places the shape (to_world is
  // then relative to it), and the deformation of its mesh (skinning, morph targets); -1 = none.
  int animation_node = -1;
  int deformation = -1;
  std::string name;      // for messages
  SourceLocation where;  // where the scene file declares it (file empty = unknown), for messages
};

// A group of shapes defined once and placed many times (pbrt's ObjectBegin/ObjectInstance): Embree
// builds its acceleration structure once and instances share it. Emissive shapes are not allowed
// in objects (readers expand those into ordinary shapes).
struct ObjectDesc {
  std::vector<ShapeDesc> shapes;  // in the object's own space; their to_world is object-relative
  std::string name;
  SourceLocation where;
};

struct InstanceDesc {
  int object = 0;  // index into SceneDesc::objects
  Transform to_world;
  std::optional<Transform> to_world_end;  // moving instance, as ShapeDesc::to_world_end
  int animation_node = -1;  // as ShapeDesc::animation_node
  SourceLocation where;
};

}  // namespace candela
