// OrderStatistic: an exact order statistic in bounded memory (io/order_statistic.hpp).
#include "lash/io/order_statistic.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

namespace lash {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::uint64_t kTop = std::uint64_t{1} << 63;
constexpr std::uint64_t kNegZeroKey = kTop - 1;  // the key −0 would have (no value has it: −0 is +0)
constexpr std::size_t kBins = 65536;

/// The order-preserving key of a double that is not NaN: x < y ⇔ key(x) < key(y); −0 is +0.
std::uint64_t key(double x) noexcept {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  if (b == kTop) b = 0;  // −0 → +0
  return (b & kTop) ? ~b : (b | kTop);
}
double from_key(std::uint64_t k) noexcept {
  const std::uint64_t b = (k & kTop) ? (k & ~kTop) : ~k;
  double x;
  std::memcpy(&x, &b, sizeof x);
  return x;
}
}  // namespace

OrderStatistic OrderStatistic::quantile(double q, std::size_t cap) { return OrderStatistic(q, false, cap); }
OrderStatistic OrderStatistic::median(std::size_t cap) { return OrderStatistic(0.5, true, cap); }

void OrderStatistic::bracket(std::vector<double>& s, std::size_t n_expected) {
  constexpr std::size_t kMinSample = 256;
  if (s.size() < kMinSample) return;  // keep every value
  std::sort(s.begin(), s.end());
  if (std::isnan(s.front()) || std::isnan(s.back())) return;
  const double q = q_;
  const double m = static_cast<double>(s.size());
  const double margin = 4.0 * std::sqrt(m * q * (1.0 - q)) + 8.0;
  const double r = q * (m - 1.0);
  const auto i_lo = static_cast<std::size_t>(std::max(0.0, r - margin));
  const auto i_hi = static_cast<std::size_t>(std::min(m - 1.0, r + margin));
  bracket(s[i_lo], s[i_hi]);
  const double want = static_cast<double>(n_expected) * (static_cast<double>(i_hi - i_lo) + 2.0) / m * 1.25 + 64.0;
  kept_.resize(static_cast<std::size_t>(std::min(want, static_cast<double>(cap_))));
}

void OrderStatistic::bracket(double lo, double hi) {
  lo_ = lo;
  hi_ = hi;
  state_ = first_ = State::keep;
}

void OrderStatistic::reserve_kept(std::size_t want) {
  if (kept_.size() < want) kept_.resize(std::min(cap_, std::max({2 * kept_.size(), kept + 1024, want})));
}

void OrderStatistic::to_bins() {
  high_water_ = std::max(high_water_, kept);
  bins_.assign(kBins, 0);
  const std::uint64_t d = key(lo_) ^ key(hi_);
  const int common = d ? std::countl_zero(d) : 64;
  shift_ = std::max(0, 64 - common - 16);
  State was = state_;
  state_ = State::bins;
  if (was == State::keep_all) {  // every value was kept: now counted against [−inf, +inf]
    for (std::size_t j = 0; j < kept; ++j) {
      const double v = kept_[j];
      at_lo_ += v == -kInf ? 1 : 0;
      at_hi_ += v == kInf ? 1 : 0;
      if (v > -kInf && v < kInf) {
        ++bins_[(key(v) >> shift_) & (kBins - 1)];
        ++in_bins_;
      }
    }
  } else {
    for (std::size_t j = 0; j < kept; ++j) ++bins_[(key(kept_[j]) >> shift_) & (kBins - 1)];
    in_bins_ += kept;
  }
  kept = 0;
  std::vector<double>().swap(kept_);
}

void OrderStatistic::bin_values(const double* x, std::size_t m) {
  const double l = lo_, h = hi_;
  for (std::size_t j = 0; j < m; ++j) {
    const double v = x[j];
    if (v > l && v < h) {
      ++bins_[(key(v) >> shift_) & (kBins - 1)];
      ++in_bins_;
    }
  }
}

void OrderStatistic::keep_block(const double* x, std::size_t m) {
  const double l = lo_, h = hi_;
  for (std::size_t j = 0; j < m; ++j) {
    const double v = x[j];
    if (!(v > l && v < h)) continue;
    if (state_ == State::keep && kept == cap_) to_bins();
    if (state_ == State::bins) {
      ++bins_[(key(v) >> shift_) & (kBins - 1)];
      ++in_bins_;
    } else {
      reserve_kept(kept + 1);
      kept_[kept++] = v;
    }
  }
}

void OrderStatistic::add(const double* x, std::size_t m) {
  n_pass_ += m;
  if (state_ == State::done) return;
  if (state_ == State::max_below) {
    const double t = upper_;
    for (std::size_t j = 0; j < m; ++j) {
      const double v = x[j];
      if (v < t) {
        max_below_ = any_below_ ? std::max(max_below_, v) : v;
        any_below_ = true;
      }
    }
    return;
  }
  if (state_ == State::keep_all) {
    const std::size_t take = std::min(m, cap_ - kept);
    kept_.resize(kept);
    kept_.insert(kept_.end(), x, x + take);
    kept = kept_.size();
    high_water_ = std::max(high_water_, kept);
    if (take == m) return;
    // over the cap: every value counted against the bracket [−inf, +inf] from here on
    lo_ = -kInf;
    hi_ = kInf;
    to_bins();
    x += take;
    m -= take;
    n_pass_ -= m;  // counted again below
    add(x, m);
    return;
  }
  count<false>(x, m);
}

