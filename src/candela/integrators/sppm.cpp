#include "candela/integrators/sppm.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/film/filter.h"
#include "candela/integrators/bdpt.h"
#include "candela/integrators/path_integrator.h"
#include "candela/render/progress.h"
#include "candela/sampling/samplers.h"

namespace candela {
namespace {

using SppmClock = std::chrono::steady_clock;

double sppm_seconds_since(SppmClock::time_point start) {
  return std::chrono::duration<double>(SppmClock::now() - start).count();
}

// Whether the BSDF has a diffuse lobe (pbrt-v4's BxDFFlags::Diffuse): Lambertian reflection or
// transmission, alone or under a coating, or the diffuse part of a mixture. Conductors, rough
// dielectrics and coated conductors are only glossy; mirrors and smooth glass only specular.
bool sppm_has_diffuse_lobe(const SurfaceBsdf& bsdf) {
  for (int k = 0; k < bsdf.count; ++k) {
    const SurfaceBsdf::Component& c = bsdf.components[size_t(k)];
    if (!(c.weight > 0)) continue;
    const bool diffuse = std::visit(
        [](const auto& b) {
          using T = std::decay_t<decltype(b)>;
          return std::is_same_v<T, DiffuseBsdf> || std::is_same_v<T, PhongBsdf> ||
                 std::is_same_v<T, CoatedDiffuseBsdf> || std::is_same_v<T, DiffuseTransmissionBsdf> ||
                 std::is_same_v<T, PrincipledBsdf> || std::is_same_v<T, PrincipledThinBsdf> ||
                 std::is_same_v<T, LayeredDiffuseBsdf>;
        },
        c.bsdf);
    if (diffuse && bsdf_has_non_delta(c.bsdf)) return true;
  }
  return false;
}

// Where a camera path stops to gather photons (step 1).
struct SppmVisiblePoint {
  Point3 p;
  Vec3 wo_local;  // towards the camera, in the shading frame
  Shading shading;
  RGB beta;  // the camera path's throughput up to here, times the pixel filter's weight
  bool valid = false;
};

// A pixel's progressive estimate (step 4) and its direct light.
struct SppmPixel {
  float radius = 0;
  float n = 0;      // N: the photons the estimate holds, after the alpha reductions
  double ld[3] = {0, 0, 0};   // the camera paths' light (emission, direct light), summed over iterations
  double tau[3] = {0, 0, 0};  // the flux within the radius, rescaled as it shrinks
};

// The visitor that leaves the visible point at the first diffuse surface (or a glossy one at the
// maximum depth) and ends the camera path there (PathIntegrator runs one more bounce for the
// emission along its sampled direction).
class SppmVisiblePointVisitor final : public PathVertexVisitor {
 public:
  SppmVisiblePointVisitor(SppmVisiblePoint& vp, int max_depth) : vp_(vp), max_depth_(max_depth) {}
  bool visit(const PathVertexView& v) override {
    const SurfaceBsdf& bsdf = v.shading.bsdf;
    if (!(sppm_has_diffuse_lobe(bsdf) || (bsdf_has_non_delta(bsdf) && v.depth == max_depth_))) return false;
    vp_.p = v.hit.p;
    vp_.wo_local = v.shading.frame.to_local(v.wo);
    vp_.shading = v.shading;
    vp_.beta = v.beta;
    vp_.valid = true;
    return true;
  }

