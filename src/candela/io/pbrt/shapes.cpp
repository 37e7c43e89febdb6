// The Shape directive (each shape type built into candela's geometry, area lights spread over its
// primitives) and object instancing: ObjectBegin, ObjectEnd, ObjectInstance.
#include <algorithm>
#include <cmath>
#include <map>

#include "candela/geometry/curves.h"
#include "candela/geometry/loop_subdivision.h"
#include "candela/io/mesh_io.h"
#include "candela/io/pbrt/scene_parser.h"

namespace candela::pbrt {

namespace {

// Tessellation of the shapes candela has no primitive for.
constexpr int kDiskSegmentsPerTurn = 128;  // with the rings scaled to keep the area exact
constexpr int kBilinearPatchTessellation = 16;  // a non-planar bilinear patch becomes 16 x 16 quads

}  // namespace

namespace {

// pbrt-v4's phimax of a sphere or cylinder, in degrees: in (0, 360] (pbrt-v4 clamps it to [0, 360];
// 0 would leave nothing, and a value past a full turn is taken for a mistake).
float read_phi_max(ParamList& params) {
  float phi_max = params.get_float("phimax", 360);
  if (!(phi_max > 0 && phi_max <= 360)) params.fail("phimax", "must be in (0, 360] degrees, got {}", phi_max);
  return phi_max;
}

// pbrt-v4's zmin and zmax of a sphere or cylinder: zmin below zmax (pbrt-v4 would swap them).
void check_z_range(ParamList& params, float z_min, float z_max) {
  if (!(z_min < z_max)) params.fail("zmax", "must exceed \"zmin\" ({}), got {}", z_min, z_max);
}

}  // namespace

// pbrt-v4's sphere: radius, and the partial sphere of zmin <= z <= zmax (clamped to the radius, as
// pbrt-v4 does) and phi <= phimax, with pbrt-v4's (u, v) of the part kept. A value that cuts nothing
// off leaves the whole sphere (written without the cut).
BuiltGeometry SceneParser::make_sphere(ParamList& params) {
  float radius = params.get_float("radius", 1);
  if (!(radius > 0)) params.fail("radius", "must be positive, got {}", radius);
  float z_min = params.get_float("zmin", -radius);
  float z_max = params.get_float("zmax", radius);
  float phi_max = read_phi_max(params);
  if (!(z_min < radius)) params.fail("zmin", "must be below the radius ({}) or nothing is left, got {}", radius, z_min);
  if (!(z_max > -radius))
    params.fail("zmax", "must be above minus the radius ({}) or nothing is left, got {}", -radius, z_max);
  check_z_range(params, z_min, z_max);
  SphereShape sphere{Point3(0.0f), radius, SphereUv::Pbrt};
  sphere.z_min_given = z_min > -radius;
  sphere.z_max_given = z_max < radius;
  if (sphere.z_min_given) sphere.z_min = z_min;
  if (sphere.z_max_given) sphere.z_max = z_max;
  sphere.phi_max = phi_max;
  BuiltGeometry built;
  built.geometry = sphere;
  // pbrt-v4's Area(): phimax r (zmax - zmin), the heights clamped (4 pi r^2 for the whole sphere).
  built.object_area = sphere.partial()
                          ? static_cast<float>(radians(phi_max) * double(radius) * (double(sphere.z_hi()) - sphere.z_lo()))
                          : 4 * kPi * radius * radius;
  return built;
}

// pbrt-v4's cylinder: the open tube x^2 + y^2 = radius^2 for zmin <= z <= zmax and phi <= phimax, a
// CylinderShape from (0, 0, zmin) to (0, 0, zmax) (its phi from +x, (u, v) = (phi / phimax,
// (z - zmin) / (zmax - zmin)), as pbrt-v4's).
BuiltGeometry SceneParser::make_cylinder(ParamList& params) {
  float radius = params.get_float("radius", 1);
  if (!(radius > 0)) params.fail("radius", "must be positive, got {}", radius);
  float z_min = params.get_float("zmin", -1);
  float z_max = params.get_float("zmax", 1);
  float phi_max = read_phi_max(params);
  check_z_range(params, z_min, z_max);
  BuiltGeometry built;
  built.geometry = CylinderShape{{0, 0, z_min}, {0, 0, z_max}, radius, phi_max};
  built.object_area = static_cast<float>(radians(phi_max) * double(radius) * (double(z_max) - z_min));
  return built;
}

BuiltGeometry SceneParser::make_triangle_mesh(ParamList& params) {
  TriangleMesh mesh;
  mesh.positions = params.get_vec3_array("P", "point3");
  std::vector<int> indices = params.get_int_array("indices");
  mesh.normals = params.get_vec3_array("N", "normal");
  mesh.uvs = params.get_point2_array("uv");
  size_t n = mesh.positions.size();
  if (n == 0) params.fail("P", "is required: give the vertex positions as \"point3 P\"");
  if (indices.empty()) {
    if (n != 3) params.fail("indices", "is required unless \"P\" has exactly 3 points (it has {})", n);
    indices = {0, 1, 2};
  }
  if (indices.size() % 3 != 0)
    params.fail("indices", "has {} values, which is not a multiple of 3 (three per triangle)", indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || static_cast<size_t>(indices[i]) >= n)
      params.fail("indices", "value {} (number {}) is out of range: \"P\" has {} points", indices[i], i + 1, n);
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    params.fail("N", "has {} normals but \"P\" has {} points; give one normal per point", mesh.normals.size(), n);
  if (!mesh.uvs.empty() && mesh.uvs.size() != n)
    params.fail("uv", "has {} coordinates but \"P\" has {} points; give one per point", mesh.uvs.size(), n);
  ignore_param(params, "S", "candela derives the shading tangents itself");
  params.take_any("faceIndices");  // only for ptex textures
  mesh.indices.assign(indices.begin(), indices.end());
  return BuiltGeometry{MeshShape{std::move(mesh)}, {}, 0};
}

BuiltGeometry SceneParser::make_ply_mesh(ParamList& params) {
  if (!params.has("filename")) params.fail("filename", "is required: name the .ply file");
  std::string name = params.get_string("filename", "");
  SourceLocation where = params.where("filename");
  fs::path file = resolve_path(name, where, fmt::format("{}: \"filename\"", params.owner()));
  ignore_param(params, "displacement", "displacement mapping is not supported");
  params.take_any("edgelength");  // the displacement's tessellation
  return BuiltGeometry{MeshShape{load_mesh_file(file, where)}, {}, 0};
}

// pbrt-v4's disk: radius, innerradius and phimax at z = height, facing +z; u = phi / phimax and
// v = (radius - r) / (radius - innerradius). Triangulated with kDiskSegmentsPerTurn segments per
// full turn, the rings pushed out by sqrt(dphi / sin dphi) so the polygon has exactly the disk's
// area (the outline then deviates from the circle by at most 0.02% of the radius).
BuiltGeometry SceneParser::make_disk(ParamList& params) {
  float height = params.get_float("height", 0);
  float radius = params.get_float("radius", 1);
  float inner = params.get_float("innerradius", 0);
  float phi_max_degrees = params.get_float("phimax", 360);
  if (!(radius > 0)) params.fail("radius", "must be positive, got {}", radius);
  if (!(inner >= 0 && inner < radius))
    params.fail("innerradius", "must be in [0, \"radius\" = {}), got {}", radius, inner);
  if (!(phi_max_degrees > 0)) params.fail("phimax", "must be positive, got {}", phi_max_degrees);
  double phi_max = std::min(phi_max_degrees, 360.0f) * std::numbers::pi / 180;
  int segments = std::max(3, static_cast<int>(std::ceil(kDiskSegmentsPerTurn * phi_max / (2 * std::numbers::pi))));
  double dphi = phi_max / segments;
  double stretch = std::sqrt(dphi / std::sin(dphi));

  TriangleMesh mesh;
  auto add_vertex = [&](double r, double phi, float u, float v) {
    mesh.positions.emplace_back(static_cast<float>(stretch * r * std::cos(phi)),
                                static_cast<float>(stretch * r * std::sin(phi)), height);
    mesh.normals.emplace_back(0, 0, 1);
    mesh.uvs.emplace_back(u, v);
    return static_cast<uint32_t>(mesh.positions.size() - 1);
  };
  std::vector<uint32_t> outer_ring, inner_ring;
  for (int i = 0; i <= segments; ++i)
    outer_ring.push_back(add_vertex(radius, i * dphi, static_cast<float>(i) / segments, 0));
  if (inner > 0) {
    for (int i = 0; i <= segments; ++i)
      inner_ring.push_back(add_vertex(inner, i * dphi, static_cast<float>(i) / segments, 1));
    for (int i = 0; i < segments; ++i)
      mesh.indices.insert(mesh.indices.end(), {outer_ring[i], outer_ring[i + 1], inner_ring[i + 1], outer_ring[i],
                                               inner_ring[i + 1], inner_ring[i]});
  } else {
    for (int i = 0; i < segments; ++i) {
      uint32_t centre = add_vertex(0, 0, (i + 0.5f) / segments, 1);
      mesh.indices.insert(mesh.indices.end(), {centre, outer_ring[i], outer_ring[i + 1]});
    }
  }
  BuiltGeometry built{MeshShape{std::move(mesh)}, {}, 0};
  built.object_area = static_cast<float>(0.5 * phi_max * (double(radius) * radius - double(inner) * inner));
  return built;
}

// pbrt-v4's bilinear patches: four vertices (p00, p10, p01, p11) each, p(u, v) the bilinear
// interpolation. A planar patch becomes two triangles; any other is tessellated into
// kBilinearPatchTessellation^2 quads with bilinear positions, uvs and normals.
BuiltGeometry SceneParser::make_bilinear_mesh(ParamList& params) {
  std::vector<Vec3> p = params.get_vec3_array("P", "point3");
  std::vector<int> indices = params.get_int_array("indices");
  std::vector<Vec3> normals = params.get_vec3_array("N", "normal");
  std::vector<Vec2> uvs = params.get_point2_array("uv");
  size_t n = p.size();
  if (n == 0) params.fail("P", "is required: give the vertex positions as \"point3 P\"");
  if (indices.empty()) {
    if (n != 4) params.fail("indices", "is required unless \"P\" has exactly 4 points (it has {})", n);
    indices = {0, 1, 2, 3};
  }
  if (indices.size() % 4 != 0)
    params.fail("indices", "has {} values, which is not a multiple of 4 (four per patch)", indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || static_cast<size_t>(indices[i]) >= n)
      params.fail("indices", "value {} (number {}) is out of range: \"P\" has {} points", indices[i], i + 1, n);
  if (!normals.empty() && normals.size() != n)
    params.fail("N", "has {} normals but \"P\" has {} points; give one normal per point", normals.size(), n);
  if (!uvs.empty() && uvs.size() != n)
    params.fail("uv", "has {} coordinates but \"P\" has {} points; give one per point", uvs.size(), n);
  ignore_param(params, "emissionfilename", "textured area lights are not supported");

  size_t patches = indices.size() / 4;
  auto corner = [&](size_t patch, int c) { return static_cast<size_t>(indices[4 * patch + c]); };
  auto is_planar = [&](size_t patch) {
    Vec3 p00 = p[corner(patch, 0)], p10 = p[corner(patch, 1)], p01 = p[corner(patch, 2)], p11 = p[corner(patch, 3)];
    Vec3 normal = cross(p10 - p00, p01 - p00);
    float size = length(p10 - p00) + length(p01 - p00) + length(p11 - p00);
    if (!(length(normal) > 0)) return false;
    return std::abs(dot(p11 - p00, normalize(normal))) <= 1e-5f * size;
  };
  std::vector<bool> planar(patches);
  bool all_planar = true;
  for (size_t i = 0; i < patches; ++i) {
    planar[i] = is_planar(i);
    all_planar = all_planar && planar[i];
  }

  BuiltGeometry built;
  TriangleMesh mesh;
  const Vec2 default_uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  for (size_t patch = 0; patch < patches; ++patch) {
    Vec3 q[4], nq[4];
    Vec2 t[4];
    for (int c = 0; c < 4; ++c) {
      q[c] = p[corner(patch, c)];
      t[c] = uvs.empty() ? default_uv[c] : uvs[corner(patch, c)];
      if (!normals.empty()) nq[c] = normals[corner(patch, c)];
    }
    auto lerp3 = [](float s, Vec3 a, Vec3 b) { return a * (1 - s) + b * s; };
    auto add_vertex = [&](float u, float v) {
      mesh.positions.push_back(lerp3(v, lerp3(u, q[0], q[1]), lerp3(u, q[2], q[3])));
      mesh.uvs.emplace_back((1 - v) * ((1 - u) * t[0].x + u * t[1].x) + v * ((1 - u) * t[2].x + u * t[3].x),
                            (1 - v) * ((1 - u) * t[0].y + u * t[1].y) + v * ((1 - u) * t[2].y + u * t[3].y));
      if (!normals.empty()) {
        mesh.normals.push_back(normalize(lerp3(v, lerp3(u, nq[0], nq[1]), lerp3(u, nq[2], nq[3]))));
      } else if (!all_planar) {
        Vec3 dpdu = lerp3(v, q[1] - q[0], q[3] - q[2]), dpdv = lerp3(u, q[2] - q[0], q[3] - q[1]);
        Vec3 normal = cross(dpdu, dpdv);
        mesh.normals.push_back(length(normal) > 0 ? normalize(normal) : Vec3(0, 0, 1));
      }
      return static_cast<uint32_t>(mesh.positions.size() - 1);
    };
    int steps = planar[patch] ? 1 : kBilinearPatchTessellation;
    uint32_t first = static_cast<uint32_t>(mesh.positions.size());
    for (int j = 0; j <= steps; ++j)
      for (int i = 0; i <= steps; ++i) add_vertex(static_cast<float>(i) / steps, static_cast<float>(j) / steps);
    auto vertex = [&](int i, int j) { return first + static_cast<uint32_t>(j * (steps + 1) + i); };
    for (int j = 0; j < steps; ++j)
      for (int i = 0; i < steps; ++i) {
        // (u, v) -> (u+1, v) -> (u+1, v+1) faces along dp/du x dp/dv, pbrt's patch normal.
        mesh.indices.insert(mesh.indices.end(), {vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j),
                                                 vertex(i + 1, j + 1), vertex(i, j + 1)});
        built.primitive_of_triangle.insert(built.primitive_of_triangle.end(), 2, static_cast<uint32_t>(patch));
      }
  }
  built.geometry = MeshShape{std::move(mesh)};
  return built;
}

