#pragma once
/// Helpers shared by the settings field tables (identify/config_fields.hpp: the estimator's,
/// control/controller_fields.hpp: the controller's): one row per setting, with its TOML key,
/// its command-line flag and a pointer-to-member visited with std::visit.

#include <span>
#include <string_view>

namespace lash {

/// std::visit with one lambda per alternative: std::visit(Overload{[](A*) {...}, [](B*) {...}}, ref).
template <class... F>
struct Overload : F... {
  using F::operator()...;
};
template <class... F>
Overload(F...) -> Overload<F...>;

/// The row of a field table whose command-line flag (without "--", the row's `flag` member) is
/// `flag`; nullptr for an empty flag or when no row has it.
template <class Field>
const Field* find_by_flag(std::span<const Field> fields, std::string_view flag) noexcept {
  if (flag.empty()) return nullptr;
  for (const auto& f : fields)
    if (flag == f.flag) return &f;
  return nullptr;
}

}  // namespace lash
