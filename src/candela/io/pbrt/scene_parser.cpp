#include "candela/io/pbrt/scene_parser.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "candela/io/gzip.h"

namespace candela::pbrt {

namespace {

// A SceneError from an included file that already names where the file was included.
struct IncludedFileError : SceneError {
  using SceneError::SceneError;
};

constexpr int kMaxIncludeDepth = 64;
// Files read in all: 30 levels of files that each include the next twice would read 2^30 files.
constexpr int kMaxFilesRead = 100000;

std::string read_file_text(const fs::path& file, const SourceLocation& where) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw_scene_error(where, "cannot open \"{}\"", file.string());
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw_scene_error(where, "cannot read \"{}\"", file.string());
  std::string bytes = std::move(text).str();
  // pbrt-v4 reads gzipped scene files ("geometry.pbrt.gz") as their text.
  if (!is_gzip(bytes)) return bytes;
  try {
    return gunzip(bytes);
  } catch (const FileContentError& problem) {
    throw_scene_error(where, "cannot read \"{}\": {}", file.string(), problem.what());
  }
}

}  // namespace

const std::unordered_map<std::string_view, SceneParser::Handler>& SceneParser::handlers() {
  static const std::unordered_map<std::string_view, Handler> table = {
      {"Identity", &SceneParser::identity},
      {"Translate", &SceneParser::translate},
      {"Scale", &SceneParser::scale},
      {"Rotate", &SceneParser::rotate},
      {"LookAt", &SceneParser::look_at},
      {"Transform", &SceneParser::transform},
      {"ConcatTransform", &SceneParser::concat_transform},
      {"CoordinateSystem", &SceneParser::coordinate_system},
      {"CoordSysTransform", &SceneParser::coord_sys_transform},
      {"AttributeBegin", &SceneParser::attribute_begin},
      {"AttributeEnd", &SceneParser::attribute_end},
      {"TransformBegin", &SceneParser::attribute_begin},  // deprecated; pbrt-v4 treats it as AttributeBegin
      {"TransformEnd", &SceneParser::attribute_end},
      {"Attribute", &SceneParser::attribute},
      {"ReverseOrientation", &SceneParser::reverse_orientation},
      {"Camera", &SceneParser::camera},
      {"Film", &SceneParser::film},
      {"Sampler", &SceneParser::sampler},
      {"Integrator", &SceneParser::integrator},
      {"PixelFilter", &SceneParser::pixel_filter},
      {"Accelerator", &SceneParser::accelerator},
      {"Option", &SceneParser::option},
      {"ColorSpace", &SceneParser::color_space},
      {"WorldBegin", &SceneParser::world_begin},
      {"Texture", &SceneParser::texture},
      {"Material", &SceneParser::material},
      {"MakeNamedMaterial", &SceneParser::make_named_material},
      {"NamedMaterial", &SceneParser::named_material},
      {"LightSource", &SceneParser::light_source},
      {"AreaLightSource", &SceneParser::area_light_source},
      {"Shape", &SceneParser::shape},
      {"ObjectBegin", &SceneParser::object_begin},
      {"ObjectEnd", &SceneParser::object_end},
      {"ObjectInstance", &SceneParser::object_instance},
      {"MakeNamedMedium", &SceneParser::make_named_medium},
      {"MediumInterface", &SceneParser::medium_interface},
      {"Include", &SceneParser::include},
      {"Import", &SceneParser::import},
      {"ActiveTransform", &SceneParser::active_transform},
      {"TransformTimes", &SceneParser::transform_times},
      {"WorldEnd", &SceneParser::world_end},
  };
  return table;
}

void SceneParser::ignore_param(ParamList& params, std::string_view name, std::string_view why) {
  bool own = params.has_own(name);
  const Param* p = params.take_any(name);
  if (p && own) warn(p->where, "{}: \"{}\" is ignored: {}", params.owner(), name, why);
}

// ---------------------------------------------------------------- files

SceneDesc SceneParser::parse(const fs::path& file) {
  start(file.string(), file.parent_path());
  return finish(parse_file(file, nullptr));
}

SceneDesc SceneParser::parse(std::string text, const std::string& name, const fs::path& base_dir) {
  start(name, base_dir);
  Tokenizer tokens(std::move(text), name);
  return finish(parse_tokens(tokens, base_dir, fs::path(), nullptr));
}

// pbrt-v4's defaults for a scene that leaves out a directive (the rendering options' are
// RenderDirectives').
void SceneParser::start(const std::string& source, const fs::path& top_directory) {
  scene_.source_file = source;
  scene_.camera.fov_degrees = 90;
  scene_.camera.fov_axis = FovAxis::Smaller;
  scene_.film.width = 1280;
  scene_.film.height = 720;
  top_directory_ = top_directory;
}

