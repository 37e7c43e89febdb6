// The limit: how close candela comes to raw Embree on the rays it traces.
//
// 1. Renders the scene with the path tracer (timed, the log off) and counts its rays: candela's
//    Mrays/s is rays / render time, everything included (sampling, hit reconstruction, shading,
//    light sampling, film).
// 2. Renders it again with a ray log attached (geometry/ray_log.h), which keeps every camera,
//    bounce and shadow ray exactly as Embree received it, and replays those rays through raw
//    rtcIntersect1 / rtcOccluded1 with the same thread count and nothing else: the speed of
//    Embree alone. candela's efficiency is the ratio of the two.
// 3. Tries Embree's other query APIs on the same work and prints what each gains over
//    rtcIntersect1: packets (rtcIntersect4/8/16) on coherent camera rays, one per pixel traced in
//    pixel blocks, and ray streams (rtcIntersect1M / rtcOccluded1M, coherent and incoherent
//    hints) on the recorded bounce and shadow rays.
// 4. The floor: the least a path tracer can do around Embree (see floor_paths), one path at a time
//    and as a wavefront, timed, then its own rays replayed through raw Embree the same way. Its
//    efficiency bounds, to within a few points of code generation, what any path tracer that draws
//    directions per hit can reach on this scene and machine.
//
// Usage: candela_ray_replay SCENE [--spp N] [--resolution WxH] [--threads T] [--repeat R]
// (prints a Markdown table; the fastest of R replays counts).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "candela/film/film.h"
#include "candela/io/scene_reader.h"
#include "candela/math/frame.h"
#include "candela/integrators/integrator.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The fastest of `repeat` runs of `work`, in seconds.
double best_of(int repeat, const std::function<void()>& work) {
  double best = 1e300;
  for (int i = 0; i < repeat; ++i) {
    auto start = std::chrono::steady_clock::now();
    work();
    best = std::min(best, seconds_since(start));
  }
  return best;
}

// Runs body(begin, end) over [0, n) in chunks on the arena's threads.
void parallel_chunks(tbb::task_arena& arena, size_t n, size_t chunk, const std::function<void(size_t, size_t)>& body) {
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, chunk),
                      [&](const tbb::blocked_range<size_t>& r) { body(r.begin(), r.end()); });
  });
}

RTCRayHit to_rayhit(const RTCRay& ray) {
  RTCRayHit rh;
  rh.ray = ray;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// rtcIntersect1 / rtcOccluded1 on each ray, as candela calls them (a fresh context and hit per ray).
void replay_single(RTCScene scene, const RecordedRay* rays, size_t n, uint64_t& hits) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (size_t i = 0; i < n; ++i) {
    if (rays[i].occlusion) {
      RTCRay r = rays[i].ray;
      rtcOccluded1(scene, &context, &r);
      hits += r.tfar < 0;
    } else {
      RTCRayHit rh = to_rayhit(rays[i].ray);
      rtcIntersect1(scene, &context, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
  }
}

// The same rays as streams of up to `stream` rays of one kind (rtcIntersect1M / rtcOccluded1M).
void replay_streams(RTCScene scene, const std::vector<RTCRayHit>& closest, const std::vector<RTCRay>& shadow,
                    size_t begin_c, size_t end_c, size_t begin_s, size_t end_s, size_t stream, bool coherent,
                    uint64_t& hits) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  std::vector<RTCRayHit> rh(stream);
  std::vector<RTCRay> r(stream);
  for (size_t i = begin_c; i < end_c; i += stream) {
    size_t m = std::min(stream, end_c - i);
    std::copy_n(closest.begin() + long(i), m, rh.begin());
    rtcIntersect1M(scene, &context, rh.data(), unsigned(m), sizeof(RTCRayHit));
    for (size_t k = 0; k < m; ++k) hits += rh[k].hit.geomID != RTC_INVALID_GEOMETRY_ID;
  }
  for (size_t i = begin_s; i < end_s; i += stream) {
    size_t m = std::min(stream, end_s - i);
    std::copy_n(shadow.begin() + long(i), m, r.begin());
    rtcOccluded1M(scene, &context, r.data(), unsigned(m), sizeof(RTCRay));
    for (size_t k = 0; k < m; ++k) hits += r[k].tfar < 0;
  }
}

// A packet of K rays in Embree's SOA layout (RTCRayHit4/8/16), filled from K single rays.
template <int K>
struct PacketTraits;
template <>
struct PacketTraits<4> {
  using RayHit = RTCRayHit4;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect4(valid, s, c, rh); }
};
template <>
struct PacketTraits<8> {
  using RayHit = RTCRayHit8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect8(valid, s, c, rh); }
};
template <>
struct PacketTraits<16> {
  using RayHit = RTCRayHit16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect16(valid, s, c, rh); }
};