void OrderStatistic::add_steps(const double* t, std::size_t m) {
  if (state_ == State::keep || state_ == State::bins) {
    n_pass_ += m;
    count<true>(t, m);
    return;
  }
  double buf[256];
  for (std::size_t i = 0; i < m; i += 256) {
    const std::size_t c = std::min<std::size_t>(256, m - i);
    for (std::size_t j = 0; j < c; ++j) buf[j] = t[i + j + 1] - t[i + j];
    add(buf, c);
  }
}

template <bool kSteps>
void OrderStatistic::count(const double* x, std::size_t m) {
  // Blocks of 16 values: the counts two lanes at a time (SSE2's width; GCC/Clang vector
  // extensions, a lane's comparison is −1 where true) without a branch on the data, and whether
  // any value of the block lies inside; only such a block is searched for them (for the tail
  // quantiles nearly none is). kSteps: the values are x[i + 1] − x[i], made as they are read.
  using V = double __attribute__((vector_size(16)));
  using M = std::int64_t __attribute__((vector_size(16)));
  const double l = lo_, h = hi_;
  const V lv = {l, l}, hv = {h, h};
  M c_lt_lo{}, c_le_lo{}, c_lt_hi{}, c_le_hi{}, c_gt_hi{};
  std::size_t i = 0;
  for (; i + 16 <= m; i += 16) {
    M any{};
    [[maybe_unused]] double steps[16];
    for (std::size_t j = 0; j < 16; j += 2) {
      V v;
      std::memcpy(&v, x + i + j, sizeof v);
      if constexpr (kSteps) {
        V v1;
        std::memcpy(&v1, x + i + j + 1, sizeof v1);
        v = v1 - v;
      }
      const M lt_l = v < lv, lt_h = v < hv, le_l = v <= lv;
      c_lt_lo -= lt_l;
      c_le_lo -= le_l;
      c_lt_hi -= lt_h;
      c_le_hi -= v <= hv;
      c_gt_hi -= v > hv;
      any |= lt_h & ~le_l;  // lo < v < hi
    }
    if (any[0] | any[1]) {
      const double* b = x + i;
      if constexpr (kSteps) {  // made again: the same bits, and no store in the loop above
        for (std::size_t j = 0; j < 16; ++j) steps[j] = x[i + j + 1] - x[i + j];
        b = steps;
      }
      if (state_ == State::keep && kept + 16 <= cap_) {
        // every value written at the end, the end advanced past those inside
        if (kept_.size() < kept + 16) reserve_kept(kept + 16);
        double* out = kept_.data();
        for (std::size_t j = 0; j < 16; ++j) {
          out[kept] = b[j];
          kept += ((b[j] > l) & (b[j] < h)) ? 1 : 0;
        }
      } else if (state_ == State::keep) {
        keep_block(b, 16);  // near the cap: checked value by value
      } else {
        bin_values(b, 16);
      }
    }
  }
  const auto sum = [](const M& c) { return static_cast<std::size_t>(c[0] + c[1]); };
  std::size_t lt_lo = sum(c_lt_lo), le_lo = sum(c_le_lo), lt_hi = sum(c_lt_hi), le_hi = sum(c_le_hi),
              gt_hi = sum(c_gt_hi);
  for (; i < m; ++i) {
    double v = x[i];
    if constexpr (kSteps) v = x[i + 1] - x[i];
    lt_lo += v < l ? 1 : 0;
    le_lo += v <= l ? 1 : 0;
    lt_hi += v < h ? 1 : 0;
    le_hi += v <= h ? 1 : 0;
    gt_hi += v > h ? 1 : 0;
    if (v > l && v < h) keep_block(&v, 1);
  }
  below_ += lt_lo;
  at_lo_ += le_lo - lt_lo;
  at_hi_ += l < h ? le_hi - lt_hi : 0;  // lo == hi: a value equal to both counts once (at lo)
  above_ += gt_hi;
  high_water_ = std::max(high_water_, kept);
}

void OrderStatistic::start_pass(State s) {
  state_ = s;
  n_pass_ = below_ = at_lo_ = at_hi_ = above_ = in_bins_ = 0;
  kept = 0;
  any_below_ = false;
  if (s != State::bins) std::vector<std::uint64_t>().swap(bins_);
  if (s == State::bins) {
    std::vector<double>().swap(kept_);
    bins_.assign(kBins, 0);
    const std::uint64_t d = key(lo_) ^ key(hi_);
    const int common = d ? std::countl_zero(d) : 64;
    shift_ = std::max(0, 64 - common - 16);
  }
}

double OrderStatistic::nth(std::size_t k) {
  kept_.resize(kept);
  const auto it = kept_.begin() + static_cast<std::ptrdiff_t>(k);
  std::nth_element(kept_.begin(), it, kept_.end());
  return *it;
}

