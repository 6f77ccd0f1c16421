#include "lash/io/csv.hpp"

#include <charconv>
#include <cmath>
#include <fstream>

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

std::size_t CsvTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  std::string have;
  for (const auto& h : header) have += (have.empty() ? "" : ",") + h;
  throw InputError(file, 1, std::string(name), "no such column (the header has: " + have + ")");
}

namespace {
std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i == line.size() || line[i] == ',') {
      out.push_back(line.substr(start, i - start));
      start = i + 1;
    }
  }
  return out;
}
std::string trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '"')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '"')) s.remove_suffix(1);
  return std::string(s);
}
}  // namespace

CsvTable read_csv(const std::filesystem::path& path) {
  CsvTable t;
  t.file = path.string();
  std::ifstream in(path);
  if (!in) throw InputError(t.file, 0, "", "cannot open file for reading");
  std::string line;
  int lineno = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++lineno;
    std::string_view sv(line);
    if (!sv.empty() && sv.back() == '\r') sv.remove_suffix(1);
    if (sv.find_first_not_of(" \t") == std::string_view::npos || sv.front() == '#') continue;
    auto fields = split(sv);
    if (!have_header) {
      for (auto f : fields) {
        auto name = trim(f);
        if (name.empty()) throw InputError(t.file, lineno, "header", "empty column name");
        t.header.push_back(name);
      }
      t.cols.resize(t.header.size());
      have_header = true;
      continue;
    }
    if (fields.size() != t.header.size())
      throw InputError(t.file, lineno, "", "expected " + std::to_string(t.header.size()) + " fields, found " +
                                               std::to_string(fields.size()));
    for (std::size_t c = 0; c < fields.size(); ++c) {
      double v;
      if (!parse_double(fields[c], v))
        throw InputError(t.file, lineno, t.header[c],
                         "not a finite number: '" + std::string(fields[c]) + "'");
      t.cols[c].push_back(v);
    }
    t.line_of_row.push_back(lineno);
  }
  if (!have_header) throw InputError(t.file, 0, "", "empty file (expected a header line and data rows)");
  if (t.rows() == 0) throw InputError(t.file, lineno, "", "no data rows after the header");
  return t;
}

void require_increasing(const CsvTable& table, std::string_view name) {
  const auto& c = table[name];
  for (std::size_t i = 1; i < c.size(); ++i)
    if (!(c[i] > c[i - 1]))
      throw InputError(table.file, table.line_of_row[i], std::string(name),
                       "not strictly increasing (" + format_double(c[i]) + " after " + format_double(c[i - 1]) + ")");
}

}  // namespace lash