// pbrt-v4's Loop subdivision surface: "levels" (3) levels of Loop subdivision of the triangles
// "indices" over the points "P", every vertex then on the limit surface with the limit surface's
// normal (geometry/loop_subdivision.h, with pbrt-v4's rules; the normals face away from the
// triangles' winding, as pbrt-v4's do). "scheme" is read and not used, as in pbrt-v4.
BuiltGeometry SceneParser::make_loop_subdivision(ParamList& params) {
  int levels = params.get_int("levels", 3);
  std::vector<Vec3> p = params.get_vec3_array("P", "point3");
  std::vector<int> indices = params.get_int_array("indices");
  std::string scheme = params.get_string("scheme", "loop");
  size_t n = p.size();
  if (n == 0) params.fail("P", "is required: give the control mesh's points as \"point3 P\"");
  if (indices.empty())
    params.fail("indices", "is required: give the control mesh's triangles as \"integer indices\", three each");
  if (indices.size() % 3 != 0)
    params.fail("indices", "has {} values, which is not a multiple of 3 (three per triangle)", indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || static_cast<size_t>(indices[i]) >= n)
      params.fail("indices", "value {} (number {}) is out of range: \"P\" has {} points", indices[i], i + 1, n);
  if (levels < 0) params.fail("levels", "must be at least 0, got {}", levels);
  if (uint64_t triangles = loop_subdivision_triangle_count(indices.size() / 3, levels);
      triangles > kMaxLoopSubdivisionTriangles)
    params.fail("levels", "{} would make {} triangles of the {} given, more than the {} candela makes of one shape; "
                "give fewer levels", levels,
                triangles == UINT64_MAX ? std::string("too many") : std::to_string(triangles), indices.size() / 3,
                kMaxLoopSubdivisionTriangles);
  if (std::string problem = loop_subdivision_problem(n, indices, levels); !problem.empty())
    params.fail("indices", "do not make a mesh that can be subdivided: {}", problem);
  if (scheme != "loop")
    warn(params.where("scheme"), "{}: \"scheme\" \"{}\" is ignored: pbrt-v4 subdivides with Loop's scheme whatever "
         "it names, and so does candela", params.owner(), scheme);
  return BuiltGeometry{MeshShape{loop_subdivide(p, indices, levels, LoopRules::PbrtV4)}, {}, 0};
}

