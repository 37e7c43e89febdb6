#pragma once
// The format-neutral scene description: plain structs with defaults that every reader (JSON, pbrt-v4,
// Mitsuba 3, glTF, OBJ) fills in and that scene/build turns into a render scene. Nothing after this
// point knows which file format a scene came from. Units are whatever the scene uses; colours are linear RGB.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"

namespace candela {

// ---------------------------------------------------------------- textures

// A material or texture parameter: a constant `value`, or the texture SceneDesc::textures[texture]
// evaluated at the hit point (texture >= 0). Float parameters read a colour texture as the average of
// its channels (as pbrt-v4 does for float image textures).
template <typename T>
struct Textured {
  T value{};
  int texture = -1;
  Textured() = default;
  Textured(T v) : value(v) {}  // NOLINT: a constant converts implicitly
  bool is_constant() const { return texture < 0; }
};
using ColorInput = Textured<RGB>;
using FloatInput = Textured<float>;

// Texture coordinates from the surface's (u, v) by an affine map:
//   s = su u + s_from_v v + du,   t = t_from_u u + sv v + dv.
// The cross terms are zero unless the texture is rotated or sheared (glTF's KHR_texture_transform
// rotation, Mitsuba's to_uv, JSON's uv_matrix).
struct UVMapping {
  float su = 1, sv = 1, du = 0, dv = 0;
  float s_from_v = 0, t_from_u = 0;
  bool is_axis_aligned() const { return s_from_v == 0 && t_from_u == 0; }
};

// What happens outside [0,1]^2.
enum class TextureWrap { Repeat, Clamp, Black, Mirror };
// How 8-bit texel values become linear: Auto = sRGB for 8-bit files, linear for float files (EXR, HDR).
enum class ColorEncoding { Auto, Linear, SRGB };

// An image read with OpenImageIO, looked up with bilinear filtering (or nearest, `bilinear = false`).
// t = 0 is the *bottom* row of the image (pbrt-v4 and Mitsuba flip v the same way).
struct ImageTexture {
  std::string filename;  // resolved by the reader (absolute or relative to the working directory)
  TextureWrap wrap = TextureWrap::Repeat;
  ColorEncoding encoding = ColorEncoding::Auto;
  bool bilinear = true;
  float scale = 1;      // texel values are multiplied by this...
  bool invert = false;  // ...and then replaced by 1 - value when set (pbrt's "invert")
  bool luminance = false;  // each texel read as its luminance, grey (Mitsuba's float lookup of an RGB image)
  UVMapping mapping;
};

// Alternating tex1/tex2 on the unit squares of (s, t): tex1 where floor(s) + floor(t) is even.
struct CheckerboardTexture {
  ColorInput tex1{RGB(1.0f)}, tex2{RGB(0.0f)};
  UVMapping mapping;
};

// tex * scale.
struct ScaleTexture {
  ColorInput tex{RGB(1.0f)};
  FloatInput scale{1.0f};
};

// (1 - amount) * tex1 + amount * tex2.
struct MixTexture {
  ColorInput tex1{RGB(0.0f)}, tex2{RGB(1.0f)};
  FloatInput amount{0.5f};
};

// A value stored on the mesh itself (Mitsuba's mesh_attribute): the TriangleMesh::attributes entry
// of this name and kind, per vertex (interpolated with the hit's barycentrics) or per face (a mesh
// may have both of one name, as Mitsuba's "vertex_color" and "face_color"). Zero on other shapes.
struct MeshAttributeTexture {
  std::string name;  // without the "vertex_" / "face_" prefix
  bool per_face = false;
};

using TextureDesc = std::variant<ImageTexture, CheckerboardTexture, ScaleTexture, MixTexture, MeshAttributeTexture>;

// ---------------------------------------------------------------- materials

// Lambertian reflector.
struct DiffuseMaterial {
  ColorInput reflectance{RGB(0.5f)};
};

// The paper's material model (Häkkinen 2002, sec. 4.6): a diffuse lobe, a normalised Phong lobe and
// ideal refraction, chosen per path vertex by Russian roulette with probabilities d, s, t
// (d + s + t <= 1; the rest absorbs). The BSDF is d*diffuse/pi + s*specular*phong + t*transmission*delta.
struct PhongMaterial {
  ColorInput diffuse{RGB(0.5f)};
  ColorInput specular{RGB(1.0f)};
  float exponent = 32;  // Phong exponent n of cos^n around the mirror direction
  ColorInput transmission{RGB(1.0f)};
  float ior = 1.5f;  // index of refraction inside / outside, for the transmitted part
  float d = 1, s = 0, t = 0;
};

// Ideal specular reflector.
struct MirrorMaterial {
  ColorInput reflectance{RGB(1.0f)};
};

// The microfacet normal distribution: Trowbridge-Reitz (GGX, the default) or Beckmann (Mitsuba's
// "beckmann"); alpha has the usual meaning for each (Beckmann: the RMS slope).
// GGX with pbrt-v4's height-correlated masking-shadowing 1 / (1 + Lambda(wo) + Lambda(wi)), or with
// Mitsuba's separable G1(wo) G1(wi) (GGXSeparable: what Mitsuba's rough BSDFs use); Beckmann (always
// separable, as Mitsuba's).
enum class MicrofacetDistribution { GGX, GGXSeparable, Beckmann };

// Microfacet roughness: the Trowbridge-Reitz (GGX) alpha along the shading frame's u and v axes.
// alpha < 1e-3 on both axes is treated as perfectly smooth (a delta BSDF), as pbrt-v4 does.
// remap = true reads u, v as pbrt's "roughness" and uses alpha = sqrt(roughness) (pbrt-v4's
// RoughnessToAlpha); false uses them as alpha directly (Mitsuba's "alpha").
struct Roughness {
  FloatInput u{0.0f}, v{0.0f};
  bool remap = false;
  MicrofacetDistribution distribution = MicrofacetDistribution::GGX;
};

// Metal: Fresnel reflection of a conductor with complex index of refraction eta + i k (per RGB
// channel), on a GGX microfacet surface. With `reflectance` set, eta and k are ignored and the
// normal-incidence reflectance is given instead (pbrt-v4's artist mode: eta = 1, k = 2 sqrt(r) / sqrt(1 - r)).
// The defaults are copper (pbrt-v4's default "metal-Cu-eta" / "metal-Cu-k", as RGB).
struct ConductorMaterial {
  ColorInput eta{RGB(0.200438f, 0.924033f, 1.102212f)};
  ColorInput k{RGB(3.912949f, 2.452848f, 2.142188f)};
  std::optional<ColorInput> reflectance;
  ColorInput specular_tint{RGB(1.0f)};  // multiplies the reflection (Mitsuba's specular_reflectance)
  Roughness roughness;
};

// Dielectric interface (glass, water): Fresnel-weighted reflection and refraction, smooth or GGX-rough.
// ior = n_inside / n_outside, inside being the side opposite the geometric normal.
struct DielectricMaterial {
  float ior = 1.5f;
  ColorInput reflectance{RGB(1.0f)};    // tints (Mitsuba's specular_reflectance / _transmittance); 1 = physical
  ColorInput transmittance{RGB(1.0f)};
  Roughness roughness;
  // A thin sheet (Mitsuba's "thindielectric"): light passes straight through without refraction,
  // with the Fresnel reflectance of the two interfaces and their internal reflections summed
  // (R' = R + T^2 R / (1 - R^2)); smooth only.
  bool thin = false;
};

// Plastic / coated diffuse: a dielectric coat (smooth or GGX-rough) of index `ior` over a Lambertian
// base. Light refracted into the coat scatters diffusely and bounces between base and coat; the
// closed form for the infinite series of internal reflections (Mitsuba's plastic, after Weidlich and
// Wilkie) keeps it energy-consistent.
struct CoatedDiffuseMaterial {
  ColorInput reflectance{RGB(0.5f)};  // the diffuse base
  ColorInput specular{RGB(1.0f)};     // tints the coat's reflection (1 = physical)
  float ior = 1.5f;
  Roughness roughness;
  bool nonlinear = false;  // Mitsuba's "nonlinear": account for the colour shift of internal bounces
  // Mitsuba 3's roughplastic: the rough coat's transmittance and internal reflectance integrated
  // over its microfacets and tabulated (materials/rough_coat.h) instead of the smooth Fresnel
  // factors. Needs a constant roughness.
  bool tabulated_coat = false;
};

// Lambertian reflection and Lambertian transmission to the other side (leaves, paper, lamp shades).
struct DiffuseTransmissionMaterial {
  ColorInput reflectance{RGB(0.25f)};
  ColorInput transmittance{RGB(0.25f)};
};

// Absorbs everything: for pure emitters and light blockers.
struct BlackMaterial {};

// No surface at all: rays pass straight through without counting as a bounce (pbrt-v4's
// "interface", Mitsuba's "null"). Marks the boundary of a participating medium, or hides a shape
// while keeping it as an emitter.
struct InterfaceMaterial {};

// Mitsuba 3's principled BSDF (after the Disney BSDF, Burley 2015), with Mitsuba's exact definitions
// of every lobe and of how the parameters combine; `thin` selects Mitsuba's principledthin (a thin
// sheet: diffuse and specular transmission without refraction). glTF's metallic-roughness model is
// this with specular 0.5 and the other lobes off.
struct PrincipledMaterial {
  ColorInput base_color{RGB(0.5f)};
  FloatInput roughness{0.5f};
  FloatInput metallic{0.0f};
  FloatInput specular{0.5f};       // ignored where eta is given (eta_given)
  FloatInput specular_tint{0.0f};
  FloatInput anisotropic{0.0f};
  FloatInput sheen{0.0f};
  FloatInput sheen_tint{0.0f};
  FloatInput clearcoat{0.0f};
  FloatInput clearcoat_gloss{0.0f};
  FloatInput spec_trans{0.0f};
  float eta = 1.5f;
  bool eta_given = false;
  // principledthin only:
  bool thin = false;
  FloatInput diff_trans{0.0f};
  FloatInput flatness{0.0f};
};

// Wrappers around another material (indices into SceneDesc::materials, always smaller than the
// wrapper's own index). Mitsuba's BSDFs are one-sided unless wrapped in "twosided"; candela's are
// two-sided, so a reader of Mitsuba scenes wraps its opaque BSDFs in OneSidedMaterial.

// The material seen from the front (the side the shading normal points to); black from the back.
struct OneSidedMaterial {
  int material = -1;
};

// Different materials on the two sides (Mitsuba's "twosided" with two BSDFs): `front` where the
// direction the light leaves towards (the viewer) is on the side the geometric normal points to,
// `back` on the other side, each seen as from its own front. Chosen per hit, so it must be the
// outermost wrapper (no mask, blend or map around it).
struct TwoSidedMaterial {
  int front = -1, back = -1;
};

// Alpha masking (Mitsuba's "mask"): with probability 1 - opacity the surface is not there and the
// ray passes straight through; otherwise `material` scatters.
struct MaskMaterial {
  FloatInput opacity{1.0f};
  int material = -1;
};

// f = (1 - weight) f_material0 + weight f_material1 (Mitsuba's "blendbsdf").
struct BlendMaterial {
  FloatInput weight{0.5f};
  int material0 = -1, material1 = -1;
};

// What Mitsuba 3 (since 3.7.1) adds to a tilted shading normal, both off by default here (pbrt-v4
// and glTF have neither) and on in Mitsuba scenes (its defaults):
//   flip_invalid_normals  where the direction towards the previous vertex, wo, lies below the tilted
//                         normal, the normal is mirrored about the original one (Schuessler et al. 2017)
//   shadowing_function    the BSDF is scaled by a microfacet shadowing term of the sampled direction
//                         (Conty Estevez et al. 2019) that softens the terminator of a strong tilt
struct PerturbedNormalOptions {
  bool flip_invalid_normals = false;
  bool shadowing_function = false;
};

// Shading normals from a tangent-space normal map (Mitsuba's "normalmap"): the texture's RGB in
// [0, 1], read without any colour decoding, is n = 2 rgb - 1 in the frame (dp/du, dp/dv, n).
struct NormalMapMaterial {
  int normal_map = -1;  // index into SceneDesc::textures
  int material = -1;
  PerturbedNormalOptions options;
};

// Shading normals from a height field (Mitsuba's "bumpmap"): the surface displaced by
// scale * height(u, v) along its normal; the height texture's finite differences in u and v tilt
// the normal.
struct BumpMapMaterial {
  int height = -1;  // index into SceneDesc::textures (its channel average is the height)
  float scale = 1;
  int material = -1;
  PerturbedNormalOptions options;
};

using MaterialDesc = std::variant<DiffuseMaterial, PhongMaterial, MirrorMaterial, DielectricMaterial, BlackMaterial,
                                  ConductorMaterial, CoatedDiffuseMaterial, DiffuseTransmissionMaterial,
                                  InterfaceMaterial, PrincipledMaterial, OneSidedMaterial, MaskMaterial,
                                  BlendMaterial, NormalMapMaterial, BumpMapMaterial, TwoSidedMaterial>;

// ---------------------------------------------------------------- shapes

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

// Sphere of `radius` around `center`, in object space (then to_world applies).
struct SphereShape {
  Point3 center{0.0f};
  float radius = 1;
};

// Infinite plane through `point` with normal `normal` (object space).
struct PlaneShape {
  Point3 point{0.0f};
  Normal3 normal{0, 1, 0};
};

// Axis-aligned box [lo, hi] in object space; to_world may rotate and scale it.
struct BoxShape {
  Point3 lo{-1.0f}, hi{1.0f};
};

// Parallelogram corner + s*edge_u + t*edge_v, (s,t) in [0,1]^2; normal = normalize(cross(edge_u, edge_v)).
struct RectangleShape {
  Point3 corner{-1, -1, 0};
  Vec3 edge_u{2, 0, 0}, edge_v{0, 2, 0};
};

struct MeshShape {
  TriangleMesh mesh;
};

// Disk of radius 1 around the origin in the z = 0 plane, normal +z (Mitsuba's "disk"); to_world
// scales it. (u, v) = (r, phi / 2 pi), as Mitsuba parameterises it.
struct DiskShape {};

// Open tube (no caps) of `radius` around the segment p0-p1 (Mitsuba's "cylinder"), normals pointing
// outwards; (u, v) = (phi / 2 pi, distance along the axis / its length).
struct CylinderShape {
  Point3 p0{0.0f}, p1{0, 0, 1};
  float radius = 1;
};

// How an SDF grid's shading normal is found (Mitsuba's sdfgrid "normals").
enum class SdfNormals {
  Smooth,   // Hansson-Söderlund et al.'s blend of the gradients of the voxels around the hit, continuous
            // across voxel faces (Mitsuba's default)
  Analytic  // the gradient of the hit voxel's trilinear interpolant, as the geometric normal
};

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

using ShapeGeometry =
    std::variant<SphereShape, PlaneShape, BoxShape, RectangleShape, MeshShape, DiskShape, CylinderShape, SdfGridShape>;

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
  SourceLocation where;
};

