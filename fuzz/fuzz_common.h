#pragma once
// Shared by the libFuzzer targets: the readers take file paths, so each input is written to a file
// in a per-process directory under /dev/shm (or $TMPDIR when /dev/shm is missing).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>

namespace candela_fuzz {

// An empty directory of this process; relative paths in fuzzed scenes resolve inside it.
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    std::filesystem::path base = std::filesystem::exists("/dev/shm") ? std::filesystem::path("/dev/shm")
                                                                     : std::filesystem::temp_directory_path();
    std::filesystem::path d = base / ("candela-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    // Small meshes that fuzzed scenes may name ("mesh.obj", "mesh.ply"), so mesh loading is reached.
    auto put = [&](const char* name, const char* text) {
      std::FILE* f = std::fopen((d / name).c_str(), "wb");
      if (!f) std::abort();
      std::fputs(text, f);
      std::fclose(f);
    };
    put("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    put("mesh.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    static std::filesystem::path to_remove = d;
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(to_remove, ec);
    });
    return d;
  }();
  return dir;
}

// Writes the input to scratch_dir()/name and returns the path.
inline std::filesystem::path write_input(const uint8_t* data, size_t size, const char* name) {
  std::filesystem::path file = scratch_dir() / name;
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return file;
}

// With CANDELA_FUZZ_VERBOSE set, prints why an input was rejected (for checking seeds by hand).
inline void rejected(const std::exception& e) {
  if (std::getenv("CANDELA_FUZZ_VERBOSE")) std::fprintf(stderr, "rejected: %s\n", e.what());
}

}  // namespace candela_fuzz