SceneDesc SceneParser::finish(const SourceLocation& end) {
  check_end_of_scene(end);
  check_media_defined();
  write_render_settings(scene_.settings);
  return std::move(scene_);
}

// Reads one file's directives with the current state; returns where the file ended.
SourceLocation SceneParser::parse_file(const fs::path& file, const SourceLocation* included_from) {
  SourceLocation blame = included_from ? *included_from : location(file.string(), 0, 0);
  if (!included_from && !fs::is_regular_file(file)) throw_scene_error(blame, "no such scene file");
  if (open_files_.size() >= kMaxIncludeDepth)
    throw_scene_error(blame, "files are included more than {} deep", kMaxIncludeDepth);
  if (++files_read_ > kMaxFilesRead)
    throw_scene_error(blame, "more than {} files are included in all (a file included many times over?)",
                      kMaxFilesRead);
  std::error_code error;
  fs::path canonical = fs::weakly_canonical(file, error);
  if (error) canonical = fs::absolute(file).lexically_normal();
  if (std::find(open_files_.begin(), open_files_.end(), canonical) != open_files_.end())
    throw_scene_error(blame, "\"{}\" includes itself (directly or through other files)", file.string());

  Tokenizer tokens(read_file_text(file, blame), file.string());
  return parse_tokens(tokens, file.parent_path(), canonical, included_from);
}

// Reads the directives of `tokens` (the text of `canonical_file`, if it is a file) with the current
// state; returns where the text ended.
SourceLocation SceneParser::parse_tokens(Tokenizer& tokens, const fs::path& directory, const fs::path& canonical_file,
                                         const SourceLocation* included_from) {
  Tokenizer* outer = std::exchange(tokens_, &tokens);
  fs::path outer_directory = std::exchange(directory_, directory);
  open_files_.push_back(canonical_file);
  if (included_from) include_places_.push_back(*included_from);
  auto restore = [&] {
    tokens_ = outer;
    directory_ = std::move(outer_directory);
    open_files_.pop_back();
    if (included_from) include_places_.pop_back();
  };
  try {
    parse_directives();
  } catch (const IncludedFileError&) {
    restore();
    throw;  // already says where its file was included from
  } catch (const SceneError& error) {
    if (!included_from) {
      restore();
      throw;
    }
    // Errors inside an included file name that file; add where it was included from, and so on out.
    IncludedFileError with_places(fmt::format("{} {}", error.what(), describe_include_places()));
    restore();
    throw with_places;
  }
  SourceLocation end = at(tokens.peek());
  restore();
  return end;
}

// "(in the file included at b.pbrt:1:9, included at main.pbrt:2:9)", from the innermost include
// out; a chain of more than kShown shows its two innermost places and the top-level file's.
std::string SceneParser::describe_include_places() const {
  constexpr size_t kShown = 4;
  std::string text = "(in the file included at ";
  const size_t count = include_places_.size();
  for (size_t k = 0; k < count; ++k) {
    const bool elided = count > kShown && k >= 2 && k + 1 < count;
    if (elided && k == 2) text += fmt::format(", ... {} more Includes ...", count - 3);
    if (elided) continue;
    text += (k == 0 ? "" : ", included at ") + include_places_[count - 1 - k].to_string();
  }
  return text + ")";
}

void SceneParser::parse_directives() {
  while (true) {
    Token directive = tokens_->next();
    if (directive.kind == TokenKind::End) return;
    if (directive.kind != TokenKind::Word)
      throw_scene_error(at(directive), "expected a directive (such as Shape or AttributeBegin), got {}",
                        describe(directive));
    auto handler = handlers().find(directive.text);
    if (handler == handlers().end()) throw_scene_error(at(directive), "unknown directive \"{}\"", directive.text);
    (this->*handler->second)(directive);
  }
}

// Relative names are looked up beside the file that names them, then (as pbrt-v4 does for every
// relative name) beside the top-level scene file.
fs::path SceneParser::resolve_path(const std::string& name, const SourceLocation& where, std::string_view what) const {
  if (name.empty()) throw_scene_error(where, "{}: the file name is empty", what);
  fs::path path(name);
  if (path.is_absolute()) {
    if (!fs::is_regular_file(path)) throw_scene_error(where, "{}: cannot find \"{}\"", what, name);
    return path;
  }
  fs::path beside_this = directory_ / path;
  if (fs::is_regular_file(beside_this)) return beside_this;
  fs::path beside_top = top_directory_ / path;
  if (beside_top != beside_this && fs::is_regular_file(beside_top)) return beside_top;
  if (beside_top != beside_this)
    throw_scene_error(where, "{}: cannot find \"{}\" (looked for \"{}\" and \"{}\")", what, name,
                      beside_this.string(), beside_top.string());
  throw_scene_error(where, "{}: cannot find \"{}\" (looked for \"{}\")", what, name, beside_this.string());
}

