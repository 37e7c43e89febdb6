#pragma once
// An image written to a fresh temporary directory for tests that read images from files.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

#include "candela/film/image_io.h"

namespace candela::testing {

// `image` written as <name>.exr in a directory of its own (per process and name), removed with it.
class TempImageFile {
 public:
  TempImageFile(const Image& image, const std::string& name) {
    dir_ = std::filesystem::temp_directory_path() / ("candela-test-image-" + std::to_string(::getpid()) + "-" + name);
    std::filesystem::create_directories(dir_);
    path_ = dir_ / (name + ".exr");
    write_image(path_, image);
  }
  TempImageFile(const TempImageFile&) = delete;
  TempImageFile& operator=(const TempImageFile&) = delete;
  ~TempImageFile() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path dir_, path_;
};

}  // namespace candela::testing
