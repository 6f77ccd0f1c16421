#pragma once
/// @file table.hpp
/// One table type for every record lash reads, and one reader that picks the format:
/// read_table(path) reads a MAT file (by its ".mat" extension or its "MATLAB" header) with
/// io/mat.hpp, anything else as text (CSV and its cousins). Not real-time safe.
///
/// Text files (docs/data_files.md):
/// - separator sniffed from the first non-comment line: tab if it holds one, else ';' if it
///   holds one, else ',' if it holds one, else runs of spaces (whitespace-separated columns);
/// - a UTF-8 byte-order mark is dropped; '\r\n' line ends are accepted;
/// - lines whose first non-blank character is '#', and blank lines, are skipped;
/// - decimal comma ("1,5") is read when the separator is not ',' (e.g. ';' files from a
///   German spreadsheet);
/// - the first line is the header unless every field of it is a number (then the columns are
///   named "0", "1", …);
/// - columns are chosen by header name or by 0-based index ("0", "2"); a column chosen twice
///   is refused; only the chosen columns are parsed;
/// - a row where a chosen cell is not finite ("nan", "inf", empty) is skipped and counted in
///   Table::skipped_rows, or is an InputError naming file:line:column with `strict`;
/// - any other text in a chosen cell is an InputError naming file:line:column.
/// Ingest streams the file in 1 MiB blocks, parses with std::from_chars straight into the
/// columns (reserved from the file size) and allocates nothing per row.
#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <span>
#include <vector>

#include "lash/io/column_store.hpp"

namespace lash {

/// The file line of each row of a table, kept as runs of rows on consecutive lines (a file
/// without comments, blank or skipped lines is one run): memory grows with the breaks, not with
/// the rows (a 10^7-row CSV needs a few bytes where a line number per row took 40 MB).
class RowLines {
 public:
  /// Appends the line of the next row.
  void push_back(int line) {
    if (n_ == 0 || line != last_ + 1) runs_.push_back({n_, line});
    last_ = line;
    ++n_;
  }
  /// Rows 0 … n − 1 on lines first, first + 1, … (a MAT file's element indices).
  void assign_consecutive(std::size_t n, int first) {
    runs_.clear();
    n_ = n;
    if (n) runs_.push_back({0, first});
    last_ = first + static_cast<int>(n) - 1;
  }
  /// The line of row `row` (< size()); O(log breaks).
  int operator[](std::size_t row) const noexcept {
    auto it = std::upper_bound(runs_.begin(), runs_.end(), row,
                               [](std::size_t r, const Run& x) { return r < x.row; });
    --it;
    return it->line + static_cast<int>(row - it->row);
  }
  std::size_t size() const noexcept { return n_; }
  bool empty() const noexcept { return n_ == 0; }
  int front() const noexcept { return runs_.front().line; }
  int back() const noexcept { return last_; }
  std::size_t runs() const noexcept { return runs_.size(); }
  std::vector<int> to_vector() const {
    std::vector<int> v(n_);
    for (std::size_t i = 0; i < n_; ++i) v[i] = (*this)[i];
    return v;
  }

 private:
  struct Run {
    std::size_t row;  ///< first row of the run
    int line;         ///< its line; row + i is on line + i until the next run
  };
  std::vector<Run> runs_;
  std::size_t n_ = 0;
  int last_ = 0;
};

/// Named numeric columns of one length, with where each row came from.
struct Table {
  std::string file;                       ///< where it came from (for messages)
  std::vector<std::string> names;         ///< column names, in file order or in the order chosen
  std::vector<std::vector<double>> cols;  ///< cols[c][row]
  RowLines line_of_row;                   ///< 1-based file line of each row (MAT: element index)
  std::size_t skipped_rows = 0;           ///< rows dropped for a non-finite chosen cell
  int first_skipped_line = 0;             ///< line of the first such row (0: none)
  std::vector<std::size_t> gap_rows;      ///< rows i where a gap ends (mark_gaps): t[i] − t[i−1] is a gap
  /// A text file longer than TableOptions::spill_after_rows: every row is here, in a temporary
  /// file (io/column_store.hpp), and `cols` is empty.
  ColumnStore spilled;