void SceneParser::check_end_of_scene(const SourceLocation& end) const {
  if (section_ != Section::World)
    throw_scene_error(end, "the scene ends before WorldBegin; the shapes and lights must follow a WorldBegin");
  if (!blocks_.empty()) {
    const OpenBlock& block = blocks_.back();
    throw_scene_error(block.where, "{} is never closed by {} before the end of the scene", block.opener,
                      block.kind == BlockKind::Object ? "ObjectEnd" : "AttributeEnd");
  }
}

// ---------------------------------------------------------------- reading arguments

Token SceneParser::expect_string(const Token& directive, std::string_view what) {
  Token token = tokens_->next();
  if (token.kind != TokenKind::String)
    throw_scene_error(at(token), "{}: expected {} as a quoted string, got {}", directive.text, what, describe(token));
  return token;
}

double SceneParser::expect_number(const Token& directive, int index, int count) {
  Token token = tokens_->next();
  std::optional<double> value = token.kind == TokenKind::Word ? parse_number(token.text) : std::nullopt;
  if (!value)
    throw_scene_error(at(token), "{}: expected {} numbers, got {} as number {}", directive.text, count,
                      describe(token), index + 1);
  return *value;
}

Vec3 SceneParser::read_vec3(const Token& directive, int first_index, int count) {
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = static_cast<float>(expect_number(directive, first_index + i, count));
  return v;
}

// pbrt writes matrices column by column (the translation is in elements 13 to 15).
Matrix4 SceneParser::read_bracketed_matrix(const Token& directive) {
  Token open = tokens_->next();
  if (open.kind != TokenKind::OpenBracket)
    throw_scene_error(at(open), "{}: expected \"[\" and 16 numbers, got {}", directive.text, describe(open));
  Matrix4 m;
  for (int i = 0; i < 16; ++i) m.m[i % 4][i / 4] = expect_number(directive, i, 16);
  Token close = tokens_->next();
  if (close.kind != TokenKind::CloseBracket)
    throw_scene_error(at(close), "{}: expected \"]\" after 16 numbers, got {}", directive.text, describe(close));
  return m;
}

// `target` names the Attribute defaults that apply to this directive.
ParamList SceneParser::read_params(const Token& directive, std::string owner, AttributeTarget target) {
  std::vector<Param> params = read_parameter_list(*tokens_, owner);
  std::vector<Param> defaults;
  if (target < kAttributeTargets) defaults = state_.attributes[target];
  return ParamList(std::move(owner), at(directive), std::move(params), std::move(defaults));
}

// ---------------------------------------------------------------- state checks

void SceneParser::require_world(const Token& directive) const {
  if (section_ != Section::World)
    throw_scene_error(at(directive), "{} is not allowed before WorldBegin (it belongs in the world section)",
                      directive.text);
}

void SceneParser::require_options(const Token& directive) const {
  if (section_ == Section::World)
    throw_scene_error(at(directive),
                      "{} is not allowed after WorldBegin (at {}); rendering options come before WorldBegin",
                      directive.text, world_begin_.to_string());
}

void SceneParser::push_block(const Token& directive, BlockKind kind) {
  blocks_.push_back({kind, directive.text, at(directive), state_});
}

void SceneParser::pop_block(const Token& directive, BlockKind kind) {
  std::string_view opener = kind == BlockKind::Object ? "ObjectBegin" : "AttributeBegin";
  if (blocks_.size() <= block_floor_) {
    if (block_floor_ > 0)
      throw_scene_error(at(directive), "{} without a matching {} in this imported file", directive.text, opener);
    throw_scene_error(at(directive), "{} without a matching {}", directive.text, opener);
  }
  const OpenBlock& open = blocks_.back();
  if (open.kind != kind)
    throw_scene_error(at(directive), "{} does not match the open {} at {}", directive.text, open.opener,
                      open.where.to_string());
  state_ = open.saved;
  blocks_.pop_back();
}

// ---------------------------------------------------------------- transform directives

