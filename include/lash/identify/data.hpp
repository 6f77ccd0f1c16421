#pragma once
/// @file data.hpp
/// Loading a measured record (t, v, y) for estimation from any file io::read_table reads
/// (CSV and its cousins, MAT; io/table.hpp). Not real-time safe. Errors are lash::InputError
/// naming file, line (where there is one) and column.
#include <filesystem>
#include <string>
#include <vector>

#include "lash/identify/record_columns.hpp"
#include "lash/io/table.hpp"

namespace lash {

/// The columns asked for, in that order (the table type of io/table.hpp).
using ColumnData = Table;

/// Reads exactly the columns `names` (names or 0-based indices) from `path`; InputError for a
/// missing one. Rows with a non-finite chosen cell are skipped and counted (ColumnData::
/// skipped_rows) unless `strict`, which makes them an error.
ColumnData load_columns(const std::filesystem::path& path, const std::vector<std::string>& names, bool strict = false);

/// A record for estimation: `names` = {t, v, y} columns. t must increase strictly (InputError
/// naming the line). Sampling: dt_s is the mean step over the steps that are not gaps; a step
/// longer than kGapFactor (io/table.hpp) median steps is a gap, listed in data.gap_rows (row i
/// starts a new stretch: an estimator restarts its regressors there) — never averaged into dt.
/// A text record longer than `spill_after_rows` (load_record's argument; 0: never) is read into a
/// temporary file (io/column_store.hpp) instead of memory: data.cols is then empty, and the
/// record is read through columns() in chunks (estimate_record).
struct Record {
  ColumnData data;
  double dt_s = 0.0;       ///< sample period [s]: mean step without the gaps
  Sampling sampling;       ///< median step, jitter, gaps
  /// t, v, y for whole-record passes (views of data.cols, or the spill file).
  RecordColumns columns() const;
  bool spilled() const noexcept { return data.spilled.rows() > 0; }
  std::size_t rows() const noexcept { return data.rows(); }
  /// The columns in memory (empty when spilled()).
  const std::vector<double>& t() const { return data.cols[0]; }
  const std::vector<double>& v() const { return data.cols[1]; }
  const std::vector<double>& y() const { return data.cols[2]; }
  std::size_t skipped_rows() const noexcept { return data.skipped_rows; }
  const std::vector<std::size_t>& gap_rows() const noexcept { return data.gap_rows; }
};
Record load_record(const std::filesystem::path& path, const std::vector<std::string>& names, bool strict = false,
                   std::size_t spill_after_rows = 0);

}  // namespace lash
