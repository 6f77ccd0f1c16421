#pragma once
/// @file page_hinkley.hpp
/// Page–Hinkley change detector: a two-sided test for a change in the mean of a sequence,
/// E. S. Page, "Continuous inspection schemes", Biometrika 41 (1954) 100–115, in the form of
/// M. Basseville and I. V. Nikiforov, "Detection of Abrupt Changes: Theory and Application",
/// Prentice Hall 1993, §2.2.3 (Eq. 2.2.31–2.2.33), with the unknown mean before the change
/// replaced by the running mean of the samples seen since the last reset:
///
///   x̄_k = x̄_{k−1} + (x_k − x̄_{k−1}) / k                       (running mean)
///   U_k = U_{k−1} + (x_k − x̄_k − δ),   m_k = min_{j≤k} U_j      (increase)
///   L_k = L_{k−1} + (x_k − x̄_k + δ),   M_k = max_{j≤k} L_j      (decrease)
///   alarm when U_k − m_k > h (up) or M_k − L_k > h (down),  U_0 = L_0 = m_0 = M_0 = 0.
///
/// δ is the magnitude of change the test ignores (drift allowance), h the alarm threshold,
/// both in the unit of x. The change time estimate is the sample after the extremum (m_k or
/// M_k); `before` is the mean of the samples up to it. After an alarm the caller resets the
/// detector (reset()) to start watching the new level.
/// Real time: update() is noexcept, O(1) and allocation-free.
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace lash {

struct PageHinkleySettings {
  double delta = 0.0;      ///< δ: allowance [unit of x], >= 0
  double threshold = 1.0;  ///< h: alarm threshold [unit of x], > 0
  /// Throws std::invalid_argument naming the field.
  void validate() const {
    if (!(delta >= 0.0) || delta == std::numeric_limits<double>::infinity())
      throw std::invalid_argument("delta must be finite and >= 0");
    if (!(threshold > 0.0) || threshold == std::numeric_limits<double>::infinity())
      throw std::invalid_argument("threshold must be finite and > 0");
  }
};

class PageHinkley {
 public:
  enum class Change : std::uint8_t { none, up, down };

  /// Validates `s` (std::invalid_argument).
  explicit PageHinkley(const PageHinkleySettings& s) : s_(s) { s_.validate(); }

  /// One sample; returns the change detected at this sample (none for a non-finite x, which
  /// is skipped). noexcept, O(1).
  Change update(double x) noexcept {
    if (!(x - x == 0.0)) return Change::none;  // NaN or ±inf
    ++n_;
    sum_ += x;
    mean_ += (x - mean_) / static_cast<double>(n_);
    up_ += x - mean_ - s_.delta;
    down_ += x - mean_ + s_.delta;
    if (up_ < up_min_) {
      up_min_ = up_;
      up_n_ = n_;
      up_sum_ = sum_;
    }
    if (down_ > down_max_) {
      down_max_ = down_;
      down_n_ = n_;
      down_sum_ = sum_;
    }
    if (up_ - up_min_ > s_.threshold) return Change::up;
    if (down_max_ - down_ > s_.threshold) return Change::down;
    return Change::none;
  }

  /// Forgets every sample (after an alarm: watch the new level).
  void reset() noexcept { *this = PageHinkley(s_, 0); }

  std::uint64_t count() const noexcept { return n_; }
  double mean() const noexcept { return mean_; }
  /// U_k − m_k and M_k − L_k: the statistics compared with h.
  double up_statistic() const noexcept { return up_ - up_min_; }
  double down_statistic() const noexcept { return down_max_ - down_; }
  /// Mean of the samples up to the estimated change time of `c` (the extremum of U or L);
  /// the running mean when the extremum is the start (no sample before it). NaN before a sample.
  double mean_before(Change c) const noexcept {
    const std::uint64_t n = c == Change::down ? down_n_ : up_n_;
    const double sum = c == Change::down ? down_sum_ : up_sum_;
    if (n == 0) return n_ == 0 ? std::numeric_limits<double>::quiet_NaN() : mean_;
    return sum / static_cast<double>(n);
  }
  /// Mean of the samples after the estimated change time of `c` (the level the test moved to);
  /// the running mean when the extremum is the start. NaN before a sample.
  double mean_after(Change c) const noexcept {
    const std::uint64_t n = c == Change::down ? down_n_ : up_n_;
    const double sum = c == Change::down ? down_sum_ : up_sum_;
    if (n_ == 0) return std::numeric_limits<double>::quiet_NaN();
    if (n == 0 || n == n_) return mean_;
    return (sum_ - sum) / static_cast<double>(n_ - n);
  }
  const PageHinkleySettings& settings() const noexcept { return s_; }

 private:
  PageHinkley(const PageHinkleySettings& s, int) noexcept : s_(s) {}
  PageHinkleySettings s_;
  std::uint64_t n_ = 0;
  double sum_ = 0.0, mean_ = 0.0;
  double up_ = 0.0, up_min_ = 0.0, down_ = 0.0, down_max_ = 0.0;
  std::uint64_t up_n_ = 0, down_n_ = 0;  ///< sample count at the extremum (0 = at the start)
  double up_sum_ = 0.0, down_sum_ = 0.0;
};

}  // namespace lash
