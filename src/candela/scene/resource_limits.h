#pragma once
// Resource limits: before the film and the render scene are allocated, estimate how much memory they
// will take and refuse inputs that cannot fit (an absurd resolution, a mesh too big for the machine)
// with a SceneError naming the scene file, instead of being killed by the kernel part way through.
//
// The estimate is deliberately rough (within tens of percent for large scenes): it counts the data
// structures that grow with the input, per pixel, per triangle, per instance and per texel.
//   film:    sizeof(PixelSums) = 64 bytes per pixel, the output Image (12 bytes per pixel) and an
//            8-bit copy for PNG output (3), plus 5 bytes per pixel of adaptive-sampling state when on.
//   scene:   per triangle mesh: candela's ShapeRecord copy (12 bytes per vertex for positions, 12 for
//            normals, 8 for uvs, 12 per triangle of indices; twice the positions and normals when the
//            shape moves), Embree's vertex and index buffers (12 bytes per vertex and per triangle per
//            time step) and Embree's high-quality BVH, kEmbreeBvhBytesPerTriangle (twice that for
//            motion blur); emissive meshes add one Light and 8 bytes of light distribution per
//            triangle; an SDF grid, per voxel holding surface, its index and a BVH leaf as a triangle's.
//            Objects (instancing) count once, each instance kBytesPerInstance.
//   textures: image textures and environment maps, read from their headers only: 12 bytes per texel
//            for the float RGB image plus the file's own pixels while it is converted (channels x
//            bytes per channel); environment maps add 8 bytes per texel of sampling distribution.
// The SceneDesc itself (meshes already read from files) is not counted: it is already allocated, so
// it has already been subtracted from the memory that available_memory_bytes() reports.
#include <cstdint>
#include <string>

#include "candela/description/scene_desc.h"

namespace candela {

// Embree 3's RTC_BUILD_QUALITY_HIGH BVH plus its build's temporary arrays, per triangle. Measured as
// the growth of peak RSS while building candela's Scene from one grid mesh: 127 bytes per triangle
// at 4.2 million triangles and 142 at 0.72 million, of which about 36 are the ShapeRecord copy and
// Embree's vertex and index buffers counted separately; so 90 to 105 for the BVH, rounded up.
// (The whole estimate is then 148 bytes per triangle of such a mesh, 5 to 15% above the measurement.)
inline constexpr uint64_t kEmbreeBvhBytesPerTriangle = 112;
inline constexpr uint64_t kBytesPerInstance = 512;   // InstanceRecord + Embree instance geometry + BVH leaf
inline constexpr uint64_t kBytesPerSimpleShape = 1024;  // a sphere, plane, box or rectangle, all in

// Resolutions refused whatever the memory: more than this many pixels on a side or in all.
inline constexpr uint64_t kMaxFilmSide = uint64_t(1) << 20;
inline constexpr uint64_t kMaxFilmPixels = uint64_t(1) << 32;

struct MemoryEstimate {
  uint64_t film_bytes = 0;   // the Film, the output image and adaptive-sampling state
  uint64_t scene_bytes = 0;  // the render Scene: shapes, Embree, lights, instances and textures
  uint64_t total = 0;        // film_bytes + scene_bytes (saturating)
  // Details for messages (already included in scene_bytes):
  uint64_t texture_bytes = 0;
  uint64_t triangles = 0;  // triangles counted (object triangles once, however often instanced)
};

// Overflow-safe: every sum and product saturates at UINT64_MAX. Image files are opened for their
// headers only (OpenImageIO's ImageInput::open); one that cannot be opened counts as nothing here
// (reading it later reports the problem), one larger than candela reads at all (film/image_io.h's
// check_image_size) is a SceneError naming the file and the scene's place for it.
MemoryEstimate estimate_memory(const SceneDesc& desc);

// Throws SceneError "<scene file>: the film resolution W x H is too large ..." for a resolution over
// kMaxFilmSide on a side or kMaxFilmPixels in all (or not positive), whatever the memory.
void check_resolution(const SceneDesc& desc);

// check_resolution, then throws SceneError when estimate_memory(desc).total > available_bytes:
//   "scene.json: the render needs about 3.2 TiB (film 3.1 TiB for 1000000 x 1000000 pixels, scene
//    12.0 GiB for 5000000 triangles) but only 23.4 GiB of memory is available"
void check_memory(const SceneDesc& desc, uint64_t available_bytes);

// The memory this process can still allocate: MemAvailable from /proc/meminfo, lowered to what the
// cgroup (v2 memory.max / v1 memory.limit_in_bytes, less current usage) and RLIMIT_AS (less the
// current virtual size) allow. UINT64_MAX when nothing can be read (not Linux).
uint64_t available_memory_bytes();

// check_memory(desc, available_memory_bytes()): call after reading the scene (and applying command
// line overrides of the resolution) and before building the Scene and the Film.
void check_resources(const SceneDesc& desc);

// "3.2 TiB", "23.4 GiB", "512 bytes": binary units with one decimal.
std::string format_bytes(uint64_t bytes);

}  // namespace candela
