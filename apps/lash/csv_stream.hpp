#pragma once
// A CSV written row by row as the data are produced (round-trip precision, like
// write_columns_csv), through an AtomicFile: a regular file appears whole at commit() or not at
// all; stdout (`-`), a FIFO or a device get the rows as they come. Memory: one buffer of
// ~64 kB, whatever the number of rows.
#include <span>
#include <string>
#include <vector>

#include "lash/io/atomic_file.hpp"

namespace lash::cli {

class CsvStream {
 public:
  /// Opens the output (InputError naming the file if it cannot) and writes the header line.
  CsvStream(const std::string& path, const std::vector<std::string>& names);
  void row(std::span<const double> values);
  std::size_t rows() const noexcept { return rows_; }
  /// Flushes and (regular file) renames into place; throws InputError on an I/O error.
  void commit();

 private:
  void flush();
  AtomicFile file_;
  std::string buf_;
  std::size_t rows_ = 0;
};

}  // namespace lash::cli
