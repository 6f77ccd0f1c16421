#include "lash/console/decimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace lash::console {

void DecimatorConfig::validate() const {
  if (signals == 0) throw std::invalid_argument("decimator: signals must be >= 1");
  if (!(base_s > 0.0) || !std::isfinite(base_s)) throw std::invalid_argument("decimator: base_s must be > 0");
  if (levels == 0 || levels > 16) throw std::invalid_argument("decimator: levels must be 1..16");
  if (buckets < 2) throw std::invalid_argument("decimator: buckets must be >= 2");
}

Decimator::Decimator(const DecimatorConfig& c) : c_(c) {
  c_.validate();
  double w = c_.base_s;
  levels_.resize(c_.levels);
  for (auto& l : levels_) {
    l.width = w;
    l.index.assign(c_.buckets, Level::kNoBucket);  // not -1: that is the bucket of t in [-width, 0)
    l.lo.assign(c_.buckets * c_.signals, 0.0);
    l.hi.assign(c_.buckets * c_.signals, 0.0);
    w *= 4.0;
  }
}

void Decimator::add(double t_s, std::span<const double> values) noexcept {
  if (!std::isfinite(t_s) || values.size() < c_.signals) return;
  const std::size_t n = c_.signals;
  for (auto& l : levels_) {
    const auto b = static_cast<std::int64_t>(std::floor(t_s / l.width));
    const std::size_t slot = static_cast<std::size_t>(((b % static_cast<std::int64_t>(c_.buckets)) +
                                                       static_cast<std::int64_t>(c_.buckets)) %
                                                      static_cast<std::int64_t>(c_.buckets));
    double* lo = &l.lo[slot * n];
    double* hi = &l.hi[slot * n];
    if (l.index[slot] != b) {
      l.index[slot] = b;
      for (std::size_t s = 0; s < n; ++s) lo[s] = hi[s] = values[s];
      continue;
    }
    for (std::size_t s = 0; s < n; ++s) {  // NaN (no value yet) never hides a value
      if (std::isnan(lo[s])) {
        lo[s] = hi[s] = values[s];
      } else if (!std::isnan(values[s])) {
        lo[s] = std::min(lo[s], values[s]);
        hi[s] = std::max(hi[s], values[s]);
      }
    }
  }
  last_t_ = std::max(last_t_, t_s);
  ++samples_;
}

DecimatedView Decimator::view(double t_end, double window_s, std::size_t columns) const {
  DecimatedView v;
  const std::size_t n = c_.signals;
  v.min.assign(n, {});
  v.max.assign(n, {});
  if (!(window_s > 0.0) || columns == 0) return v;
  const Level* lv = &levels_.back();
  for (const auto& l : levels_)
    if (l.width * static_cast<double>(c_.buckets - 1) >= window_s) {
      lv = &l;
      break;
    }
  v.bucket_s = lv->width;
  const double t0 = t_end - window_s;
  const double col_w = std::max(window_s / static_cast<double>(columns), lv->width);
  const auto ncol = static_cast<std::size_t>(std::ceil(window_s / col_w));
  v.t0_s = t0;
  v.col_s = col_w;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  v.t_s.resize(ncol);
  for (std::size_t s = 0; s < n; ++s) {
    v.min[s].assign(ncol, nan);
    v.max[s].assign(ncol, nan);
  }
  const auto nb = static_cast<std::int64_t>(c_.buckets);
  for (std::size_t c = 0; c < ncol; ++c) {
    const double a = t0 + static_cast<double>(c) * col_w;
    v.t_s[c] = a;
    const auto b0 = static_cast<std::int64_t>(std::floor(a / lv->width));
    auto b1 = static_cast<std::int64_t>(std::floor((a + col_w) / lv->width));
    if (b1 <= b0) b1 = b0 + 1;
    for (std::int64_t b = b0; b < b1; ++b) {
      const auto slot = static_cast<std::size_t>(((b % nb) + nb) % nb);
      if (lv->index[slot] != b) continue;
      for (std::size_t s = 0; s < n; ++s) {
        const double lo = lv->lo[slot * n + s], hi = lv->hi[slot * n + s];
        double& m = v.min[s][c];
        double& M = v.max[s][c];
        m = std::isnan(m) ? lo : std::min(m, lo);
        M = std::isnan(M) ? hi : std::max(M, hi);
      }
    }
  }
  return v;
}

std::size_t Decimator::view_f32(double t_end, double window_s, std::size_t columns, std::span<const std::size_t> signals,
                                std::vector<float>& out, double& t0_s, double& col_s, double& bucket_s,
                                std::int64_t from_col) const {
  out.clear();
  t0_s = col_s = bucket_s = 0.0;
  if (!(window_s > 0.0) || columns == 0 || !std::isfinite(t_end)) return 0;
  const std::size_t n = c_.signals;
  const Level* lv = &levels_.back();
  for (const auto& l : levels_)
    if (l.width * static_cast<double>(c_.buckets - 1) >= window_s) {
      lv = &l;
      break;
    }
  bucket_s = lv->width;
  // the grid: k buckets per column; the window's columns end with the one holding t_end
  const auto k = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::ceil(window_s / static_cast<double>(columns) / lv->width - 1e-9)));
  col_s = static_cast<double>(k) * lv->width;
  const auto floor_div = [k](std::int64_t b) { return b >= 0 ? b / k : -((-b + k - 1) / k); };
  const std::int64_t last = floor_div(static_cast<std::int64_t>(std::floor(t_end / lv->width)));
  const std::int64_t first =
      std::max(floor_div(static_cast<std::int64_t>(std::floor((t_end - window_s) / lv->width))), from_col);
  t0_s = static_cast<double>(first) * col_s;
  if (first > last) return 0;
  const auto ncol = static_cast<std::size_t>(last - first + 1);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  out.assign(signals.size() * 2 * ncol, nan);
  const auto nb = static_cast<std::int64_t>(c_.buckets);
  for (std::size_t c = 0; c < ncol; ++c) {
    const std::int64_t b0 = (first + static_cast<std::int64_t>(c)) * k;
    for (std::int64_t b = b0; b < b0 + k; ++b) {
      const auto slot = static_cast<std::size_t>(((b % nb) + nb) % nb);
      if (lv->index[slot] != b) continue;
      const double* lo = &lv->lo[slot * n];
      const double* hi = &lv->hi[slot * n];
      for (std::size_t q = 0; q < signals.size(); ++q) {
        const std::size_t s = signals[q];
        if (s >= n) continue;
        float& m = out[(2 * q) * ncol + c];
        float& M = out[(2 * q + 1) * ncol + c];
        const auto l = static_cast<float>(lo[s]), h = static_cast<float>(hi[s]);
        m = std::isnan(m) ? l : std::min(m, l);
        M = std::isnan(M) ? h : std::max(M, h);
      }
    }
  }
  return ncol;
}

std::size_t Decimator::memory_bytes() const noexcept {
  std::size_t b = 0;
  for (const auto& l : levels_)
    b += l.index.size() * sizeof(std::int64_t) + (l.lo.size() + l.hi.size()) * sizeof(double);
  return b;
}

}  // namespace lash::console