// ---------------------------------------------------------------- participating media

// A quantity that varies over space (Mitsuba's volume plugins): a constant, or samples on a grid over
// the unit cube [0,1]^3 of its own space, which to_world places in the scene. Sample (i, j, k) sits at
// the voxel centre ((i + 0.5) / nx, (j + 0.5) / ny, (k + 0.5) / nz); values in between are trilinear,
// and between the outermost centres and the cube's faces they are clamped (Mitsuba's gridvolume with
// its default wrap mode "clamp") or fade to zero (pbrt-v4's grids, whose samples beyond the grid are 0).
enum class VolumeBorder { Clamp, Zero };
struct VolumeDesc {
  RGB constant{1.0f};  // the value everywhere when there is no grid
  std::array<int, 3> resolution{0, 0, 0};
  int channels = 1;  // 1 (a scalar) or 3 (RGB)
  // nx ny nz channels floats, a sample's channels together, x fastest, then y, then z; null = constant.
  std::shared_ptr<const std::vector<float>> values;
  Transform to_world;    // the grid's unit cube to world space
  VolumeBorder border = VolumeBorder::Clamp;
  std::string filename;  // where it was read from, for messages (empty: made in memory)
  std::string grid_name;  // the grid within an OpenVDB or NanoVDB file
  // The part of to_world that the file itself gives (a VDB grid's voxel placement; identity for .vol
  // files and inline grids): to_world = the scene's own placement x file_to_world.
  Transform file_to_world;
  bool is_constant() const { return !values; }
};

