// The glTF reader: images (the cache of embedded and derived ones) and textures; materials.
#include "candela/io/gltf/reader.h"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <system_error>

#include "candela/base/error.h"
#include "candela/film/image_io.h"

namespace candela::gltf {

// ---------------------------------------------------------------- images and textures

fs::path GltfReader::cache_file(uint64_t hash, const std::string& extension) {
  std::error_code ec;
  fs::create_directories(cache_dir_, ec);
  if (ec) fail("", "cannot create the image cache directory {}: {}", cache_dir_.string(), ec.message());
  return cache_dir_ / fmt::format("{:016x}{}", hash, extension);
}

// Writes `bytes` to `target` through a temporary name, so that concurrent readers see whole files.
void GltfReader::write_file_atomically(const fs::path& target, std::string_view bytes) {
  fs::path tmp = target;
  tmp += fmt::format(".{}.tmp", getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) fail("", "cannot write {}", tmp.string());
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) fail("", "cannot write {}: {}", target.string(), ec.message());
}

// The file holding image `index`: its own file, or the embedded bytes written to the cache.
std::string GltfReader::image_file(int index, const std::string& user) {
  if (index < 0 || size_t(index) >= model_.images.size()) fail(user, "image {} does not exist", index);
  if (auto found = image_files_.find(index); found != image_files_.end()) return found->second;
  const tg::Image& image = model_.images[size_t(index)];
  const std::string pointer = fmt::format("/images/{}", index);
  std::string result;
  if (!image.uri.empty() && !image.uri.starts_with("data:")) {
    fs::path path = base_dir_ / uri_decode(image.uri);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) fail(pointer, "image file \"{}\" not found", path.string());
    result = path.string();
  } else {
    std::string_view bytes;
    if (image.bufferView >= 0) {
      const std::byte* base = nullptr;
      size_t available = 0;
      view_bytes(image.bufferView, 0, pointer, base, available);
      bytes = std::string_view(reinterpret_cast<const char*>(base), available);
    } else {
      bytes = std::string_view(reinterpret_cast<const char*>(image.image.data()), image.image.size());
    }
    if (bytes.empty()) fail(pointer, "the embedded image is empty");
    std::string ext = image.mimeType == "image/jpeg" ? ".jpg" : image.mimeType == "image/png" ? ".png" : "";
    if (ext.empty()) {
      if (bytes.starts_with("\x89PNG")) ext = ".png";
      else if (bytes.starts_with("\xFF\xD8")) ext = ".jpg";
      else fail(pointer, "embedded image of type \"{}\" is not supported (PNG and JPEG are)", image.mimeType);
    }
    fs::path path = cache_file(fnv1a(bytes), ext);
    std::error_code ec;
    if (!fs::exists(path, ec)) write_file_atomically(path, bytes);
    result = path.string();
  }
  image_files_[index] = result;
  return result;
}

// check_exr_header (an attribute claiming more bytes than the file holds), its error at `pointer`.
void GltfReader::checked_exr_header(const std::string& file, const std::string& pointer) const {
  try {
    check_exr_header(file);
  } catch (const FileContentError& malformed) {
    fail(pointer, "{}", malformed.what());
  }
}

GltfReader::Pixels GltfReader::read_pixels(const std::string& file, const std::string& pointer) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  checked_exr_header(file, pointer);
  auto in = OIIO::ImageInput::open(file, &config);
  if (!in) fail(pointer, "cannot read image {}: {}", file, OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  Pixels px;
  px.width = spec.width;
  px.height = spec.height;
  px.channels = spec.nchannels;
  px.integer = spec.format == OIIO::TypeDesc::UINT8 || spec.format == OIIO::TypeDesc::UINT16;
  if (px.width <= 0 || px.height <= 0 || px.channels <= 0 || px.width > kMaxResolution || px.height > kMaxResolution)
    fail(pointer, "image {} has an unusable size {} x {} x {}", file, px.width, px.height, px.channels);
  px.data.resize(size_t(px.width) * size_t(px.height) * size_t(px.channels));
  if (!in->read_image(0, 0, 0, px.channels, OIIO::TypeDesc::FLOAT, px.data.data()))
    fail(pointer, "cannot read image {}: {}", file, in->geterror());
  return px;
}

