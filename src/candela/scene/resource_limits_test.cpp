#include "candela/scene/resource_limits.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "candela/film/image.h"
#include "candela/film/image_io.h"
#include "candela/base/error.h"

namespace candela {
namespace {

constexpr uint64_t kGiB = uint64_t(1) << 30;

// A scene of one mesh: a grid of `quads` x 1 quads (2 triangles each).
SceneDesc scene_with(int width, int height, uint32_t quads = 0) {
  SceneDesc desc;
  desc.source_file = "scene.json";
  desc.film.width = width;
  desc.film.height = height;
  if (quads > 0) {
    MeshShape shape;
    for (uint32_t i = 0; i <= quads; ++i) {
      shape.mesh.positions.push_back({float(i), 0, 0});
      shape.mesh.positions.push_back({float(i), 1, 0});
    }
    for (uint32_t i = 0; i < quads; ++i) {
      const uint32_t a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
      shape.mesh.indices.insert(shape.mesh.indices.end(), {a, c, b, b, c, d});
    }
    ShapeDesc s;
    s.geometry = std::move(shape);
    desc.shapes.push_back(std::move(s));
  }
  return desc;
}

std::string error_of(const SceneDesc& desc, uint64_t available) {
  try {
    check_memory(desc, available);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "check_memory did not throw";
  return "";
}

TEST(ResourceLimits, EstimateGrowsWithResolution) {
  const MemoryEstimate small = estimate_memory(scene_with(640, 480));
  const MemoryEstimate large = estimate_memory(scene_with(1280, 960));
  EXPECT_GE(small.film_bytes, uint64_t(640) * 480 * 64);  // at least the Film's PixelSums
  EXPECT_EQ(large.film_bytes, 4 * small.film_bytes);
  EXPECT_EQ(large.scene_bytes, small.scene_bytes);
  EXPECT_EQ(small.total, small.film_bytes + small.scene_bytes);
  EXPECT_GT(large.total, small.total);

  SceneDesc adaptive = scene_with(640, 480);
  adaptive.settings.adaptive_threshold = 0.01f;
  EXPECT_GT(estimate_memory(adaptive).film_bytes, small.film_bytes);
}

TEST(ResourceLimits, EstimateGrowsWithTriangleCount) {
  const MemoryEstimate none = estimate_memory(scene_with(64, 64));
  const MemoryEstimate few = estimate_memory(scene_with(64, 64, 1000));
  const MemoryEstimate many = estimate_memory(scene_with(64, 64, 100000));
  EXPECT_EQ(few.triangles, 2000u);
  EXPECT_EQ(many.triangles, 200000u);
  EXPECT_GT(few.scene_bytes, none.scene_bytes);
  // At least the BVH and both index buffers per triangle.
  EXPECT_GE(many.scene_bytes - few.scene_bytes, uint64_t(198000) * (kEmbreeBvhBytesPerTriangle + 24));
  EXPECT_EQ(many.film_bytes, few.film_bytes);
}

TEST(ResourceLimits, InstancedObjectsCountOnceAndInstancesEach) {
  SceneDesc desc = scene_with(64, 64, 1000);
  ObjectDesc object;
  object.shapes.push_back(desc.shapes[0]);
  desc.objects.push_back(object);
  const MemoryEstimate one = [&] {
    desc.instances.resize(1);
    return estimate_memory(desc);
  }();
  desc.instances.resize(1001);
  const MemoryEstimate many = estimate_memory(desc);
  EXPECT_EQ(one.triangles, 4000u);  // the world mesh and the object, once
  EXPECT_EQ(many.triangles, 4000u);
  EXPECT_EQ(many.scene_bytes - one.scene_bytes, 1000 * kBytesPerInstance);
}

TEST(ResourceLimits, TexturesAreCountedFromTheirHeaders) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("candela_limits_" + std::to_string(getpid()) + ".exr");
  write_image(file, Image(256, 128), {});
  SceneDesc desc = scene_with(64, 64);
  const MemoryEstimate without = estimate_memory(desc);
  ImageTexture texture;
  texture.filename = file.string();
  desc.textures.push_back(texture);
  const MemoryEstimate with = estimate_memory(desc);
  EXPECT_GE(with.texture_bytes, uint64_t(256) * 128 * 12);
  EXPECT_GE(with.scene_bytes - without.scene_bytes, with.texture_bytes);

  // A missing file is left for the texture reader to report.
  desc.textures[0] = ImageTexture{.filename = (file.string() + ".missing")};
  EXPECT_EQ(estimate_memory(desc).texture_bytes, 0u);
  std::filesystem::remove(file);
}

// A PNG whose header claims width x height 8-bit RGB pixels, followed by a little image data.
std::string png_claiming(uint32_t width, uint32_t height) {
  const auto big_endian = [](uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  };
  const auto chunk = [&](const std::string& type, const std::string& data) {
    const std::string typed = type + data;
    return big_endian(uint32_t(data.size())) + typed +
           big_endian(uint32_t(crc32(0, reinterpret_cast<const Bytef*>(typed.data()), uInt(typed.size()))));
  };
  const std::string row_start(16, '\0');
  std::string idat(64, '\0');
  uLongf idat_size = uLongf(idat.size());
  compress(reinterpret_cast<Bytef*>(idat.data()), &idat_size, reinterpret_cast<const Bytef*>(row_start.data()),
           uLong(row_start.size()));
  idat.resize(idat_size);
  const std::string rgb8 = std::string("\x08\x02\0\0\0", 5);  // bit depth, colour type, compression, filter, interlace
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", big_endian(width) + big_endian(height) + rgb8) +
         chunk("IDAT", idat) + chunk("IEND", "");
}

// Hostile inputs (docs/reliability.md): a texture file of a few bytes whose header claims 100000 x
// 100000 texels is refused from its header, naming the scene's entry, the file and the limit, before
// anything is allocated for it; so is a PFM whose pixels are not all in the file.
TEST(ResourceLimits, ImagesLargerThanCandelaReadsAreRefusedFromTheirHeaders) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("candela_limits_images_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return (dir / name).string();
  };
  const std::string png = write("huge.png", png_claiming(100000, 100000));
  const std::string pfm = write("huge.pfm", "PF\n100000 100000\n-1.0\n" + std::string(1200, '\0'));
  const std::string limit = "more than candela reads (at most 65536 on a side and 536870912 = 2^29 in all)";
  SceneDesc desc = scene_with(64, 64);
  desc.textures.push_back(ImageTexture{.filename = png});
  desc.places.textures.push_back(SourceLocation{"scene.json", 4, 16, "/textures/wood"});
  try {
    estimate_memory(desc);
    ADD_FAILURE() << "not refused";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()),
              "scene.json:4:16: at /textures/wood: " + png + ": the image is 100000 x 100000 texels, " + limit);
  }
  desc.textures.clear();
  desc.lights.push_back(EnvironmentMap{.filename = pfm});  // no place known: the scene file is named
  EXPECT_THROW(estimate_memory(desc), SceneError);
  for (const std::string& file : {png, pfm}) {
    try {
      read_image(file);
      ADD_FAILURE() << file << " read";
    } catch (const FileContentError& e) {
      EXPECT_EQ(std::string(e.what()), file + ": the image is 100000 x 100000 texels, " + limit);
    }
  }
  // An EXR texture whose header attribute claims 1.8 GB: OpenEXR would allocate it before failing.
  const std::string exr = (dir / "attribute.exr").string();
  write_image(exr, Image(2, 2), {{"comment", "hello"}});
  {
    std::ifstream in(exr, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t size_at = bytes.find(std::string("comment\0string\0", 15)) + 15;
    ASSERT_LT(size_at, bytes.size());
    const int32_t huge = 1800000000;
    std::memcpy(bytes.data() + size_at, &huge, 4);
    write("attribute.exr", bytes);
  }
  desc.lights.clear();
  desc.textures.push_back(ImageTexture{.filename = exr});
  try {
    estimate_memory(desc);
    ADD_FAILURE() << "not refused";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("scene.json:4:16: at /textures/wood: " + exr +
                                              ": cannot read image: its OpenEXR header attribute 'comment' claims "
                                              "1800000000 bytes, more than the ",
                                          0),
              0u)
        << e.what();
  }
  // Within the limits, but the file holds 1200 of the 4.8 GB of pixels its header claims.
  const std::string short_pfm = write("short.pfm", "PF\n20000 20000\n-1.0\n" + std::string(1200, '\0'));
  try {
    read_image(short_pfm);
    ADD_FAILURE() << "read";
  } catch (const FileContentError& e) {
    EXPECT_EQ(std::string(e.what()), short_pfm + ": cannot read image: the file has 1220 bytes, too few for the "
                                                  "20000 x 20000 pixels its header claims (cut short?)");
  }
  std::filesystem::remove_all(dir);
}

