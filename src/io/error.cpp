#include "lash/io/error.hpp"

#include <fmt/core.h>

namespace lash {
namespace {
std::string compose(const std::string& file, int line, const std::string& field, const std::string& message) {
  std::string where;
  if (!file.empty()) where = line > 0 ? fmt::format("{}:{}: ", file, line) : fmt::format("{}: ", file);
  std::string what = field.empty() ? std::string() : fmt::format("'{}': ", field);
  return fmt::format("{}{}{}", where, what, message);
}
}  // namespace

InputError::InputError(std::string file, int line, std::string field, const std::string& message)
    : Error(compose(file, line, field, message)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      message_(message) {}

}  // namespace lash