int GltfReader::image_channels(const std::string& file, const std::string& pointer) {
  if (auto found = channel_counts_.find(file); found != channel_counts_.end()) return found->second;
  checked_exr_header(file, pointer);
  auto in = OIIO::ImageInput::open(file);
  if (!in) fail(pointer, "cannot read image {}: {}", file, OIIO::geterror());
  int channels = in->spec().nchannels;
  channel_counts_[file] = channels;
  return channels;
}

// The image `source` after `op`, as a half-float EXR (linear) in the cache.
std::string GltfReader::derived_image(const std::string& source, const ImageOp& op, const std::string& pointer) {
  std::error_code ec;
  auto size = fs::file_size(source, ec);
  auto time = fs::last_write_time(source, ec).time_since_epoch().count();
  std::string key = fmt::format("{}|{}|{}|{}", fs::absolute(source, ec).string(), size, time, op.describe());
  fs::path target = cache_file(fnv1a(key), ".exr");
  if (fs::exists(target, ec)) return target.string();
  Pixels px = read_pixels(source, pointer);
  const size_t count = size_t(px.width) * size_t(px.height);
  const int out_channels = op.kind == ImageOp::Multiply || op.kind == ImageOp::NormalScale ? 3 : 1;
  std::vector<float> out(count * size_t(out_channels));
  const int nc = px.channels;
  for (size_t i = 0; i < count; ++i) {
    const float* p = &px.data[i * size_t(nc)];
    auto channel = [&](int c) { return p[std::min(c, nc - 1)]; };
    switch (op.kind) {
      case ImageOp::Channel:
        out[i] = channel(nc >= 3 ? op.channel : 0);  // grey images: their one channel
        break;
      case ImageOp::Alpha: {
        float a = (nc == 4 ? p[3] : nc == 2 ? p[1] : 1.0f) * op.alpha_factor;
        out[i] = op.cutoff >= 0 ? (a >= op.cutoff ? 1.0f : 0.0f) : std::clamp(a, 0.0f, 1.0f);
        break;
      }
      case ImageOp::Multiply:
        for (int c = 0; c < 3; ++c) {
          float v = channel(nc >= 3 ? c : 0);
          out[i * 3 + size_t(c)] = (px.integer ? srgb_to_linear(v) : v) * op.factor[c];
        }
        break;
      case ImageOp::NormalScale: {
        Vec3 v(2 * channel(0) - 1, 2 * channel(1) - 1, 2 * channel(2) - 1);
        v.x *= op.normal_scale;
        v.y *= op.normal_scale;
        float len = length(v);
        if (len > 0) v = v / len;
        for (int c = 0; c < 3; ++c) out[i * 3 + size_t(c)] = 0.5f * (v[c] + 1);
        break;
      }
    }
  }
  fs::path tmp = target;
  tmp += fmt::format(".{}.tmp.exr", getpid());
  auto writer = OIIO::ImageOutput::create(tmp.string());
  OIIO::ImageSpec spec(px.width, px.height, out_channels, OIIO::TypeDesc::HALF);
  if (!writer || !writer->open(tmp.string(), spec) ||
      !writer->write_image(OIIO::TypeDesc::FLOAT, out.data()) || !writer->close())
    fail(pointer, "cannot write the derived image {}: {}", tmp.string(), writer ? writer->geterror() : OIIO::geterror());
  fs::rename(tmp, target, ec);
  if (ec) fail(pointer, "cannot write {}: {}", target.string(), ec.message());
  return target.string();
}