void SceneParser::scale(const Token& d) {
  Vec3 s = read_vec3(d);
  if (s.x == 0 || s.y == 0 || s.z == 0)
    throw_scene_error(at(d), "Scale: the factors must be non-zero, got {} {} {}", s.x, s.y, s.z);
  post_multiply_ctm(Transform::scale(s));
}

void SceneParser::rotate(const Token& d) {
  float degrees = static_cast<float>(expect_number(d, 0, 4));
  Vec3 axis = read_vec3(d, 1, 4);
  if (axis == Vec3(0.0f)) throw_scene_error(at(d), "Rotate: the rotation axis must not be zero");
  post_multiply_ctm(Transform::rotate(degrees, axis));
}

void SceneParser::look_at(const Token& d) {
  Point3 eye = read_vec3(d, 0, 9);
  Point3 target = read_vec3(d, 3, 9);
  Vec3 up = read_vec3(d, 6, 9);
  if (eye == target) throw_scene_error(at(d), "LookAt: the eye and the look-at point are the same");
  float sine = up == Vec3(0.0f) ? 0.0f : length(cross(normalize(up), normalize(target - eye)));
  if (!(sine >= 1e-6f))
    throw_scene_error(at(d), "LookAt: the up vector is zero or parallel to the viewing direction");
  post_multiply_ctm(Transform::look_at_pbrt(eye, target, up));
}

void SceneParser::transform(const Token& d) {
  std::optional<Transform> t = Transform::from_matrix(read_bracketed_matrix(d));
  if (!t) throw_scene_error(at(d), "Transform: the matrix is singular (it has no inverse)");
  update_active_ctms([&](const Transform&) { return *t; });
}

void SceneParser::concat_transform(const Token& d) {
  std::optional<Transform> t = Transform::from_matrix(read_bracketed_matrix(d));
  if (!t) throw_scene_error(at(d), "ConcatTransform: the matrix is singular (it has no inverse)");
  post_multiply_ctm(*t);
}

void SceneParser::coordinate_system(const Token& d) {
  coordinate_systems_[expect_string(d, "a name").text] = state_.ctm;
}

void SceneParser::coord_sys_transform(const Token& d) {
  Token name = expect_string(d, "a coordinate system name");
  auto system = coordinate_systems_.find(name.text);
  if (system == coordinate_systems_.end())
    throw_scene_error(at(name),
                      "CoordSysTransform: no coordinate system named \"{}\" (\"camera\" exists after Camera, "
                      "\"world\" after WorldBegin, others after CoordinateSystem)",
                      name.text);
  state_.ctm = system->second;
}

void SceneParser::active_transform(const Token& d) {
  Token which = tokens_->next();
  bool is_word = which.kind == TokenKind::Word;
  if (is_word && which.text == "StartTime")
    state_.active_transforms = kStartTransform;
  else if (is_word && which.text == "EndTime")
    state_.active_transforms = kEndTransform;
  else if (is_word && which.text == "All")
    state_.active_transforms = kAllTransforms;
  else
    throw_scene_error(at(which), "{}: expected StartTime, EndTime or All, got {}", d.text, describe(which));
}

void SceneParser::transform_times(const Token& d) {
  require_options(d);
  double start = expect_number(d, 0, 2), end = expect_number(d, 1, 2);
  // Shapes are interpolated between the two times, so they must span an interval.
  if (!(start < end))
    throw_scene_error(at(d), "TransformTimes: the start time must be less than the end time, got {} and {}", start,
                      end);
  scene_.transform_start_time = static_cast<float>(start);
  scene_.transform_end_time = static_cast<float>(end);
}

// ---------------------------------------------------------------- attribute blocks

void SceneParser::attribute_begin(const Token& d) {
  require_world(d);
  push_block(d, BlockKind::Attribute);
}

void SceneParser::attribute_end(const Token& d) {
  require_world(d);
  pop_block(d, BlockKind::Attribute);
}

// Attribute "target" params: defaults for the parameters of every following directive of that kind
// in this attribute block (pbrt-v4).
void SceneParser::attribute(const Token& d) {
  require_world(d);
  Token target =
      expect_string(d, "the attribute target (\"shape\", \"light\", \"material\", \"medium\" or \"texture\")");
  AttributeTarget index = kAttributeTargets;
  if (target.text == "shape") index = kShapeAttributes;
  if (target.text == "light") index = kLightAttributes;
  if (target.text == "material") index = kMaterialAttributes;
  if (target.text == "medium") index = kMediumAttributes;
  if (target.text == "texture") index = kTextureAttributes;
  if (index == kAttributeTargets)
    throw_scene_error(at(target), "Attribute: unknown target \"{}\" (expected \"shape\", \"light\", \"material\", "
                      "\"medium\" or \"texture\")", target.text);
  std::vector<Param> params = read_parameter_list(*tokens_, fmt::format("Attribute \"{}\"", target.text));
  std::vector<Param>& defaults = state_.attributes[index];
  for (Param& param : params) {
    auto same = std::find_if(defaults.begin(), defaults.end(), [&](const Param& p) { return p.name == param.name; });
    if (same != defaults.end())
      *same = std::move(param);
    else
      defaults.push_back(std::move(param));
  }
}

