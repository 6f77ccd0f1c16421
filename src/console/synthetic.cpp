#include "lash/console/synthetic.hpp"

#include <cmath>
#include <numbers>

#include "lash/io/error.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::console {

void SyntheticOptions::validate() const {
  if (signals == 0 || signals > kMaxSignals)
    throw InputError("", 0, "--signals", "must be 1.." + std::to_string(kMaxSignals));
  if (!(rate_hz > 0.0) || rate_hz > 100000.0) throw InputError("", 0, "--rate", "must be > 0 and <= 100000 [Hz]");
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s)) throw InputError("", 0, "--duration", "must be >= 0 [s]");
}

double synthetic_value(std::size_t i, std::uint64_t k, double rate_hz, std::uint64_t& x) noexcept {
  const double t = static_cast<double>(k) / rate_hz;
  const double a = 1.0 + static_cast<double>(i);
  const double f = 0.2 * static_cast<double>(1 + i % 8);
  double v = a * std::sin(2.0 * std::numbers::pi * f * t);
  if (i % 4 == 3) v += std::fmod(t, 1.0) < 0.5 ? a : -a;
  x ^= x << 13;  // xorshift64
  x ^= x >> 7;
  x ^= x << 17;
  const double u = static_cast<double>(x >> 11) * 0x1.0p-53;  // [0, 1)
  return v + (u - 0.5) * 0.1 * a;
}

SyntheticProducer::SyntheticProducer(SyntheticOptions o) : o_(o) { o_.validate(); }
SyntheticProducer::~SyntheticProducer() { stop(); }

std::vector<std::string> SyntheticProducer::names() const {
  std::vector<std::string> n;
  for (std::size_t i = 0; i < o_.signals; ++i) n.push_back((i < 10 ? "sig0" : "sig") + std::to_string(i));
  return n;
}

void SyntheticProducer::start(Feed& feed) {
  thread_ = std::thread([this, &feed] {
    std::uint64_t x = o_.seed ? o_.seed : 0x9E3779B97F4A7C15ull;
    const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / o_.rate_hz));
    const std::int64_t t0 = rt::monotonic_ns();
    const auto n_max = o_.duration_s > 0 ? static_cast<std::uint64_t>(std::llround(o_.duration_s * o_.rate_hz)) : 0;
    Sample s;
    s.count = static_cast<std::uint32_t>(o_.signals);
    for (std::uint64_t k = 0; !stop_.load(std::memory_order_relaxed) && (n_max == 0 || k < n_max); ++k) {
      rt::sleep_until_ns(t0 + static_cast<std::int64_t>(k) * period_ns, &stop_);
      s.t_s = static_cast<double>(k) / o_.rate_hz;
      for (std::size_t i = 0; i < o_.signals; ++i) s.values[i] = synthetic_value(i, k, o_.rate_hz, x);
      feed.push(s);
      produced_.fetch_add(1, std::memory_order_relaxed);
    }
    done_.store(true);
  });
}

void SyntheticProducer::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

}  // namespace lash::console