// A glTF texture reference (index, texCoord, extensions) as an ImageTexture; -1 where an Alpha
// op finds no alpha channel. `uv_set` is the material's texture coordinate set so far (-1: none yet).
int GltfReader::add_texture(int index, int tex_coord, const tg::ExtensionMap& extensions, ColorEncoding encoding,
                            std::optional<ImageOp> op, float scale, const std::string& pointer, int& uv_set) {
  if (index < 0 || size_t(index) >= model_.textures.size()) fail(pointer + "/index", "texture {} does not exist", index);
  const tg::Texture& texture = model_.textures[size_t(index)];
  const std::string tpointer = fmt::format("/textures/{}", index);
  if (texture.source < 0) {
    warn(tpointer, "the texture has no source image (or only one in an unsupported extension); it is ignored");
    return -1;
  }
  ImageTexture image;
  std::string file = image_file(texture.source, tpointer + "/source");
  image.encoding = encoding;
  image.scale = scale;
  if (op) {
    if (op->kind == ImageOp::Alpha) {
      int channels = image_channels(file, tpointer);
      if (channels != 2 && channels != 4) return -1;
    }
    file = derived_image(file, *op, tpointer);
    image.encoding = ColorEncoding::Linear;
  }
  image.filename = file;
  if (texture.sampler >= 0) {
    if (size_t(texture.sampler) >= model_.samplers.size()) fail(tpointer + "/sampler", "sampler {} does not exist", texture.sampler);
    const tg::Sampler& s = model_.samplers[size_t(texture.sampler)];
    auto wrap = [](int mode) {
      return mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? TextureWrap::Clamp
             : mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? TextureWrap::Mirror
                                                             : TextureWrap::Repeat;
    };
    image.wrap = wrap(s.wrapS);
    if (s.wrapS != s.wrapT && warned_samplers_.insert(texture.sampler).second)
      warn(fmt::format("/samplers/{}", texture.sampler),
           "different wrap modes in s and t ({} and {}); candela uses wrapS ({}) for both", s.wrapS, s.wrapT, s.wrapS);
    image.filter = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ? TextureFilter::Nearest : TextureFilter::Bilinear;
  }
  if (auto tt = extensions.find("KHR_texture_transform"); tt != extensions.end()) {
    const tg::Value& v = tt->second;
    double ox = 0, oy = 0, sx = 1, sy = 1;
    if (v.Has("offset") && v.Get("offset").ArrayLen() == 2) {
      ox = v.Get("offset").Get(0).GetNumberAsDouble();
      oy = v.Get("offset").Get(1).GetNumberAsDouble();
    }
    if (v.Has("scale") && v.Get("scale").ArrayLen() == 2) {
      sx = v.Get("scale").Get(0).GetNumberAsDouble();
      sy = v.Get("scale").Get(1).GetNumberAsDouble();
    }
    const double rotation = number_or(v, "rotation", 0);
    if (v.Has("texCoord")) tex_coord = v.Get("texCoord").GetNumberAsInt();
    // glTF: uv' = T(offset) R(rotation) S(scale) uv, i.e.
    //   u' = cos sx u + sin sy v + ox,   v' = -sin sx u + cos sy v + oy,
    // with v down the image; candela's t = 1 - v, so with v = 1 - t and t' = 1 - v':
    //   s' = cos sx u - sin sy t + (sin sy + ox),   t' = sin sx u + cos sy t + (1 - cos sy - oy).
    const double c = std::cos(rotation), sn = std::sin(rotation);
    image.mapping.su = float(c * sx);
    image.mapping.s_from_v = float(-sn * sy);
    image.mapping.du = float(sn * sy + ox);
    image.mapping.t_from_u = float(sn * sx);
    image.mapping.sv = float(c * sy);
    image.mapping.dv = float(1 - c * sy - oy);
  }
  if (uv_set < 0) uv_set = tex_coord;
  else if (tex_coord != uv_set)
    warn(pointer, "the texture uses TEXCOORD_{} but the material's first texture uses TEXCOORD_{}; candela meshes "
                  "have one set of texture coordinates, so TEXCOORD_{} is used", tex_coord, uv_set, uv_set);
  scene_.textures.push_back(image);
  scene_.places.textures.push_back(at(pointer));
  return int(scene_.textures.size()) - 1;
}

// ---------------------------------------------------------------- materials

RGB GltfReader::base_color_factor(int m) const {
  if (m < 0) return RGB(1.0f);
  return rgb_of(model_.materials[size_t(m)].pbrMetallicRoughness.baseColorFactor, RGB(1.0f));
}

MaterialInfo GltfReader::material_info(int m, bool has_vertex_colors) {
  if (m >= 0 && size_t(m) >= model_.materials.size()) fail("", "material {} does not exist", m);
  // Vertex colours multiply the base colour; candela can use them only where there is no base
  // colour texture (the mesh attribute then carries colour x factor).
  bool vertex_colors = has_vertex_colors;
  if (m >= 0 && model_.materials[size_t(m)].pbrMetallicRoughness.baseColorTexture.index >= 0) vertex_colors = false;
  auto key = std::make_pair(m, vertex_colors);
  if (auto found = materials_.find(key); found != materials_.end()) return found->second;
  MaterialInfo info = make_material(m, vertex_colors, has_vertex_colors);
  materials_[key] = info;
  return info;
}

