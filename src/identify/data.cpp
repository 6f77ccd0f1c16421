#include "lash/identify/data.hpp"

#include "lash/identify/estimate.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/mat.hpp"

namespace lash {

ColumnData load_columns(const std::filesystem::path& path, const std::vector<std::string>& names, bool strict) {
  TableOptions o;
  o.columns = names;
  o.strict = strict;
  if (names.empty()) throw InputError("", 0, "--columns", "no columns named");
  return read_table(path, o);
}

Record load_record(const std::filesystem::path& path, const std::vector<std::string>& names, bool strict) {
  if (names.size() != 3) throw InputError("", 0, "--columns", "expected three column names: t,v,y");
  Record r;
  r.data = load_columns(path, names, strict);
  const auto& t = r.data.cols.at(0);
  if (t.empty()) throw InputError(r.data.file, 0, r.data.names[0], "no data rows");
  if (t.size() < 3) throw InputError(r.data.file, 0, r.data.names[0], "need at least 3 samples");
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] > t[i - 1])) {
      const int line = r.data.line_of_row.empty() ? 0 : r.data.line_of_row[i];
      throw InputError(r.data.file, line, r.data.names[0],
                       "time must increase strictly (row " + std::to_string(i + 1) + ": " + format_double(t[i]) +
                           " after " + format_double(t[i - 1]) + ")");
    }
  }
  r.sampling = analyse_sampling(t);
  r.data.gap_rows = r.sampling.gap_rows;
  r.dt_s = r.sampling.dt;  // without gaps: (t.back() − t.front())/(n − 1) on a record without gaps
  return r;
}

}  // namespace lash