// A participating medium (pbrt-v4's homogeneous and uniformgrid, Mitsuba 3's homogeneous and
// heterogeneous): extinction sigma_t(p) = scale * sigma_t * density(p), of which the fraction
// albedo(p) scatters (sigma_s = albedo sigma_t) and the rest is absorbed (sigma_a = sigma_t - sigma_s).
// A medium whose density is a grid has no density outside the grid's cube (Mitsuba bounds a
// heterogeneous medium by its volume's box). It emits radiance Le(p) (`emission`, or a temperature's
// blackbody, times an emission scale) in proportion to absorption (the source term sigma_a Le, as
// pbrt-v4 defines Le). Light scatters by Henyey-Greenstein's phase
// function with mean cosine g in (-1, 1) (0: isotropic).
struct MediumDesc {
  RGB sigma_t{1.0f};    // per unit length, times density and scale
  VolumeDesc density;   // a scalar; constant 1 = homogeneous
  VolumeDesc albedo;    // RGB in [0, 1]
  float scale = 1;
  RGB emission{0.0f};
  // Emission that varies through the medium (pbrt-v4's grid and NanoVDB media): the radiance emitted
  // at p is emission_scale(p) times, with a temperature, pbrt-v4's peak-normalised blackbody
  // (spectral/blackbody.h) at (temperature(p) - temperature_offset) x temperature_scale kelvin where
  // that exceeds temperature_cutoff (nothing elsewhere), and without one `emission`.
  VolumeDesc emission_scale;               // a scalar >= 0; constant 1 by default
  std::optional<VolumeDesc> temperature;  // a scalar (kelvin before offset and scale)
  float temperature_scale = 1, temperature_offset = 0, temperature_cutoff = 100;
  float g = 0;
  // A density grid's majorant: the largest density over cells of this many samples along each axis
  // (at most 64 cells per axis), traversed cell by cell; 0 = one majorant for the whole grid (what
  // Mitsuba does by default, majorant_resolution_factor = 0). Changes the noise, not the expectation.
  int majorant_cell_samples = 4;
  std::string name;      // for messages
  SourceLocation where;  // where the scene file declares it
  bool is_homogeneous() const { return density.is_constant() && albedo.is_constant(); }
};