MaterialInfo GltfReader::make_material(int m, bool vertex_colors, bool has_vertex_colors) {
  MaterialInfo info;
  info.uses_vertex_colors = vertex_colors;
  if (m < 0) {
    info.material = add_default_material(vertex_colors);
    return info;
  }
  const tg::Material& mat = model_.materials[size_t(m)];
  const std::string pointer = fmt::format("/materials/{}", m);
  const tg::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
  int uv_set = -1;
  PrincipledMaterial p;
  p.specular = 0.5f;
  const RGB factor = rgb_of(pbr.baseColorFactor, RGB(1.0f));
  const float alpha = pbr.baseColorFactor.size() == 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
  if (has_vertex_colors && !vertex_colors)
    warn(pointer, "vertex colours (COLOR_0) are ignored where the base colour has a texture");

  // The parts in the order their textures are added (the first texture sets uv_set).
  read_base_color(pbr, factor, vertex_colors, pointer, p, uv_set);
  read_metallic_roughness(pbr, pointer, p, uv_set);
  const bool unlit = read_material_extensions(mat, pointer, p, uv_set);
  const AreaEmission emission = read_emission(mat, pointer, uv_set);
  if (unlit) {
    add_unlit_material(pbr, factor, vertex_colors, pointer, uv_set, info);
  } else {
    if (emission.radiance.r > 0 || emission.radiance.g > 0 || emission.radiance.b > 0) info.emission = emission;
    // Ambient occlusion (occlusionTexture) is what a path tracer computes; nothing to do (and no
    // warning needed).
    scene_.materials.push_back(p);
    scene_.places.materials.push_back(at(pointer));
    int top = int(scene_.materials.size()) - 1;
    top = add_normal_map(mat, pointer, top, uv_set);
    top = add_alpha(mat, alpha, pointer, top, uv_set);
    // doubleSided false means back-face culling to a rasteriser; candela's surfaces are seen from
    // both sides, so only one-sided emission depends on it.
    info.material = top;
  }
  if (uv_set >= 0) material_has_textures_.insert(m);
  info.uv_set = std::max(uv_set, 0);
  return info;
}

int GltfReader::add_default_material(bool vertex_colors) {
  // The specification's default material: white, fully metallic and rough.
  PrincipledMaterial p;
  p.base_color = RGB(1.0f);
  p.metallic = 1.0f;
  p.roughness = 1.0f;
  p.specular = 0.5f;
  if (vertex_colors) p.base_color = attribute_texture();
  scene_.materials.push_back(p);
  scene_.places.materials.push_back(SourceLocation{});
  return int(scene_.materials.size()) - 1;
}

void GltfReader::read_base_color(const tg::PbrMetallicRoughness& pbr, RGB factor, bool vertex_colors,
                                 const std::string& pointer, PrincipledMaterial& p, int& uv_set) {
  // Base colour: factor x texture (sRGB), or factor x vertex colour.
  if (pbr.baseColorTexture.index >= 0) {
    const std::string where = pointer + "/pbrMetallicRoughness/baseColorTexture";
    if (factor.r == factor.g && factor.g == factor.b) {
      p.base_color.texture = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                         pbr.baseColorTexture.extensions, ColorEncoding::SRGB, std::nullopt, factor.r,
                                         where, uv_set);
    } else {
      ImageOp op;
      op.kind = ImageOp::Multiply;
      op.factor = factor;
      p.base_color.texture = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                         pbr.baseColorTexture.extensions, ColorEncoding::Linear, op, 1, where, uv_set);
    }
    if (p.base_color.texture < 0) p.base_color = factor;
  } else if (vertex_colors) {
    p.base_color = attribute_texture();
  } else {
    p.base_color = factor;
  }
}