// pbrt-v4's curve (Curve::Create): "P" with "basis" "bezier" (degree + 1 points, then degree more
// per segment) or "bspline" (each point after degree + 1 adds a segment), "degree" 2 or 3, "type" flat,
// cylinder or ribbon (a ribbon needs "N", one normal per segment end), "width" (1), "width0" and
// "width1" (default "width") at the ends. "splitdepth" is pbrt-v4's tessellation depth: Embree
// intersects the curves themselves, so it is read and has no effect. Where pbrt-v4 reports an error
// and goes on without the curve (or, for an unknown type, with a cylinder), candela stops.
BuiltGeometry SceneParser::make_curve(ParamList& params) {
  CurveShape curve;
  const float width = params.get_float("width", 1);
  curve.width0 = params.get_float("width0", width);
  curve.width1 = params.get_float("width1", width);
  for (std::string_view name : {"width", "width0", "width1"}) {
    const float w = name == "width" ? width : name == "width0" ? curve.width0 : curve.width1;
    if (!(w >= 0)) params.fail(name, "must be >= 0, got {}", w);
  }
  curve.degree = params.get_int("degree", 3);
  if (curve.degree != 2 && curve.degree != 3)
    params.fail("degree", "must be 2 or 3 (quadratic or cubic segments, as in pbrt-v4), got {}", curve.degree);
  const std::string basis = params.get_string("basis", "bezier");
  if (basis == "bspline") curve.basis = CurveBasis::BSpline;
  else if (basis != "bezier") params.fail("basis", "must be \"bezier\" or \"bspline\", got \"{}\"", basis);
  curve.points = params.get_vec3_array("P", "point3");
  if (curve.points.empty()) params.fail("P", "is required: give the control points as \"point3 P\"");
  const size_t segments = curve.segment_count();
  if (segments == 0)
    params.fail("P", "has {} points, but a degree {} {} curve needs {}", curve.points.size(), curve.degree,
                basis == "bspline" ? "B-spline" : "Bézier", curve.expected_point_count());
  const std::string type = params.get_string("type", "flat");
  if (std::optional<CurveType> t = enum_from_name<CurveType>(type)) curve.type = *t;
  else params.fail("type", "must be \"flat\", \"cylinder\" or \"ribbon\", got \"{}\"", type);
  const bool normals_given = params.has_own("N");
  curve.normals = params.get_vec3_array("N", "normal");
  if (curve.type != CurveType::Ribbon) {
    if (normals_given && !curve.normals.empty())
      warn(params.where("N"), "{}: \"N\" is ignored: curve normals are only used with \"ribbon\" curves (as in pbrt-v4)",
           params.owner());
    curve.normals.clear();
  } else if (curve.normals.empty()) {
    params.fail("N", "is required for \"ribbon\" curves: one normal at each end of each segment ({})", segments + 1);
  } else if (curve.normals.size() != segments + 1) {
    params.fail("N", "has {} normals, but a ribbon of {} segments needs {} (one at each end of each segment)",
                curve.normals.size(), segments, segments + 1);
  }
  (void)params.get_int("splitdepth", 3);  // pbrt-v4's tessellation: nothing to do with Embree's curves
  if (std::string problem = curve_problem(curve); !problem.empty())
    params.fail(curve.type == CurveType::Ribbon && problem.find("normal") != std::string::npos ? "N" : "P", "{}",
                problem);
  return BuiltGeometry{std::move(curve), {}, 0};
}

