// Colours, spectra and textured parameters, and the Texture directive.
#include <algorithm>
#include <cmath>
#include <span>

#include "candela/io/pbrt/scene_parser.h"
#include "candela/io/spectrum_file.h"

namespace candela::pbrt {

using pbrt_spectra::Role;

namespace {

// Checks (wavelength, value) pairs written inline in the scene (a file's were checked as it was read)
// and turns them into RGB for `role`.
RGB sampled_pairs_rgb(std::span<const double> pairs, const Param& p, const ParamList& params, Role role) {
  for (size_t i = 0; i < pairs.size(); i += 2)
    if (pairs[i + 1] < 0)
      throw_scene_error(p.where, "{}: {}: the value at {} nm is negative ({})", params.owner(), p.declaration(),
                        pairs[i], pairs[i + 1]);
  RGB rgb = pbrt_spectra::sampled_spectrum_rgb(pairs, role);
  rgb = rgb.map([](float v) { return std::max(v, 0.0f); });
  if (role == Role::Reflectance) rgb = rgb.map([](float v) { return std::min(v, 1.0f); });
  return rgb;
}

}  // namespace

// As pbrt-v4 does: a string that is not a named spectrum is a file name, looked up as other files are.
const std::vector<double>& SceneParser::spectrum_file_pairs(const Param& p, const ParamList& params) {
  const std::string& name = p.strings[0];
  std::string names;
  for (std::string_view n : pbrt_spectra::named_spectrum_names())
    names += fmt::format("{}\"{}\"", names.empty() ? "" : ", ", n);
  fs::path file = resolve_path(
      name, p.where,
      fmt::format("{}: {}: \"{}\" is neither a named spectrum ({}) nor a spectrum file", params.owner(),
                  p.declaration(), name, names));
  auto cached = spectrum_files_.find(file);
  if (cached == spectrum_files_.end()) cached = spectrum_files_.emplace(file, read_spectrum_file(file)).first;
  return cached->second;
}

RGB SceneParser::spectrum_rgb(const Param& p, const ParamList& params, Role role) {
  if (!p.strings.empty()) {
    params.expect_count(p, 1);
    const std::string& name = p.strings[0];
    std::optional<pbrt_spectra::NamedSpectrum> named = pbrt_spectra::find_named(name);
    if (!named) return sampled_pairs_rgb(spectrum_file_pairs(p, params), p, params, role);
    bool fits = role == Role::Illuminant ? named->kind == pbrt_spectra::NamedKind::Illuminant
                                         : named->kind != pbrt_spectra::NamedKind::Illuminant;
    if (!fits || role == Role::Reflectance)
      throw_scene_error(p.where, "{}: {}: \"{}\" is {} and does not fit here", params.owner(), p.declaration(), name,
                        named->kind == pbrt_spectra::NamedKind::Illuminant ? "an illuminant spectrum"
                        : named->kind == pbrt_spectra::NamedKind::Metal    ? "a conductor's optical constant"
                                                                           : "a glass's refractive index");
    return named->rgb;
  }
  params.expect_multiple(p, 2);
  for (size_t i = 2; i < p.numbers.size(); i += 2)
    if (!(p.numbers[i] > p.numbers[i - 2]))
      throw_scene_error(p.where, "{}: {}: the wavelengths must increase ({} follows {})", params.owner(),
                        p.declaration(), p.numbers[i], p.numbers[i - 2]);
  return sampled_pairs_rgb(p.numbers, p, params, role);
}

// A colour parameter of a material or texture: "rgb", "spectrum" or "texture" (a spectrum texture).
// `is_albedo` limits constant colours to [0, 1], as pbrt-v4 does for reflectances.
std::optional<ColorInput> SceneParser::read_color(ParamList& params, std::string_view name, Role role) {
  const Param* p = params.take(name, {"rgb", "spectrum", "texture"});
  if (!p) return std::nullopt;
  if (p->type == "rgb") return ColorInput(params.checked_rgb(*p, role == Role::Reflectance));
  if (p->type == "spectrum") return ColorInput(spectrum_rgb(*p, params, role));
  params.expect_count(*p, 1);
  auto texture = spectrum_textures_.find(p->strings[0]);
  if (texture == spectrum_textures_.end()) {
    bool is_float = float_textures_.contains(p->strings[0]);
    throw_scene_error(p->where, "{}: {}: no spectrum texture named \"{}\" is defined{}", params.owner(),
                      p->declaration(), p->strings[0],
                      is_float ? " (there is a \"float\" texture of that name; this parameter needs a \"spectrum\" one)"
                               : " (Texture must come first)");
  }
  return texture->second.color;
}

// A float parameter that may be textured: "float" or "texture" (a float texture).
std::optional<FloatInput> SceneParser::read_float_texture(ParamList& params, std::string_view name) {
  const Param* p = params.take(name, {"float", "texture"});
  if (!p) return std::nullopt;
  params.expect_count(*p, 1);
  if (p->type == "float") return FloatInput(static_cast<float>(p->numbers[0]));
  auto texture = float_textures_.find(p->strings[0]);
  if (texture == float_textures_.end()) {
    bool is_spectrum = spectrum_textures_.contains(p->strings[0]);
    throw_scene_error(p->where, "{}: {}: no float texture named \"{}\" is defined{}", params.owner(), p->declaration(),
                      p->strings[0],
                      is_spectrum
                          ? " (there is a \"spectrum\" texture of that name; this parameter needs a \"float\" one)"
                          : " (Texture must come first)");
  }
  return texture->second.value;
}

// A light's emission spectrum: "rgb", "spectrum" (named illuminant or pairs) or "blackbody" (a
// temperature in kelvin). Named and sampled spectra are normalised to luminance 1 as in pbrt-v4;
// RGB values are used as given (pbrt-v4 renders an RGB emission as that RGB).
std::optional<RGB> SceneParser::read_emission(ParamList& params, std::string_view name) {
  const Param* p = params.take(name, {"rgb", "spectrum", "blackbody"});
  if (!p) return std::nullopt;
  if (p->type == "rgb") return params.checked_rgb(*p, false);
  if (p->type == "spectrum") return spectrum_rgb(*p, params, Role::Illuminant);
  if (p->count() != 1)
    throw_scene_error(p->where, "{}: {} takes one value, the temperature in kelvin, got {} (pbrt-v3's second "
                      "\"scale\" value is not pbrt-v4 syntax)", params.owner(), p->declaration(), p->count());
  double kelvin = p->numbers[0];
  if (!(kelvin > 0))
    throw_scene_error(p->where, "{}: {}: the temperature must be positive, got {}", params.owner(), p->declaration(),
                      kelvin);
  return pbrt_spectra::blackbody_rgb(static_cast<float>(kelvin));
}

// A constant spectrum that cannot be textured (a medium's coefficients): "rgb" or "spectrum".
std::optional<RGB> SceneParser::read_spectrum(ParamList& params, std::string_view name, Role role) {
  const Param* p = params.take(name, {"rgb", "spectrum"});
  if (!p) return std::nullopt;
  return p->type == "rgb" ? params.checked_rgb(*p, role == Role::Reflectance) : spectrum_rgb(*p, params, role);
}

// A dielectric's index of refraction: "float", or a "spectrum" (a named glass or pairs) taken at
// 550 nm, since candela does not disperse light.
std::optional<float> SceneParser::read_ior(ParamList& params, std::string_view name) {
  const Param* p = params.take(name, {"float", "spectrum", "rgb"});
  if (!p) return std::nullopt;
  float ior = 0;
  if (p->type == "float") {
    params.expect_count(*p, 1);
    ior = static_cast<float>(p->numbers[0]);
  } else if (p->type == "rgb") {
    RGB rgb = params.checked_rgb(*p, false);
    ior = rgb.g;
    warn(p->where, "{}: {}: candela does not disperse light; the green value {} is the index of refraction",
         params.owner(), p->declaration(), ior);
  } else if (!p->strings.empty()) {
    params.expect_count(*p, 1);
    std::optional<pbrt_spectra::NamedSpectrum> named = pbrt_spectra::find_named(p->strings[0]);
    if (named && named->kind == pbrt_spectra::NamedKind::Glass)
      ior = named->ior_550nm;
    else if (!named)
      ior = pbrt_spectra::sampled_spectrum_at(spectrum_file_pairs(*p, params), 550);
    else
      throw_scene_error(p->where,
                        "{}: {}: \"{}\" is not one of pbrt-v4's glasses (\"glass-BK7\", \"glass-BAF10\", "
                        "\"glass-FK51A\", \"glass-LASF9\", \"glass-F5\", \"glass-F10\", \"glass-F11\")",
                        params.owner(), p->declaration(), p->strings[0]);
  } else {
    spectrum_rgb(*p, params, Role::Unbounded);  // validates the pairs
    ior = pbrt_spectra::sampled_spectrum_at(p->numbers, 550);
  }
  if (!(ior > 0)) throw_scene_error(p->where, "{}: \"{}\" must be positive, got {}", params.owner(), name, ior);
  return ior;
}

// pbrt-v4's microfacet roughness: "roughness" for both axes unless "uroughness"/"vroughness" are
// given; "remaproughness" (true) reads them as roughness and uses alpha = sqrt(roughness). `prefix`
// names one layer of a coated conductor ("interface.", "conductor."); "remaproughness" has none.
Roughness SceneParser::read_roughness(ParamList& params, std::string_view prefix) {
  const std::string p(prefix), both_name = p + "roughness", u_name = p + "uroughness", v_name = p + "vroughness";
  Roughness roughness;
  FloatInput both = read_float_texture(params, both_name).value_or(FloatInput(0.0f));
  roughness.u = read_float_texture(params, u_name).value_or(both);
  roughness.v = read_float_texture(params, v_name).value_or(both);
  roughness.remap = params.get_bool("remaproughness", true);
  for (auto [name, value] : {std::pair{&both_name, both}, std::pair{&u_name, roughness.u},
                             std::pair{&v_name, roughness.v}})
    if (value.is_constant() && value.value < 0) params.fail(*name, "must not be negative, got {}", value.value);
  return roughness;
}

int SceneParser::add_texture(TextureDesc texture, const SourceLocation& where) {
  scene_.textures.push_back(std::move(texture));
  scene_.places.textures.push_back(where);
  return static_cast<int>(scene_.textures.size()) - 1;
}

// ---------------------------------------------------------------- textures

// pbrt-v4's 2D texture mappings: "uv" scales and offsets the surface's (u, v); the others project the
// point in the texture's space (the CTM where the texture is declared maps it to the world) and take
// no scale ("planar" takes offsets).
UVMapping SceneParser::read_uv_mapping(ParamList& params) {
  std::string mapping = params.get_string("mapping", "uv");
  UVMapping uv;
  if (mapping == "uv") {
    uv.su = params.get_float("uscale", 1);
    uv.sv = params.get_float("vscale", 1);
  } else if (mapping == "spherical" || mapping == "cylindrical" || mapping == "planar") {
    uv.projection = *enum_from_name<TextureProjection>(mapping);
    uv.to_world = state_.ctm.start;
  } else {
    params.fail("mapping", "must be \"uv\", \"spherical\", \"cylindrical\" or \"planar\", got \"{}\"", mapping);
  }
  if (mapping == "planar") {
    uv.planar_s = params.get_vector3("v1", Vec3(1, 0, 0));
    uv.planar_t = params.get_vector3("v2", Vec3(0, 1, 0));
  }
  if (mapping == "uv" || mapping == "planar") {
    uv.du = params.get_float("udelta", 0);
    uv.dv = params.get_float("vdelta", 0);
  }
  return uv;
}

ImageTexture SceneParser::make_image_texture(ParamList& params) {
  ImageTexture texture;
  if (!params.has("filename")) params.fail("filename", "is required: name the image file");
  std::string name = params.get_string("filename", "");
  fs::path file = resolve_path(name, params.where("filename"), fmt::format("{}: \"filename\"", params.owner()));
  texture.filename = file.string();

  std::string filter = params.get_string("filter", "bilinear");
  if (filter == "point") {
    texture.filter = TextureFilter::Nearest;
  } else if (filter == "trilinear" || filter == "ewa") {
    warn(params.where("filter"),
         "{}: filter \"{}\" is read as \"bilinear\": candela does not mipmap textures (minified textures alias "
         "where pbrt would blur them)",
         params.owner(), filter);
  } else if (filter != "bilinear") {
    params.fail("filter", "must be \"point\", \"bilinear\", \"trilinear\" or \"ewa\", got \"{}\"", filter);
  }
  params.get_float("maxanisotropy", 8);  // only for "ewa"

  std::string wrap = params.get_string("wrap", "repeat");
  if (wrap == "repeat")
    texture.wrap = TextureWrap::Repeat;
  else if (wrap == "black")
    texture.wrap = TextureWrap::Black;
  else if (wrap == "clamp")
    texture.wrap = TextureWrap::Clamp;
  else if (wrap == "octahedralsphere")
    params.fail("wrap", "\"octahedralsphere\" is not supported for image textures (only for environment maps)");
  else
    params.fail("wrap", "must be \"repeat\", \"black\", \"clamp\" or \"octahedralsphere\", got \"{}\"", wrap);

  texture.scale = params.get_float("scale", 1);
  texture.invert = params.get_bool("invert", false);

  // pbrt-v4's "encoding" defaults to "sRGB" for .png files and to "linear" for others, but it reads
  // every 8-bit format other than PNG (.tga, .jpg, ...) through stb_image as sRGB whatever the
  // parameter says: 8-bit files are sRGB, float files linear, which is ColorEncoding::Auto. (Checked
  // on veach-ajar's .tga textures against its pbrt-v4 reference render.) An explicit "encoding" is
  // honoured for every file.
  texture.encoding = ColorEncoding::Auto;
  if (params.has("encoding")) {
    std::string encoding = params.get_string("encoding", "");
    if (encoding == "sRGB") {
      texture.encoding = ColorEncoding::SRGB;
    } else if (encoding == "linear") {
      texture.encoding = ColorEncoding::Linear;
    } else if (encoding.starts_with("gamma ")) {
      std::optional<double> gamma = parse_number(std::string_view(encoding).substr(6));
      if (!gamma || !(*gamma > 0)) params.fail("encoding", "\"{}\" needs a positive gamma value", encoding);
      if (std::abs(*gamma - 1) < 1e-3) {
        texture.encoding = ColorEncoding::Linear;
      } else if (std::abs(*gamma - 2.2) <= 0.1) {
        texture.encoding = ColorEncoding::SRGB;
        warn(params.where("encoding"), "{}: \"encoding\" \"{}\" is read as sRGB (the closest curve candela has)",
             params.owner(), encoding);
      } else {
        params.fail("encoding", "\"{}\" is not supported (only \"sRGB\", \"linear\" and gammas near 1 or 2.2)",
                    encoding);
      }
    } else {
      params.fail("encoding", "must be \"sRGB\", \"linear\" or \"gamma <value>\", got \"{}\"", encoding);
    }
  }
  texture.mapping = read_uv_mapping(params);
  return texture;
}

// A texture's input: a spectrum texture's "rgb"/"spectrum"/"texture" or a float texture's
// "float"/"texture" (as a grey colour).
ColorInput SceneParser::read_texture_input(ParamList& params, std::string_view name, bool is_float, RGB fallback) {
  if (!is_float) return read_color(params, name, Role::Unbounded).value_or(ColorInput(fallback));
  std::optional<FloatInput> value = read_float_texture(params, name);
  if (!value) return ColorInput(fallback);
  ColorInput color;
  if (value->is_constant())
    color.value = RGB(value->value);
  else
    color.texture = value->texture;
  return color;
}

// A texture's constant colour (bilerp's corners): a spectrum texture's "rgb"/"spectrum", a float
// texture's "float" (as grey). Not a texture: pbrt-v4 reads these as plain values.
RGB SceneParser::read_constant_input(ParamList& params, std::string_view name, bool is_float, RGB fallback) {
  if (is_float) return RGB(params.get_float(name, fallback.average()));
  std::optional<ColorInput> color = read_color(params, name, Role::Unbounded);
  if (!color) return fallback;
  if (!color->is_constant()) params.fail(name, "must be a value, not a texture");
  return color->value;
}

// The octaves of a noise texture: pbrt-v4 sums this many (fewer where a pixel covers the finest).
int SceneParser::read_octaves(ParamList& params) {
  const int octaves = params.get_int("octaves", 8);
  if (octaves < 1 || octaves > 32) params.fail("octaves", "must be in [1, 32], got {}", octaves);
  return octaves;
}

void SceneParser::texture(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the texture name");
  Token kind = expect_string(d, "the texture's value type (\"spectrum\" or \"float\")");
  if (kind.text != "spectrum" && kind.text != "float")
    throw_scene_error(at(kind), "Texture \"{}\": the value type must be \"spectrum\" or \"float\", got \"{}\"",
                      name.text, kind.text);
  bool is_float = kind.text == "float";
  Token type = expect_string(d, "the texture type");
  auto& table = is_float ? float_textures_ : spectrum_textures_;
  if (auto earlier = table.find(name.text); earlier != table.end())
    throw_scene_error(at(name), "Texture: {} texture \"{}\" is already defined at {}", kind.text, name.text,
                      earlier->second.where.to_string());
  ParamList params =
      read_params(d, fmt::format("Texture \"{}\" \"{}\" \"{}\"", name.text, kind.text, type.text), kTextureAttributes);

  NamedTexture named;
  named.where = at(name);
  if (type.text == "imagemap") {
    named.index = add_texture(make_image_texture(params), at(d));
  } else if (type.text == "checkerboard") {
    int dimension = params.get_int("dimension", 2);
    if (dimension != 2 && dimension != 3) params.fail("dimension", "must be 2 or 3, got {}", dimension);
    ColorInput tex1 = read_texture_input(params, "tex1", is_float, RGB(1.0f));
    ColorInput tex2 = read_texture_input(params, "tex2", is_float, RGB(0.0f));
    if (dimension == 3)
      named.index = add_texture(SolidCheckerboardTexture{tex1, tex2, state_.ctm.start}, at(d));
    else
      named.index = add_texture(CheckerboardTexture{tex1, tex2, read_uv_mapping(params)}, at(d));
  } else if (type.text == "bilerp") {
    BilerpTexture bilerp;
    for (auto [key, corner] : {std::pair{"v00", &BilerpTexture::v00}, std::pair{"v01", &BilerpTexture::v01},
                               std::pair{"v10", &BilerpTexture::v10}, std::pair{"v11", &BilerpTexture::v11}})
      bilerp.*corner = read_constant_input(params, key, is_float, bilerp.*corner);
    bilerp.mapping = read_uv_mapping(params);
    named.index = add_texture(bilerp, at(d));
  } else if (type.text == "dots") {
    // pbrt-v4 hands "inside" to the dots' surroundings and "outside" to the dots (its constructor takes
    // them in the other order than its Create passes them); its renders show that, and so does candela.
    DotsTexture dots;
    dots.outside = read_texture_input(params, "inside", is_float, RGB(1.0f));
    dots.inside = read_texture_input(params, "outside", is_float, RGB(0.0f));
    dots.mapping = read_uv_mapping(params);
    named.index = add_texture(dots, at(d));
  } else if (type.text == "fbm" || type.text == "wrinkled") {
    if (!is_float) throw_scene_error(at(type), "Texture \"{}\": \"{}\" is a float texture only", name.text, type.text);
    const int octaves = read_octaves(params);
    const float roughness = params.get_float("roughness", 0.5f);
    if (type.text == "fbm")
      named.index = add_texture(FbmTexture{octaves, roughness, state_.ctm.start}, at(d));
    else
      named.index = add_texture(WrinkledTexture{octaves, roughness, state_.ctm.start}, at(d));
  } else if (type.text == "marble") {
    if (is_float) throw_scene_error(at(type), "Texture \"{}\": \"marble\" is a spectrum texture only", name.text);
    MarbleTexture marble;
    marble.octaves = read_octaves(params);
    marble.roughness = params.get_float("roughness", 0.5f);
    marble.scale = params.get_float("scale", 1);
    marble.variation = params.get_float("variation", 0.2f);
    marble.to_world = state_.ctm.start;
    named.index = add_texture(marble, at(d));
  } else if (type.text == "directionmix") {
    DirectionMixTexture mix;
    mix.tex1 = read_texture_input(params, "tex1", is_float, RGB(0.0f));
    mix.tex2 = read_texture_input(params, "tex2", is_float, RGB(1.0f));
    // Given in the texture's space, as pbrt-v4 reads it.
    const Vec3 direction = state_.ctm.start.vector(params.get_vector3("dir", Vec3(0, 1, 0)));
    if (!(length_squared(direction) > 0) || !is_finite(normalize(direction)))
      params.fail("dir", "must be a non-zero direction");
    mix.direction = normalize(direction);
    named.index = add_texture(mix, at(d));
  } else if (type.text == "scale") {
    ScaleTexture scale;
    scale.tex = read_texture_input(params, "tex", is_float, RGB(1.0f));
    scale.scale = read_float_texture(params, "scale").value_or(FloatInput(1.0f));
    named.index = add_texture(scale, at(d));
  } else if (type.text == "mix") {
    MixTexture mix;
    mix.tex1 = read_texture_input(params, "tex1", is_float, RGB(0.0f));
    mix.tex2 = read_texture_input(params, "tex2", is_float, RGB(1.0f));
    mix.amount = read_float_texture(params, "amount").value_or(FloatInput(0.5f));
    named.index = add_texture(mix, at(d));
  } else if (type.text == "constant") {
    // No texture at all: parameters that name it get its value.
    if (is_float) {
      named.value = FloatInput(params.get_float("value", 1));
      named.color = ColorInput(RGB(named.value.value));
    } else {
      named.color = read_color(params, "value", Role::Unbounded).value_or(ColorInput(RGB(1.0f)));
      named.value = FloatInput(named.color.value.average());
    }
  } else {
    reject_type(at(type), "texture", type.text,
                {"imagemap", "checkerboard", "scale", "mix", "constant", "bilerp", "directionmix", "dots", "fbm",
                 "marble", "wrinkled"},
                {"ptex", "windy"}, "candela has no such texture");
  }
  params.reject_unused();
  if (named.index >= 0) {
    named.color.texture = named.index;
    named.value.texture = named.index;
  }
  table[name.text] = named;
}


}  // namespace candela::pbrt
