#include "lash/identify/data.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <mutex>

#include "lash/identify/estimate.hpp"
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
  r.dt_s = sample_period(r.data.cols.at(0), r.data.file, r.data.line_of_row, names[0]);
  return r;
}

}  // namespace lash