namespace {

// The triangles `triangles` of `mesh` as a mesh of their own.
TriangleMesh submesh(const TriangleMesh& mesh, const std::vector<uint32_t>& triangles) {
  TriangleMesh out;
  std::vector<int64_t> remap(mesh.positions.size(), -1);
  for (uint32_t t : triangles)
    for (int c = 0; c < 3; ++c) {
      uint32_t v = mesh.indices[3 * t + c];
      if (remap[v] < 0) {
        remap[v] = static_cast<int64_t>(out.positions.size());
        out.positions.push_back(mesh.positions[v]);
        if (!mesh.normals.empty()) out.normals.push_back(mesh.normals[v]);
        if (!mesh.uvs.empty()) out.uvs.push_back(mesh.uvs[v]);
      }
      out.indices.push_back(static_cast<uint32_t>(remap[v]));
    }
  return out;
}

}  // namespace

// An area light with "power": pbrt-v4 gives every primitive (a triangle, a bilinear patch, a sphere,
// a disk) the radiance L * scale * power / (pi * (twosided ? 2 : 1) * its area), so each primitive
// emits "power" (the RGB L is not normalised). Triangles whose primitives have the same area share
// a shape; others become shapes of their own.
void SceneParser::add_emissive_shape(ShapeDesc shape, const BuiltGeometry& built, const Token& directive) {
  const AreaLightSpec& light = *state_.area_light;
  if (!light.power) {
    shape.emission = AreaEmission{light.radiance, light.two_sided, light.texture};
    add_shape(std::move(shape), directive);
    return;
  }
  double sides = light.two_sided ? 2 : 1;
  auto radiance_for = [&](double area) {
    if (!(area > 0))
      throw_scene_error(at(directive), "Shape: the area light's \"power\" (at {}) cannot be spread over a "
                        "primitive of zero area", light.where.to_string());
    return light.radiance * static_cast<float>(*light.power / (std::numbers::pi * sides * area));
  };
  const auto* mesh_shape = std::get_if<MeshShape>(&shape.geometry);
  if (built.object_area > 0 || !mesh_shape) {
    shape.emission = AreaEmission{radiance_for(built.object_area), light.two_sided};
    add_shape(std::move(shape), directive);
    return;
  }
  const TriangleMesh& mesh = mesh_shape->mesh;
  size_t triangles = mesh.triangle_count();
  std::vector<double> triangle_area(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    Point3 a = shape.to_world.point(mesh.positions[mesh.indices[3 * t]]);
    Point3 b = shape.to_world.point(mesh.positions[mesh.indices[3 * t + 1]]);
    Point3 c = shape.to_world.point(mesh.positions[mesh.indices[3 * t + 2]]);
    triangle_area[t] = 0.5 * length(cross(b - a, c - a));
  }
  std::vector<double> area = triangle_area;  // of the primitive each triangle belongs to
  if (!built.primitive_of_triangle.empty()) {
    std::map<uint32_t, double> primitive_area;
    for (size_t t = 0; t < triangles; ++t) primitive_area[built.primitive_of_triangle[t]] += triangle_area[t];
    for (size_t t = 0; t < triangles; ++t) area[t] = primitive_area[built.primitive_of_triangle[t]];
  }
  std::vector<uint32_t> order(triangles);
  for (uint32_t t = 0; t < triangles; ++t) order[t] = t;
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return area[a] < area[b]; });
  std::vector<std::vector<uint32_t>> groups;
  for (uint32_t t : order) {
    if (groups.empty() || area[t] > area[groups.back().front()] * (1 + 1e-4)) groups.emplace_back();
    groups.back().push_back(t);
  }
  for (std::vector<uint32_t>& group : groups) {
    ShapeDesc part = shape;
    part.emission = AreaEmission{radiance_for(area[group.front()]), light.two_sided};
    if (groups.size() > 1) {
      std::sort(group.begin(), group.end());
      part.geometry = MeshShape{submesh(mesh, group)};
      part.name =
          fmt::format("{} (the {} triangles of primitive area {})", shape.name, group.size(), area[group.front()]);
    }
    add_shape(std::move(part), directive);
  }
}

