#include "candela/io/spectrum_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <variant>

#include "candela/base/error.h"
#include "candela/description/scene_desc.h"
#include "candela/io/named_spectra.h"
#include "candela/io/pbrt_reader.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

std::string spectrum_error_of(std::string_view text) {
  try {
    parse_spectrum_file(text, "s.spd");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(SpectrumFile, ReadsPairsWithCommentsAndAnySpacing) {
  std::vector<double> pairs = parse_spectrum_file("# gold\n360 1.70\n400\t1.66  # comment\n\n450 1.38 500 +0.97\r\n", "s.spd");
  EXPECT_EQ(pairs, (std::vector<double>{360, 1.70, 400, 1.66, 450, 1.38, 500, 0.97}));
}

TEST(SpectrumFile, RefusesWhatIsNotIncreasingFinitePairs) {
  EXPECT_NE(spectrum_error_of("400 1\n380 1\n").find("s.spd:2:1: wavelengths must increase (380 after 400)"),
            std::string::npos);
  EXPECT_NE(spectrum_error_of("400 1\n500 x\n").find("s.spd:2:1: expected \"wavelength value\""), std::string::npos);
  EXPECT_NE(spectrum_error_of("400 1 500\n").find("odd count"), std::string::npos);
  EXPECT_NE(spectrum_error_of("400 nan\n").find("finite"), std::string::npos);
  EXPECT_NE(spectrum_error_of("400 1e999\n").find("finite"), std::string::npos);
  EXPECT_NE(spectrum_error_of("# nothing\n").find("no wavelength-value pairs"), std::string::npos);
  EXPECT_NE(spectrum_error_of(std::string(kMaxSpectrumFileBytes + 1, ' ')).find("more than a spectrum file"),
            std::string::npos);
}

// pbrt-v4: a "spectrum" string that is not a named spectrum is a file, meaning what its pairs inline mean.
TEST(SpectrumFile, PbrtParametersNameFilesBesideTheScene) {
  fs::path dir = fs::temp_directory_path() / ("candela_spd_" + std::to_string(getpid()));
  fs::create_directories(dir / "spds");
  std::ofstream(dir / "spds/eta.spd") << "# eta\n400 0.5\n500 0.8\n600 1.2\n700 1.5\n";
  std::ofstream(dir / "bad.spd") << "400 0.5\n500\n";
  auto conductor_eta = [&](std::string_view eta) {
    std::ofstream(dir / "scene.pbrt") << "WorldBegin\nMaterial \"conductor\" \"spectrum eta\" " << eta
                                      << " \"spectrum k\" [ 400 3 700 3 ]\nShape \"sphere\"\n";
    SceneDesc scene = read_pbrt_scene(dir / "scene.pbrt");
    return std::get<ConductorMaterial>(scene.materials.at(0)).eta.value;
  };
  EXPECT_EQ(conductor_eta("\"spds/eta.spd\""), conductor_eta("[ 400 0.5 500 0.8 600 1.2 700 1.5 ]"));
  auto error_of = [&](std::string_view eta) {
    try {
      conductor_eta(eta);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("\"bad.spd\"").find("bad.spd:2:1: holds 3 numbers, an odd count"), std::string::npos)
      << error_of("\"bad.spd\"");
  std::string missing = error_of("\"no-such.spd\"");
  EXPECT_NE(missing.find("scene.pbrt:2:"), std::string::npos) << missing;
  EXPECT_NE(missing.find("\"no-such.spd\" is neither a named spectrum"), std::string::npos) << missing;
  EXPECT_NE(missing.find("cannot find"), std::string::npos) << missing;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace candela
