#pragma once
/// @file record_columns.hpp
/// The columns of a record that whole-record estimation reads (estimate_auto, the intervals,
/// analyse_record): views of arrays, or a record spilled to a temporary file (io/column_store.hpp).
#include <array>
#include <cstddef>
#include <span>

#include "lash/io/column_store.hpp"

namespace lash {

/// The v and y of a record (and t, when the caller has it) as whole-record passes read them:
/// columns of a ColumnStore (io/column_store.hpp), in memory or spilled to a temporary file.
struct RecordColumns {
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  ColumnStore store;
  std::array<std::size_t, 2> vy{0, 1};  ///< the columns of v and y
  std::size_t t = kNone;                ///< the column of t (kNone: none)
  std::size_t size() const noexcept { return store.rows(); }
  /// Views of v and y (equal lengths, else std::invalid_argument naming them).
  static RecordColumns of(std::span<const double> v, std::span<const double> y);
  /// Views of t, v and y (equal lengths, else std::invalid_argument).
  static RecordColumns of(std::span<const double> t, std::span<const double> v, std::span<const double> y);
};

}  // namespace lash
