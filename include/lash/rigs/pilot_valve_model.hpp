#pragma once
/// @file pilot_valve_model.hpp
/// Pilot-valve pressure plant of docs/method.md §B1 (thesis paper 2, §2.7.1, Fig 2.11):
/// solenoid current [mA] → input deadzone → first-order lag → + bias → + noise
/// → sensor (duty-cycle encoding, uint16 on the bus).
///
///   z(k)   = DZ(i(k))  = max(i − c, 0) for i ≥ 0 (and min(i + c, 0) below 0)   [mA]
///   w(k+1) = e^{−T/τ}·w(k) + K(1 − e^{−T/τ})·z(k)   (ZOH, thesis eq 8–10)      [kPa]
///   p(k)   = bias + w(k) + σ·n(k),  n ~ N(0,1) (lash::Rng, seeded)              [kPa]
///   duty   = p/48.82 + 5.98 [%];  raw = round(duty·(2¹⁶ − 1)/100) ∈ [0, 65535]
///   measured p̂ = (raw·100/(2¹⁶ − 1) − 5.98)·48.82                             [kPa]
/// Thesis values: c = 288 mA, K = 2.15 kPa/mA, τ = 0.07 s, bias = 90.1 kPa,
/// σ = 7.28 kPa, T = 5 ms.
///
/// Optional (beyond the thesis, default off): a second, faster lag τ₂ in series
/// (τ₂ > 0), standing in for the unmodelled higher-order effects the thesis blamed
/// for 181 % overshoot on the real bench.
///
/// Step order each sample k (what the slave node does): measure() → y(k) from
/// w(k), then apply(i(k)) → w(k+1). measure() and apply() are noexcept, O(1),
/// allocation-free.
#include <cstdint>

#include "lash/signals/rng.hpp"

namespace lash {

struct PilotValveParams {
  double deadzone_mA = 288.0;        ///< c: x-intercept of steady pressure vs current [mA]
  double gain_kPa_per_mA = 2.15;     ///< K: steady-state slope above the deadzone [kPa/mA]
  double tau_s = 0.07;               ///< τ: first-order time constant [s]
  double tau2_s = 0.0;               ///< τ₂: optional second lag [s]; 0 = none (thesis)
  double bias_kPa = 90.1;            ///< pressure at zero current [kPa]
  double noise_sigma_kPa = 7.28;     ///< σ of the Gaussian sensor noise [kPa]; 0 = none
  double dt_s = 0.005;               ///< sample period T [s]
  bool quantize = true;              ///< round through the uint16 duty-cycle sensor code
  std::uint64_t seed = 1;            ///< noise seed

  /// Throws std::invalid_argument naming the field unless c ≥ 0, K, τ, T > 0, τ₂ ≥ 0, σ ≥ 0, all finite.
  void validate() const;
};

/// Sensor encoding of docs/method.md §B1.
inline constexpr double kDutyOffsetPct = 5.98;         ///< [%]
inline constexpr double kKpaPerDutyPct = 48.82;        ///< [kPa/%]
inline constexpr double kRawPerDutyPct = 65535.0 / 100.0;  ///< [counts/%]

/// kPa → uint16 bus value: round((p/48.82 + 5.98)·65535/100), clamped to [0, 65535].
std::uint16_t encode_pressure_raw(double pressure_kPa) noexcept;
/// uint16 bus value → kPa: (raw·100/65535 − 5.98)·48.82.
double decode_pressure_raw(std::uint16_t raw) noexcept;
/// Round trip through the sensor code (what the master sees).
inline double quantize_pressure(double pressure_kPa) noexcept {
  return decode_pressure_raw(encode_pressure_raw(pressure_kPa));
}

class PilotValvePlant {
 public:
  /// Throws std::invalid_argument if the parameters are invalid.
  explicit PilotValvePlant(const PilotValveParams& p);

  /// Sensor reading of the current sample k [kPa] (quantised if enabled); draws
  /// the noise of sample k. Call exactly once per sample, before apply().
  double measure() noexcept {
    const double p = true_pressure_kPa() + (sigma_ > 0.0 ? sigma_ * rng_.gaussian() : 0.0);
    last_raw_ = encode_pressure_raw(p);
    last_measured_ = quantize_ ? decode_pressure_raw(last_raw_) : p;
    return last_measured_;
  }
  /// The bus value of the last measure() (always the uint16 sensor code).
  std::uint16_t last_raw() const noexcept { return last_raw_; }
  double last_measured_kPa() const noexcept { return last_measured_; }

  /// Holds current i(k) [mA] over one sample and advances the state to k+1.
  void apply(double current_mA) noexcept {
    const double z = deadzone(current_mA);
    if (two_lags_) {
      w_ = a_ * w_ + b_ * x1_;  // second lag fed by the first lag's previous output
      x1_ = a1_ * x1_ + b1_ * z;
    } else {
      w_ = a_ * w_ + b_ * z;
    }
  }

  /// Noise-free pressure bias + w(k) [kPa].
  double true_pressure_kPa() const noexcept { return bias_ + w_; }
  /// Input deadzone: max(i − c, 0) above, min(i + c, 0) below [mA].
  double deadzone(double current_mA) const noexcept {
    if (current_mA > c_) return current_mA - c_;
    if (current_mA < -c_) return current_mA + c_;
    return 0.0;
  }
  /// Puts the plant at rest at the steady state of a constant current; reseeds the noise.
  void reset(double steady_current_mA = 0.0) noexcept;
  const PilotValveParams& params() const noexcept { return p_; }

 private:
  PilotValveParams p_;
  double c_, bias_, sigma_;
  bool quantize_, two_lags_;
  double a_ = 0.0, b_ = 0.0;    // output lag (τ, or τ₂ when two lags)
  double a1_ = 0.0, b1_ = 0.0;  // first lag (τ) when two lags
  double w_ = 0.0, x1_ = 0.0;
  Rng rng_;
  std::uint16_t last_raw_ = 0;
  double last_measured_ = 0.0;
};

}  // namespace lash
