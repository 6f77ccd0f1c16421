#pragma once
/// @file column_store.hpp
/// Numeric columns of one length that a whole-record computation reads in passes, held either in
/// memory (views of the caller's arrays: no copy) or in a temporary spill file (a record too long
/// to hold: SpillWriter), so that the memory of a pass does not grow with the record
/// (docs/memory.md). Passes read the columns in chunks of kChunkRows rows (for_chunks); a store in
/// memory hands out the whole range at once, so a computation over arrays runs as it did on them.
///
/// The spill file is created unlinked (O_TMPFILE, or mkstemp + unlink where the file system lacks
/// it) with mode 0600 in $TMPDIR (else /tmp): no name exists that another process could plant or
/// open, and the kernel frees it when the last store holding it goes. Not real-time safe.
#include <algorithm>
#include <array>
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace lash {

class SpillFile;  // column_store.cpp

/// Rows per block of a spill file (SpillWriter): a block holds its columns one after the other.
inline constexpr std::size_t kSpillBlockRows = std::size_t{1} << 15;

class ColumnStore {
 public:
  /// Rows per chunk of a pass over a spilled store (16 Ki rows: 128 KiB per column).
  static constexpr std::size_t kChunkRows = std::size_t{1} << 14;

  ColumnStore() = default;
  /// Views of `cols` (equal lengths, else std::invalid_argument); the arrays must outlive the store.
  explicit ColumnStore(std::vector<std::span<const double>> cols);

  std::size_t rows() const noexcept { return rows_; }
  std::size_t columns() const noexcept { return file_ ? file_columns_ : mem_.size(); }
  bool in_memory() const noexcept { return !file_; }
  /// Column c whole (in memory only; std::logic_error for a spilled store).
  std::span<const double> column(std::size_t c) const;
  /// Copies rows [begin, begin + n) of column c into out (std::out_of_range beyond rows()).
  void read(std::size_t c, std::size_t begin, std::size_t n, double* out) const;
  /// Rows [begin, begin + n) of column c in place, for a spilled store that is mapped (read-only
  /// mmap) when they lie in one block of SpillWriter::kBlockRows rows; nullptr otherwise (read()).
  const double* mapped(std::size_t c, std::size_t begin, std::size_t n) const noexcept;
  /// Drops the mapped pages of the block holding `row` from the process (they stay in the page
  /// cache): a pass releases each block behind it, so its resident memory is one block.
  void release_block(std::size_t row) const noexcept;
  /// One value (a single read for a spilled store: for bisection, not for passes).
  double at(std::size_t c, std::size_t row) const;
  /// The store's last row of column c (rows() > 0).
  double back(std::size_t c) const { return at(c, rows_ - 1); }

 private:
  friend class SpillWriter;
  std::vector<std::span<const double>> mem_;
  std::shared_ptr<const SpillFile> file_;
  std::size_t file_columns_ = 0;
  std::size_t rows_ = 0;
};

/// Calls f(base, cols) for consecutive chunks of rows [begin, end) of the store's columns `which`
/// (cols[i]: std::span<const double> of column which[i], rows [base, base + cols[i].size())).
/// In memory: one call with the whole range (views, no copy); spilled: chunks of kChunkRows read
/// into one buffer allocated per call.
template <std::size_t K, class F>
void for_chunks(const ColumnStore& s, const std::array<std::size_t, K>& which, std::size_t begin, std::size_t end,
                F&& f) {
  std::array<std::span<const double>, K> cols;
  if (end <= begin) return;
  if (s.in_memory()) {
    for (std::size_t i = 0; i < K; ++i) cols[i] = s.column(which[i]).subspan(begin, end - begin);
    f(begin, std::as_const(cols));
    return;
  }
  // chunks never cross a block of the spill file: in a mapped store they are read in place, and
  // each block is released when the pass leaves it
  constexpr std::size_t B = kSpillBlockRows;
  std::vector<double> buf;
  for (std::size_t b = begin; b < end;) {
    const std::size_t m = std::min({ColumnStore::kChunkRows, end - b, B - b % B});
    bool in_place = true;
    for (std::size_t i = 0; i < K && in_place; ++i) {
      const double* p = s.mapped(which[i], b, m);
      in_place = p != nullptr;
      cols[i] = std::span<const double>(p, in_place ? m : 0);
    }
    if (!in_place) {
      buf.resize(K * ColumnStore::kChunkRows);
      for (std::size_t i = 0; i < K; ++i) {
        double* out = buf.data() + i * ColumnStore::kChunkRows;
        s.read(which[i], b, m, out);
        cols[i] = std::span<const double>(out, m);
      }
    }
    f(b, std::as_const(cols));
    b += m;
    if (in_place && (b % B == 0 || b == end)) s.release_block(b - 1);
  }
}

/// Rows [begin, begin + n) of some columns, read on demand into a buffer of its own (a view when
/// the store is in memory): for computations that visit scattered short windows of a record.
template <std::size_t K>
class ChunkBuffer {
 public:
  std::array<std::span<const double>, K> get(const ColumnStore& s, const std::array<std::size_t, K>& which,
                                             std::size_t begin, std::size_t n) {
    std::array<std::span<const double>, K> cols;
    if (s.in_memory()) {
      for (std::size_t i = 0; i < K; ++i) cols[i] = s.column(which[i]).subspan(begin, n);
      return cols;
    }
    if (buf_.size() < K * n) buf_.resize(K * n);
    for (std::size_t i = 0; i < K; ++i) {
      s.read(which[i], begin, n, buf_.data() + i * n);
      cols[i] = std::span<const double>(buf_.data() + i * n, n);
    }
    return cols;
  }

 private:
  std::vector<double> buf_;
};

/// Writes rows of `columns` values into a new spill file (see the file comment) and hands it over
/// as a ColumnStore. Memory: one block of kBlockRows rows. Errors (no temporary directory, disk
/// full) are lash::InputError naming the directory and the system's reason.
class SpillWriter {
 public:
  static constexpr std::size_t kBlockRows = kSpillBlockRows;

  explicit SpillWriter(std::size_t columns);
  ~SpillWriter();
  SpillWriter(const SpillWriter&) = delete;
  SpillWriter& operator=(const SpillWriter&) = delete;

  /// Appends one row (columns values).
  void push(const double* row) {
    for (std::size_t c = 0; c < columns_; ++c) block_[c * kBlockRows + fill_] = row[c];
    if (++fill_ == kBlockRows) flush_block();
    ++rows_;
  }
  /// Appends n rows given column-wise: cols[c][0..n).
  void push_columns(const std::vector<std::vector<double>>& cols, std::size_t n);
  std::size_t rows() const noexcept { return rows_; }
  /// The rows written so far, as a store (the writer is spent afterwards).
  ColumnStore finish();

 private:
  void flush_block();

  std::size_t columns_;
  std::vector<double> block_;
  std::size_t fill_ = 0;
  std::size_t blocks_ = 0;
  std::size_t rows_ = 0;
  std::shared_ptr<SpillFile> file_;
};

}  // namespace lash
