#include "candela/io/json/reader.h"

#include "candela/geometry/sdf_grid.h"
#include "candela/io/mesh_io.h"

namespace candela::json {

// ---- shapes

void JsonSceneReader::read_shapes(const Json& value, const std::string& pointer) {
  check_is_array(report_, value, pointer, "shapes");
  for (size_t i = 0; i < value.size(); ++i) {
    if (is_instance(value[i]))
      scene_.instances.push_back(read_instance(value[i], child_pointer(pointer, i)));
    else
      scene_.shapes.push_back(read_shape(value[i], child_pointer(pointer, i)));
  }
}

ShapeDesc JsonSceneReader::read_shape(const Json& value, const std::string& pointer) {
  CheckedObject s(report_, value, pointer);
  ShapeDesc shape;
  shape.where = place(pointer);
  shape.geometry = read_geometry(s);
  shape.material = read_shape_material(s);
  if (const Json* emission = s.find("emission")) shape.emission = read_emission(*emission, s.pointer_of("emission"));
  if (shape.emission && std::holds_alternative<SdfGridShape>(shape.geometry))
    report_.fail(s.pointer_of("emission"), "an sdfgrid cannot emit light (as in Mitsuba: it has no area to sample)");
  shape.to_world = read_transform_key(s);
  if (const Json* end = s.find("transform_end")) shape.to_world_end = read_moving_transform(*end, s, shape);
  shape.name = s.string_or("name", "");
  shape.reverse_orientation = s.boolean_or("reverse_orientation", false);
  shape.interior_medium = medium_reference(s, "interior");
  shape.exterior_medium = medium_reference(s, "exterior");
  shape.animation_node = animation_node_of(s);
  if (shape.animation_node >= 0 && shape.to_world_end)
    report_.fail(s.pointer_of("transform_end"), "an animated shape is moved by its node: it cannot have transform_end");
  if (const Json* deformation = s.find("deformation")) shape.deformation = read_deformation_use(*deformation, s, shape);
  s.finish();
  return shape;
}

// The geometry's schema (description/shapes.h); a mesh's and an SDF grid's data beside it.
ShapeGeometry JsonSceneReader::read_geometry(CheckedObject& s) {
  // Instances are told apart before a shape is read (read_shapes).
  ShapeGeometry geometry = default_of_named_type<ShapeGeometry>(s, "shape", {kInstanceType});
  if (auto* mesh = std::get_if<MeshShape>(&geometry)) *mesh = read_mesh(s);
  if (auto* grid = std::get_if<SdfGridShape>(&geometry)) *grid = read_sdf_grid(s);
  if (auto* curve = std::get_if<CurveShape>(&geometry)) *curve = read_curve(s);
  read_schema_fields(s, geometry);
  return geometry;
}

// A curve's points and (a ribbon's) normals, beside its schema; "width" is short for equal "width0" and
// "width1". The schema's check then matches their numbers to the basis, degree and curve_type.
CurveShape JsonSceneReader::read_curve(CheckedObject& s) const {
  CurveShape curve;
  curve.points = read_vec3_list(s.require("points"), s.pointer_of("points"), "points [x, y, z]");
  if (const Json* normals = s.find("normals")) {
    curve.normals = read_vec3_list(*normals, s.pointer_of("normals"), "normals [x, y, z]");
    check_nonzero_normals(curve.normals, s.pointer_of("normals"));
  }
  if (s.has("width")) {
    for (std::string_view key : {"width0", "width1"})
      if (s.has(key)) report_.fail(s.pointer_of(key), "give either \"width\" or \"width0\" and \"width1\", not both");
    curve.width0 = curve.width1 = s.number("width", kNonNegative);
  }
  return curve;
}

// A Mitsuba .vol file, or the samples inline (as `candela convert` writes a grid made in memory).
// Its "normals" is a field of its schema, read after.
SdfGridShape JsonSceneReader::read_sdf_grid(CheckedObject& s) const {
  const SdfNormals mode = SdfGridShape{}.normals;
  const bool from_file = s.has("filename"), inline_data = s.has("values") || s.has("resolution");
  if (from_file == inline_data)
    report_.fail(s.pointer(), "an sdfgrid takes either \"filename\" or inline \"resolution\" and \"values\", {}",
                 from_file ? "not both" : "and has neither");
  if (from_file)
    return read_sdf_grid_file(existing_file(s, "filename", "SDF grid"), report_.location(s.pointer_of("filename")),
                              mode);
  SdfGridShape grid;
  grid.normals = mode;
  const Json& resolution = s.require("resolution");
  const std::string resolution_pointer = s.pointer_of("resolution");
  if (!resolution.is_array() || resolution.size() != 3)
    report_.fail(resolution_pointer, "expected an array of 3 integers, got {}", describe(resolution));
  for (size_t i = 0; i < 3; ++i) {
    const int64_t n = read_int64(report_, resolution[i], child_pointer(resolution_pointer, i));
    if (n < 2 || n > std::numeric_limits<int>::max())
      report_.fail(child_pointer(resolution_pointer, i), "expected an integer >= 2 (a voxel needs 2 samples), got {}", n);
    grid.resolution[i] = int(n);
  }
  const Json& values = s.require("values");
  const std::string values_pointer = s.pointer_of("values");
  check_is_array(report_, values, values_pointer, "SDF values");
  const double expected = double(grid.resolution[0]) * grid.resolution[1] * grid.resolution[2];
  if (double(values.size()) != expected)
    report_.fail(values_pointer, "expected {} values (x fastest, then y, then z), got {}", expected, values.size());
  std::vector<float> samples(values.size());
  for (size_t k = 0; k < values.size(); ++k) samples[k] = read_float_element(report_, values, k, values_pointer);
  grid.values = std::make_shared<const std::vector<float>>(std::move(samples));
  if (std::string problem = sdf_grid_problem(grid); !problem.empty()) report_.fail(s.pointer(), "{}", problem);
  return grid;
}

int JsonSceneReader::read_shape_material(CheckedObject& s) {
  const Json* material = s.find("material");
  if (!material) return -1;  // the default diffuse 0.5
  std::string pointer = s.pointer_of("material");
  if (material->is_string()) return material_by_name(material->get<std::string>(), pointer);
  if (material->is_object()) return add_material(read_material(*material, pointer), place(pointer));
  report_.fail(pointer, "expected a material name or a material object, got {}", describe(*material));
}

AreaEmission JsonSceneReader::read_emission(const Json& value, const std::string& pointer) {
  CheckedObject e(report_, value, pointer);
  AreaEmission emission{e.rgb("radiance", ColorKind::Emission), e.boolean_or("two_sided", false)};
  if (e.has("texture")) emission.texture = texture_reference(e, "texture");
  e.finish();
  return emission;
}

// ---- objects and instances

bool JsonSceneReader::is_instance(const Json& shape) {
  if (!shape.is_object()) return false;
  auto type = shape.find("type");
  return type != shape.end() && *type == kInstanceType;
}

void JsonSceneReader::read_objects(const Json& value, const std::string& pointer) {
  if (!value.is_object())
    report_.fail(pointer, "expected an object mapping object names to objects, got {}", describe(value));
  for (auto it = value.begin(); it != value.end(); ++it) {
    if (it.key() == "_comment") continue;
    ObjectDesc object = read_object(it.value(), child_pointer(pointer, it.key()));
    object.name = it.key();
    object.where = place(child_pointer(pointer, it.key()));
    object_index_[it.key()] = int(scene_.objects.size());
    scene_.objects.push_back(std::move(object));
  }
}

// An object's shapes are in its own space; they may not emit, move or be instances themselves.
ObjectDesc JsonSceneReader::read_object(const Json& value, const std::string& pointer) {
  CheckedObject o(report_, value, pointer);
  const Json& shapes = o.require("shapes");
  std::string shapes_pointer = o.pointer_of("shapes");
  check_is_array(report_, shapes, shapes_pointer, "shapes");
  if (shapes.empty()) report_.fail(shapes_pointer, "an object needs at least one shape");
  ObjectDesc object;
  for (size_t i = 0; i < shapes.size(); ++i) {
    std::string shape_pointer = child_pointer(shapes_pointer, i);
    if (is_instance(shapes[i]))
      report_.fail(child_pointer(shape_pointer, "type"), "an object cannot contain instances (objects do not nest)");
    ShapeDesc shape = read_shape(shapes[i], shape_pointer);
    if (shape.emission)
      report_.fail(child_pointer(shape_pointer, "emission"),
                   "a shape in an object cannot emit light (instanced area lights are not supported); put it in "
                   "the top-level \"shapes\"");
    if (shape.to_world_end)
      report_.fail(child_pointer(shape_pointer, "transform_end"),
                   "a shape in an object cannot move; give the instance a transform_end instead");
    for (std::string_view key : {"animation_node", "animation", "deformation"})
      if (shapes[i].contains(key))
        report_.fail(child_pointer(shape_pointer, key),
                     "a shape in an object cannot be animated or deformed; animate the instance instead, or put the "
                     "shape in the top-level \"shapes\"");
    object.shapes.push_back(std::move(shape));
  }
  o.finish();
  return object;
}

InstanceDesc JsonSceneReader::read_instance(const Json& value, const std::string& pointer) {
  CheckedObject s(report_, value, pointer);
  s.string("type");
  InstanceDesc instance;
  instance.where = place(pointer);
  instance.object = object_by_name(s.string("object"), s.pointer_of("object"));
  instance.to_world = read_transform_key(s);
  if (const Json* end = s.find("transform_end")) {
    const ObjectDesc& object = scene_.objects[size_t(instance.object)];
    for (const ShapeDesc& shape : object.shapes)
      if (std::holds_alternative<PlaneShape>(shape.geometry))
        report_.fail(s.pointer_of("transform_end"),
                     "an infinite plane must not move: object \"{}\" contains one, so its instances cannot have "
                     "transform_end",
                     object.name);
    instance.to_world_end = read_transform(*end, s.pointer_of("transform_end"));
  }
  instance.animation_node = animation_node_of(s);
  if (instance.animation_node >= 0 && instance.to_world_end)
    report_.fail(s.pointer_of("transform_end"),
                 "an animated instance is moved by its node: it cannot have transform_end");
  s.finish();
  return instance;
}

int JsonSceneReader::object_by_name(const std::string& name, const std::string& pointer) const {
  auto it = object_index_.find(name);
  if (it != object_index_.end()) return it->second;
  std::vector<std::string> names;
  for (const auto& entry : object_index_) names.push_back(entry.first);
  if (names.empty()) report_.fail(pointer, "unknown object \"{}\" (\"objects\" defines none)", name);
  report_.fail(pointer, "unknown object \"{}\"; defined: {}", name, fmt::join(names, ", "));
}

// ---- meshes

MeshShape JsonSceneReader::read_mesh(CheckedObject& s) const {
  bool from_file = s.has("file"), inline_data = s.has("positions");
  if (from_file && inline_data)
    report_.fail(s.pointer(), "a mesh takes either \"file\" or inline \"positions\", not both");
  if (from_file) return {read_mesh_file(s)};
  if (!inline_data) report_.fail(s.pointer(), "a mesh needs either \"file\" or inline \"positions\"");
  return {read_inline_mesh(s)};
}

TriangleMesh JsonSceneReader::read_mesh_file(CheckedObject& s) const {
  for (std::string_view key : {"indices", "normals", "uvs", "attributes"})
    if (s.has(key)) report_.fail(s.pointer_of(key), "inline mesh data cannot be combined with \"file\"");
  std::string file = s.string("file");
  if (file.empty()) report_.fail(s.pointer_of("file"), "the mesh file name is empty");
  return load_mesh_file(base_dir_ / file, report_.location(s.pointer_of("file")));
}

TriangleMesh JsonSceneReader::read_inline_mesh(CheckedObject& s) const {
  TriangleMesh mesh;
  mesh.positions = read_vec3_list(s.require("positions"), s.pointer_of("positions"), "positions [x, y, z]");
  if (mesh.positions.size() < 3)
    report_.fail(s.pointer_of("positions"), "a mesh needs at least 3 positions, got {}", mesh.positions.size());
  if (const Json* indices = s.find("indices"))
    mesh.indices = read_indices(*indices, s.pointer_of("indices"), mesh.positions.size());
  else if (mesh.positions.size() == 3)
    mesh.indices = {0, 1, 2};
  else
    report_.fail(s.pointer(),
                 "missing required key \"indices\" (only a single triangle of 3 positions may leave it out)");
  if (const Json* normals = s.find("normals")) {
    mesh.normals = read_vec3_list(*normals, s.pointer_of("normals"), "normals [x, y, z]");
    check_per_vertex_count(mesh.normals.size(), mesh.positions.size(), s.pointer_of("normals"));
    check_nonzero_normals(mesh.normals, s.pointer_of("normals"));
  }
  if (const Json* uvs = s.find("uvs")) {
    mesh.uvs = read_vec2_list(*uvs, s.pointer_of("uvs"));
    check_per_vertex_count(mesh.uvs.size(), mesh.positions.size(), s.pointer_of("uvs"));
  }
  if (const Json* attributes = s.find("attributes")) read_mesh_attributes(*attributes, s.pointer_of("attributes"), mesh);
  return mesh;
}

// [{"name": ..., "per_face": bool, "channels": 1 or 3, "values": [...]}, ...]
void JsonSceneReader::read_mesh_attributes(const Json& value, const std::string& pointer, TriangleMesh& mesh) const {
  check_is_array(report_, value, pointer, "mesh attributes");
  for (size_t i = 0; i < value.size(); ++i) {
    CheckedObject a(report_, value[i], child_pointer(pointer, i));
    TriangleMesh::Attribute attribute;
    attribute.name = a.string("name");
    attribute.per_face = a.boolean_or("per_face", false);
    attribute.channels = a.integer_or("channels", 1, 1, 3);
    if (attribute.channels == 2) report_.fail(a.pointer_of("channels"), "an attribute has 1 or 3 channels, got 2");
    const Json& values = a.require("values");
    check_is_array(report_, values, a.pointer_of("values"), "attribute values");
    size_t count = attribute.per_face ? mesh.triangle_count() : mesh.positions.size();
    if (values.size() != count * size_t(attribute.channels))
      report_.fail(a.pointer_of("values"), "expected {} values ({} per {}), got {}", count * attribute.channels,
                   attribute.channels, attribute.per_face ? "triangle" : "position", values.size());
    attribute.values.reserve(values.size());
    for (size_t k = 0; k < values.size(); ++k)
      attribute.values.push_back(read_float(report_, values[k], child_pointer(a.pointer_of("values"), k)));
    a.finish();
    mesh.attributes.push_back(std::move(attribute));
  }
}

std::vector<Vec3> JsonSceneReader::read_vec3_list(const Json& value, const std::string& pointer, std::string_view of_what) const {
  check_is_array(report_, value, pointer, of_what);
  std::vector<Vec3> list;
  list.reserve(value.size());
  for (size_t i = 0; i < value.size(); ++i) list.push_back(read_vec3(report_, value[i], child_pointer(pointer, i)));
  return list;
}

std::vector<Vec2> JsonSceneReader::read_vec2_list(const Json& value, const std::string& pointer) const {
  check_is_array(report_, value, pointer, "uvs [u, v]");
  std::vector<Vec2> list;
  list.reserve(value.size());
  for (size_t i = 0; i < value.size(); ++i) list.push_back(read_vec2(report_, value[i], child_pointer(pointer, i)));
  return list;
}

std::vector<uint32_t> JsonSceneReader::read_indices(const Json& value, const std::string& pointer, size_t vertex_count) const {
  check_is_array(report_, value, pointer, "vertex indices");
  if (value.empty() || value.size() % 3 != 0)
    report_.fail(pointer, "expected a non-zero multiple of 3 indices (three per triangle), got {}", value.size());
  std::vector<uint32_t> indices;
  indices.reserve(value.size());
  for (size_t i = 0; i < value.size(); ++i) {
    int64_t index = read_int64(report_, value[i], child_pointer(pointer, i));
    if (index < 0 || uint64_t(index) >= vertex_count)
      report_.fail(child_pointer(pointer, i), "index {} is out of range: the mesh has {} positions", index,
                   vertex_count);
    indices.push_back(uint32_t(index));
  }
  return indices;
}

void JsonSceneReader::check_per_vertex_count(size_t count, size_t vertex_count, const std::string& pointer) const {
  if (count != vertex_count)
    report_.fail(pointer, "expected one entry per position ({}), got {}", vertex_count, count);
}

void JsonSceneReader::check_nonzero_normals(const std::vector<Normal3>& normals, const std::string& pointer) const {
  for (size_t i = 0; i < normals.size(); ++i)
    if (length_squared(normals[i]) == 0) report_.fail(child_pointer(pointer, i), "a normal must be non-zero");
}

// ---- transforms

// A moving shape's transform at the end time (render.transform_times); lights and infinite planes
// cannot move.
Transform JsonSceneReader::read_moving_transform(const Json& value, CheckedObject& s, const ShapeDesc& shape) const {
  std::string pointer = s.pointer_of("transform_end");
  if (shape.emission) report_.fail(pointer, "area lights must not move: an emissive shape cannot have transform_end");
  if (std::holds_alternative<PlaneShape>(shape.geometry))
    report_.fail(pointer, "an infinite plane must not move: it cannot have transform_end");
  return read_transform(value, pointer);
}

Transform JsonSceneReader::read_transform_key(CheckedObject& object) const {
  const Json* steps = object.find("transform");
  return steps ? read_transform(*steps, object.pointer_of("transform")) : Transform();
}

// Steps apply in the order listed: the first one acts on the object first.
Transform JsonSceneReader::read_transform(const Json& value, const std::string& pointer) const {
  check_is_array(report_, value, pointer, "transform steps such as {\"translate\": [x, y, z]}");
  Transform to_world;
  for (size_t i = 0; i < value.size(); ++i)
    to_world = read_transform_step(value[i], child_pointer(pointer, i)) * to_world;
  return to_world;
}

Transform JsonSceneReader::read_transform_step(const Json& value, const std::string& pointer) const {
  CheckedObject step(report_, value, pointer);
  std::vector<std::string_view> operations;
  for (std::string_view op : {"translate", "rotate", "scale", "matrix"})
    if (step.has(op)) operations.push_back(op);
  if (operations.size() != 1) {
    step.finish();  // a misspelt operation is best reported as such
    report_.fail(pointer, "a transform step needs exactly one of: translate, rotate, scale, matrix; got {}",
                 operations.empty() ? std::string("none") : fmt::format("{}", fmt::join(operations, ", ")));
  }
  Transform transform;
  std::string op_pointer = step.pointer_of(operations[0]);
  if (operations[0] == "translate")
    transform = Transform::translate(step.vec3("translate"));
  else if (operations[0] == "rotate")
    transform = read_rotation(step.require("rotate"), op_pointer);
  else if (operations[0] == "scale")
    transform = read_scale(step.require("scale"), op_pointer);
  else
    transform = read_matrix(step.require("matrix"), op_pointer);
  step.finish();
  return transform;
}

Transform JsonSceneReader::read_rotation(const Json& value, const std::string& pointer) const {
  CheckedObject rotation(report_, value, pointer);
  float degrees = rotation.number("angle");
  Vec3 axis = rotation.direction("axis");
  rotation.finish();
  return Transform::rotate(degrees, axis);
}

Transform JsonSceneReader::read_scale(const Json& value, const std::string& pointer) const {
  Vec3 factors = value.is_number() ? Vec3(read_float(report_, value, pointer)) : read_vec3(report_, value, pointer);
  if (factors.x == 0 || factors.y == 0 || factors.z == 0)
    report_.fail(pointer, "scale factors must be non-zero, got [{}, {}, {}]", factors.x, factors.y, factors.z);
  return Transform::scale(factors);
}

Transform JsonSceneReader::read_matrix(const Json& value, const std::string& pointer) const {
  // Normals, bounds and instancing assume affine maps: read_node_matrix refuses a projective bottom row.
  std::optional<Transform> transform = Transform::from_matrix(read_node_matrix(value, pointer));
  if (!transform) report_.fail(pointer, "the matrix is singular (not invertible)");
  return *transform;
}

}  // namespace candela::json
