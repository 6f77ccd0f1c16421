#include "lash/identify/data.hpp"

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/mat.hpp"

namespace lash {

namespace {
ColumnData to_columns(CsvTable t, const std::vector<std::string>& names) {
  ColumnData d;
  for (const auto& n : names) d.cols.push_back(std::move(t.cols[t.column(n)]));
  d.file = std::move(t.file);
  d.names = names;
  d.line_of_row = std::move(t.line_of_row);
  return d;
}
}  // namespace

ColumnData load_columns(const std::filesystem::path& path, const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < names.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (names[i] == names[j]) throw InputError("", 0, "--columns", "column '" + names[i] + "' is chosen twice");
  return to_columns(is_mat_file(path) ? read_mat(path, names) : read_csv(path), names);
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
