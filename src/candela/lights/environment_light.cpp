#include "candela/lights/environment_light.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "candela/film/image_io.h"
#include "candela/base/error.h"
#include "candela/sampling/distribution2d.h"
#include "candela/sampling/warp.h"

namespace candela {

namespace {

// The upper-left 3x3 of a 4x4 matrix, in float.
std::array<Vec3, 3> rows_of(const Matrix4& m) {
  std::array<Vec3, 3> r;
  for (int i = 0; i < 3; ++i) r[size_t(i)] = Vec3(float(m.m[i][0]), float(m.m[i][1]), float(m.m[i][2]));
  return r;
}

Vec3 apply(const std::array<Vec3, 3>& rows, const Vec3& v) {
  return {dot(rows[0], v), dot(rows[1], v), dot(rows[2], v)};
}

float non_negative(float v) { return v > 0 && std::isfinite(v) ? v : 0.0f; }

}  // namespace

struct EnvironmentLight::Data {
  int width = 0, height = 0;
  EnvironmentMapping mapping = EnvironmentMapping::Equirectangular;
  std::vector<RGB> texels;  // scaled, row-major, top row first
  bool nearest = false;     // lookups take the texel the point falls in, not a bilinear blend
  Distribution2D distribution;
  std::array<Vec3, 3> world_from_light, light_from_world;
  float scene_radius = 1;
  float average_luminance = 0;

  // The texel at integer coordinates one step outside the image at most, wrapped as the mapping
  // continues across the image's edges.
  bool latitude_longitude() const { return mapping != EnvironmentMapping::EqualAreaOctahedral; }
  bool pole_rows() const { return mapping == EnvironmentMapping::EquirectangularPoleRows; }

  const RGB& texel(int x, int y) const {
    if (latitude_longitude()) {
      // Periodic in phi; the top and bottom rows extend to the poles.
      x = x < 0 ? x + width : (x >= width ? x - width : x);
      y = std::clamp(y, 0, height - 1);
    } else {
      // The square's edges fold onto themselves: across the left or right edge lies the same
      // column mirrored top to bottom, across the top or bottom edge the same row mirrored left to
      // right (pbrt-v4's OctahedralSphere wrap, mirrored about the edge itself).
      if (x < 0 || x >= width) {
        x = x < 0 ? -1 - x : 2 * width - 1 - x;
        y = height - 1 - y;
      }
      if (y < 0 || y >= height) {
        y = y < 0 ? -1 - y : 2 * height - 1 - y;
        x = width - 1 - x;
      }
      x = std::clamp(x, 0, width - 1);
      y = std::clamp(y, 0, height - 1);
    }
    return texels[size_t(y) * size_t(width) + size_t(x)];
  }

  // The radiance at uv: the nearest texel's, or the bilinear blend of the four around uv.
  RGB lookup(Vec2 uv) const {
    if (!nearest) return bilinear(uv);
    const int x = std::clamp(int(uv.x * float(width)), 0, width - 1);
    const int y = std::clamp(int(uv.y * float(height)), 0, height - 1);
    return texels[size_t(y) * size_t(width) + size_t(x)];
  }

  RGB bilinear(Vec2 uv) const {
    // Continuous pixel coordinates with texel centres at integers (Mitsuba's rows: row 0 at v = 0,
    // the last row at v = 1).
    float x = uv.x * float(width) - 0.5f;
    float y = pole_rows() ? uv.y * float(height - 1) : uv.y * float(height) - 0.5f;
    float fx0 = std::floor(x), fy0 = std::floor(y);
    float dx = x - fx0, dy = y - fy0;
    int x0 = std::clamp(int(fx0), -1, width - 1);
    int y0 = pole_rows() ? std::clamp(int(fy0), 0, height - 2) : std::clamp(int(fy0), -1, height - 1);
    if (pole_rows()) dy = std::clamp(y - float(y0), 0.0f, 1.0f);
    return (texel(x0, y0) * (1 - dx) + texel(x0 + 1, y0) * dx) * (1 - dy) +
           (texel(x0, y0 + 1) * (1 - dx) + texel(x0 + 1, y0 + 1) * dx) * dy;
  }

  Vec2 direction_to_uv(const Vec3& d) const {
    if (mapping == EnvironmentMapping::EqualAreaOctahedral) return equal_area_sphere_to_square(d);
    // Invert (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi)).
    float u = std::atan2(d.x, -d.z) * kInv2Pi;
    if (u < 0) u += 1;
    float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) * kInvPi;
    return {u, v};
  }
  Vec3 uv_to_direction(Vec2 uv) const {
    if (mapping == EnvironmentMapping::EqualAreaOctahedral) return equal_area_square_to_sphere(uv);
    float phi = 2 * kPi * uv.x, theta = kPi * uv.y;
    float sin_theta = std::sin(theta);
    return {sin_theta * std::sin(phi), std::cos(theta), -sin_theta * std::cos(phi)};
  }
  // The sampling distribution's cells. Centred rows: the pixels themselves. Pole rows: the
  // (height - 1) x width patches between texel centres, patch (i, j) spanning u in
  // [(i + 1/2) / width, (i + 3/2) / width] (wrapping) and v in [j / (height - 1), (j + 1) / (height - 1)].
  // Both grids cover the unit square, so a density over one is the same density over (u, v).
  int cells_y() const { return pole_rows() ? height - 1 : height; }
  Vec2 cell_to_image(Vec2 p) const {
    if (!pole_rows()) return p;
    float u = p.x + 0.5f / float(width);
    return {u >= 1 ? u - 1 : u, p.y};
  }
  Vec2 image_to_cell(Vec2 uv) const {
    if (!pole_rows()) return uv;
    float u = uv.x - 0.5f / float(width);
    return {u < 0 ? u + 1 : u, uv.y};
  }

