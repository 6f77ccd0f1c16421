#include "lash/io/error.hpp"

#include <fmt/core.h>

namespace lash {

std::string bounded(std::string s, std::size_t max) {
  if (s.size() <= max) return s;
  const std::size_t n = s.size();
  std::size_t cut = max;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
  s.resize(cut);
  return s + fmt::format("\u2026 ({} bytes)", n);
}

namespace {
constexpr std::size_t kMaxField = 200;     // a name or a value quoted from the input
constexpr std::size_t kMaxMessage = 1000;  // what was wrong (it may quote the input too)

std::string compose(const std::string& file, int line, const std::string& field, const std::string& message) {
  std::string where;
  if (!file.empty()) where = line > 0 ? fmt::format("{}:{}: ", file, line) : fmt::format("{}: ", file);
  std::string what = field.empty() ? std::string() : fmt::format("'{}': ", field);
  return fmt::format("{}{}{}", where, what, message);
}
}  // namespace

InputError::InputError(std::string file, int line, std::string field, const std::string& message)
    : Error(compose(file, line, bounded(field, kMaxField), bounded(message, kMaxMessage))),
      file_(std::move(file)),
      line_(line),
      field_(bounded(std::move(field), kMaxField)),
      message_(bounded(message, kMaxMessage)) {}

}  // namespace lash
