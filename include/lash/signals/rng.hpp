#pragma once
/// @file rng.hpp
/// Deterministic random numbers: xoshiro256** seeded through splitmix64, and
/// Gaussian samples by the Marsaglia polar method written here, so that one
/// seed gives the same bits with libstdc++ and libc++, g++ and clang
/// (std::normal_distribution does not). step() members are noexcept and O(1).
#include <cmath>
#include <cstdint>

namespace lash {

class Rng {
 public:
  explicit Rng(std::uint64_t seed = 1) noexcept { this->seed(seed); }
  void seed(std::uint64_t seed) noexcept {
    std::uint64_t x = seed;
    for (auto& w : s_) w = splitmix64(x);
    has_spare_ = false;
  }
  /// Next 64 random bits (xoshiro256**, Blackman & Vigna 2018).
  std::uint64_t next() noexcept {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  /// Uniform on [0, 1) with 53 random bits.
  double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Standard normal N(0, 1), Marsaglia polar method (pairs; the spare is cached).
  double gaussian() noexcept {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double m = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * m;
    has_spare_ = true;
    return u * m;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& x) noexcept {
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  std::uint64_t s_[4]{};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// Additive zero-mean Gaussian noise of a given variance [unit²].
class GaussianNoise {
 public:
  GaussianNoise(double variance, std::uint64_t seed) noexcept : sigma_(std::sqrt(variance)), rng_(seed) {}
  double step() noexcept { return sigma_ == 0.0 ? 0.0 : sigma_ * rng_.gaussian(); }
  double sigma() const noexcept { return sigma_; }

 private:
  double sigma_;
  Rng rng_;
};

}  // namespace lash