void SceneParser::add_shape(ShapeDesc shape, const Token& directive) {
  if (!open_object_) {
    scene_.shapes.push_back(std::move(shape));
    return;
  }
  if (shape.emission)
    throw_scene_error(at(directive),
                      "Shape inside ObjectBegin \"{}\": area lights in object instances are not supported (nor "
                      "are they in pbrt-v4)",
                      open_object_->name);
  open_object_->shapes.push_back(std::move(shape));
}

void SceneParser::shape(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the shape type");
  ParamList params = read_params(d, fmt::format("Shape \"{}\"", type.text), kShapeAttributes);
  BuiltGeometry built;
  if (type.text == "sphere")
    built = make_sphere(params);
  else if (type.text == "cylinder")
    built = make_cylinder(params);
  else if (type.text == "trianglemesh")
    built = make_triangle_mesh(params);
  else if (type.text == "plymesh")
    built = make_ply_mesh(params);
  else if (type.text == "disk")
    built = make_disk(params);
  else if (type.text == "bilinearmesh")
    built = make_bilinear_mesh(params);
  else if (type.text == "loopsubdiv")
    built = make_loop_subdivision(params);
  else if (type.text == "curve")
    built = make_curve(params);
  else
    reject_type(at(type), "shape", type.text,
                {"sphere", "cylinder", "trianglemesh", "plymesh", "disk", "bilinearmesh", "loopsubdiv", "curve"}, {},
                "candela has no primitive or tessellation for it");
  const bool curve = type.text == "curve";
  if (curve && state_.area_light)
    throw_scene_error(at(d), "Shape \"curve\": a curve cannot be an area light (AreaLightSource at {}): pbrt-v4 "
                      "cannot sample points on curves either (it stops with \"Curve::Sample not implemented\")",
                      state_.area_light->where.to_string());
  // pbrt-v4's alpha: where it is below 1 the surface is there only with that probability (0: a hole),
  // for camera and shadow rays alike; candela's mask material does exactly that around the material.
  std::optional<FloatInput> alpha = read_float_texture(params, "alpha");
  if (alpha && alpha->is_constant()) {
    if (!(alpha->value >= 0 && alpha->value <= 1))
      params.fail("alpha", "must be in [0, 1], got {}", alpha->value);
    if (alpha->value == 1) alpha.reset();
  }
  if (alpha && state_.area_light)
    params.fail("alpha", "on an area light is not supported: candela's emitters emit wherever they are hit (pbrt-v4 "
                "cuts the emission out too); give the emitter no alpha");
  params.reject_unused();
  ShapeDesc desc;
  desc.geometry = built.geometry;
  desc.to_world = state_.ctm.start;
  if (state_.ctm.is_animated()) {
    // Area lights are sampled at fixed positions.
    if (state_.area_light)
      throw_scene_error(at(d), "Shape: area lights must not move (the CTM is animated inside an AreaLightSource)");
    if (open_object_)
      throw_scene_error(at(d), "Shape inside ObjectBegin \"{}\": shapes of an object cannot move (the CTM is "
                        "animated); animate the ObjectInstance instead", open_object_->name);
    desc.to_world_end = state_.ctm.end;
  }
  desc.material = alpha ? masked_material(state_.material, *alpha, at(d)) : state_.material;
  desc.reverse_orientation = state_.reverse_orientation;
  desc.interior_medium = state_.inside_medium;
  desc.exterior_medium = state_.outside_medium;
  // A subsurface material fills its shape with its medium (pbrt-v4's BSSRDF never enters an inside
  // medium the MediumInterface names, so that is not used).
  if (auto filled = subsurface_media_.find(state_.material); filled != subsurface_media_.end()) {
    if (desc.is_medium_transition() && desc.interior_medium >= 0)
      warn(at(d), "Shape: the MediumInterface's inside medium \"{}\" is not used: the subsurface material (at {}) "
           "fills the shape with its own medium, as pbrt-v4's BSSRDF does", scene_.media[desc.interior_medium].name,
           scene_.media[filled->second].where.to_string());
    desc.interior_medium = filled->second;
  }
  if (curve && desc.is_medium_transition()) {
    // A curve has no inside: it sits in the outside medium (pbrt-v4 would switch media on crossing it).
    warn(at(d), "Shape \"curve\": the MediumInterface's inside medium is ignored: a curve has no inside and stays "
         "in the outside medium");
    desc.interior_medium = desc.exterior_medium;
  }
  desc.name = fmt::format("{} at {}", type.text, at(d).to_string());
  desc.where = at(d);
  if (state_.area_light)
    add_emissive_shape(std::move(desc), built, d);
  else
    add_shape(std::move(desc), d);
}

