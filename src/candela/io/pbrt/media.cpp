// Participating media: MakeNamedMedium ("homogeneous", "uniformgrid", "nanovdb" and "cloud"),
// MediumInterface, and the media the shapes and the camera get from it.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <tuple>
#include <utility>

#include "candela/io/pbrt/scene_parser.h"
#include "candela/io/grid_files.h"
#include "candela/media/medium.h"
#include "candela/media/subsurface_albedo.h"

namespace candela::pbrt {

using pbrt_spectra::Role;

namespace {

// pbrt-v4's named scattering coefficients ("string preset"), in mm^-1 as measured (pbrt converts no
// units; "scale" does): the first twelve from Jensen et al. 2001, "A Practical Model for Subsurface
// Light Transport", the others from Narasimhan et al. 2006, "Acquiring Scattering Properties of
// Participating Media by Dilution". The measured scattering is the reduced coefficient
// sigma_s' = sigma_s (1 - g); pbrt-v4 uses it as sigma_s, and so does candela.
struct ScatteringPreset {
  std::string_view name;
  RGB sigma_s, sigma_a;
};

constexpr ScatteringPreset kScatteringPresets[] = {
    {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.00f, 0.00f, 0.00f}},
    {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
    {"Lowfat Milk", {0.89187f, 1.5136f, 2.532f}, {0.002875f, 0.00575f, 0.0115f}},
    {"Reduced Milk", {2.4858f, 3.1669f, 4.5214f}, {0.0025556f, 0.0051111f, 0.012778f}},
    {"Regular Milk", {4.5513f, 5.8294f, 7.136f}, {0.0015333f, 0.0046f, 0.019933f}},
    {"Espresso", {0.72378f, 0.84557f, 1.0247f}, {4.7984f, 6.5751f, 8.8493f}},
    {"Mint Mocha Coffee", {0.31602f, 0.38538f, 0.48131f}, {3.772f, 5.8228f, 7.82f}},
    {"Lowfat Soy Milk", {0.30576f, 0.34233f, 0.61664f}, {0.0014375f, 0.0071875f, 0.035937f}},
    {"Regular Soy Milk", {0.59223f, 0.73866f, 1.4693f}, {0.0019167f, 0.0095833f, 0.065167f}},
    {"Lowfat Chocolate Milk", {0.64925f, 0.83916f, 1.1057f}, {0.0115f, 0.0368f, 0.1564f}},
    {"Regular Chocolate Milk", {1.4585f, 2.1289f, 2.9527f}, {0.010063f, 0.043125f, 0.14375f}},
    {"Coke", {8.9053e-05f, 8.372e-05f, 0.0f}, {0.10014f, 0.16503f, 0.2468f}},
    {"Pepsi", {6.1697e-05f, 4.2564e-05f, 0.0f}, {0.091641f, 0.14158f, 0.20729f}},
    {"Sprite", {6.0306e-06f, 6.4139e-06f, 6.5504e-06f}, {0.001886f, 0.0018308f, 0.0020025f}},
    {"Gatorade", {0.0024574f, 0.003007f, 0.0037325f}, {0.024794f, 0.019289f, 0.008878f}},
    {"Chardonnay", {1.7982e-05f, 1.3758e-05f, 1.2023e-05f}, {0.010782f, 0.011855f, 0.023997f}},
    {"White Zinfandel", {1.7501e-05f, 1.9069e-05f, 1.288e-05f}, {0.012072f, 0.016184f, 0.019843f}},
    {"Merlot", {2.1129e-05f, 0.0f, 0.0f}, {0.11632f, 0.25191f, 0.29434f}},
    {"Budweiser Beer", {2.4356e-05f, 2.4079e-05f, 1.0564e-05f}, {0.011492f, 0.024911f, 0.057786f}},
    {"Coors Light Beer", {5.0922e-05f, 4.301e-05f, 0.0f}, {0.006164f, 0.013984f, 0.034983f}},
    {"Clorox", {0.0024035f, 0.0031373f, 0.003991f}, {0.0033542f, 0.014892f, 0.026297f}},
    {"Apple Juice", {0.00013612f, 0.00015836f, 0.000227f}, {0.012957f, 0.023741f, 0.052184f}},
    {"Cranberry Juice", {0.00010402f, 0.00011646f, 7.8139e-05f}, {0.039437f, 0.094223f, 0.12426f}},
    {"Grape Juice", {5.382e-05f, 0.0f, 0.0f}, {0.10404f, 0.23958f, 0.29325f}},
    {"Ruby Grapefruit Juice", {0.011002f, 0.010927f, 0.011036f}, {0.085867f, 0.18314f, 0.25262f}},
    {"White Grapefruit Juice", {0.22826f, 0.23998f, 0.32748f}, {0.0138f, 0.018831f, 0.056781f}},
    {"Shampoo", {0.0007176f, 0.0008303f, 0.0009016f}, {0.014107f, 0.045693f, 0.061717f}},
    {"Strawberry Shampoo", {0.00015671f, 0.00015947f, 1.518e-05f}, {0.01449f, 0.05796f, 0.075823f}},
    {"Head & Shoulders Shampoo", {0.023805f, 0.028804f, 0.034306f}, {0.084621f, 0.15688f, 0.20365f}},
    {"Lemon Tea Powder", {0.040224f, 0.045264f, 0.051081f}, {2.4288f, 4.5757f, 7.2127f}},
    {"Orange Powder", {0.00015617f, 0.00017482f, 0.0001762f}, {0.001449f, 0.003441f, 0.007863f}},
    {"Pink Lemonade Powder", {0.00012103f, 0.00013073f, 0.00012528f}, {0.001165f, 0.002366f, 0.003195f}},
    {"Cappuccino Powder", {1.8436f, 2.5851f, 2.1662f}, {35.844f, 49.547f, 61.084f}},
    {"Salt Powder", {0.027333f, 0.032451f, 0.031979f}, {0.28415f, 0.3257f, 0.34148f}},
    {"Sugar Powder", {0.00022272f, 0.00025513f, 0.000271f}, {0.012638f, 0.031051f, 0.050124f}},
    {"Suisse Mocha Powder", {2.7979f, 3.5452f, 4.3365f}, {17.502f, 27.004f, 35.433f}},
    {"Pacific Ocean Surface Water", {0.0001764f, 0.00032095f, 0.00019617f}, {0.031845f, 0.031324f, 0.030147f}},
};

const ScatteringPreset* find_scattering_preset(std::string_view name) {
  for (const ScatteringPreset& preset : kScatteringPresets)
    if (preset.name == name) return &preset;
  return nullptr;
}

// Bounds3f(p0, p1) in pbrt: the box between the two corners, whichever way round; it must have volume
// (`what` names the box in the message).
std::pair<Point3, Point3> read_medium_box(ParamList& params, std::string_view what) {
  const Point3 p0 = params.get_point3("p0", Point3(0.0f)), p1 = params.get_point3("p1", Point3(1.0f));
  const Point3 lo(std::min(p0.x, p1.x), std::min(p0.y, p1.y), std::min(p0.z, p1.z));
  const Point3 hi(std::max(p0.x, p1.x), std::max(p0.y, p1.y), std::max(p0.z, p1.z));
  for (int axis = 0; axis < 3; ++axis)
    if (!(hi[axis] > lo[axis]))
      params.fail("p1", "must differ from \"p0\" on every axis ({} has no volume), got {} {} {} and {} {} {}", what,
                  p0.x, p0.y, p0.z, p1.x, p1.y, p1.z);
  return {lo, hi};
}

// pbrt-v4's CloudMedium's own parameters (CloudDensity; its defaults): "density" (1), "wispiness" (1),
// "frequency" (5) (finite: the tokenizer takes no other numbers), and the box from "p0" (0 0 0) to
// "p1" (1 1 1) in the medium's space, which the CTM at MakeNamedMedium (`medium_to_world`) places. The
// noise and the altitude falloff are taken in the medium's space, as pbrt-v4 takes them (its
// renderFromMedium's inverse).
VolumeDesc read_cloud_density(ParamList& params, const Transform& medium_to_world) {
  CloudDensity cloud;
  cloud.density = params.get_float("density", cloud.density);
  cloud.wispiness = params.get_float("wispiness", cloud.wispiness);
  cloud.frequency = params.get_float("frequency", cloud.frequency);
  std::tie(cloud.box_min, cloud.box_max) = read_medium_box(params, "the cloud's box");
  VolumeDesc density;
  density.to_world = medium_to_world * cloud.unit_cube_to_cloud();
  density.cloud = cloud;
  return density;
}

std::string scattering_preset_names() {
  std::string names;
  for (const ScatteringPreset& preset : kScatteringPresets)
    names += fmt::format("{}\"{}\"", names.empty() ? "" : ", ", preset.name);
  return names;
}

}  // namespace

// ---------------------------------------------------------------- names

// The index in SceneDesc::media of the medium `name` refers to (-1 for "", the vacuum). As in
// pbrt-v4, a medium may be defined after the MediumInterface that names it: its slot is reserved at
// the first reference and filled by MakeNamedMedium; check_media_defined() reports a name the scene
// never defines.
int SceneParser::medium_index(const Token& name) {
  if (name.text.empty()) return -1;
  auto [named, first_reference] = media_.try_emplace(name.text);
  if (first_reference) {
    named->second = NamedMedium{static_cast<int>(scene_.media.size()), false, at(name)};
    MediumDesc placeholder;
    placeholder.name = name.text;
    placeholder.where = at(name);
    scene_.media.push_back(std::move(placeholder));
  }
  return named->second.index;
}

void SceneParser::check_media_defined() const {
  const std::pair<const std::string, NamedMedium>* first_undefined = nullptr;
  for (const auto& entry : media_)
    if (!entry.second.defined && (!first_undefined || entry.second.index < first_undefined->second.index))
      first_undefined = &entry;
  if (first_undefined)
    throw_scene_error(first_undefined->second.first_reference,
                      "MediumInterface: no medium named \"{}\" is defined (MakeNamedMedium defines it, anywhere in "
                      "the scene)",
                      first_undefined->first);
}

// ---------------------------------------------------------------- directives

// MediumInterface "inside" ["outside"]: one name means the same medium on both sides; "" is the
// vacuum. The shapes that follow get the two (ShapeDesc::interior_medium, exterior_medium), and a
// Camera the outside one (pbrt-v4's CameraMedium); lights take nothing from it.
void SceneParser::medium_interface(const Token& d) {
  Token inside = expect_string(d, "the inside medium's name");
  Token outside = inside;
  if (tokens_->peek().kind == TokenKind::String) outside = tokens_->next();
  state_.inside_medium = medium_index(inside);
  state_.outside_medium = medium_index(outside);
}

void SceneParser::make_named_medium(const Token& d) {
  Token name = expect_string(d, "the medium name");
  ParamList params = read_params(d, fmt::format("MakeNamedMedium \"{}\"", name.text), kMediumAttributes);
  if (name.text.empty())
    throw_scene_error(at(name), "MakeNamedMedium: the name must not be empty (\"\" stands for the vacuum in "
                      "MediumInterface)");
  if (auto earlier = media_.find(name.text); earlier != media_.end() && earlier->second.defined)
    throw_scene_error(at(name), "MakeNamedMedium: medium \"{}\" is already defined at {}", name.text,
                      scene_.media[earlier->second.index].where.to_string());

  const Param* type = params.take("type", {"string"});
  if (!type)
    throw_scene_error(at(d), "{}: \"string type\" is required (\"homogeneous\", \"uniformgrid\", \"nanovdb\" or "
                      "\"cloud\")", params.owner());
  params.expect_count(*type, 1);
  MediumDesc medium;
  if (type->strings[0] == "homogeneous") {
    medium = make_homogeneous_medium(params);
  } else if (type->strings[0] == "uniformgrid") {
    medium = make_grid_medium(params);
  } else if (type->strings[0] == "nanovdb") {
    medium = make_nanovdb_medium(params);
  } else if (type->strings[0] == "cloud") {
    // pbrt-v4's CloudMedium: sigma_a, sigma_s and g as every medium, no "scale" (its density stays
    // within [0, 1]; pbrt-v4 reports "scale" unused) and no emission.
    if (params.has_own("scale"))
      params.fail("scale", "is not a parameter of a \"cloud\" medium (as in pbrt-v4): scale \"sigma_a\" and "
                  "\"sigma_s\" instead");
    read_scattering(params, medium, std::nullopt, std::nullopt);
    medium.scale = 1;  // an Attribute "medium" "scale" does not reach a cloud either
    medium.density = read_cloud_density(params, state_.ctm.start);
  } else {
    reject_type(type->where, "medium", type->strings[0], {"homogeneous", "uniformgrid", "nanovdb", "cloud"},
                {"rgbgrid"}, "grids of RGB coefficients are not supported yet");
  }
  params.reject_unused();
  medium.name = name.text;
  medium.where = at(d);
  // The parameters were checked one by one above; this is the renderer's own account of what it can
  // render, so that the two cannot drift apart.
  if (std::string problem = medium_problem(medium); !problem.empty())
    throw_scene_error(at(d), "{}: {}", params.owner(), problem);

  int index = medium_index(name);
  scene_.media[index] = std::move(medium);
  media_[name.text].defined = true;
}

// ---------------------------------------------------------------- the medium types

// sigma_a, sigma_s (pbrt-v4's defaults: 1 each), "scale" and "g", which every medium type reads.
void SceneParser::read_scattering(ParamList& params, MediumDesc& medium, std::optional<RGB> sigma_a,
                                  std::optional<RGB> sigma_s) {
  if (!sigma_a) sigma_a = read_spectrum(params, "sigma_a", Role::Unbounded);
  if (!sigma_s) sigma_s = read_spectrum(params, "sigma_s", Role::Unbounded);
  set_sigma_a_sigma_s(medium, sigma_a.value_or(RGB(1.0f)), sigma_s.value_or(RGB(1.0f)));
  medium.scale = params.get_float("scale", 1);
  if (!(medium.scale >= 0)) params.fail("scale", "must not be negative, got {}", medium.scale);
  medium.g = params.get_float("g", 0);
  if (!(medium.g > -1 && medium.g < 1))
    params.fail("g", "(Henyey-Greenstein's mean cosine) must be between -1 and 1, exclusive, got {}", medium.g);
}

// "Le", an emission spectrum normalised as lights' are (read_emission), times `scale` ("Lescale").
RGB SceneParser::read_medium_emission(ParamList& params, float scale) {
  if (!(scale >= 0)) params.fail("Lescale", "must not be negative, got {}", scale);
  return read_emission(params, "Le").value_or(RGB(0.0f)) * scale;
}

// The same coefficients everywhere: pbrt-v4's HomogeneousMedium. Its CTM does not matter.
MediumDesc SceneParser::make_homogeneous_medium(ParamList& params) {
  std::optional<RGB> sigma_a, sigma_s;
  if (const Param* preset = params.take("preset", {"string"})) {
    params.expect_count(*preset, 1);
    const ScatteringPreset* found = find_scattering_preset(preset->strings[0]);
    // pbrt-v4 warns and falls back to sigma_a and sigma_s; a misspelt preset changes the image
    // entirely, so it is an error here.
    if (!found)
      params.fail("preset", "names no scattering preset: \"{}\" (the presets are {})", preset->strings[0],
                  scattering_preset_names());
    sigma_a = found->sigma_a;  // and "sigma_a" and "sigma_s" stay unread: an unused-parameter error
    sigma_s = found->sigma_s;
  }
  MediumDesc medium;
  read_scattering(params, medium, sigma_a, sigma_s);
  medium.emission = read_medium_emission(params, params.get_float("Lescale", 1));
  return medium;
}

// A grid of nx ny nz densities over the box from p0 to p1 in the medium's space (pbrt-v4's
// GridMedium): extinction (sigma_a + sigma_s) scale density(p), the samples at the voxel centres, and
// zero beyond them (pbrt's SampledGrid), so the density fades to zero over the outer half voxel.
// Emission: "Lescale" (one value, or one per voxel) looked up in the same way, times the blackbody of
// a "temperature" grid where there is one (offset, scaled, above a cutoff of 100 K), else "Le".
MediumDesc SceneParser::make_grid_medium(ParamList& params) {
  int resolution[3];
  for (int axis = 0; axis < 3; ++axis) {
    const char* name = axis == 0 ? "nx" : axis == 1 ? "ny" : "nz";
    resolution[axis] = params.get_int(name, 1);
    if (resolution[axis] < 1) params.fail(name, "must be at least 1, got {}", resolution[axis]);
  }
  const int64_t voxels = int64_t{resolution[0]} * resolution[1] * resolution[2];
  // A per-voxel grid given inline: `name`'s values, all finite (and >= 0 unless negatives are allowed).
  auto read_voxels = [&](const Param& p, bool allow_negative) {
    if (int64_t(p.count()) != voxels)
      throw_scene_error(p.where, "{}: {} has {} values; nx ny nz = {} x {} x {} needs {}", params.owner(),
                        p.declaration(), p.count(), resolution[0], resolution[1], resolution[2], voxels);
    std::vector<float> values(p.numbers.size());
    for (size_t i = 0; i < values.size(); ++i) {
      values[i] = static_cast<float>(p.numbers[i]);
      if (!std::isfinite(values[i]) || (!allow_negative && values[i] < 0))
        throw_scene_error(p.where, "{}: {}: value {} (number {}, x fastest) must be finite{}", params.owner(),
                          p.declaration(), p.numbers[i], i + 1, allow_negative ? "" : " and not negative");
    }
    return values;
  };
  const Param* density = params.take("density", {"float"});
  if (!density)
    throw_scene_error(params.directive(), "{}: a \"uniformgrid\" medium needs \"float density\" (nx ny nz values)",
                      params.owner());
  std::vector<float> values = read_voxels(*density, false);

  const std::pair<Point3, Point3> box = read_medium_box(params, "the grid's box");
  const Point3 lo = box.first, hi = box.second;

  MediumDesc medium;
  read_scattering(params, medium, std::nullopt, std::nullopt);
  // Every grid of the medium shares the box and pbrt's lookup (zero beyond the outer samples).
  auto grid = [&](std::vector<float> v, std::array<int, 3> res) {
    VolumeDesc g;
    g.resolution = res;
    g.channels = 1;
    g.values = std::make_shared<const std::vector<float>>(std::move(v));
    g.to_world = state_.ctm.start * Transform::translate(lo) * Transform::scale(hi - lo);
    g.border = VolumeBorder::Zero;
    return g;
  };
  const std::array<int, 3> res{resolution[0], resolution[1], resolution[2]};
  medium.density = grid(std::move(values), res);

  // pbrt-v4 reads "Lescale" as a grid of nx ny nz values, or of one value (a one-voxel grid, whose
  // lookup fades from the box's centre to half at its faces).
  if (const Param* scale = params.take("Lescale", {"float"})) {
    if (scale->count() == 1) {
      if (!(scale->numbers[0] >= 0) || !std::isfinite(scale->numbers[0]))
        params.fail("Lescale", "must be finite and not negative, got {}", scale->numbers[0]);
      medium.emission_scale = grid({static_cast<float>(scale->numbers[0])}, {1, 1, 1});
    } else {
      medium.emission_scale = grid(read_voxels(*scale, false), res);
    }
  } else {
    medium.emission_scale = grid({1.0f}, {1, 1, 1});
  }
  if (const Param* temperature = params.take("temperature", {"float"})) {
    medium.temperature = grid(read_voxels(*temperature, true), res);
    if (params.has("Le"))
      warn(params.where("Le"), "{}: \"Le\" is not used where there is a \"temperature\" grid (as in pbrt-v4)",
           params.owner());
    params.take("Le", {"rgb", "spectrum", "blackbody"});
  } else {
    medium.emission = read_medium_emission(params, 1);
  }
  read_temperature_mapping(params, medium);
  return medium;
}

// pbrt-v4's temperature mapping, read whether or not there is a temperature grid (as pbrt-v4 does):
// the blackbody of (T - "temperatureoffset") x "temperaturescale" kelvin, above "temperaturecutoff".
void SceneParser::read_temperature_mapping(ParamList& params, MediumDesc& medium) {
  medium.temperature_offset = params.get_float("temperatureoffset", 0);
  medium.temperature_scale = params.get_float("temperaturescale", 1);
  medium.temperature_cutoff = params.get_float("temperaturecutoff", 100);
  for (auto [name, value] : {std::pair{"temperatureoffset", medium.temperature_offset},
                             std::pair{"temperaturescale", medium.temperature_scale},
                             std::pair{"temperaturecutoff", medium.temperature_cutoff}})
    if (!std::isfinite(value)) params.fail(name, "must be finite, got {}", value);
}

// pbrt-v4's NanoVDBMedium: the "density" grid of a NanoVDB file (io/grid_files.h; an OpenVDB .vdb
// file is read too), placed by the file's own transform and then the CTM. Where the file has a
// "temperature" grid too, the medium emits its blackbody (see read_temperature_mapping) times "Lescale".
MediumDesc SceneParser::make_nanovdb_medium(ParamList& params) {
  const Param* name = params.take("filename", {"string"});
  if (!name) throw_scene_error(params.directive(), "{}: a \"nanovdb\" medium needs \"string filename\"", params.owner());
  params.expect_count(*name, 1);
  const fs::path file = resolve_path(name->strings[0], name->where, fmt::format("{}: \"filename\"", params.owner()));
  MediumDesc medium;
  read_scattering(params, medium, std::nullopt, std::nullopt);
  medium.density = read_grid_file(file, "density", name->where);
  medium.density.to_world = state_.ctm.start * medium.density.to_world;
  const float le_scale = params.get_float("Lescale", 1);
  if (!(le_scale >= 0) || !std::isfinite(le_scale)) params.fail("Lescale", "must be finite and not negative, got {}", le_scale);
  medium.emission_scale.constant = RGB(le_scale);
  read_temperature_mapping(params, medium);
  const std::vector<std::string> grids = grid_names_in_file(file, name->where);
  if (std::find(grids.begin(), grids.end(), "temperature") != grids.end()) {
    medium.temperature = read_grid_file(file, "temperature", name->where);
    medium.temperature->to_world = state_.ctm.start * medium.temperature->to_world;
  }
  return medium;
}

// ---------------------------------------------------------------- the subsurface material

// pbrt-v4's "subsurface" material (SubsurfaceMaterial) is a dielectric boundary ("eta", 1.33, and the
// roughness parameters) over a scattering interior, which pbrt-v4 renders with a tabulated BSSRDF
// (photon beam diffusion) and candela by random-walking a homogeneous medium inside the boundary
// (volpath; MediumDesc::subsurface makes the excursion one bounce, as pbrt-v4's BSSRDF is). The
// interior is given, as pbrt-v4 reads it, by one of
//   1. "name": a scattering preset (then g = 0: the presets are reduced scattering coefficients);
//   2. "sigma_a" and "sigma_s", both;
//   3. "reflectance" and "mfp" (1): per channel, the albedo whose effective albedo (the share of the
//      light let in that comes out again, media/subsurface_albedo.h) is the reflectance, and
//      sigma_t = 1 / mfp. pbrt-v4 inverts its diffusion profile's effective albedo in the same way;
//      candela inverts the exact transport's, which its random walk renders;
//   4. none of them: pbrt-v4's default, the coefficients of whole milk.
// "scale" (1) multiplies the coefficients of 1, 2 and 4, and the mean free path of 3 (as pbrt-v4
// does); units are the scene's (pbrt-v4 converts none: the presets are per millimetre). "g" (0) is the
// Henyey-Greenstein phase function's. Integrators other than volpath render, as pbrt-v4's do, the
// boundary alone: a clear dielectric.
MaterialDesc SceneParser::make_subsurface_material(ParamList& params) {
  DielectricMaterial boundary;
  boundary.ior = params.get_float("eta", 1.33f);
  if (!(boundary.ior > 0)) params.fail("eta", "must be positive, got {}", boundary.ior);
  boundary.roughness = read_roughness(params);
  read_shading_normals(params);

  float g = params.get_float("g", 0);
  if (!(g > -1 && g < 1))
    params.fail("g", "(Henyey-Greenstein's mean cosine) must be between -1 and 1, exclusive, got {}", g);
  const float scale = params.get_float("scale", 1);
  if (!(scale >= 0)) params.fail("scale", "must not be negative, got {}", scale);
  RGB sigma_a, sigma_s;
  const std::string name = params.get_string("name", "");
  if (!name.empty()) {
    const ScatteringPreset* preset = find_scattering_preset(name);
    if (!preset)
      params.fail("name", "names no scattering preset: \"{}\" (the presets are {})", name, scattering_preset_names());
    if (g != 0)
      warn(params.where("g"), "{}: \"g\" {} is ignored with a named medium: its coefficients are reduced ones, for "
           "g = 0 (as in pbrt-v4)", params.owner(), g);
    g = 0;
    sigma_a = preset->sigma_a * scale;
    sigma_s = preset->sigma_s * scale;
  } else if (params.has("sigma_a") || params.has("sigma_s")) {
    const std::optional<RGB> a = read_spectrum(params, "sigma_a", Role::Unbounded);
    const std::optional<RGB> s = read_spectrum(params, "sigma_s", Role::Unbounded);
    if (!a || !s)
      params.fail(a ? "sigma_s" : "sigma_a", "is required with \"{}\" (as in pbrt-v4: give both coefficients)",
                  a ? "sigma_a" : "sigma_s");
    sigma_a = *a * scale;
    sigma_s = *s * scale;
  } else if (params.has("reflectance")) {
    const RGB reflectance = read_spectrum(params, "reflectance", Role::Reflectance).value_or(RGB(0.0f));
    const RGB mfp = read_spectrum(params, "mfp", Role::Unbounded).value_or(RGB(1.0f)) * scale;
    float a[3], s[3];
    for (int c = 0; c < 3; ++c) {
      if (!(mfp[c] > 0))
        params.fail("mfp", "times \"scale\" must be positive (the mean free path), got {} in channel {}", mfp[c], c);
      const float albedo = static_cast<float>(
          subsurface_albedo_from_effective(std::clamp(reflectance[c], 0.0f, 1.0f), g, boundary.ior));
      s[c] = albedo / mfp[c];
      a[c] = (1 - albedo) / mfp[c];
    }
    sigma_a = RGB(a[0], a[1], a[2]);
    sigma_s = RGB(s[0], s[1], s[2]);
  } else {
    const ScatteringPreset* milk = find_scattering_preset("Wholemilk");
    sigma_a = milk->sigma_a * scale;
    sigma_s = milk->sigma_s * scale;
  }

  // What renders subsurface scattering: volpath, pbrt-v4's default (candela's for simplevolpath too).
  if (options_.integrator_given && options_.integrator != "volpath") {
    warn(params.directive(), "{}: the {} integrator does not render subsurface scattering (nor does pbrt-v4's): "
         "the material is its dielectric boundary alone; use Integrator \"volpath\"", params.owner(),
         options_.integrator);
    return boundary;
  }
  MediumDesc medium;
  set_sigma_a_sigma_s(medium, sigma_a, sigma_s);
  medium.g = g;
  medium.subsurface = true;
  medium.name = fmt::format("subsurface at {}", params.directive().to_string());
  medium.where = params.directive();
  if (std::string problem = medium_problem(medium); !problem.empty())
    throw_scene_error(params.directive(), "{}: {}", params.owner(), problem);
  scene_.media.push_back(std::move(medium));
  pending_subsurface_medium_ = static_cast<int>(scene_.media.size()) - 1;
  return boundary;
}

void SceneParser::claim_subsurface_medium(int material) {
  if (pending_subsurface_medium_ >= 0) subsurface_media_[material] = pending_subsurface_medium_;
  pending_subsurface_medium_ = -1;
}

}  // namespace candela::pbrt
