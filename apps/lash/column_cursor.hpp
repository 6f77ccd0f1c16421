#pragma once
// A column of a record's store read row by row (the trace of `lash estimate`, the input file of
// `lash simulate`).
#include <algorithm>
#include <cstddef>
#include <span>

#include "lash/io/column_store.hpp"

namespace lash::cli {

/// One column of a store read row by row, a chunk of kChunkRows rows at a time (views when the
/// store is in memory): for a caller that walks the rows in order, one at a time.
class ColumnCursor {
 public:
  ColumnCursor(const ColumnStore& s, std::size_t column) : s_(s), c_(column) {}
  /// The value at `row` (< rows()); cheapest in increasing order.
  double at(std::size_t row) {
    if (row - base_ >= chunk_.size()) {
      base_ = row;
      chunk_ = buf_.get(s_, {c_}, row, std::min(ColumnStore::kChunkRows, s_.rows() - row))[0];
    }
    return chunk_[row - base_];
  }

 private:
  const ColumnStore& s_;
  std::size_t c_;
  ChunkBuffer<1> buf_;
  std::span<const double> chunk_;
  std::size_t base_ = 0;
};

}  // namespace lash::cli
