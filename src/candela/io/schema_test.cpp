// The material, light and texture schemas (description/materials.h, lights.h, textures.h) walked field by field through every front end
// generated from them: the JSON writer and reader (so `candela convert`), the editable scene
// parameters (scene/parameters.h), and the "did you mean" messages. A field added to a schema is
// checked here with no other edit.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "candela/base/error.h"
#include "candela/base/nearest_name.h"
#include "candela/description/scene_desc.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/scene/parameters.h"

namespace candela {
namespace {

// A value for the field that differs from the type's default and keeps every cross-field rule
// (Phong's d + s + t <= 1, diffuse transmission's reflectance + transmittance <= 1): materials 0
// and 1 and texture 0 exist in the test scene.
void set_probe(const Field& f, void* object) {
  const RGB color(0.125f, 0.25f, 0.375f);
  const float number = 0.25f;
  switch (f.kind) {
    case FieldKind::Color: field_value<ColorInput>(f, object) = color; break;
    case FieldKind::OptionalColor: field_value<std::optional<ColorInput>>(f, object) = ColorInput(color); break;
    case FieldKind::Float: field_value<FloatInput>(f, object) = number; break;
    case FieldKind::Number: field_value<float>(f, object) = number; break;
    case FieldKind::NumberIfGiven:
      // Above z_min where a rule wants a range (a partial sphere's z_min < z_max).
      field_value<float>(f, object) = f.key == "z_max" ? 2 * number : number;
      field_second<bool>(f, object) = true;
      break;
    case FieldKind::Flag: field_value<bool>(f, object) = !field_value<bool>(f, object); break;
    case FieldKind::Roughness:
      field_value<Roughness>(f, object) =
          Roughness{.u = number, .v = number, .remap = true, .distribution = MicrofacetDistribution::Beckmann};
      break;
    case FieldKind::Material: field_value<int>(f, object) = 1; break;
    case FieldKind::MaterialPair:
      field_value<int>(f, object) = 1;
      field_second<int>(f, object) = 0;
      break;
    case FieldKind::Texture: field_value<int>(f, object) = 0; break;
    case FieldKind::Rgb: field_value<RGB>(f, object) = color; break;
    // Apart where a rule wants two points apart (a box's min < max, a cylinder's axis).
    case FieldKind::Point:
      field_value<Point3>(f, object) = f.key == "max" || f.key == "p1" ? Point3(2, 3, 4) : Point3(1, 2, 3);
      break;
    case FieldKind::Direction: field_value<Vec3>(f, object) = Vec3(1, 0, 0); break;
    case FieldKind::Vector: field_value<Vec3>(f, object) = f.key == "edge_v" ? Vec3(0, 0, 3) : Vec3(2, 0, 0); break;
    case FieldKind::Transform: field_value<Transform>(f, object) = Transform::rotate(90, {1, 0, 0}); break;
    case FieldKind::Enum: {
      // The last of its names (each enum's first is its default).
      const std::string names = f.names->list();
      ASSERT_TRUE(f.names->set_by_name(f.member(object), names.substr(names.rfind(' ') + 1))) << names;
      break;
    }
    case FieldKind::File: field_value<std::string>(f, object) = std::string(CANDELA_SOURCE_DIR) + "/tests/data/textures/sky.hdr"; break;
    case FieldKind::Text: field_value<std::string>(f, object) = "probe"; break;
    case FieldKind::UvMapping: field_value<UVMapping>(f, object) = UVMapping{.su = 2, .sv = 4, .du = 0.5f, .dv = 0.25f}; break;
    case FieldKind::Integer: field_value<int>(f, object) = 2; break;
    case FieldKind::ScalarVolume: field_value<VolumeDesc>(f, object).constant = RGB(number); break;
    case FieldKind::ColorVolume: field_value<VolumeDesc>(f, object).constant = color; break;
    case FieldKind::OptionalScalarVolume: field_value<std::optional<VolumeDesc>>(f, object).emplace().constant = RGB(number); break;
  }
}

bool same_volume(const VolumeDesc& x, const VolumeDesc& y) {
  return x.constant == y.constant && x.is_constant() == y.is_constant() && (x.is_constant() || *x.values == *y.values);
}

// Whether the field holds the same value in a and b; `what` says what differs.
bool same_field(const Field& f, const void* a, const void* b, std::string& what) {
  auto same_input = [](const auto& x, const auto& y) { return x.texture == y.texture && x.value == y.value; };
  bool same = true;
  switch (f.kind) {
    case FieldKind::Color: same = same_input(field_value<ColorInput>(f, a), field_value<ColorInput>(f, b)); break;
    case FieldKind::OptionalColor: {
      const auto &x = field_value<std::optional<ColorInput>>(f, a), &y = field_value<std::optional<ColorInput>>(f, b);
      same = bool(x) == bool(y) && (!x || same_input(*x, *y));
      break;
    }
    case FieldKind::Float: same = same_input(field_value<FloatInput>(f, a), field_value<FloatInput>(f, b)); break;
    case FieldKind::Number: same = field_value<float>(f, a) == field_value<float>(f, b); break;
    case FieldKind::NumberIfGiven:
      same = field_value<float>(f, a) == field_value<float>(f, b) && field_second<bool>(f, a) == field_second<bool>(f, b);
      break;
    case FieldKind::Flag: same = field_value<bool>(f, a) == field_value<bool>(f, b); break;
    case FieldKind::Roughness: {
      const Roughness &x = field_value<Roughness>(f, a), &y = field_value<Roughness>(f, b);
      same = same_input(x.u, y.u) && same_input(x.v, y.v) && x.remap == y.remap && x.distribution == y.distribution;
      break;
    }
    case FieldKind::Material:
    case FieldKind::Texture: same = field_value<int>(f, a) == field_value<int>(f, b); break;
    case FieldKind::MaterialPair:
      same = field_value<int>(f, a) == field_value<int>(f, b) && field_second<int>(f, a) == field_second<int>(f, b);
      break;
    case FieldKind::Rgb: same = field_value<RGB>(f, a) == field_value<RGB>(f, b); break;
    case FieldKind::Point:
    case FieldKind::Direction:
    case FieldKind::Vector: same = field_value<Vec3>(f, a) == field_value<Vec3>(f, b); break;
    case FieldKind::Transform:
      same = field_value<Transform>(f, a).matrix().m == field_value<Transform>(f, b).matrix().m;
      break;
    case FieldKind::Enum: same = f.names->name_of(f.member(const_cast<void*>(a))) == f.names->name_of(f.member(const_cast<void*>(b))); break;
    case FieldKind::File:
    case FieldKind::Text: same = field_value<std::string>(f, a) == field_value<std::string>(f, b); break;
    case FieldKind::Integer: same = field_value<int>(f, a) == field_value<int>(f, b); break;
    case FieldKind::ScalarVolume:
    case FieldKind::ColorVolume: same = same_volume(field_value<VolumeDesc>(f, a), field_value<VolumeDesc>(f, b)); break;
    case FieldKind::OptionalScalarVolume: {
      const auto &x = field_value<std::optional<VolumeDesc>>(f, a), &y = field_value<std::optional<VolumeDesc>>(f, b);
      same = bool(x) == bool(y) && (!x || same_volume(*x, *y));
      break;
    }
    case FieldKind::UvMapping: {
      const UVMapping &x = field_value<UVMapping>(f, a), &y = field_value<UVMapping>(f, b);
      same = x.su == y.su && x.sv == y.sv && x.du == y.du && x.dv == y.dv && x.s_from_v == y.s_from_v &&
             x.t_from_u == y.t_from_u;
      break;
    }
  }
  if (!same) what = std::string(f.key);
  return same;
}

SceneDesc schema_test_scene() {
  SceneDesc scene = read_json_scene(builtin_scene_json(), "builtin", ".");
  scene.textures.push_back(CheckerboardTexture{});
  return scene;
}

// The scene's entries are a variant of types (MaterialDesc, LightDesc, TextureDesc) or one type
// (MediumDesc).
template <typename T>
constexpr bool kIsVariant = false;
template <typename... Ts>
constexpr bool kIsVariant<std::variant<Ts...>> = true;

template <typename Entry>
void* object_address(Entry& m) {
  if constexpr (kIsVariant<Entry>) return std::visit([](auto& x) -> void* { return &x; }, m);
  else return &m;
}
template <typename Entry>
const TypeSchema& entry_schema(const Entry& m) {
  if constexpr (kIsVariant<Entry>) return schema_of(m);
  else return SchemaOf<Entry>::schema;
}

// Each alternative of a variant, default-constructed (or the one type).
template <typename Entry>
std::vector<Entry> every_type_of() {
  std::vector<Entry> out;
  if constexpr (kIsVariant<Entry>)
    [&]<size_t... I>(std::index_sequence<I...>) {
      (out.emplace_back(std::in_place_index<I>), ...);
    }(std::make_index_sequence<std::variant_size_v<Entry>>());
  else
    out.emplace_back();
  return out;
}
std::vector<MaterialDesc> every_material_type() { return every_type_of<MaterialDesc>(); }

// Within each variant type names are unique, and within each type keys and members are.
template <typename Variant>
void expect_unique_names_and_keys() {
  if constexpr (kIsVariant<Variant>) {
    std::set<std::string_view> names;
    for (std::string_view name : type_names_of<Variant>()) EXPECT_TRUE(names.insert(name).second) << name;
  }
  for (Variant& m : every_type_of<Variant>()) {
    const TypeSchema& schema = entry_schema(m);
    if constexpr (kIsVariant<Variant>) {
      EXPECT_EQ(default_of_type<Variant>(schema.name)->index(), m.index()) << schema.name;
    }
    std::set<std::string_view> keys;
    std::set<void*> members;
    for (const Field& f : schema.fields) {
      EXPECT_TRUE(keys.insert(f.key).second) << schema.name << "." << f.key;
      EXPECT_TRUE(members.insert(f.member(object_address(m))).second) << schema.name << "." << f.key << " shares a member";
    }
  }
}
TEST(MaterialSchema, NamesAndKeysAreUnique) { expect_unique_names_and_keys<MaterialDesc>(); }
TEST(LightSchema, NamesAndKeysAreUnique) { expect_unique_names_and_keys<LightDesc>(); }
TEST(TextureSchema, NamesAndKeysAreUnique) { expect_unique_names_and_keys<TextureDesc>(); }
TEST(MediumSchema, KeysAreUnique) { expect_unique_names_and_keys<MediumDesc>(); }

// Every field of every alternative of the variant the scene keeps in `list` (materials, lights),
// set to a value that is not its default, is written by the JSON writer and read back by the JSON
// reader unchanged.
template <typename Variant>
void expect_every_field_round_trips(std::vector<Variant> SceneDesc::*list) {
  for (Variant& probe : every_type_of<Variant>()) {
    const TypeSchema& schema = entry_schema(probe);
    for (const Field& f : schema.fields) set_probe(f, object_address(probe));
    SceneDesc scene = schema_test_scene();
    (scene.*list).push_back(probe);
    SceneDesc back = read_json_scene(scene_to_json(scene), "round-trip.json", ".");
    ASSERT_EQ((back.*list).size(), (scene.*list).size()) << schema.name;
    Variant& read = (back.*list).back();
    if constexpr (kIsVariant<Variant>) {
      ASSERT_EQ(read.index(), probe.index()) << schema.name;
    }
    for (const Field& f : schema.fields) {
      if (field_ignored(schema, f, object_address(probe))) continue;  // not written
      std::string what;
      EXPECT_TRUE(same_field(f, object_address(probe), object_address(read), what)) << schema.name << "." << what;
    }
  }
}

// Every constant number and colour of every alternative is an editable scene parameter, named
// <section>.<label>.<key> (a transform: <section>.<label>.to_world).
template <typename Variant>
void expect_every_constant_input_editable(std::vector<Variant> SceneDesc::*list, std::string_view section) {
  for (Variant& probe : every_type_of<Variant>()) {
    const TypeSchema& schema = entry_schema(probe);
    for (const Field& f : schema.fields) set_probe(f, object_address(probe));
    SceneDesc scene = schema_test_scene();
    (scene.*list).push_back(probe);
    std::set<std::string> names;
    for (const SceneParameter& p : scene_parameters(scene)) names.insert(p.name);
    const std::string prefix = fmt::format("{}.{}.", section, (scene.*list).size() - 1);
    for (const Field& f : schema.fields) {
      const bool editable = f.kind == FieldKind::Color || f.kind == FieldKind::OptionalColor ||
                            f.kind == FieldKind::Float || f.kind == FieldKind::Number ||
                            f.kind == FieldKind::NumberIfGiven || f.kind == FieldKind::Roughness ||
                            f.kind == FieldKind::Rgb || f.kind == FieldKind::Transform ||
                            f.kind == FieldKind::ColorVolume;
      const std::string name = prefix + (f.kind == FieldKind::Transform ? "to_world" : std::string(f.key));
      EXPECT_EQ(names.count(name), editable ? 1u : 0u) << schema.name << "." << f.key;
    }
  }
}

TEST(MaterialSchema, EveryFieldRoundTripsThroughJson) { expect_every_field_round_trips(&SceneDesc::materials); }
TEST(LightSchema, EveryFieldRoundTripsThroughJson) { expect_every_field_round_trips(&SceneDesc::lights); }
TEST(TextureSchema, EveryFieldRoundTripsThroughJson) { expect_every_field_round_trips(&SceneDesc::textures); }
TEST(MediumSchema, EveryFieldRoundTripsThroughJson) { expect_every_field_round_trips(&SceneDesc::media); }

// A shape of each geometry, every field of its schema set; a mesh and an SDF grid with data inline.
std::vector<ShapeDesc> every_geometry_probe() {
  std::vector<ShapeDesc> shapes;
  for (ShapeGeometry& geometry : every_type_of<ShapeGeometry>()) {
    for (const Field& f : schema_of(geometry).fields) set_probe(f, object_address(geometry));
    if (auto* mesh = std::get_if<MeshShape>(&geometry))
      mesh->mesh = TriangleMesh{.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, .indices = {0, 1, 2}};
    if (auto* grid = std::get_if<SdfGridShape>(&geometry))
      grid->values = std::make_shared<const std::vector<float>>(std::vector<float>{-1, 1, 1, 1, 1, 1, 1, 1});
    if (auto* curve = std::get_if<CurveShape>(&geometry)) {  // one segment, whatever the basis and degree
      for (int i = 0; i <= curve->degree; ++i) curve->points.emplace_back(float(i), float(i % 2), 0);
      if (curve->type == CurveType::Ribbon) curve->normals.assign(2, Normal3(0, 0, 1));
    }
    shapes.push_back(ShapeDesc{.geometry = geometry});
  }
  return shapes;
}

TEST(ShapeSchema, EveryFieldRoundTripsThroughJson) {
  for (const ShapeDesc& probe : every_geometry_probe()) {
    const TypeSchema& schema = schema_of(probe.geometry);
    SceneDesc scene = schema_test_scene();
    scene.shapes.push_back(probe);
    SceneDesc back = read_json_scene(scene_to_json(scene), "round-trip.json", ".");
    ASSERT_EQ(back.shapes.size(), scene.shapes.size()) << schema.name;
    const ShapeGeometry& read = back.shapes.back().geometry;
    ASSERT_EQ(read.index(), probe.geometry.index()) << schema.name;
    for (const Field& f : schema.fields) {
      std::string what;
      EXPECT_TRUE(same_field(f, object_address(const_cast<ShapeGeometry&>(probe.geometry)),
                             object_address(const_cast<ShapeGeometry&>(read)), what))
          << schema.name << "." << what;
    }
  }
}

TEST(ShapeSchema, NamesAndKeysAreUnique) { expect_unique_names_and_keys<ShapeGeometry>(); }

// A shape's numbers (a sphere's radius) are editable parameters, and edits keep the type's rule.
TEST(ShapeSchema, NumbersAreEditableParameters) {
  SceneDesc scene = schema_test_scene();
  for (const ShapeDesc& probe : every_geometry_probe()) scene.shapes.push_back(probe);
  std::set<std::string> names;
  for (const SceneParameter& p : scene_parameters(scene)) names.insert(p.name);
  const size_t first = scene.shapes.size() - every_geometry_probe().size();
  for (size_t i = first; i < scene.shapes.size(); ++i)
    for (const Field& f : schema_of(scene.shapes[i].geometry).fields)
      EXPECT_EQ(names.count(fmt::format("shapes.{}.{}", i, f.key)),
                f.kind == FieldKind::Number || f.kind == FieldKind::NumberIfGiven ? 1u : 0u)  // given in the probe
          << schema_of(scene.shapes[i].geometry).name << "." << f.key;
  const size_t sphere = first + size_t(ShapeGeometry(SphereShape{}).index());
  set_scene_parameter(scene, fmt::format("shapes.{}.radius", sphere), 2.5f);
  EXPECT_EQ(std::get<SphereShape>(scene.shapes[sphere].geometry).radius, 2.5f);
  EXPECT_THROW(set_scene_parameter(scene, fmt::format("shapes.{}.radius", sphere), -1.0f), UsageError);
}

TEST(MaterialSchema, EveryConstantInputIsAnEditableParameter) {
  expect_every_constant_input_editable(&SceneDesc::materials, "materials");
}
TEST(LightSchema, EveryConstantInputIsAnEditableParameter) {
  expect_every_constant_input_editable(&SceneDesc::lights, "lights");
}
TEST(MediumSchema, EveryConstantInputIsAnEditableParameter) {
  expect_every_constant_input_editable(&SceneDesc::media, "media");
}
TEST(TextureSchema, EveryConstantInputIsAnEditableParameter) {
  expect_every_constant_input_editable(&SceneDesc::textures, "textures");
}

TEST(MaterialSchema, ParameterEditsKeepTheCrossFieldRule) {
  SceneDesc scene = schema_test_scene();
  scene.materials.push_back(PhongMaterial{.d = 0.5f, .s = 0.25f, .t = 0});
  const std::string d = fmt::format("materials.{}.d", scene.materials.size() - 1);
  set_scene_parameter(scene, d, 0.75f);
  EXPECT_EQ(std::get<float>(scene_parameter(scene, d)), 0.75f);
  try {
    set_scene_parameter(scene, d, 0.9f);
    FAIL() << "d + s + t > 1 was accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("d + s + t must be <= 1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(std::get<float>(scene_parameter(scene, d)), 0.75f);  // unchanged
  // A reflectance is at most 1: the schema's range.
  const std::string r = "materials.white.reflectance";
  EXPECT_THROW(set_scene_parameter(scene, r, RGB(1.5f)), UsageError);
}

std::string material_json_error(const nlohmann::json& material) {
  nlohmann::json scene = nlohmann::json::parse(builtin_scene_json());
  scene["materials"]["white"] = material;
  try {
    read_json_scene(scene.dump(), "typo.json", ".");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(MaterialSchema, MisspeltNamesGetADidYouMean) {
  EXPECT_NE(material_json_error({{"type", "difuse"}}).find("did you mean \"diffuse\"?"), std::string::npos)
      << material_json_error({{"type", "difuse"}});
  const std::string key = material_json_error({{"type", "diffuse"}, {"reflectanse", 0.5}});
  EXPECT_NE(key.find("/materials/white/reflectanse"), std::string::npos) << key;
  EXPECT_NE(key.find("did you mean \"reflectance\"?"), std::string::npos) << key;
  // Nothing close: no suggestion, the list of keys.
  const std::string far = material_json_error({{"type", "diffuse"}, {"zzzzzzzz", 0.5}});
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  EXPECT_NE(far.find("expected one of: "), std::string::npos) << far;
}

TEST(MaterialSchema, MisspeltParameterNamesGetADidYouMean) {
  SceneDesc scene = schema_test_scene();
  try {
    scene_parameter(scene, "materials.white.reflectanse");
    FAIL() << "a misspelt parameter was found";
  } catch (const UnknownParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'materials.white.reflectance'?"), std::string::npos) << e.what();
  }
}

// docs/scene-format.md names every material, light and texture type and every key of its schema
// (as `name`).
TEST(MaterialSchema, EveryTypeAndKeyIsDocumented) {
  std::ifstream in(std::string(CANDELA_SOURCE_DIR) + "/docs/scene-format.md");
  ASSERT_TRUE(in) << "docs/scene-format.md";
  const std::string docs((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto documented = [&](std::string_view name) {
    return docs.find("`" + std::string(name) + "`") != std::string::npos ||
           docs.find("\"" + std::string(name) + "\"") != std::string::npos;
  };
  for (std::string_view name : type_names_of<MaterialDesc>()) EXPECT_TRUE(documented(name)) << "type " << name;
  for (MaterialDesc& m : every_material_type())
    for (const Field& f : schema_of(m).fields) EXPECT_TRUE(documented(f.key)) << schema_of(m).name << "." << f.key;
  for (std::string_view name : type_names_of<LightDesc>()) EXPECT_TRUE(documented(name)) << "light " << name;
  for (LightDesc& l : every_type_of<LightDesc>())
    for (const Field& f : schema_of(l).fields) EXPECT_TRUE(documented(f.key)) << schema_of(l).name << "." << f.key;
  for (std::string_view name : type_names_of<TextureDesc>()) EXPECT_TRUE(documented(name)) << "texture " << name;
  for (TextureDesc& t : every_type_of<TextureDesc>())
    for (const Field& f : schema_of(t).fields)
      if (f.kind != FieldKind::UvMapping) {  // written as uv_scale, uv_offset or uv_matrix
        EXPECT_TRUE(documented(f.key)) << schema_of(t).name << "." << f.key;
      }
  for (std::string_view key : {"uv_scale", "uv_offset", "uv_matrix", "projection", "projection_transform", "planar_s",
                               "planar_t"})
    EXPECT_TRUE(documented(key)) << key;
  for (const Field& f : SchemaOf<MediumDesc>::schema.fields) EXPECT_TRUE(documented(f.key)) << "medium." << f.key;
  for (std::string_view name : type_names_of<ShapeGeometry>()) EXPECT_TRUE(documented(name)) << "shape " << name;
  for (ShapeGeometry& g : every_type_of<ShapeGeometry>())
    for (const Field& f : schema_of(g).fields) EXPECT_TRUE(documented(f.key)) << schema_of(g).name << "." << f.key;
}

TEST(TextureSchema, MisspeltNamesGetADidYouMean) {
  nlohmann::json scene = nlohmann::json::parse(builtin_scene_json());
  scene["textures"]["checks"] = {{"type", "checkerbord"}};
  try {
    read_json_scene(scene.dump(), "typo.json", ".");
    FAIL() << "a misspelt texture type was read";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean \"checkerboard\"?"), std::string::npos) << e.what();
  }
  scene["textures"]["checks"] = {{"type", "checkerboard"}, {"uv_scal", 2}};
  try {
    read_json_scene(scene.dump(), "typo.json", ".");
    FAIL() << "a misspelt texture key was read";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean \"uv_scale\"?"), std::string::npos) << e.what();
  }
}

TEST(NearestName, FindsLikelyTypos) {
  const std::string_view names[] = {"roughness", "reflectance", "ior", "specular_tint"};
  EXPECT_EQ(nearest_name("rougness", names), "roughness");
  EXPECT_EQ(nearest_name("Reflectance", names), "reflectance");
  EXPECT_EQ(nearest_name("ion", names), "ior");
  EXPECT_EQ(nearest_name("specular_tnit", names), "specular_tint");  // swapped neighbours: one edit
  EXPECT_EQ(nearest_name("colour", names), std::nullopt);
  EXPECT_EQ(nearest_name("", names), std::nullopt);
  EXPECT_EQ(did_you_mean("xyz", names), "");
}

}  // namespace
}  // namespace candela