// pbrt-v4's and JSON's way of giving a medium: absorption and scattering coefficients.
inline void set_sigma_a_sigma_s(MediumDesc& m, const RGB& sigma_a, const RGB& sigma_s) {
  m.sigma_t = sigma_a + sigma_s;
  m.albedo.constant = {m.sigma_t.r > 0 ? sigma_s.r / m.sigma_t.r : 0.0f, m.sigma_t.g > 0 ? sigma_s.g / m.sigma_t.g : 0.0f,
                       m.sigma_t.b > 0 ? sigma_s.b / m.sigma_t.b : 0.0f};
}

// ---------------------------------------------------------------- lights (those that are not shapes)

struct PointLight {
  Point3 position{0.0f};
  RGB intensity{1.0f};  // W/sr
};

// Point light emitting into a cone around `direction`: full intensity inside cone_angle - cone_delta,
// falling off to zero at cone_angle with pbrt-v4's smoothstep in cos(angle), or (mitsuba_falloff)
// with Mitsuba 3's spot: linearly in the angle from beam width = cone_angle - cone_delta to cone_angle,
// times the image `texture` projected over the cone (-1 = none), as Mitsuba defines both.
struct SpotLight {
  Point3 position{0.0f};
  Vec3 direction{0, 0, 1};
  RGB intensity{1.0f};  // W/sr on the axis
  float cone_angle = 30;  // degrees from the axis where the light reaches zero
  float cone_delta = 5;   // degrees over which it falls off
  bool mitsuba_falloff = false;
  int texture = -1;      // index into SceneDesc::textures
  Vec3 up{0, 1, 0};      // with a texture: the image's up direction (the light frame's +y)
};

