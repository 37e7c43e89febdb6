#pragma once
// Spectrum files (".spd"), as pbrt-v4 and Mitsuba 3 read them: (wavelength in nm, value) pairs as plain
// numbers separated by white space (or commas), with "#" starting a comment that runs to the end of
// the line. pbrt-v4 reads one where a "spectrum" parameter's string is not a named spectrum
// (`"spectrum eta" "spds/Au.eta.spd"`); Mitsuba's <spectrum filename="...">.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace candela {

// The pairs, flattened (w0, v0, w1, v1, ...): at least one pair, wavelengths strictly increasing,
// every number finite. Anything else throws SceneError at `file_name`:line.
std::vector<double> parse_spectrum_file(std::string_view text, const std::string& file_name);

// Reads and parses `file` (at most kMaxSpectrumFileBytes); a missing or unreadable file throws
// SceneError naming it.
std::vector<double> read_spectrum_file(const std::filesystem::path& file);

inline constexpr size_t kMaxSpectrumFileBytes = size_t(16) << 20;

}  // namespace candela