TEST(ResourceLimits, NormalScenePasses) {
  const SceneDesc desc = scene_with(1920, 1080, 50000);
  EXPECT_LT(estimate_memory(desc).total, kGiB);
  EXPECT_NO_THROW(check_memory(desc, 8 * kGiB));
  EXPECT_NO_THROW(check_resources(desc));
}

TEST(ResourceLimits, AbsurdFilmIsRefusedNamingTheSize) {
  // Refused whatever the memory.
  const std::string message = error_of(scene_with(1000000, 1000000), std::numeric_limits<uint64_t>::max());
  EXPECT_EQ(message.rfind("scene.json: ", 0), 0u) << message;
  EXPECT_NE(message.find("1000000 x 1000000"), std::string::npos) << message;
  EXPECT_NE(message.find("too large"), std::string::npos) << message;
  EXPECT_THROW(check_resources(scene_with(1000000, 1000000)), SceneError);
  EXPECT_THROW(check_resources(scene_with(2000000, 1)), SceneError);       // a side over 2^20
  EXPECT_THROW(check_resources(scene_with(2147483647, 2147483647)), SceneError);  // no overflow
  EXPECT_THROW(check_resources(scene_with(0, 100)), SceneError);
  EXPECT_THROW(check_resources(scene_with(-5, 100)), SceneError);
  // The estimate itself saturates rather than wrapping.
  EXPECT_GT(estimate_memory(scene_with(2147483647, 2147483647)).total, uint64_t(1) << 62);
}

