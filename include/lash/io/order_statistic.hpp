#pragma once
/// @file order_statistic.hpp
/// One exact order statistic of a sequence read in one or more passes, in memory bounded by a
/// fixed cap whatever the sequence's length (issue 29): the quantiles analyse_record takes of a
/// record (identify/auto.cpp) and the median step of a time column (analyse_sampling, io/table.hpp).
/// Lives in io (the ground layer) so that both can use it. Not real-time safe (allocates).
///
/// The result is the value std::nth_element puts at the rank on a full copy of the sequence:
/// - quantile(q): rank ⌊q·(n − 1)⌋ of the n values;
/// - median(): rank n/2, and for even n the mean 0.5·(x[n/2] + x[n/2 − 1]) (max of the lower part).
///
/// How (Floyd & Rivest's selection, then radix selection): a bracket [lo, hi] chosen from a small
/// sample of the sequence (bracket(); without one every value is kept, the reference rule); each
/// pass counts the values below lo, equal to lo, equal to hi and above hi and keeps those strictly
/// between, at most `cap` of them; the rank is then found in the counts or by nth_element among the
/// kept values. end_pass() says whether another pass over the same values is needed:
/// - the bracket missed the rank: the next pass brackets the side it lies on, [−inf, lo] or
///   [hi, +inf], when that side holds at most a quarter of the values, else keeps every value;
/// - more than `cap` values fell inside the bracket: from then on the pass stops keeping and
///   counts the values inside in 65536 bins of 16 bits of their order-preserving 64-bit key (the
///   bits below the prefix that lo's and hi's keys share); the bin that holds the rank becomes the
///   next bracket. Each such pass fixes 16 more bits of the key: at most 4 of them, fewer as soon
///   as a bin's values fit the cap (the next pass keeps them) or a bin is one key (its value);
/// - median() with even n: the value below the upper median, when it is not among the kept ones,
///   is the largest value below it (one pass that keeps nothing).
/// Memory: at most `cap` kept doubles (kept_high_water() ≤ cap) plus, only while a pass counts in
/// bins, 65536 64-bit counters (512 KiB).
///
/// Whenever no pass keeps more than `cap` values, the result and the passes are those of the
/// rule without a cap, bit for bit (including a sequence that holds a NaN: it keeps every value
/// and takes nth_element over them, as the reference rule on a full copy does).
/// Over the cap:
/// - a NaN in the sequence makes the result NaN (no order ranks it; nth_element's answer on
///   such a sequence is not defined by any order either);
/// - values are ordered as by `<`, ±0 being one value: a result of zero is +0 whatever the signs
///   of the zeros in the sequence (within the cap the zero nth_element picks).
/// Every pass must deliver the same values in the same order (add() in chunks of any size).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace lash {

class OrderStatistic {
 public:
  /// The default cap on kept values: 2^18 doubles = 2 MiB. The widest bracket analyse_record
  /// takes (the median of |Δ²y|, ≈ 6.6 % of the values) stays within it up to ~4·10⁶ rows,
  /// analyse_sampling's median step (≈ 9.4 % of the steps when they all differ) up to ~2.8·10⁶:
  /// one pass there, one or two more beyond.
  static constexpr std::size_t kDefaultCap = std::size_t{1} << 18;

  /// The value of rank ⌊q·(n − 1)⌋ (q in [0, 1]).
  static OrderStatistic quantile(double q, std::size_t cap = kDefaultCap);
  /// The median as above (rank n/2; even n: mean with rank n/2 − 1).
  static OrderStatistic median(std::size_t cap = kDefaultCap);

  /// Brackets the rank with the sample `s` (sorted here) of the sequence: a margin of ~4 standard
  /// deviations of the sample quantile's rank; `n_expected` ≈ values in the pass (sizes the
  /// buffer). Fewer than 256 values, or a NaN among them: no bracket (every value kept).
  void bracket(std::vector<double>& s, std::size_t n_expected);
  /// The bracket [lo, hi] (lo ≤ hi, neither NaN).
  void bracket(double lo, double hi);

  /// The next m values of the pass.
  void add(const double* x, std::size_t m);
  void add(std::span<const double> x) { add(x.data(), x.size()); }
  /// The next m values of the pass being the steps t[i + 1] − t[i], i < m (reads t[0, m]): as
  /// add() of them, without writing them anywhere first.
  void add_steps(const double* t, std::size_t m);

  /// Ends a pass: true when another pass over the same values is needed (then add them all
  /// again and call end_pass again), false when value() is known (the kept values are freed).
  bool end_pass();
  /// Whether the next pass is needed (false before the first pass ends).
  bool needs_pass() const noexcept { return state_ != State::done && passes_ > 0; }

  /// The result (after end_pass returned false); 0 for an empty sequence.
  double value() const noexcept { return value_; }
  std::size_t count() const noexcept { return n_; }        ///< values per pass
  std::size_t passes() const noexcept { return passes_; }  ///< passes ended
  std::size_t cap() const noexcept { return cap_; }
  /// The most values ever kept at once (≤ cap()).
  std::size_t kept_high_water() const noexcept { return high_water_; }

 private:
  enum class State { keep_all, keep, bins, max_below, done };
  OrderStatistic(double q, bool median, std::size_t cap) : q_(q), median_(median), cap_(cap < 16 ? 16 : cap) {}

  void start_pass(State s);
  template <bool kSteps>
  void count(const double* x, std::size_t m);       // the counts and the kept values of a bracket
  void keep_block(const double* x, std::size_t m);  // scalar keep with the cap checked per value
  void to_bins();                                   // the kept values into the bins
  void bin_values(const double* x, std::size_t m);  // values strictly inside into the bins
  void reserve_kept(std::size_t want);
  /// After a pass with a bracket: the rank's value from the counts (and the kept values), or the
  /// next pass set up (true).
  bool resolve();
  /// Settles the result at v, frees the kept values and bins; returns false (no further pass).
  bool finish(double v);
  double nth(std::size_t k);

  double q_;
  bool median_;
  std::size_t cap_;
  State state_ = State::keep_all;
  State first_ = State::keep_all;
  double lo_ = 0.0, hi_ = 0.0;
  std::size_t n_ = 0, n_pass_ = 0;
  std::size_t below_ = 0, at_lo_ = 0, at_hi_ = 0, above_ = 0, in_bins_ = 0;
  std::vector<double> kept_;  ///< kept_[0, kept) (the rest is room to write into)
  std::size_t kept = 0, high_water_ = 0;
  std::vector<std::uint64_t> bins_;
  int shift_ = 0;
  double upper_ = 0.0;          // median(): the upper value, while the lower one is searched
  double max_below_ = 0.0;
  bool any_below_ = false;
  std::size_t passes_ = 0;
  double value_ = 0.0;
};

}  // namespace lash
