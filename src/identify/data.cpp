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

Record load_record(const std::filesystem::path& path, const std::vector<std::string>& names, bool strict,
                   std::size_t spill_after_rows) {
  if (names.size() != 3) throw InputError("", 0, "--columns", "expected three column names: t,v,y");
  if (names.empty()) throw InputError("", 0, "--columns", "no columns named");
  TableOptions o;
  o.columns = names;
  o.strict = strict;
  o.spill_after_rows = spill_after_rows;
  Record r;
  r.data = read_table(path, o);
  const std::size_t n = r.data.rows();
  if (n == 0) throw InputError(r.data.file, 0, r.data.names[0], "no data rows");
  if (n < 3) throw InputError(r.data.file, 0, r.data.names[0], "need at least 3 samples");
  const ColumnStore store = r.data.store();
  double prev = 0.0;
  for_chunks(store, std::array<std::size_t, 1>{0}, 0, n, [&](std::size_t base, const auto& c) {
    const std::span<const double> t = c[0];
    for (std::size_t j = 0; j < t.size(); ++j) {
      const std::size_t i = base + j;
      if (i > 0 && !(t[j] > prev)) {
        const int line = r.data.line_of_row.empty() ? 0 : r.data.line_of_row[i];
        throw InputError(r.data.file, line, r.data.names[0],
                         "time must increase strictly (row " + std::to_string(i + 1) + ": " + format_double(t[j]) +
                             " after " + format_double(prev) + ")");
      }
      prev = t[j];
    }
  });
  r.sampling = analyse_sampling(store, 0);
  r.data.gap_rows = r.sampling.gap_rows;
  r.dt_s = r.sampling.dt;  // without gaps: (t.back() − t.front())/(n − 1) on a record without gaps
  return r;
}

RecordColumns Record::columns() const {
  RecordColumns c;
  c.store = data.store();
  c.t = 0;
  c.vy = {1, 2};
  return c;
}

}  // namespace lash
