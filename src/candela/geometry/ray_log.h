#pragma once
// A record of every ray the scene traces, exactly as Embree receives it. bench/ray_replay.cpp
// replays the rays of a render through raw Embree (no hit reconstruction, no shading) to measure
// what everything around Embree costs. Off unless a log is attached (EmbreeScene::set_ray_log): the
// hot path then pays one predictable branch per ray.
#include <embree3/rtcore.h>
#include <tbb/enumerable_thread_specific.h>

#include <vector>

namespace candela {

struct RecordedRay {
  RTCRay ray;      // origin, direction, [tnear, tfar] and Embree's time in [0, 1]
  bool occlusion;  // rtcOccluded1 (shadow ray) rather than rtcIntersect1 (closest hit)
};

class RayLog {
 public:
  void add(const RTCRay& ray, bool occlusion) { per_thread_.local().push_back({ray, occlusion}); }
  // Every thread's rays (in no particular order), emptying the log.
  std::vector<RecordedRay> take() {
    std::vector<RecordedRay> all;
    for (auto& rays : per_thread_) {
      all.insert(all.end(), rays.begin(), rays.end());
      std::vector<RecordedRay>().swap(rays);
    }
    return all;
  }

 private:
  tbb::enumerable_thread_specific<std::vector<RecordedRay>> per_thread_;
};

}  // namespace candela