 private:
  SppmVisiblePoint& vp_;
  int max_depth_;
};

// Step 2: a uniform grid over the visible points' spheres of radius r, hashed into a table of lists
// (each list the visible points whose sphere overlaps a cell hashing there).
class SppmGrid {
 public:
  void build(const std::vector<SppmVisiblePoint>& vps, const std::vector<SppmPixel>& pixels) {
    lo_ = Point3(std::numeric_limits<float>::infinity());
    Point3 hi(-std::numeric_limits<float>::infinity());
    float max_radius = 0;
    for (size_t i = 0; i < vps.size(); ++i) {
      if (!vps[i].valid) continue;
      const float r = pixels[i].radius;
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], vps[i].p[a] - r);
        hi[a] = std::max(hi[a], vps[i].p[a] + r);
      }
      max_radius = std::max(max_radius, r);
    }
    empty_ = !(max_radius > 0);
    if (empty_) return;
    // Cells about as large as the largest radius (pbrt-v4's choice), at most 2^20 along an axis.
    const Vec3 diag = hi - lo_;
    const float max_diag = std::max({diag.x, diag.y, diag.z});
    const float base = std::min(max_diag / max_radius, float(1 << 20));
    for (int a = 0; a < 3; ++a) {
      res_[a] = std::max(1, int(base * diag[a] / max_diag));
      inv_cell_[a] = diag[a] > 0 ? float(res_[a]) / diag[a] : 0.0f;
    }
    // A power-of-two table of about one bucket per visible point.
    size_t buckets = 1;
    while (buckets < vps.size()) buckets <<= 1;
    mask_ = buckets - 1;
    // Count the entries per bucket, lay the buckets out, then fill them (any order: see sppm.h).
    std::vector<std::atomic<uint32_t>> count(buckets);
    for (auto& c : count) c.store(0, std::memory_order_relaxed);
    auto for_each_cell = [&](size_t i, auto&& body) {
      const float r = pixels[i].radius;
      const CellIndex a = cell_of(vps[i].p - Vec3(r)), b = cell_of(vps[i].p + Vec3(r));
      for (int z = a.c[2]; z <= b.c[2]; ++z)
        for (int y = a.c[1]; y <= b.c[1]; ++y)
          for (int x = a.c[0]; x <= b.c[0]; ++x) body(bucket(x, y, z));
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vps.size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i)
        if (vps[i].valid) for_each_cell(i, [&](size_t h) { count[h].fetch_add(1, std::memory_order_relaxed); });
    });
    start_.assign(buckets + 1, 0);
    for (size_t h = 0; h < buckets; ++h) start_[h + 1] = start_[h] + count[h].load(std::memory_order_relaxed);
    entries_.resize(start_[buckets]);
    for (size_t h = 0; h < buckets; ++h) count[h].store(start_[h], std::memory_order_relaxed);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vps.size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i)
        if (vps[i].valid)
          for_each_cell(i, [&](size_t h) { entries_[count[h].fetch_add(1, std::memory_order_relaxed)] = uint32_t(i); });
    });
  }

  // The visible points whose cells hash where p's cell does (a superset of those within their radius
  // of p), or none when p lies outside the grid.
  struct Span {
    const uint32_t* begin = nullptr;
    const uint32_t* end = nullptr;
  };
  Span near(const Point3& p) const {
    if (empty_) return {};
    CellIndex c;
    for (int a = 0; a < 3; ++a) {
      const float g = (p[a] - lo_[a]) * inv_cell_[a];
      if (!(g >= 0) || g >= float(res_[a])) return {};
      c.c[a] = std::min(int(g), res_[a] - 1);
    }
    const size_t h = bucket(c.c[0], c.c[1], c.c[2]);
    return {entries_.data() + start_[h], entries_.data() + start_[h + 1]};
  }

 private:
  struct CellIndex {
    int c[3] = {0, 0, 0};
  };
  CellIndex cell_of(const Point3& p) const {
    CellIndex c;
    for (int a = 0; a < 3; ++a) c.c[a] = std::clamp(int((p[a] - lo_[a]) * inv_cell_[a]), 0, res_[a] - 1);
    return c;
  }
  size_t bucket(int x, int y, int z) const {
    return size_t(hash_values(uint64_t(uint32_t(x)), uint64_t(uint32_t(y)), uint64_t(uint32_t(z)))) & mask_;
  }

  bool empty_ = true;
  Point3 lo_;
  int res_[3] = {1, 1, 1};
  float inv_cell_[3] = {0, 0, 0};
  size_t mask_ = 0;
  std::vector<uint32_t> start_;    // per bucket, its first entry (and one past the last bucket's)
  std::vector<uint32_t> entries_;  // visible point (pixel) indices, bucket by bucket
};