template <int K>
void trace_packets(RTCScene scene, const RTCRay* rays, size_t n, uint64_t& hits) {
  using Traits = PacketTraits<K>;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) typename Traits::RayHit p;
  alignas(64) int valid[K];
  for (size_t i = 0; i < n; i += K) {
    for (int k = 0; k < K; ++k) {
      size_t j = i + size_t(k);
      valid[k] = j < n ? -1 : 0;
      const RTCRay& r = rays[std::min(j, n - 1)];
      p.ray.org_x[k] = r.org_x;
      p.ray.org_y[k] = r.org_y;
      p.ray.org_z[k] = r.org_z;
      p.ray.tnear[k] = r.tnear;
      p.ray.dir_x[k] = r.dir_x;
      p.ray.dir_y[k] = r.dir_y;
      p.ray.dir_z[k] = r.dir_z;
      p.ray.time[k] = r.time;
      p.ray.tfar[k] = r.tfar;
      p.ray.mask[k] = r.mask;
      p.ray.id[k] = 0;
      p.ray.flags[k] = 0;
      p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      p.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    Traits::intersect(valid, scene, &context, &p);
    for (int k = 0; k < K; ++k) hits += valid[k] && p.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
  }
}

// One camera ray through each pixel centre, ordered in blocks of bw x bh pixels (a packet's rays
// are neighbours on the film), as Embree sees them.
std::vector<RTCRay> camera_rays(const Scene& scene, int width, int height, int bw, int bh) {
  std::vector<RTCRay> rays;
  rays.reserve(size_t(width) * size_t(height));
  const PerspectiveCamera& camera = scene.camera();
  for (int by = 0; by < height; by += bh)
    for (int bx = 0; bx < width; bx += bw)
      for (int y = by; y < std::min(by + bh, height); ++y)
        for (int x = bx; x < std::min(bx + bw, width); ++x) {
          RTCRay e = scene.embree().embree_ray(
              camera.generate_ray({float(x) + 0.5f, float(y) + 0.5f}, {0.5f, 0.5f}, 0));
          rays.push_back(e);
        }
  return rays;
}

// The floor path tracer: per sample a PCG stream, a jittered pinhole camera ray, then at each hit the
// geometric normal as Embree returns it (no hit reconstruction, no material, no light, no film), one
// shadow ray in a cosine-distributed direction (the cheapest next-event estimate: a sky's) and a
// cosine-distributed bounce, to max_depth or until a ray escapes, surviving Russian roulette with
// probability 0.7 from the second bounce on.

// The camera ray of sample s of pixel (x, y), and the PCG stream its path continues with.
RTCRayHit floor_camera_ray(const Scene& scene, int x, int y, int s, Rng& rng) {
  rng = Rng(hash_values(uint64_t(x), uint64_t(y)), uint64_t(s));
  const float jx = rng.next_float(), jy = rng.next_float();
  return to_rayhit(scene.embree().embree_ray(scene.camera().generate_ray({float(x) + jx, float(y) + jy}, {0.5f, 0.5f}, 0)));
}

// The work at a hit: the shadow ray, and the bounce unless Russian roulette ends the path.
struct FloorVertex {
  RTCRay shadow;
  std::optional<RTCRayHit> bounce;
};
FloorVertex floor_vertex(const Scene& scene, const RTCRayHit& rh, int depth, Rng& rng) {
  const Vec3 d(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z);
  const Point3 p = Point3(rh.ray.org_x, rh.ray.org_y, rh.ray.org_z) + d * rh.ray.tfar;
  Vec3 n = normalize(Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
  if (dot(n, d) > 0) n = -n;
  const Frame frame(n);
  const Point3 origin = offset_ray_origin(p, n, n);  // both new rays leave on n's side
  const float u0 = rng.next_float(), u1 = rng.next_float();
  FloorVertex v{scene.embree().embree_ray(Ray{origin, frame.to_world(square_to_cosine_hemisphere({u0, u1}))}), {}};
  if (depth >= 1 && rng.next_float() >= 0.7f) return v;
  const float v0 = rng.next_float(), v1 = rng.next_float();
  v.bounce = to_rayhit(scene.embree().embree_ray(Ray{origin, frame.to_world(square_to_cosine_hemisphere({v0, v1}))}));
  return v;
}

// Rows [y0, y1) of the image, one path at a time; counts the rays, and logs them when `log` is set.
void floor_paths(RTCScene rtc, const Scene& scene, int width, int y0, int y1, int spp, int max_depth,
                 std::vector<RecordedRay>* log, uint64_t& rays, uint64_t& sink) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < width; ++x)
      for (int s = 0; s < spp; ++s) {
        Rng rng;
        RTCRayHit rh = floor_camera_ray(scene, x, y, s, rng);
        for (int depth = 0; depth < max_depth; ++depth) {
          if (log) log->push_back({rh.ray, false});
          rtcIntersect1(rtc, &context, &rh);
          ++rays;
          if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
          FloorVertex v = floor_vertex(scene, rh, depth, rng);
          if (log) log->push_back({v.shadow, true});
          rtcOccluded1(rtc, &context, &v.shadow);
          ++rays;
          sink += v.shadow.tfar < 0;
          if (!v.bounce) break;
          rh = *v.bounce;
        }
      }
}

