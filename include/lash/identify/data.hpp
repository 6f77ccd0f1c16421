#pragma once
/// @file data.hpp
/// Loading a measured record as named numeric columns, independent of the file format.
/// A ".mat" file is read as MAT (io/mat.hpp), anything else as CSV (io/csv.hpp).
/// Not real-time safe. Errors are lash::InputError naming file, line (where there is one) and column.
#include <filesystem>
#include <string>
#include <vector>

namespace lash {

/// Columns in the order they were asked for, all of the same length.
struct ColumnData {
  std::string file;
  std::vector<std::string> names;
  std::vector<std::vector<double>> cols;
  std::vector<int> line_of_row;  ///< 1-based source line of each row (empty when the format has no lines)
  std::size_t rows() const noexcept { return cols.empty() ? 0 : cols[0].size(); }
};

/// Reads exactly the columns `names` from `path` (MAT or CSV); InputError for a missing one.
ColumnData load_columns(const std::filesystem::path& path, const std::vector<std::string>& names);

/// Loads t, v, y for estimation: `names` = {t, v, y} column names; checks that t is strictly
/// increasing (InputError naming the line) and returns the sample period (mean step of t).
struct Record {
  ColumnData data;
  double dt_s = 0.0;
  const std::vector<double>& t() const { return data.cols[0]; }
  const std::vector<double>& v() const { return data.cols[1]; }
  const std::vector<double>& y() const { return data.cols[2]; }
};
Record load_record(const std::filesystem::path& path, const std::vector<std::string>& names);

}  // namespace lash