// A point light that projects an image (Mitsuba's "projector"): at the origin of to_world looking
// along its +z with the field of view `fov_degrees` on the image's wider axis; `irradiance` is the
// image (index into SceneDesc::textures), scaled by `scale`, as Mitsuba defines it (irradiance on a
// surface one unit away facing the projector).
struct ProjectorLight {
  Transform to_world;
  float fov_degrees = 90;
  int irradiance = -1;
  RGB scale{1.0f};
};

// Parallel light from infinitely far away, travelling along `direction`; `radiance` is the
// irradiance it delivers to a surface facing it (pbrt-v4's distant "L").
struct DistantLight {
  Vec3 direction{0, 0, 1};
  RGB radiance{1.0f};
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

// An environment map: radiance from every direction read from an image, importance-sampled.
struct EnvironmentMap {
  std::string filename;  // resolved by the reader
  EnvironmentMapping mapping = EnvironmentMapping::Equirectangular;
  RGB scale{1.0f};
  Transform to_world;  // from the map's local frame to the world (rotations only are meaningful)
  bool mis_compensation = false;  // sample by luminance minus its mean (environment_light.h)
};

using LightDesc = std::variant<PointLight, SkyLight, SpotLight, DistantLight, EnvironmentMap, ProjectorLight>;

// ---------------------------------------------------------------- camera, film, settings

enum class FovAxis { X, Y, Smaller, Larger, Diagonal };
enum class Projection {
  Perspective,
  // Parallel rays along +z; the film covers camera-space x in [-1, 1] and y in [-1 / aspect,
  // 1 / aspect] (aspect = width / height), as Mitsuba's orthographic sensor; world_from_camera
  // scales it.
  Orthographic
};

struct CameraDesc {
  // Maps camera space (+x image right, +y image up, +z forward) to world space. It may scale
  // (orthographic cameras); directions are normalised after it.
  Transform world_from_camera;
  Projection projection = Projection::Perspective;
  // Nothing nearer than this (along +z, in camera space) is seen by camera rays (Mitsuba's near_clip).
  float near_clip = 0;
  float fov_degrees = 40;
  FovAxis fov_axis = FovAxis::Y;  // JSON gives a vertical fov; pbrt-v4 gives it on the smaller axis
  // Thin lens (depth of field): 0 = pinhole. Points at focus_distance along +z are sharp.
  float lens_radius = 0;
  float focus_distance = 1e6f;
  // Each camera path gets a time uniformly in [shutter_open, shutter_close] (motion blur).
  float shutter_open = 0, shutter_close = 1;
  // The participating medium the camera sits in (index into SceneDesc::media; -1 = vacuum).
  int medium = -1;
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

struct FilmDesc {
  int width = 512;
  int height = 512;
  std::string filename;  // empty = the command line's default
  // The AOV layers written beside the colour in an EXR output, as --aov takes them ("albedo,normal";
  // film/aov_film.h); empty = none. The command line's --aov replaces it.
  std::string aovs;
};

// How pixel samples are placed (Häkkinen 2002, sec. 4.3).
enum class SamplerType {
  Independent,  // uniform random numbers
  Stratified,   // jittered strata in every dimension, shuffled per pixel (pbrt-v4's StratifiedSampler)
  Poisson,      // Poisson-disc pixel positions with a minimum distance; other dimensions independent
  ZSobol        // Owen-scrambled Sobol' points in Morton order over the image (pbrt-v4's ZSobolSampler)
};
struct SamplerDesc {
  // Independent here; the readers choose ZSobol when a scene names no sampler (pbrt-v4's default,
  // and the most efficient measured in docs/performance.md).
  SamplerType type = SamplerType::Independent;
  bool jitter = true;  // stratified: false puts each sample at its stratum's centre
  // Draw every pixel's samples as two independently randomised halves, so the render can estimate
  // its own error (film/error_estimate.h): ZSobol as two interleaved replicas of its sequence, the
  // set-based samplers (stratified, poisson) in sets of half the samples or of one pass. Set by
  // --estimate-error and --target-error. The independent sampler's halves are always independent.
  bool replicas = false;
};

// Pixel reconstruction filters; every sample contributes to its own pixel only, with the weight
// f(offset) / pdf(offset) of filter importance sampling (pbrt-v4).
enum class FilterType { Box, Tent, Gaussian, Mitchell };
struct FilterDesc {
  FilterType type = FilterType::Box;
  Vec2 radius{0.5f, 0.5f};    // in pixels; pbrt's defaults: box 0.5, triangle 2, gaussian 1.5, mitchell 2
  float gaussian_sigma = 0.5f;
  float mitchell_b = 1.0f / 3, mitchell_c = 1.0f / 3;
};

// A filter of the given type with pbrt-v4's default parameters.
inline FilterDesc default_filter(FilterType type) {
  FilterDesc f;
  f.type = type;
  float r = type == FilterType::Box ? 0.5f : type == FilterType::Gaussian ? 1.5f : 2.0f;
  f.radius = {r, r};
  return f;
}

// How the next direction is chosen at non-delta vertices (sec. 4.7).
enum class DirectionSampling {
  Bsdf,     // importance-sample the BSDF's lobes
  Cosine,   // cosine-weighted hemisphere, weighted by the BSDF
  Uniform   // uniform hemisphere (the paper's eq. 11), weighted by the BSDF
};

// How Embree lays out the triangles' acceleration structure.
enum class BvhLayout {
  Fast,    // leaves hold copies of their triangles' vertices: the fastest traversal
  Compact  // leaves index into the shared vertex arrays (Embree's RTC_SCENE_FLAG_COMPACT): about half
           // the memory per triangle, traversal about a third slower (docs/performance.md)
};

// How shadow rays are spent at each vertex (sec. 4.5).
enum class LightSelection {
  Power,   // `shadow_rays` rays, each to one light chosen with probability proportional to its power
  Paper,   // every light gets a share of `shadow_rays` proportional to power x projected solid angle
           // as seen from the vertex (stratified over rectangles), kept unbiased
  Uniform, // as Power, but every emitter (a light, or an emissive shape with all its triangles) is
           // equally likely, and a shape's triangles by area (Mitsuba's choice): robust where power
           // misjudges, as for a small spot beside a large sky
  Bvh      // as Power, but each vertex chooses through a light BVH by the power, distance and
           // orientation its lights could have there (lights/light_sampler.h; pbrt-v4's default):
           // near lights and lights facing the vertex get the rays, O(log n) per choice
};

// Settings only the path tracer reads (integrator "path"; docs/cli.md lists the flags).
struct PathSettings {
  DirectionSampling direction_sampling = DirectionSampling::Bsdf;
  bool mis = true;  // false: light sampling for direct light, emission found by bounces ignored
  int shadow_rays = 1;  // per path vertex
  bool operator==(const PathSettings&) const = default;
};

// Metropolis light transport's settings (integrator "mlt"; RenderSettings::spp is then the number
// of mutations per pixel): bootstrap states per depth, independent chains, the deviation of small
// steps in primary sample space and the probability of a large step (pbrt's defaults), and the
// probabilities of a lens and of a caustic perturbation (mlt_sampler.h); the rest are small steps.
struct MltSettings {
  int bootstrap = 100000;
  int chains = 1000;
  float sigma = 0.01f;
  float large_step = 0.3f;
  float lens = 0;
  float caustic = 0;
  bool operator==(const MltSettings&) const = default;
  // Why these are not a valid set (the mutation probabilities sum past 1), or empty: the one
  // check behind the command line's and the readers' messages.
  std::string problem() const {
    float sum = large_step + lens + caustic;
    return sum > 1 ? fmt::format("large_step + lens + caustic must be at most 1, got {}", sum) : std::string();
  }
  // For image metadata and checkpoint fingerprints.
  std::string describe() const {
    return fmt::format("bootstrap {} chains {} sigma {} large-step {} lens {} caustic {}", bootstrap, chains, sigma,
                       large_step, lens, caustic);
  }
};

// What a render does. The fields outside `path` and `mlt` are read by more than one integrator;
// integrators/integrator.h's registry says which integrator reads which, and the readers and the
// command line reject a setting the chosen integrator does not read.
struct RenderSettings {
  int spp = 16;
  int max_depth = 16;  // maximum number of scattering events; 1 = direct lighting only
  uint64_t seed = 0;
  std::string integrator = "path";
  int rr_start_depth = 3;  // Russian roulette on throughput starts after this many bounces (path, bdpt)
  SamplerDesc sampler;
  FilterDesc filter;
  bool hide_emitters = false;  // emitters seen directly by the camera (depth 0) are not shown (Mitsuba's)
  // Spectral transport (spectral/wavelengths.h): each sample carries four wavelengths and RGB
  // parameters become smooth spectra, as in pbrt-v4; off = RGB transport.
  bool spectral = false;
  // Power, uniform and bvh choose lights for every integrator (scene.h's light_sampler()); the
  // paper's rule is the path tracer's alone.
  LightSelection light_selection = LightSelection::Power;
  BvhLayout bvh = BvhLayout::Fast;
  // Adaptive sampling (sec. 4.3; path and bdpt), on when a threshold or a budget is set (then `spp`
  // is unused). Every pixel first gets `adaptive_batch` samples (a power of two). With a threshold,
  // pixels whose relative standard error falls below it get no more. With a budget of
  // `adaptive_spp` samples per pixel on average, the rest of the budget goes, in rounds, to each
  // pixel in proportion to its estimated relative deviation (the allocation that minimises the
  // image's relMSE); without a budget every pixel above the threshold gets another batch per
  // round. No pixel gets more than `adaptive_max_spp` (0: 1024, or 8 x adaptive_spp with a budget).
  float adaptive_threshold = 0;
  int adaptive_spp = 0;
  int adaptive_batch = 16;
  int adaptive_max_spp = 0;
  bool adaptive() const { return adaptive_threshold > 0 || adaptive_spp > 0; }
  int adaptive_spp_limit() const {
    if (adaptive_max_spp > 0) return adaptive_max_spp;
    return adaptive_spp > 0 ? int(std::min<int64_t>(8 * int64_t(adaptive_spp), std::numeric_limits<int>::max())) : 1024;
  }
  PathSettings path;
  MltSettings mlt;
};

struct SceneDesc {
  CameraDesc camera;
  FilmDesc film;
  RenderSettings settings;
  std::vector<TextureDesc> textures;
  std::vector<MaterialDesc> materials;
  std::vector<ShapeDesc> shapes;
  std::vector<ObjectDesc> objects;
  std::vector<InstanceDesc> instances;
  std::vector<LightDesc> lights;
  std::vector<MediumDesc> media;  // referred to by shapes' interior/exterior and the camera
  // The times at which ShapeDesc::to_world and to_world_end hold (pbrt's TransformTimes).
  float transform_start_time = 0, transform_end_time = 1;
  std::string source_file;  // the file it was read from, for messages and image metadata
  // Where the scene file declares each texture, material and light (parallel to those vectors;
  // shorter, or an empty file, where a reader does not know): errors found while building the
  // render scene name that place.
  struct Places {
    std::vector<SourceLocation> textures, materials, lights;
  } places;
};

}  // namespace candela
