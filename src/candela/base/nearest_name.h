#pragma once
// "did you mean": the known name nearest to a misspelt one.
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace candela {

// The name among `names` nearest to `name` by edit distance (insertions, deletions, substitutions
// and swaps of neighbours, case-insensitive), if it is close enough to be a likely typo: at most
// one edit for names of up to four letters, else at most a third of the name's length.
std::optional<std::string_view> nearest_name(std::string_view name, std::span<const std::string_view> names);

// " (did you mean \"x\"?)" for the nearest name, or "" when none is close.
std::string did_you_mean(std::string_view name, std::span<const std::string_view> names);

}  // namespace candela