  std::size_t rows() const noexcept { return spilled.rows() ? spilled.rows() : cols.empty() ? 0 : cols[0].size(); }
  /// The columns as a store: views of `cols` (the table must outlive it), or the spill file.
  ColumnStore store() const&;
  ColumnStore store() const&& = delete;  ///< views of a temporary would dangle
  /// Index of column `name`, or throws InputError naming the file, header line and column.
  std::size_t column(std::string_view name) const;
  const std::vector<double>& operator[](std::string_view name) const { return cols[column(name)]; }
};

struct TableOptions {
  /// Columns to read, by name or 0-based index, in the order wanted; empty = all (text) .
  /// MAT: variable names or expressions (io/mat.hpp), or indices into a file's only N×k matrix.
  std::vector<std::string> columns;
  bool strict = false;  ///< a non-finite chosen cell is an error instead of a skipped row
  /// Text files: beyond this many rows the table goes to a temporary file (Table::spilled) instead
  /// of memory (0: never). MAT files are read into memory whole.
  std::size_t spill_after_rows = 0;
};

/// Reads a record (MAT or text, see above). Throws InputError naming file, line and column.
Table read_table(const std::filesystem::path& path, const TableOptions& options = {});

/// A gap: a time step longer than this many median steps. The rows after a gap start a new
/// stretch of data: estimators restart their regressors there (identify), and the sample
/// period is the median step, so a gap is never averaged into dt.
inline constexpr double kGapFactor = 5.0;

/// The gap rule for a stream (samples fed one at a time: the Python `Estimator`, library users
/// of the estimators): a step of t longer than kGapFactor periods, the period being the stream's
/// nominal sample period (its median step is not known while it arrives; a whole record uses
/// its median step, analyse_sampling). The caller restarts the estimator's regressors there.
class StreamGaps {
 public:
  explicit StreamGaps(double period_s) noexcept : above_(kGapFactor * period_s) {}
  /// Whether the sample at `t_s` starts a new stretch (never the first sample); remembers t_s.
  bool gap_before(double t_s) noexcept {
    const bool gap = seen_ && t_s - last_ > above_;
    last_ = t_s;
    seen_ = true;
    return gap;
  }
  void reset() noexcept { seen_ = false; }

 private:
  double above_;
  double last_ = 0.0;
  bool seen_ = false;
};

/// Sampling of a strictly increasing time column.
struct Sampling {
  double median_dt = 0.0;              ///< median of t[i] − t[i−1]
  double dt = 0.0;                     ///< mean step over the steps that are not gaps
  double max_jitter = 0.0;             ///< max |step − median| / median over non-gap steps
  std::vector<std::size_t> gap_rows;   ///< rows i with t[i] − t[i−1] > kGapFactor·median_dt
};
/// Sampling of `t` (at least 2 samples). Steps above gap_factor·median are gaps.
/// Same as analyse_sampling(SpanTimeSource(t), gap_factor).
Sampling analyse_sampling(std::span<const double> t, double gap_factor = kGapFactor);
/// The same of column `column` of a store (read in chunks when it is spilled).
Sampling analyse_sampling(const ColumnStore& store, std::size_t column, double gap_factor = kGapFactor);

/// A time column read in pieces, so that analyse_sampling needs none of it in memory (a record
/// streamed from a file). read() is called with any begin (the median's sample reads rows
/// j·stride and j·stride + 1: a random read), and then in order from row 0 to the end, once
/// per pass (usually two passes: the median step, then the gaps and jitter; more only when
/// the median's selection needs them, io/order_statistic.hpp). Every pass must read the same values.
class TimeSource {
 public:
  virtual ~TimeSource() = default;
  /// Rows of t.
  virtual std::size_t rows() const = 0;
  /// t[begin, begin + count) (begin + count ≤ rows()): at the pointer returned, which is `buf`
  /// (filled, room for `count` values) or the source's own memory, valid until the next call.
  virtual const double* read(std::size_t begin, std::size_t count, double* buf) const = 0;
};

/// A TimeSource over a column in memory (read() returns a pointer into it: no copy).
class SpanTimeSource final : public TimeSource {
 public:
  explicit SpanTimeSource(std::span<const double> t) noexcept : t_(t) {}
  std::size_t rows() const override { return t_.size(); }
  const double* read(std::size_t begin, std::size_t, double*) const override { return t_.data() + begin; }

 private:
  std::span<const double> t_;
};

/// Sampling of the time column `t` read in chunks (see TimeSource): memory bounded whatever its
/// length (the median step by OrderStatistic, at most 2 MiB of kept steps; chunks of 4096 rows;
/// gap_rows, one per gap, is the only thing that grows), and the very bits analyse_sampling(span)
/// gives on the same values.
Sampling analyse_sampling(const TimeSource& t, double gap_factor = kGapFactor);

}  // namespace lash