// The same paths (the same random numbers, so the same rays) traced as a wavefront: all camera rays
// of the rows at once, then every hit's shadow ray and the surviving bounces, one depth at a time,
// until no path is left. Each batch goes through Embree's ray stream API (`streams`) or
// rtcIntersect1/rtcOccluded1 per ray, which tells the stream API's share of the gain from the
// wavefront's order (no path waits on its own traversal).
void floor_wavefront(RTCScene rtc, const Scene& scene, int width, int y0, int y1, int spp, int max_depth,
                     bool streams, uint64_t& rays, uint64_t& sink) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  std::vector<RTCRayHit> active, next;
  std::vector<Rng> rngs, next_rngs;
  std::vector<RTCRay> shadows;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < width; ++x)
      for (int s = 0; s < spp; ++s) {
        rngs.emplace_back();
        active.push_back(floor_camera_ray(scene, x, y, s, rngs.back()));
      }
  for (int depth = 0; depth < max_depth && !active.empty(); ++depth) {
    if (streams) rtcIntersect1M(rtc, &context, active.data(), unsigned(active.size()), sizeof(RTCRayHit));
    else
      for (RTCRayHit& rh : active) rtcIntersect1(rtc, &context, &rh);
    rays += active.size();
    shadows.clear();
    next.clear();
    next_rngs.clear();
    for (size_t k = 0; k < active.size(); ++k) {
      if (active[k].hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
      FloorVertex v = floor_vertex(scene, active[k], depth, rngs[k]);
      shadows.push_back(v.shadow);
      if (!v.bounce) continue;
      next.push_back(*v.bounce);
      next_rngs.push_back(rngs[k]);
    }
    if (streams) rtcOccluded1M(rtc, &context, shadows.data(), unsigned(shadows.size()), sizeof(RTCRay));
    else
      for (RTCRay& r : shadows) rtcOccluded1(rtc, &context, &r);
    rays += shadows.size();
    for (const RTCRay& r : shadows) sink += r.tfar < 0;
    std::swap(active, next);
    std::swap(rngs, next_rngs);
  }
}

int usage() {
  std::fprintf(stderr, "usage: candela_ray_replay SCENE [--spp N] [--resolution WxH] [--threads T] [--repeat R]\n");
  return 2;
}

