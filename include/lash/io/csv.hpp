#pragma once
/// @file csv.hpp
/// CSV in and out. Numbers are written in round-trip precision: the shortest
/// text that parses back to the same double (std::to_chars). Not real-time safe.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace lash {

/// Shortest round-trip text of `x` ("0.1", "1e-05", "200"). Non-finite → "nan"/"inf"/"-inf".
std::string format_double(double x);
/// Appends the shortest round-trip text of `x` to `out`.
void append_double(std::string& out, double x);

/// Parses a whole field as a finite double; returns false for junk, empty or non-finite text.
bool parse_double(std::string_view text, double& value) noexcept;

/// A numeric table read from a CSV file with a header line.
struct CsvTable {
  std::string file;                       ///< where it came from (for messages)
  std::vector<std::string> header;        ///< column names in file order
  std::vector<std::vector<double>> cols;  ///< cols[c][row]
  std::vector<int> line_of_row;           ///< 1-based file line of each data row

  std::size_t rows() const noexcept { return cols.empty() ? 0 : cols[0].size(); }
  /// Index of column `name`, or throws InputError naming the file, header line and column.
  std::size_t column(std::string_view name) const;
  const std::vector<double>& operator[](std::string_view name) const { return cols[column(name)]; }
};

/// Reads a CSV file with a header. Every cell must be a finite number; the
/// first offending cell is reported as InputError(file, line, column).
/// Blank lines and lines starting with '#' are skipped. An empty file or a
/// file with a header but no rows is an error.
CsvTable read_csv(const std::filesystem::path& path);

/// Checks that column `name` is strictly increasing; throws InputError naming the line.
void require_increasing(const CsvTable& table, std::string_view name);

}  // namespace lash
