#pragma once
/// @file live_stats.hpp
/// Running statistics of a value seen sample by sample (the console's status panel: TET and
/// wake-up latency over the run): count, mean, min, max and the p-quantile from a histogram of
/// fixed bins (width `bin`, values below 0 in the first bin, above the range in an overflow
/// bin), so memory is fixed and a quantile costs O(bins). The quantile is the upper edge of the
/// bin holding the ceil(p * n)-th smallest value (within one bin width of the exact order
/// statistic); in the overflow bin it is the maximum. Not thread-safe; not real-time code.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace lash::console {

class LiveStats {
 public:
  explicit LiveStats(double bin = 0.1, std::size_t bins = 50000) : bin_(bin), h_(bins + 1, 0) {}
  void add(double x) noexcept {
    if (!std::isfinite(x)) return;
    ++n_;
    sum_ += x;
    min_ = std::min(min_, x);
    max_ = std::max(max_, x);
    const double b = std::floor(x / bin_);
    const std::size_t last = h_.size() - 1;
    h_[b < 0 ? 0 : (b >= static_cast<double>(last) ? last : static_cast<std::size_t>(b))]++;
  }
  std::uint64_t count() const noexcept { return n_; }
  double mean() const noexcept { return n_ ? sum_ / static_cast<double>(n_) : std::numeric_limits<double>::quiet_NaN(); }
  double max() const noexcept { return n_ ? max_ : std::numeric_limits<double>::quiet_NaN(); }
  double min() const noexcept { return n_ ? min_ : std::numeric_limits<double>::quiet_NaN(); }
  double quantile(double p) const noexcept {
    if (!n_) return std::numeric_limits<double>::quiet_NaN();
    const auto rank = static_cast<std::uint64_t>(std::max(1.0, std::ceil(p * static_cast<double>(n_))));
    std::uint64_t c = 0;
    for (std::size_t i = 0; i + 1 < h_.size(); ++i) {
      c += h_[i];
      if (c >= rank) return std::min(max_, static_cast<double>(i + 1) * bin_);
    }
    return max_;
  }

 private:
  double bin_;
  std::vector<std::uint64_t> h_;
  std::uint64_t n_ = 0;
  double sum_ = 0.0, min_ = std::numeric_limits<double>::infinity(), max_ = -std::numeric_limits<double>::infinity();
};

}  // namespace lash::console