// The iteration's wavelengths in a spectral render: one number per iteration from the van der Corput
// sequence, rotated by the seed (pbrt-v4 takes a radical inverse of the iteration too).
float sppm_wavelength_number(int iteration, uint64_t seed) {
  uint32_t bits = uint32_t(iteration);
  bits = (bits << 16) | (bits >> 16);
  bits = ((bits & 0x00ff00ffu) << 8) | ((bits & 0xff00ff00u) >> 8);
  bits = ((bits & 0x0f0f0f0fu) << 4) | ((bits & 0xf0f0f0f0u) >> 4);
  bits = ((bits & 0x33333333u) << 2) | ((bits & 0xccccccccu) >> 2);
  bits = ((bits & 0x55555555u) << 1) | ((bits & 0xaaaaaaaau) >> 1);
  const float rotation = float(hash_values(seed, 0x6c616d626461) >> 40) * 0x1p-24f;
  const float u = float(bits >> 8) * 0x1p-24f + rotation;
  return std::min(u >= 1 ? u - 1 : u, 0x1.fffffep-1f);
}

class SppmRender {
 public:
  SppmRender(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options)
      : scene_(scene),
        settings_(settings),
        film_(film),
        options_(options),
        width_(film.width()),
        height_(film.height()),
        photons_per_iteration_(sppm_photons_per_iteration(settings, film.width(), film.height())),
        camera_paths_(scene, settings),
        photon_paths_(scene, settings),
        filter_(settings.filter),
        prototype_(make_sampler(settings.sampler, settings.spp, settings.seed, film.width(), film.height())),
        arena_(options.threads > 0 ? options.threads : tbb::task_arena::automatic),
        progress_(uint64_t(settings.spp) * 2, options.progress, options.progress_fraction),
        pixels_(size_t(film.width()) * size_t(film.height())),
        vps_(pixels_.size()),
        phi_(film.width(), film.height()),
        m_(pixels_.size(), 0) {
    for (SppmPixel& p : pixels_) p.radius = settings.sppm.radius;
    // Photon contributions are summed in units of the scene's light power, near the size of a
    // photon's flux, so the fixed-point sums keep their precision whatever the scene's scale.
    double power = 0;
    for (const Light& light : scene.lights()) power += double(light_power(light));
    phi_unit_ = power > 0 && std::isfinite(power) ? power : 1.0;
  }

  RenderStats run() {
    const auto start = SppmClock::now();
    progress_.set_label(fmt::format("SPPM ({} photons per iteration)", photons_per_iteration_));
    int iteration = 0;
    double last_seconds = 0;
    for (; iteration < settings_.spp; ++iteration) {
      if (cancelled()) {
        stats_.cancelled = true;
        break;
      }
      if (options_.time_limit_seconds > 0 && iteration > 0 &&
          sppm_seconds_since(start) + last_seconds > options_.time_limit_seconds) {
        stats_.time_limited = true;
        break;
      }
      const auto iteration_start = SppmClock::now();
      Wavelengths storage;
      const Wavelengths* wl = nullptr;
      if (settings_.spectral) {
        storage = sample_visible_wavelengths(sppm_wavelength_number(iteration, settings_.seed));
        wl = &storage;
      }
      arena_.execute([&] {
        trace_camera_paths(iteration, wl);
        progress_.advance(1);
        grid_.build(vps_, pixels_);
        trace_photons(iteration, wl);
        update_pixels();
      });
      progress_.advance(1);
      last_seconds = sppm_seconds_since(iteration_start);
      if (options_.live) {
        write_film(iteration + 1);
        options_.live->pass_done(film_);
      }
    }
    progress_.finish();
    write_film(iteration);
    stats_.seconds = sppm_seconds_since(start);
    stats_.samples = uint64_t(iteration) * pixels_.size();
    for (const RayCounts& c : ray_counts_) stats_.rays += c;
    stats_.non_finite_samples = non_finite_.load();
    stats_.rank_busy_seconds = {double(busy_nanoseconds_.load()) * 1e-9};
    stats_.threads = arena_.max_concurrency();
    SppmStats details;
    details.iterations = iteration;
    details.photons = uint64_t(iteration) * photons_per_iteration_;
    details.min_radius = std::numeric_limits<double>::infinity();
    for (const SppmPixel& p : pixels_) {
      details.min_radius = std::min(details.min_radius, double(p.radius));
      details.max_radius = std::max(details.max_radius, double(p.radius));
    }
    stats_.details = details;
    return stats_;
  }

 private:
  bool cancelled() const { return options_.cancel && options_.cancel->load(std::memory_order_relaxed); }

