// Which layer may include which (docs/architecture.md), checked on the sources: the readers and the
// writer (io/) know the integrators only through their traits in the bottom layer
// (description/integrator_traits.h), and the bottom layer, description/, includes nothing of
// candela's above base/ and math/. A new #include that breaks either fails here, naming the file
// and the line. Tests (*_test.cpp) may include what they test with.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Include {
  std::string where;  // "src/candela/io/json_writer.cpp:16"
  std::string path;   // "candela/integrators/integrator.h"
};

// Every include of candela's in the non-test sources under `folder` (of src/candela/).
std::vector<Include> includes_in(const std::string& folder) {
  std::vector<Include> found;
  const fs::path root = fs::path(CANDELA_SOURCE_DIR) / "src" / "candela" / folder;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(root)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || name.ends_with("_test.cpp")) continue;
    if (!name.ends_with(".h") && !name.ends_with(".cpp") && !name.ends_with(".in")) continue;
    std::ifstream in(entry.path());
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
      const size_t at = line.find("#include \"candela/");
      if (at == std::string::npos || line.find_first_not_of(" \t") != at) continue;
      const size_t start = at + 10, end = line.find('"', start);
      found.push_back({fs::relative(entry.path(), CANDELA_SOURCE_DIR).string() + ":" + std::to_string(number),
                       line.substr(start, end - start)});
    }
  }
  return found;
}

TEST(Layering, TheReadersAndTheWriterIncludeNoIntegrator) {
  const std::vector<Include> includes = includes_in("io");
  ASSERT_GT(includes.size(), 100u) << "the sources of io/ were not found under " << CANDELA_SOURCE_DIR;
  for (const Include& include : includes)
    if (include.path.starts_with("candela/integrators/"))
      ADD_FAILURE() << include.where << ": includes " << include.path
                    << " (io/ reads the integrators' traits from description/integrator_traits.h)";
}

TEST(Layering, TheDescriptionIncludesOnlyBaseMathAndKeyframes) {
  for (const Include& include : includes_in("description"))
    if (!include.path.starts_with("candela/base/") && !include.path.starts_with("candela/math/") &&
        !include.path.starts_with("candela/description/") && include.path != "candela/animation/keyframes.h")
      ADD_FAILURE() << include.where << ": includes " << include.path
                    << " (description/ is the bottom layer: base/, math/ and the animation model only)";
  // The animation model the description holds is as low: math/ and base/ alone.
  for (const Include& include : includes_in("animation"))
    if (include.where.find("keyframes") != std::string::npos && !include.path.starts_with("candela/base/") &&
        !include.path.starts_with("candela/math/") && include.path != "candela/animation/keyframes.h")
      ADD_FAILURE() << include.where << ": includes " << include.path << " (the animation model needs math/ only)";
}

}  // namespace
