#pragma once
/// @file decimator.hpp
/// Min/max decimation with bounded memory: every sample lands in one bucket per level, the
/// buckets of level l being base_s * 4^l wide, each level a ring of `buckets` buckets. A query
/// for a time window and a number of pixel columns takes the finest level that still covers
/// the window and merges its buckets per column (min of the minima, max of the maxima), so a
/// spike of one sample is never lost at any zoom. Memory: levels * buckets * signals * 2
/// doubles, fixed at construction. Not thread-safe (the console locks around it).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace lash::console {

struct DecimatorConfig {
  std::size_t signals = 1;
  double base_s = 0.005;      ///< width of a bucket of level 0 [s]
  std::size_t levels = 7;     ///< level l: base_s * 4^l
  std::size_t buckets = 2048; ///< per level
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// One decimated view: column times (their starts) and per signal min/max (NaN = empty column).
struct DecimatedView {
  std::vector<double> t_s;                    ///< column c starts at t0_s + c * col_s
  std::vector<std::vector<double>> min, max;  ///< [signal][column]
  double bucket_s = 0.0;                      ///< the level's bucket width used
  double t0_s = 0.0;                          ///< start of column 0 [s]
  double col_s = 0.0;                         ///< width of a column [s]
};

class Decimator {
 public:
  explicit Decimator(const DecimatorConfig& c);
  /// Adds one sample (values.size() >= signals; extra values ignored). O(levels * signals).
  void add(double t_s, std::span<const double> values) noexcept;
  /// The window [t_end - window_s, t_end) in at most `columns` columns.
  DecimatedView view(double t_end, double window_s, std::size_t columns) const;
  /// Every column of the whole window (view_f32's from_col).
  static constexpr std::int64_t kWholeWindow = INT64_MIN;
  /// The window ending at t_end for the signals listed (indices < signals; others skipped),
  /// min/max as float, on a fixed grid: column j covers [j col_s, (j + 1) col_s), col_s a whole
  /// number of the level's buckets (>= window_s / columns), so a column once complete never
  /// changes and a client can ask only for the columns it lacks. The columns returned are those
  /// holding the window (the first holds t_end - window_s, the last t_end and may be partial:
  /// ceil(window_s / col_s) or one more) from index from_col on
  /// (kWholeWindow: all of them); t0_s = the first one's start (its index is t0_s / col_s).
  /// out: per listed signal, ncol minima then ncol maxima (NaN = empty column). Returns ncol.
  std::size_t view_f32(double t_end, double window_s, std::size_t columns, std::span<const std::size_t> signals,
                       std::vector<float>& out, double& t0_s, double& col_s, double& bucket_s,
                       std::int64_t from_col = kWholeWindow) const;
  double last_t() const noexcept { return last_t_; }
  std::uint64_t samples() const noexcept { return samples_; }
  /// Bytes held (constant after construction).
  std::size_t memory_bytes() const noexcept;
  const DecimatorConfig& config() const noexcept { return c_; }

 private:
  struct Level {
    double width = 0.0;
    static constexpr std::int64_t kNoBucket = INT64_MIN;
    std::vector<std::int64_t> index;  ///< bucket number held by each slot (kNoBucket: none)
    std::vector<double> lo, hi;       ///< [slot * signals + s]
  };
  DecimatorConfig c_;
  std::vector<Level> levels_;
  double last_t_ = 0.0;
  std::uint64_t samples_ = 0;
};

}  // namespace lash::console