  // Step 1: one camera path per pixel, its light into Ld and its visible point into vps_.
  void trace_camera_paths(int iteration, const Wavelengths* wl) {
    const PerspectiveCamera& camera = scene_.camera();
    const FilmSensor& sensor = scene_.film_sensor();
    const float inv_filter_integral = 1 / filter_.integral();
    tbb::parallel_for(tbb::blocked_range<int>(0, height_), [&](const tbb::blocked_range<int>& rows) {
      BusyTimer busy(busy_nanoseconds_);
      RayCounts& counts = ray_counts_.local();
      std::visit(
          [&](const auto& prototype) {
            auto sampler = prototype;
            for (int y = rows.begin(); y < rows.end(); ++y)
              for (int x = 0; x < width_; ++x) {
                const size_t index = size_t(y) * size_t(width_) + size_t(x);
                SppmVisiblePoint& vp = vps_[index];
                vp.valid = false;
                sampler.start_pixel_sample(x, y, uint64_t(iteration));
                // The camera sample as the tile loop places it (camera_sample_tiles.h); its filter
                // weight over the filter's integral weighs the path (1 for box and tent filters).
                const Filter::Sample fs = filter_.sample(sampler.get_pixel_2d());
                const Vec2 lens = camera.has_lens() ? sampler.get_2d() : Vec2(0.5f, 0.5f);
                const float time = scene_.has_motion()
                                       ? lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close())
                                       : camera.shutter_open();
                const Ray ray =
                    camera.generate_ray({float(x) + 0.5f + fs.offset.x, float(y) + 0.5f + fs.offset.y}, lens, time);
                SppmVisiblePointVisitor visitor(vp, settings_.max_depth);
                const float weight = fs.weight * inv_filter_integral;
                RGB L = wavelengths_to_rgb(camera_paths_.radiance(ray, sampler, counts, wl, &visitor), wl) * weight;
                vp.beta *= weight;
                if (!L.is_finite()) {
                  non_finite_.fetch_add(1, std::memory_order_relaxed);
                  L = RGB(0.0f);
                } else {
                  L = sensor.respond(L);
                }
                if (options_.clamp > 0 && L.max_component() > options_.clamp) L *= options_.clamp / L.max_component();
                SppmPixel& pixel = pixels_[index];
                for (int c = 0; c < 3; ++c) pixel.ld[c] += double(L[c]);
              }
          },
          prototype_);
    });
  }

  // Step 3: the iteration's photons, each one's hits after the first deposited at the visible points
  // within their radius.
  void trace_photons(int iteration, const Wavelengths* wl) {
    const PerspectiveCamera& camera = scene_.camera();
    const FilmSensor& sensor = scene_.film_sensor();
    const int max_vertices = settings_.max_depth + 1;  // the light and max_depth hits
    const uint64_t photon_seed = hash_values(settings_.seed, 0x70686f746f6e);
    const float inv_unit = float(1 / phi_unit_);
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, photons_per_iteration_, 64),
                      [&](const tbb::blocked_range<uint64_t>& range) {
      BusyTimer busy(busy_nanoseconds_);
      RayCounts& counts = ray_counts_.local();
      thread_local std::vector<BdptVertex> sppm_photon_path;
      sppm_photon_path.resize(size_t(max_vertices));
      BdptVertex* path = sppm_photon_path.data();
      IndependentSampler sampler(photon_seed);
      for (uint64_t photon = range.begin(); photon < range.end(); ++photon) {
        sampler.start_pixel_sample(int(photon & 0x7fffffff), int(photon >> 31), uint64_t(iteration));
        const float time = scene_.has_motion()
                               ? lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close())
                               : camera.shutter_open();
        const int n = photon_paths_.light_subpath(sampler, counts, max_vertices, time, path, wl);
        // Vertex 1 is the photon's first hit: direct light, which the camera paths estimate.
        for (int i = 2; i < n; ++i) {
          const BdptVertex& v = path[i];
          if (v.kind != BdptVertex::Kind::Surface) continue;
          const SppmGrid::Span candidates = grid_.near(v.p);
          for (const uint32_t* it = candidates.begin; it != candidates.end; ++it) {
            const uint32_t index = *it;
            const SppmVisiblePoint& vp = vps_[index];
            const float r = pixels_[index].radius;
            if (length_squared(vp.p - v.p) > r * r) continue;
            // The photon arrives from v.wo; the visible point's BSDF scatters it towards the camera.
            const Vec3 wi_local = vp.shading.frame.to_local(v.wo);
            const RGB phi = vp.beta * v.beta * bsdf_eval(vp.shading.bsdf, vp.wo_local, wi_local);
            const RGB value = sensor.respond(wavelengths_to_rgb(phi, wl)) * inv_unit;
            std::atomic_ref<uint32_t>(m_[index]).fetch_add(1, std::memory_order_relaxed);
            if (!value.is_finite() || value.max_component() > 1e9f || value.min_component() < -1e9f) {
              non_finite_.fetch_add(1, std::memory_order_relaxed);
              continue;
            }
            if (!value.is_black()) phi_.add_to_pixel(int(index % uint32_t(width_)), int(index / uint32_t(width_)), value);
          }
        }
      }
    });
  }

  // Step 4: the progressive update of every pixel that received photons; then the iteration's Phi
  // and M are cleared.
  void update_pixels() {
    constexpr float kAlpha = 2.0f / 3.0f;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels_.size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i) {
        const uint32_t m = m_[i];
        if (m == 0) continue;
        SppmPixel& p = pixels_[i];
        const float n_new = p.n + kAlpha * float(m);
        const float r_new = p.radius * std::sqrt(n_new / (p.n + float(m)));
        const RGB phi = phi_.at(int(i % size_t(width_)), int(i / size_t(width_)));
        const double shrink = double(r_new) * double(r_new) / (double(p.radius) * double(p.radius));
        for (int c = 0; c < 3; ++c) p.tau[c] = (p.tau[c] + double(phi[c]) * phi_unit_) * shrink;
        p.n = n_new;
        p.radius = r_new;
        m_[i] = 0;
      }
    });
    std::fill(phi_.sums().begin(), phi_.sums().end(), 0);
  }

  // The film's pixels hold the estimate after `iterations`: each pixel's mean is
  // Ld / I + tau / (I P pi r^2), as if from I samples (no independent halves: see the traits).
  void write_film(int iterations) {
    const double photons = double(iterations) * double(photons_per_iteration_);
    for (size_t i = 0; i < pixels_.size(); ++i) {
      const SppmPixel& p = pixels_[i];
      PixelSums& px = film_.pixels()[i];
      px = PixelSums{};
      if (iterations == 0) continue;
      const double area = kPi * double(p.radius) * double(p.radius);
      for (int c = 0; c < 3; ++c) {
        const double L = p.ld[c] / iterations + (photons > 0 && area > 0 ? p.tau[c] / (photons * area) : 0.0);
        px.weighted[c] = L * iterations;
        px.weighted_sq[c] = L * L * iterations;
      }
      px.weight = iterations;
      px.count = uint64_t(iterations);
    }
  }

  const Scene& scene_;
  const RenderSettings& settings_;
  Film& film_;
  const RenderOptions& options_;
  const int width_, height_;
  const uint64_t photons_per_iteration_;
  const PathIntegrator camera_paths_;
  const BdptIntegrator photon_paths_;
  const Filter filter_;
  const Sampler prototype_;
  tbb::task_arena arena_;
  ProgressBar progress_;
  std::vector<SppmPixel> pixels_;
  std::vector<SppmVisiblePoint> vps_;
  SppmGrid grid_;
  SplatImage phi_;             // the iteration's Phi per pixel, in units of phi_unit_
  std::vector<uint32_t> m_;    // the iteration's M per pixel
  double phi_unit_ = 1;
  tbb::enumerable_thread_specific<RayCounts> ray_counts_;
  std::atomic<uint64_t> busy_nanoseconds_{0};
  std::atomic<uint64_t> non_finite_{0};
  RenderStats stats_;
};

}  // namespace

uint64_t sppm_photons_per_iteration(const RenderSettings& settings, int width, int height) {
  return settings.sppm.photons_per_iteration > 0 ? uint64_t(settings.sppm.photons_per_iteration)
                                                 : uint64_t(width) * uint64_t(height);
}

RenderStats render_sppm(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  if (options.cluster && options.cluster->distributed())
    throw UsageError("the sppm integrator renders in one process: its photons reach every pixel of every rank");
  if (!(settings.sppm.radius > 0 && std::isfinite(settings.sppm.radius)))
    throw UsageError(fmt::format("the sppm integrator's radius must be positive, got {}", settings.sppm.radius));
  SppmRender sppm(scene, settings, film, options);
  return sppm.run();
}

}  // namespace candela