// The material `material` (-1: pbrt's default diffuse) cut out by `alpha` (a MaskMaterial of that
// opacity), one per pair however many shapes share it.
int SceneParser::masked_material(int material, const FloatInput& alpha, const SourceLocation& where) {
  const auto key = std::make_tuple(material, alpha.texture, alpha.is_constant() ? alpha.value : 0.0f);
  if (auto found = masked_materials_.find(key); found != masked_materials_.end()) return found->second;
  if (material < 0) material = add_material(DiffuseMaterial{}, where);
  const int masked = add_material(MaskMaterial{.opacity = alpha, .material = material}, where);
  masked_materials_.emplace(key, masked);
  return masked;
}

// ---------------------------------------------------------------- object instancing

void SceneParser::object_begin(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the object name");
  if (open_object_)
    throw_scene_error(at(d), "ObjectBegin inside the definition of \"{}\" (begun at {}); objects cannot nest",
                      open_object_->name, open_object_->where.to_string());
  if (auto earlier = objects_.find(name.text); earlier != objects_.end())
    throw_scene_error(at(name), "ObjectBegin: object \"{}\" is already defined at {}", name.text,
                      earlier->second.where.to_string());
  push_block(d, BlockKind::Object);
  open_object_ = ObjectDefinition{name.text, at(d), {}, -1};
}