void GltfReader::read_metallic_roughness(const tg::PbrMetallicRoughness& pbr, const std::string& pointer,
                                         PrincipledMaterial& p, int& uv_set) {
  // Metallic (B) and roughness (G) of the metallicRoughness texture times their factors. glTF's
  // roughness is perceptual (alpha = roughness^2), as Mitsuba's principled reads its roughness.
  p.metallic = float(pbr.metallicFactor);
  p.roughness = float(pbr.roughnessFactor);
  if (pbr.metallicRoughnessTexture.index >= 0) {
    const std::string where = pointer + "/pbrMetallicRoughness/metallicRoughnessTexture";
    // One channel of the texture times its factor, into `input` (a zero factor needs no texture).
    auto read_channel = [&](int channel, double factor, auto& input) {
      if (factor == 0) return;
      ImageOp op;
      op.channel = channel;
      int t = add_texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                          pbr.metallicRoughnessTexture.extensions, ColorEncoding::Linear, op, float(factor), where,
                          uv_set);
      if (t >= 0) input.texture = t;
    };
    read_channel(2, pbr.metallicFactor, p.metallic);
    read_channel(1, pbr.roughnessFactor, p.roughness);
  }
}

bool GltfReader::read_material_extensions(const tg::Material& mat, const std::string& pointer, PrincipledMaterial& p,
                                          int& uv_set) {
  bool unlit = false, has_volume = false;
  for (const auto& [name, value] : mat.extensions) {
    const std::string where = pointer + "/extensions/" + name;
    if (name == "KHR_materials_transmission") {
      read_transmission(value, where, p, uv_set);
    } else if (name == "KHR_materials_ior") {
      p.eta = float(number_or(value, "ior", 1.5));
      p.eta_given = true;
      if (p.eta < 1) {
        if (p.eta != 0) warn(where, "ior {} < 1 is read as 1.5", p.eta);
        p.eta = 1.5f;
      }
    } else if (name == "KHR_materials_unlit") {
      unlit = true;
    } else if (name == "KHR_materials_volume") {
      has_volume = true;
      warn(where, "KHR_materials_volume's attenuation is ignored (clear refraction)");
    } else if (name != "KHR_materials_emissive_strength") {  // read with the emission
      warn(where, "material extension {} is not supported and is ignored", name);
    }
  }
  if (p.spec_trans.texture >= 0 || p.spec_trans.value > 0) {
    if (!has_volume)
      warn(pointer, "KHR_materials_transmission without KHR_materials_volume means a thin wall in glTF; candela "
                    "refracts into the surface as into a solid (Mitsuba's principled)");
  }
  return unlit;
}

void GltfReader::read_transmission(const tg::Value& value, const std::string& where, PrincipledMaterial& p,
                                   int& uv_set) {
  double f = number_or(value, "transmissionFactor", 0);
  p.spec_trans = float(f);
  if (value.Has("transmissionTexture") && f != 0) {
    const tg::Value& ti = value.Get("transmissionTexture");
    ImageOp op;
    op.channel = 0;
    int t = add_texture(int(number_or(ti, "index", -1)), int(number_or(ti, "texCoord", 0)), texture_extensions(ti),
                        ColorEncoding::Linear, op, float(f), where + "/transmissionTexture", uv_set);
    if (t >= 0) p.spec_trans.texture = t;
  }
}

AreaEmission GltfReader::read_emission(const tg::Material& mat, const std::string& pointer, int& uv_set) {
  // Emission: factor x strength x texture (sRGB), a textured area light.
  RGB emissive = rgb_of(mat.emissiveFactor, RGB(0.0f));
  if (auto it = mat.extensions.find("KHR_materials_emissive_strength"); it != mat.extensions.end())
    emissive *= float(number_or(it->second, "emissiveStrength", 1));
  AreaEmission emission{emissive, mat.doubleSided};
  if (mat.emissiveTexture.index >= 0 && max_component(Vec3(emissive.r, emissive.g, emissive.b)) > 0)
    emission.texture = add_texture(mat.emissiveTexture.index, mat.emissiveTexture.texCoord,
                                   mat.emissiveTexture.extensions, ColorEncoding::SRGB, std::nullopt, 1,
                                   pointer + "/emissiveTexture", uv_set);
  return emission;
}

