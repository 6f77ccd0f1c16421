#include "lash/io/csv.hpp"

#include <charconv>
#include <cmath>

#include "lash/io/error.hpp"

namespace lash {

void append_double(std::string& out, double x) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, r.ptr);
}

std::string format_double(double x) {
  std::string s;
  append_double(s, x);
  return s;
}

bool parse_double(std::string_view text, double& value) noexcept {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) text.remove_suffix(1);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return false;
  double v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || !std::isfinite(v)) return false;
  value = v;
  return true;
}

Table read_csv(const std::filesystem::path& path) {
  TableOptions o;
  o.strict = true;
  return read_table(path, o);
}

void require_increasing(const Table& table, std::string_view name) {
  const auto& c = table[name];
  for (std::size_t i = 1; i < c.size(); ++i)
    if (!(c[i] > c[i - 1]))
      throw InputError(table.file, table.line_of_row[i], std::string(name),
                       "not strictly increasing (" + format_double(c[i]) + " after " + format_double(c[i - 1]) + ")");
}

}  // namespace lash