void SceneParser::object_end(const Token& d) {
  require_world(d);
  if (!open_object_) throw_scene_error(at(d), "ObjectEnd without a matching ObjectBegin");
  pop_block(d, BlockKind::Object);
  std::string name = open_object_->name;
  objects_.emplace(std::move(name), std::move(*open_object_));
  open_object_.reset();
}

// As in pbrt-v4, the shapes of an object keep the CTM they had at their definition (their
// to_world), and an instance places them with the CTM at ObjectInstance: world = instance.to_world *
// shape.to_world. The object goes into SceneDesc::objects when it is first instanced.
void SceneParser::object_instance(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the object name");
  if (open_object_)
    throw_scene_error(at(d), "ObjectInstance inside the definition of \"{}\"; instances cannot nest",
                      open_object_->name);
  auto object = objects_.find(name.text);
  if (object == objects_.end())
    throw_scene_error(at(name), "ObjectInstance: no object named \"{}\" is defined (ObjectBegin must come first)",
                      name.text);
  ObjectDefinition& definition = object->second;
  if (definition.shapes.empty()) return;  // nothing to place
  if (definition.index < 0) {
    scene_.objects.push_back(ObjectDesc{definition.shapes, definition.name, definition.where});
    definition.index = static_cast<int>(scene_.objects.size()) - 1;
  }
  InstanceDesc instance;
  instance.object = definition.index;
  instance.to_world = state_.ctm.start;
  instance.where = at(d);
  if (state_.ctm.is_animated()) instance.to_world_end = state_.ctm.end;
  scene_.instances.push_back(instance);
}


}  // namespace candela::pbrt