  // Converts a density over (u, v) into one over solid angle at the local direction d.
  float solid_angle_pdf(float pdf_uv, const Vec3& d) const {
    if (mapping == EnvironmentMapping::EqualAreaOctahedral) return pdf_uv * kInv4Pi;
    // d(omega) = sin(theta) dtheta dphi = 2 pi^2 sin(theta) du dv; the poles have no density.
    float sin_theta = std::sqrt(d.x * d.x + d.z * d.z);
    return sin_theta > 0 ? pdf_uv / (2 * kPi * kPi * sin_theta) : 0.0f;
  }
};

EnvironmentLight::EnvironmentLight(const Image& image, EnvironmentMapping mapping, const RGB& scale,
                                   const Transform& world_from_light, float scene_radius, bool mis_compensation,
                                   bool nearest) {
  if (image.width <= 0 || image.height <= 0 || image.rgb.size() < size_t(image.width) * size_t(image.height) * 3)
    throw SceneError("environment map: the image is empty");
  if (mapping == EnvironmentMapping::EqualAreaOctahedral && image.width != image.height)
    throw SceneError(fmt::format("environment map: an equal-area octahedral map must be square, not {}x{}",
                                 image.width, image.height));
  if (mapping == EnvironmentMapping::EquirectangularPoleRows && image.height < 2)
    throw SceneError(fmt::format("environment map: a map whose rows run from pole to pole needs at least 2 rows, "
                                 "not {}",
                                 image.height));
  auto d = std::make_shared<Data>();
  const int w = image.width, h = image.height;
  d->width = w;
  d->height = h;
  d->mapping = mapping;
  // Pole rows blend between the rows' centres by construction: they stay bilinear.
  d->nearest = nearest && mapping != EnvironmentMapping::EquirectangularPoleRows;
  d->scene_radius = scene_radius;
  d->world_from_light = rows_of(world_from_light.matrix());
  d->light_from_world = rows_of(world_from_light.inverse_matrix());
  d->texels.resize(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      RGB c = image.at(x, y);
      RGB s = RGB(non_negative(c.r), non_negative(c.g), non_negative(c.b)) * scale;
      d->texels[size_t(y) * size_t(w) + size_t(x)] = RGB(non_negative(s.r), non_negative(s.g), non_negative(s.b));
    }

  // Sampling weights, one per cell (cell_to_image), each the luminance the bilinear radiance has on
  // average over the cell, with the same wrapping as lookups, times the cell's solid angle: positive
  // wherever the radiance is, however dark one texel. Over a pixel of centred rows that average is the
  // separable [1 6 1] / 8 filter of the texels (a neighbour's tent reaches halfway into the pixel with
  // 1/8 of its area); over a patch between texel centres it is the mean of its four corners.
  const int cells_y = d->cells_y();
  // MIS compensation subtracts the mean texel luminance (unless the map is nearly constant, where it
  // would leave nothing), as Mitsuba's envmap does.
  float offset = 0;
  if (mis_compensation) {
    double sum = 0;
    float least = std::numeric_limits<float>::infinity();
    for (const RGB& t : d->texels) {
      sum += t.luminance();
      least = std::min(least, t.luminance());
    }
    offset = float(sum / double(d->texels.size()));
    if (offset - least <= 0.01f * offset) offset = 0;
  }
  std::vector<float> weights(size_t(w) * size_t(cells_y));
  std::vector<char> radiant(weights.size(), 0);
  const float k[3] = {0.125f, 0.75f, 0.125f};
  constexpr double pi = std::numbers::pi;
  double integral = 0;  // of the luminance over solid angle
  for (int y = 0; y < cells_y; ++y) {
    // The cell's share of the sphere's solid angle (4 pi in all): for latitude-longitude maps the
    // exact solid angle of its row, which stays positive in the polar rows.
    double cell_solid_angle;
    if (mapping == EnvironmentMapping::EqualAreaOctahedral)
      cell_solid_angle = 4 * pi / (double(w) * h);
    else
      cell_solid_angle = 2 * pi / w * (std::cos(pi * y / cells_y) - std::cos(pi * (y + 1) / cells_y));
    for (int x = 0; x < w; ++x) {
      double lum = 0;
      if (d->nearest) {
        lum = d->texel(x, y).luminance();  // constant over the cell
      } else if (d->pole_rows()) {
        lum = 0.25 * (double(d->texel(x, y).luminance()) + d->texel(x + 1, y).luminance() +
                      d->texel(x, y + 1).luminance() + d->texel(x + 1, y + 1).luminance());
      } else {
        for (int j = -1; j <= 1; ++j)
          for (int i = -1; i <= 1; ++i) lum += k[i + 1] * k[j + 1] * d->texel(x + i, y + j).luminance();
      }
      integral += lum * cell_solid_angle;
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      weights[i] = float(std::max(lum - offset, 0.0) * cell_solid_angle);
      radiant[i] = lum > 0;
    }
  }
  // A floor under every pixel that has any radiance, so that in a map with a very bright sun the
  // float CDF still resolves the dim pixels (any positive floor keeps the estimator unbiased).
  double mean_weight = 0;
  for (float wt : weights) mean_weight += wt;
  mean_weight /= double(weights.size());
  for (size_t i = 0; i < weights.size(); ++i)
    if (radiant[i]) weights[i] = std::max(weights[i], float(1e-3 * mean_weight));
  d->distribution = Distribution2D(weights, w, cells_y);
  d->average_luminance = float(integral / (4 * pi));
  data_ = std::move(d);
}

