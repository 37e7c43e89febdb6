#include "candela/io/spectrum_file.h"

#include <charconv>
#include <cmath>
#include <fstream>

#include "candela/base/error.h"

namespace candela {

std::vector<double> parse_spectrum_file(std::string_view text, const std::string& file_name) {
  auto at_line = [&](int line) { return SourceLocation{file_name, line, 1, {}}; };
  if (text.size() > kMaxSpectrumFileBytes)
    throw_scene_error(at_line(0), "{} bytes is more than a spectrum file may have ({})", text.size(),
                      kMaxSpectrumFileBytes);
  constexpr std::string_view kSeparators = " \t\r\n,#";
  std::vector<double> numbers;
  std::vector<int> lines;  // each number's line, for messages
  int line = 1;
  size_t i = 0;
  while (i < text.size()) {
    char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (kSeparators.find(c) != std::string_view::npos) {
      ++i;
    } else {
      size_t end = i;
      while (end < text.size() && kSeparators.find(text[end]) == std::string_view::npos) ++end;
      std::string_view word = text.substr(i, end - i);
      std::string_view digits = word.starts_with('+') ? word.substr(1) : word;  // from_chars takes no '+'
      double value = 0;
      auto [rest, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
      if (error != std::errc{} || rest != digits.data() + digits.size() || !std::isfinite(value))
        throw_scene_error(at_line(line), "expected \"wavelength value\" pairs of finite numbers, got \"{}\"",
                          word.substr(0, 40));
      numbers.push_back(value);
      lines.push_back(line);
      i = end;
    }
  }
  if (numbers.empty()) throw_scene_error(at_line(0), "holds no wavelength-value pairs");
  if (numbers.size() % 2 != 0)
    throw_scene_error(at_line(lines.back()), "holds {} numbers, an odd count: expected \"wavelength value\" pairs",
                      numbers.size());
  for (size_t k = 2; k < numbers.size(); k += 2)
    if (!(numbers[k] > numbers[k - 2]))
      throw_scene_error(at_line(lines[k]), "wavelengths must increase ({} after {})", numbers[k], numbers[k - 2]);
  return numbers;
}

std::vector<double> read_spectrum_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw_scene_error(SourceLocation{file.string(), 0, 0, {}}, "cannot open the spectrum file");
  std::string text(kMaxSpectrumFileBytes + 1, '\0');
  in.read(text.data(), std::streamsize(text.size()));
  if (in.bad()) throw_scene_error(SourceLocation{file.string(), 0, 0, {}}, "cannot read the spectrum file");
  text.resize(size_t(in.gcount()));
  return parse_spectrum_file(text, file.string());
}

}  // namespace candela