TEST(ResourceLimits, FilmTooBigForTheMemoryIsRefusedWithSizes) {
  // 65536 x 65536 is a legal resolution but needs over 300 GiB.
  const std::string message = error_of(scene_with(65536, 65536, 1000), 16 * kGiB);
  EXPECT_EQ(message.rfind("scene.json: the render needs about ", 0), 0u) << message;
  EXPECT_NE(message.find("film "), std::string::npos) << message;
  EXPECT_NE(message.find("for 65536 x 65536 pixels"), std::string::npos) << message;
  EXPECT_NE(message.find("2000 triangles"), std::string::npos) << message;
  EXPECT_NE(message.find("but only 16.0 GiB of memory is available"), std::string::npos) << message;
}

TEST(ResourceLimits, SceneTooBigForTheMemoryIsRefused) {
  const SceneDesc desc = scene_with(64, 64, 100000);
  const uint64_t needed = estimate_memory(desc).total;
  EXPECT_NO_THROW(check_memory(desc, needed));
  const std::string message = error_of(desc, needed / 2);
  EXPECT_NE(message.find("200000 triangles"), std::string::npos) << message;
}

TEST(ResourceLimits, FormatBytes) {
  EXPECT_EQ(format_bytes(100), "100 bytes");
  EXPECT_EQ(format_bytes(1536), "1.5 KiB");
  EXPECT_EQ(format_bytes(uint64_t(23.4 * double(kGiB))), "23.4 GiB");
  EXPECT_EQ(format_bytes(uint64_t(3.2 * 1024 * double(kGiB))), "3.2 TiB");
  EXPECT_EQ(format_bytes(std::numeric_limits<uint64_t>::max()), "16.0 EiB");
}

TEST(ResourceLimits, AvailableMemoryIsPlausible) {
  const uint64_t available = available_memory_bytes();
  EXPECT_GT(available, uint64_t(64) << 20);
  EXPECT_LT(available, uint64_t(1) << 50);  // under a PiB: something was read
}

}  // namespace
}  // namespace candela