void GltfReader::add_unlit_material(const tg::PbrMetallicRoughness& pbr, RGB factor, bool vertex_colors,
                                    const std::string& pointer, int& uv_set, MaterialInfo& info) {
  // Unlit: the base colour seen whatever the lighting, which a path tracer can only show as
  // emission (base colour factor x texture).
  if (vertex_colors) warn(pointer, "KHR_materials_unlit: vertex colours are ignored");
  warn(pointer, "KHR_materials_unlit: rendered as a black surface emitting its base colour (it also lights the "
                "rest of the scene)");
  scene_.materials.push_back(BlackMaterial{});
  scene_.places.materials.push_back(at(pointer));
  info.material = int(scene_.materials.size()) - 1;
  AreaEmission e{factor, true};
  if (pbr.baseColorTexture.index >= 0)
    e.texture = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                            pbr.baseColorTexture.extensions, ColorEncoding::SRGB, std::nullopt, 1,
                            pointer + "/pbrMetallicRoughness/baseColorTexture", uv_set);
  info.emission = e;
}

int GltfReader::add_normal_map(const tg::Material& mat, const std::string& pointer, int top, int& uv_set) {
  // Normal map: tangent-space, +y up the image; the frame is candela's (dp/du, dp/dv) from the uvs.
  if (mat.normalTexture.index < 0) return top;
  const std::string where = pointer + "/normalTexture";
  std::optional<ImageOp> op;
  if (mat.normalTexture.scale != 1) {
    op = ImageOp{};
    op->kind = ImageOp::NormalScale;
    op->normal_scale = float(mat.normalTexture.scale);
  }
  int t = add_texture(mat.normalTexture.index, mat.normalTexture.texCoord, mat.normalTexture.extensions,
                      ColorEncoding::Linear, op, 1, where, uv_set);
  if (t < 0) return top;
  scene_.materials.push_back(NormalMapMaterial{t, top});
  scene_.places.materials.push_back(at(pointer));
  return int(scene_.materials.size()) - 1;
}

int GltfReader::add_alpha(const tg::Material& mat, float alpha, const std::string& pointer, int top, int& uv_set) {
  // Alpha: MASK keeps the surface where alpha >= cutoff, BLEND lets light through with probability
  // 1 - alpha (stochastic transparency, which a path tracer averages into blending).
  if (mat.alphaMode == "MASK" || mat.alphaMode == "BLEND") {
    const tg::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
    const bool mask = mat.alphaMode == "MASK";
    const float cutoff = float(mat.alphaCutoff);
    MaskMaterial wrapper;
    wrapper.material = top;
    wrapper.opacity = mask ? (alpha >= cutoff ? 1.0f : 0.0f) : std::clamp(alpha, 0.0f, 1.0f);
    if (pbr.baseColorTexture.index >= 0) {
      ImageOp op;
      op.kind = ImageOp::Alpha;
      op.alpha_factor = mask ? alpha : 1.0f;
      op.cutoff = mask ? cutoff : -1.0f;
      int t = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
                          ColorEncoding::Linear, op, mask ? 1.0f : std::clamp(alpha, 0.0f, 1.0f),
                          pointer + "/pbrMetallicRoughness/baseColorTexture", uv_set);
      if (t >= 0) wrapper.opacity.texture = t;
    }
    // COLOR_0's alpha would multiply too; candela's mesh attributes carry the RGB only.
    if (!(wrapper.opacity.is_constant() && wrapper.opacity.value >= 1)) {
      scene_.materials.push_back(wrapper);
      scene_.places.materials.push_back(at(pointer));
      top = int(scene_.materials.size()) - 1;
    }
  } else if (mat.alphaMode != "OPAQUE" && !mat.alphaMode.empty()) {
    warn(pointer + "/alphaMode", "unknown alphaMode \"{}\" is read as OPAQUE", mat.alphaMode);
  }
  return top;
}

// The extensions of a textureInfo inside an extension (tinygltf parses only the core ones).
tg::ExtensionMap GltfReader::texture_extensions(const tg::Value& info) {
  tg::ExtensionMap map;
  if (info.IsObject() && info.Has("extensions")) {
    const tg::Value& ext = info.Get("extensions");
    if (ext.IsObject())
      for (const std::string& key : ext.Keys()) map[key] = ext.Get(key);
  }
  return map;
}

ColorInput GltfReader::attribute_texture() {
  if (attribute_texture_ < 0) {
    scene_.textures.push_back(MeshAttributeTexture{"color"});
    scene_.places.textures.push_back(SourceLocation{});  // shared by every material with vertex colours
    attribute_texture_ = int(scene_.textures.size()) - 1;
  }
  ColorInput in;
  in.texture = attribute_texture_;
  return in;
}

}  // namespace candela::gltf