int run(int argc, char** argv) {
  if (argc < 2) return usage();
  std::string scene_file = argv[1];
  int spp = 4, threads = 2, repeat = 3, width = 0, height = 0;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    if (i + 1 >= argc) return usage();
    std::string v = argv[++i];
    if (a == "--spp") spp = std::atoi(v.c_str());
    else if (a == "--threads") threads = std::atoi(v.c_str());
    else if (a == "--repeat") repeat = std::max(1, std::atoi(v.c_str()));
    else if (a == "--resolution" && std::sscanf(v.c_str(), "%dx%d", &width, &height) == 2) {}
    else return usage();
  }
  SceneDesc desc = read_scene_file(scene_file);
  if (width > 0 && height > 0) {
    desc.film.width = width;
    desc.film.height = height;
  }
  desc.settings.spp = spp;
  desc.settings.integrator = "path";
  Scene scene(desc, Scene::MeshData::Take);
  RenderOptions options;
  options.threads = threads;
  options.progress = false;
  tbb::task_arena arena(threads);

  // 1. candela, whole renders (the fastest of `repeat`).
  RenderStats stats;
  double render_s = best_of(repeat, [&] {
    Film film(desc.film.width, desc.film.height);
    stats = render(scene, desc.settings, film, options);
  });
  const double rays_rendered = double(stats.rays.total());

  // 2. The same render's rays through raw Embree.
  RayLog log;
  scene.embree().set_ray_log(&log);
  {
    Film film(desc.film.width, desc.film.height);
    render(scene, desc.settings, film, options);
  }
  scene.embree().set_ray_log(nullptr);
  std::vector<RecordedRay> rays = log.take();
  RTCScene rtc = scene.embree().handle();
  uint64_t sink = 0;
  std::atomic<uint64_t> atomic_sink{0};
  auto replay_all = [&] {
    parallel_chunks(arena, rays.size(), 4096, [&](size_t b, size_t e) {
      uint64_t h = 0;
      replay_single(rtc, &rays[b], e - b, h);
      atomic_sink += h;
    });
  };
  double raw_s = best_of(repeat, replay_all);
  size_t shadow_count = size_t(std::count_if(rays.begin(), rays.end(), [](const RecordedRay& r) { return r.occlusion; }));

  std::printf("scene: %s, %dx%d, %d spp, %d threads, %zu triangles\n\n", scene_file.c_str(), desc.film.width,
              desc.film.height, spp, threads, scene.triangle_count());
  std::printf("| what | rays | seconds | Mrays/s | vs raw Embree |\n|---|---|---|---|---|\n");
  const double raw_mrays = double(rays.size()) / raw_s * 1e-6;
  std::printf("| candela path tracer (everything) | %.0f | %.3f | %.2f | %.1f%% |\n", rays_rendered, render_s,
              rays_rendered / render_s * 1e-6, 100 * rays_rendered / render_s * 1e-6 / raw_mrays);
  std::printf("| raw rtcIntersect1/rtcOccluded1, the same rays (%zu shadow) | %zu | %.3f | %.2f | 100%% |\n",
              shadow_count, rays.size(), raw_s, raw_mrays);

  // 3a. Streams over the recorded rays, grouped by kind.
  std::vector<RTCRayHit> closest;
  std::vector<RTCRay> shadow;
  for (const RecordedRay& r : rays) {
    if (r.occlusion) shadow.push_back(r.ray);
    else closest.push_back(to_rayhit(r.ray));
  }
  for (bool coherent : {false, true})
    for (size_t stream : {size_t(16), size_t(256)}) {
      double s = best_of(repeat, [&] {
        const size_t chunks = 64;
        std::vector<uint64_t> hits(chunks, 0);
        arena.execute([&] {
          tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            replay_streams(rtc, closest, shadow, closest.size() * c / chunks, closest.size() * (c + 1) / chunks,
                           shadow.size() * c / chunks, shadow.size() * (c + 1) / chunks, stream, coherent, hits[c]);
          });
        });
        for (uint64_t h : hits) sink += h;
      });
      std::printf("| rtcIntersect1M/rtcOccluded1M streams of %zu, %s hint | %zu | %.3f | %.2f | %.1f%% |\n", stream,
                  coherent ? "coherent" : "incoherent", rays.size(), s, double(rays.size()) / s * 1e-6,
                  100 * raw_s / s);
    }

  // 3b. Packets on coherent camera rays (one per pixel centre), against single rays in the same order.
  struct Packet {
    const char* name;
    int bw, bh;
    void (*trace)(RTCScene, const RTCRay*, size_t, uint64_t&);
  };
  const Packet packets[] = {{"rtcIntersect4 (2x2 pixels)", 2, 2, trace_packets<4>},
                            {"rtcIntersect8 (4x2 pixels)", 4, 2, trace_packets<8>},
                            {"rtcIntersect16 (4x4 pixels)", 4, 4, trace_packets<16>}};
  std::printf("\n| camera rays, one per pixel | rays | seconds | Mrays/s | vs rtcIntersect1 |\n|---|---|---|---|---|\n");
  for (const Packet& p : packets) {
    std::vector<RTCRay> cam = camera_rays(scene, desc.film.width, desc.film.height, p.bw, p.bh);
    const size_t chunk = size_t(p.bw * p.bh) * 256;
    std::vector<RecordedRay> as_recorded(cam.size());
    for (size_t i = 0; i < cam.size(); ++i) as_recorded[i] = {cam[i], false};
    double single = best_of(repeat, [&] {
      parallel_chunks(arena, cam.size(), chunk, [&](size_t b, size_t e) {
        uint64_t h = 0;
        replay_single(rtc, &as_recorded[b], e - b, h);
        atomic_sink += h;
      });
    });
    double packet = best_of(repeat, [&] {
      parallel_chunks(arena, cam.size(), chunk, [&](size_t b, size_t e) {
        uint64_t h = 0;
        p.trace(rtc, &cam[b], e - b, h);
        atomic_sink += h;
      });
    });
    std::printf("| rtcIntersect1 | %zu | %.4f | %.2f | 100%% |\n", cam.size(), single, double(cam.size()) / single * 1e-6);
    std::printf("| %s | %zu | %.4f | %.2f | %.1f%% |\n", p.name, cam.size(), packet, double(cam.size()) / packet * 1e-6,
                100 * single / packet);
  }

  // 4. The floor path tracer (floor_paths), one path at a time and as a wavefront, then its rays
  // through raw Embree.
  const int rows_total = desc.film.height;
  const int max_depth = desc.settings.max_depth;
  const size_t rows = 4;  // per chunk at most; chunks may start at any row, so counts are kept per row
  // {seconds (fastest of `repeat`), rays} of trace(first row, end row, rays, occluded).
  auto time_rows = [&](auto trace) {
    std::vector<uint64_t> per_row(static_cast<size_t>(rows_total));
    double seconds = best_of(repeat, [&] {
      std::fill(per_row.begin(), per_row.end(), 0);
      parallel_chunks(arena, size_t(rows_total), rows, [&](size_t b, size_t e) {
        uint64_t h = 0;
        trace(int(b), int(e), per_row[b], h);
        atomic_sink += h;
      });
    });
    uint64_t total = 0;
    for (uint64_t r : per_row) total += r;
    return std::pair<double, uint64_t>(seconds, total);
  };
  const auto one_at_a_time = time_rows([&](int y0, int y1, uint64_t& n, uint64_t& h) {
    floor_paths(rtc, scene, desc.film.width, y0, y1, spp, max_depth, nullptr, n, h);
  });
  const auto wavefront_streams = time_rows([&](int y0, int y1, uint64_t& n, uint64_t& h) {
    floor_wavefront(rtc, scene, desc.film.width, y0, y1, spp, max_depth, true, n, h);
  });
  const auto wavefront_single = time_rows([&](int y0, int y1, uint64_t& n, uint64_t& h) {
    floor_wavefront(rtc, scene, desc.film.width, y0, y1, spp, max_depth, false, n, h);
  });
  std::vector<std::vector<RecordedRay>> floor_logs(static_cast<size_t>(rows_total));
  parallel_chunks(arena, size_t(rows_total), rows, [&](size_t b, size_t e) {
    uint64_t n = 0, h = 0;
    floor_paths(rtc, scene, desc.film.width, int(b), int(e), spp, max_depth, &floor_logs[b], n, h);
  });
  std::vector<RecordedRay> floor_log;
  for (auto& l : floor_logs) floor_log.insert(floor_log.end(), l.begin(), l.end());
  double floor_raw_s = best_of(repeat, [&] {
    parallel_chunks(arena, floor_log.size(), 4096, [&](size_t b, size_t e) {
      uint64_t h = 0;
      replay_single(rtc, &floor_log[b], e - b, h);
      atomic_sink += h;
    });
  });
  const double floor_raw_mrays = double(floor_log.size()) / floor_raw_s * 1e-6;
  std::printf("\n| the floor (PCG, Embree's normal, cosine shadow ray and bounce; %.2f rays/sample) | rays | seconds | Mrays/s | vs raw Embree |\n"
              "|---|---|---|---|---|\n",
              double(one_at_a_time.second) / (double(desc.film.width) * rows_total * spp));
  std::printf("| raw rtcIntersect1/rtcOccluded1, the floor's rays | %zu | %.3f | %.2f | 100%% |\n", floor_log.size(),
              floor_raw_s, floor_raw_mrays);
  for (const auto& [what, result] :
       {std::pair("floor path tracer, one path at a time", one_at_a_time),
        std::pair("floor as a wavefront, rtcIntersect1M/rtcOccluded1M streams", wavefront_streams),
        std::pair("floor as a wavefront, rtcIntersect1/rtcOccluded1 per ray", wavefront_single)}) {
    const double mrays = double(result.second) / result.first * 1e-6;
    std::printf("| %s | %llu | %.3f | %.2f | %.1f%% |\n", what, (unsigned long long)result.second, result.first, mrays,
                100 * mrays / floor_raw_mrays);
  }
  if (sink + atomic_sink == 42) std::printf(" ");  // keeps the traversals from being optimised away
  return 0;
}

}  // namespace
}  // namespace candela

int main(int argc, char** argv) {
  try {
    return candela::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela_ray_replay: %s\n", e.what());
    return 1;
  }
}
