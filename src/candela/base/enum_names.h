#pragma once
// Names of closed sets of choices (a sampler type, a filter, a light selection rule), declared once
// per enum as a switch with no `default:` in the enum's own header:
//
//   constexpr std::string_view enum_name(SamplerType t) {
//     switch (t) { case SamplerType::Independent: return "independent"; ... }
//     return {};
//   }
//
// GCC's -Wswitch, an error in this project (-Werror=switch, CMakeLists.txt), stops the build when an
// enumerator is added without a name. Everything else (the readers' and the command line's parsing,
// their "expected one of" lists, the writers) goes through the functions below, so a name is spelled
// in one place. Enumerators are contiguous from 0 (enumerators() walks them until one has no name).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace candela {

// Every enumerator of E, in declaration order.
template <typename E>
std::vector<E> enumerators() {
  std::vector<E> all;
  for (int i = 0; !enum_name(E(i)).empty(); ++i) all.push_back(E(i));
  return all;
}

// The enumerator named `name`, if any.
template <typename E>
std::optional<E> enum_from_name(std::string_view name) {
  for (E e : enumerators<E>())
    if (enum_name(e) == name) return e;
  return std::nullopt;
}

// "a, b, c": every name, for messages and help texts.
template <typename E>
std::string enum_names_list() {
  std::string list;
  for (E e : enumerators<E>()) list += (list.empty() ? "" : ", ") + std::string(enum_name(e));
  return list;
}

}  // namespace candela