void SceneParser::reverse_orientation(const Token& d) {
  require_world(d);
  state_.reverse_orientation = !state_.reverse_orientation;
}

void SceneParser::crop_film(const std::array<int, 4>& bounds) {
  const auto [x0, x1, y0, y1] = bounds;
  const int width = scene_.film.width, height = scene_.film.height;
  if (x0 == 0 && y0 == 0 && x1 == width && y1 == height) return;  // the whole image
  // The full image's screen window (pbrt-v4's default frames the smaller axis by [-1, 1]), of which the
  // part over the crop's pixels becomes the camera's; screen y points up, pixel rows down.
  CameraDesc& camera = scene_.camera;
  if (camera.projection == Projection::Equirectangular || camera.projection == Projection::EqualArea) {
    // A spherical camera's window is the part of the full image's (u, v) the film covers.
    camera.screen_window = std::array<float, 4>{float(x0) / float(width), float(x1) / float(width),
                                                float(y0) / float(height), float(y1) / float(height)};
  } else {
    const float aspect = float(width) / float(height);
    const std::array<float, 4> full = camera.screen_window.value_or(
        aspect > 1 ? std::array<float, 4>{-aspect, aspect, -1, 1}
                   : std::array<float, 4>{-1, 1, -1 / aspect, 1 / aspect});
    auto screen_x = [&](int px) { return full[0] + (full[1] - full[0]) * float(px) / float(width); };
    auto screen_y = [&](int py) { return full[3] - (full[3] - full[2]) * float(py) / float(height); };
    camera.screen_window = std::array<float, 4>{screen_x(x0), screen_x(x1), screen_y(y1), screen_y(y0)};
  }
  scene_.film.crop = FilmDesc::Crop{x0, y0, width, height};
  scene_.film.width = x1 - x0;
  scene_.film.height = y1 - y0;
}

void SceneParser::world_begin(const Token& d) {
  require_options(d);
  section_ = Section::World;
  // pbrt-v4 frames an orthographic camera's screen by the film's aspect ratio (now known): the
  // smaller axis spans [-1, 1].
  CameraDesc& camera = scene_.camera;
  if (camera.projection == Projection::Orthographic && !camera.screen_window) {
    const float aspect = float(scene_.film.width) / float(scene_.film.height);
    camera.screen_window = aspect > 1 ? std::array<float, 4>{-aspect, aspect, -1, 1}
                                      : std::array<float, 4>{-1, 1, -1 / aspect, 1 / aspect};
  }
  if (pixel_bounds_) crop_film(*pixel_bounds_);
  // pbrt-v4's imaging ratio: the exposure time (the shutter interval) times ISO / 100.
  scene_.film.sensor.exposure = (camera.shutter_close - camera.shutter_open) * film_iso_ / 100;
  world_begin_ = at(d);
  state_.ctm = {};
  state_.active_transforms = kAllTransforms;
  coordinate_systems_["world"] = {};
}

// ---------------------------------------------------------------- other files

void SceneParser::include(const Token& d) {
  Token name = expect_string(d, "a file name");
  SourceLocation where = at(name);
  parse_file(resolve_path(name.text, where, "Include"), &where);
}

// Like Include, but (as in pbrt-v4) only in the world section, and changes to the graphics state
// inside the imported file do not leak out of it.
void SceneParser::import(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "a file name");
  SourceLocation where = at(name);
  fs::path file = resolve_path(name.text, where, "Import");
  GraphicsState saved = state_;
  size_t outer_floor = std::exchange(block_floor_, blocks_.size());
  parse_file(file, &where);
  if (blocks_.size() > block_floor_) {
    const OpenBlock& block = blocks_.back();
    throw_scene_error(block.where, "{} is never closed before the end of the imported file", block.opener);
  }
  block_floor_ = outer_floor;
  state_ = saved;
}

void SceneParser::world_end(const Token& d) {
  throw_scene_error(at(d),
                    "WorldEnd is pbrt-v3 syntax; pbrt-v4 files simply end (\"pbrt --upgrade\" converts old files)");
}

}  // namespace candela::pbrt
