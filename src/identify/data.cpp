#include "lash/identify/data.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <mutex>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash {

namespace {
std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, ColumnReader>& registry() {
  static std::map<std::string, ColumnReader> r;
  return r;
}

ColumnData read_csv_columns(const std::filesystem::path& path, const std::vector<std::string>& names) {
  CsvTable t = read_csv(path);
  ColumnData d;
  d.file = t.file;
  d.names = names;
  for (const auto& n : names) d.cols.push_back(t[n]);
  d.line_of_row = t.line_of_row;
  return d;
}
}  // namespace

void register_column_reader(const std::string& extension, ColumnReader reader) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[extension] = std::move(reader);
}

ColumnData load_columns(const std::filesystem::path& path, const std::vector<std::string>& names) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  ColumnReader reader;
  {
    std::lock_guard<std::mutex> lock(registry_mutex());
    auto it = registry().find(ext);
    if (it != registry().end()) reader = it->second;
  }
  return reader ? reader(path, names) : read_csv_columns(path, names);
}

Record load_record(const std::filesystem::path& path, const std::vector<std::string>& names) {
  if (names.size() != 3) throw InputError("", 0, "--columns", "expected three column names: t,v,y");
  Record r;
  r.data = load_columns(path, names);
  const auto& t = r.data.cols.at(0);
  if (t.empty()) throw InputError(r.data.file, 0, names[0], "no data rows");
  if (t.size() < 3) throw InputError(r.data.file, 0, names[0], "need at least 3 samples");
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] > t[i - 1])) {
      const int line = r.data.line_of_row.empty() ? 0 : r.data.line_of_row[i];
      throw InputError(r.data.file, line, names[0],
                       "time must increase strictly (row " + std::to_string(i + 1) + ": " + format_double(t[i]) +
                           " after " + format_double(t[i - 1]) + ")");
    }
  }
  r.dt_s = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  return r;
}

}  // namespace lash
