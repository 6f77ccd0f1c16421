#include "lash/identify/data.hpp"

#include "lash/identify/estimate.hpp"
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
  r.dt_s = sample_period(r.data.cols.at(0), r.data.file, r.data.line_of_row, names[0]);
  return r;
}

}  // namespace lash