bool OrderStatistic::end_pass() {
  if (state_ == State::done) return false;
  ++passes_;
  if (passes_ == 1) {
    n_ = n_pass_;
  } else if (n_pass_ != n_) {
    return finish(kNaN);  // the passes did not see the same values
  }
  if (n_ == 0) return finish(0.0);
  if (state_ == State::max_below) return finish(any_below_ ? 0.5 * (upper_ + max_below_) : kNaN);
  if (state_ == State::keep_all) {  // every value kept, within the cap: the reference rule
    if (!median_) return finish(nth(static_cast<std::size_t>(q_ * static_cast<double>(n_ - 1))));
    const std::size_t r = n_ / 2;
    double med = nth(r);
    if (n_ % 2 == 0) med = 0.5 * (med + *std::max_element(kept_.begin(), kept_.begin() + static_cast<std::ptrdiff_t>(r)));
    return finish(med);
  }
  return resolve();
}

bool OrderStatistic::finish(double v) {
  value_ = v;
  state_ = State::done;
  std::vector<double>().swap(kept_);
  std::vector<std::uint64_t>().swap(bins_);
  kept = 0;
  return false;
}

bool OrderStatistic::resolve() {
  const std::size_t n = n_;
  const std::size_t inside = state_ == State::keep ? kept : in_bins_;
  const bool no_nan = below_ + at_lo_ + inside + at_hi_ + above_ == n;
  const bool first = passes_ == 1 && first_ == State::keep;
  if (!no_nan) {
    // a NaN: within the cap every value is kept (the reference rule); over it the result is NaN
    if (first && state_ == State::keep && n <= cap_) {
      start_pass(State::keep_all);
      return true;
    }
    return finish(kNaN);
  }
  std::size_t r = median_ ? n / 2 : static_cast<std::size_t>(q_ * static_cast<double>(n - 1));
  // the value of rank k when the counts (and the kept values) give it
  const auto known = [&](std::size_t k, double& out) {
    if (k < below_) return false;
    k -= below_;
    if (k < at_lo_) return out = lo_, true;
    k -= at_lo_;
    if (k < inside) {
      if (state_ != State::keep) return false;
      return out = nth(k), true;
    }
    k -= inside;
    if (k < at_hi_) return out = hi_, true;
    return false;
  };
  const auto miss = [&](bool low_side) {
    // the bracket missed: the side the rank lies on when it holds at most a quarter of the values,
    // else every value (the rule without a cap); then within the cap the same passes as before
    if (!first) return finish(kNaN);  // only the sample's bracket can miss
    const std::size_t side = low_side ? below_ : above_;
    if (side <= n / 4) {
      if (low_side) {
        hi_ = lo_;
        lo_ = -kInf;
      } else {
        lo_ = hi_;
        hi_ = kInf;
      }
      start_pass(State::keep);
    } else {
      start_pass(State::keep_all);
    }
    return true;
  };
  // the median's lower value (even n) once the upper one `x` is known, with n_less values below x
  const auto pair = [&](double x, std::size_t n_less) {
    if (!median_ || n % 2 != 0) return finish(x);
    double lower;
    if (known(r - 1, lower)) return finish(0.5 * (x + lower));
    if (r - 1 >= n_less) return finish(x);  // ranks r − 1 and r hold the same value
    upper_ = x;  // the lower value is the largest one below x: one more pass
    start_pass(State::max_below);
    return true;
  };
  if (r < below_) return miss(true);
  double x;
  if (r - below_ < at_lo_) return pair(lo_, below_);
  if (r - below_ - at_lo_ < inside) {
    if (state_ == State::keep) {
      known(r, x);
      return pair(x, r);  // kept: the lower value is found among the same (n_less unused)
    }
    // over the cap: the bin of the rank's key becomes the bracket
    std::size_t rr = r - below_ - at_lo_, cum = 0, b = 0;
    for (; b < kBins; ++b) {
      if (rr < cum + bins_[b]) break;
      cum += bins_[b];
    }
    const std::size_t in_bin = static_cast<std::size_t>(bins_[b]);
    const std::uint64_t klo = key(lo_), khi = key(hi_);
    const int width = shift_ + 16;
    const std::uint64_t top = width >= 64 ? 0 : (klo >> width) << width;
    std::uint64_t ks = top | (static_cast<std::uint64_t>(b) << shift_);
    std::uint64_t ke = ks + ((std::uint64_t{1} << shift_) - 1);
    ks = std::max(ks, klo + 1);
    ke = std::min(ke, khi - 1);
    if (ks == kNegZeroKey) ks = kTop;  // no value has −0's key
    if (ke == kNegZeroKey) ke = kNegZeroKey - 1;
    if (ks == ke) return pair(from_key(ks), below_ + at_lo_ + cum);
    lo_ = from_key(ks);
    hi_ = from_key(ke);
    start_pass(in_bin <= cap_ ? State::keep : State::bins);
    return true;
  }
  if (r - below_ - at_lo_ - inside < at_hi_) return pair(hi_, below_ + at_lo_ + inside);
  return miss(false);
}

}  // namespace lash
