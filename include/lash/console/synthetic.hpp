#pragma once
/// @file synthetic.hpp
/// A synthetic producer for the console's load case (docs/console.md, `lash console demo`):
/// `signals` signals at `rate_hz`, pushed into a Feed from their own thread on absolute
/// deadlines (rt/periodic.hpp's clock), as a measuring thread would. Sample k has t = k / rate_hz
/// and signal i the value
///     value_i(k) = a_i * sin(2 pi f_i t) + (i % 4 == 3 ? square of period 1 s : 0) + noise_i(k),
/// with a_i = 1 + i, f_i = 0.2 * (1 + i % 8) Hz and noise from a seeded xorshift64 (uniform in
/// [-0.05, 0.05] * a_i): deterministic for a seed. Not real-time code (a demo and benchmark aid).
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "lash/console/feed.hpp"

namespace lash::console {

struct SyntheticOptions {
  std::size_t signals = 32;   ///< 1..kMaxSignals
  double rate_hz = 1000.0;    ///< samples per second (0 < rate <= 100000)
  std::uint64_t seed = 1;
  double duration_s = 0.0;    ///< > 0: stop after this many seconds of samples
  /// Throws InputError naming the option (--signals, --rate, --duration).
  void validate() const;
};

/// value_i(k) of the doc above (the producer and the tests call it).
double synthetic_value(std::size_t i, std::uint64_t k, double rate_hz, std::uint64_t& noise_state) noexcept;

class SyntheticProducer {
 public:
  explicit SyntheticProducer(SyntheticOptions o);
  ~SyntheticProducer();
  SyntheticProducer(const SyntheticProducer&) = delete;
  SyntheticProducer& operator=(const SyntheticProducer&) = delete;
  /// The signal names: sig00, sig01, ...
  std::vector<std::string> names() const;
  void start(Feed& feed);
  void stop();  ///< idempotent
  bool done() const noexcept { return done_.load(); }
  std::uint64_t produced() const noexcept { return produced_.load(std::memory_order_relaxed); }

 private:
  SyntheticOptions o_;
  std::atomic<bool> stop_{false}, done_{false};
  std::atomic<std::uint64_t> produced_{0};
  std::thread thread_;
};

}  // namespace lash::console
