#pragma once
// Exhaustive visits over the closed sets (std::variant): either one lambda per alternative,
//   std::visit(overloaded{[](const A&) {...}, [](const B&) {...}}, v);
// which does not compile when an alternative has no case, or an `if constexpr` chain over the
// alternative's type that ends in
//   else static_assert(always_false<T>, "...");
// so that a new alternative fails to compile instead of falling into a default.

namespace candela {

template <typename... Fs>
struct overloaded : Fs... {
  using Fs::operator()...;
};
template <typename... Fs>
overloaded(Fs...) -> overloaded<Fs...>;

// A false that depends on T, for the static_assert ending an `if constexpr` chain.
template <typename T>
inline constexpr bool always_false = false;

}  // namespace candela