EnvironmentMapping EnvironmentLight::mapping() const { return data_->mapping; }
Vec2 EnvironmentLight::direction_to_uv(const Vec3& local_dir) const { return data_->direction_to_uv(local_dir); }
Vec3 EnvironmentLight::uv_to_direction(Vec2 uv) const { return data_->uv_to_direction(uv); }
Vec3 EnvironmentLight::to_local(const Vec3& world_dir) const {
  return normalize(apply(data_->light_from_world, world_dir));
}
Vec3 EnvironmentLight::to_world(const Vec3& local_dir) const {
  return normalize(apply(data_->world_from_light, local_dir));
}
RGB EnvironmentLight::lookup(Vec2 uv) const { return data_->lookup(uv); }
float EnvironmentLight::average_luminance() const { return data_->average_luminance; }

RGB EnvironmentLight::radiance(const Vec3& world_dir) const {
  Vec3 local = to_local(world_dir);
  if (!is_finite(local)) return RGB(0.0f);
  return data_->lookup(data_->direction_to_uv(local));
}

LightSample EnvironmentLight::sample_li(const LightSampleContext& ctx, Vec2 u) const {
  const Data& d = *data_;
  // Pick a cell by the 2D distribution and a point uniformly inside it, then map it to the sphere.
  Distribution2DSample s = d.distribution.sample(u);
  if (!(s.pdf > 0)) return {};
  const Vec2 uv = d.cell_to_image(s.point);
  Vec3 local = d.uv_to_direction(uv);
  // Convert the density over the image to one over solid angle.
  float pdf = d.solid_angle_pdf(s.pdf, local);
  if (!(pdf > 0) || !std::isfinite(pdf)) return {};
  Vec3 wi = to_world(local);
  LightSample ls;
  ls.radiance = d.lookup(uv);
  ls.wi = wi;
  ls.distance = std::numeric_limits<float>::infinity();
  ls.pdf = pdf;
  ls.p_light = ctx.p + wi * (2 * d.scene_radius);  // stands in for "infinitely far", as pbrt-v4
  ls.n_light = -wi;
  return ls;
}

float EnvironmentLight::pdf_li(const LightSampleContext&, const Vec3& wi, const Point3&, const Normal3&) const {
  const Data& d = *data_;
  Vec3 local = to_local(wi);
  if (!is_finite(local)) return 0;
  return d.solid_angle_pdf(d.distribution.pdf(d.image_to_cell(d.direction_to_uv(local))), local);
}

LightEmission EnvironmentLight::sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere& s) const {
  LightSample ls = sample_li({}, u_dir);
  if (!(ls.pdf > 0)) return {};
  Vec3 w = -ls.wi;
  return {ls.radiance, point_on_scene_disk(s, w, u_pos), w, Normal3(0.0f), 1 / (kPi * s.radius * s.radius), ls.pdf};
}

EmissionPdf EnvironmentLight::pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere& s) const {
  return {1 / (kPi * s.radius * s.radius), pdf_li({}, -w, {}, {})};
}

float EnvironmentLight::power() const {
  const Data& d = *data_;
  return kPi * d.scene_radius * d.scene_radius * 4 * kPi * d.average_luminance;
}

float EnvironmentLight::importance(const LightSampleContext&) const { return kPi * data_->average_luminance; }

EnvironmentLight make_environment_light(const EnvironmentMap& desc, float scene_radius) {
  std::shared_ptr<const Image> image;
  try {
    image = read_image_shared(desc.filename, IntegerEncoding::SRGB);
  } catch (const std::exception& e) {
    // read_image's message names the file already.
    throw SceneError(fmt::format("environment map: {}", e.what()));
  }
  try {
    return EnvironmentLight(*image, desc.mapping, desc.scale, desc.to_world, scene_radius, desc.mis_compensation,
                            desc.filter == TextureFilter::Nearest);
  } catch (const SceneError& e) {
    throw SceneError(fmt::format("{}: {}", desc.filename, e.what()));
  }
}

}  // namespace candela
