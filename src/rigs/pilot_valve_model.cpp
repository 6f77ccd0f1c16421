#include "lash/rigs/pilot_valve_model.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lash {
namespace {
void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}
}  // namespace

void PilotValveParams::validate() const {
  require(std::isfinite(deadzone_mA) && deadzone_mA >= 0, "pilot valve deadzone_mA must be >= 0");
  require(std::isfinite(gain_kPa_per_mA) && gain_kPa_per_mA > 0, "pilot valve gain_kPa_per_mA must be > 0");
  require(std::isfinite(tau_s) && tau_s > 0, "pilot valve tau_s must be > 0");
  require(std::isfinite(tau2_s) && tau2_s >= 0, "pilot valve tau2_s must be >= 0 (0 = no second lag)");
  // Beyond ±1e5 kPa (100 MPa) a pressure is no hydraulic pilot stage's, and the metrics' squares overflow.
  require(std::fabs(bias_kPa) <= 1e5, "pilot valve bias_kPa must be in [-1e5, 1e5] kPa");
  require(noise_sigma_kPa >= 0 && noise_sigma_kPa <= 1e5, "pilot valve noise_sigma_kPa (--noise-sigma) must be in [0, 1e5] kPa");
  require(std::isfinite(dt_s) && dt_s > 0, "pilot valve dt_s must be > 0");
}

std::uint16_t encode_pressure_raw(double pressure_kPa) noexcept {
  const double duty = pressure_kPa / kKpaPerDutyPct + kDutyOffsetPct;
  const double raw = std::round(duty * kRawPerDutyPct);
  if (!(raw > 0.0)) return 0;  // also NaN
  if (raw >= 65535.0) return 65535;
  return static_cast<std::uint16_t>(raw);
}

double decode_pressure_raw(std::uint16_t raw) noexcept {
  return (static_cast<double>(raw) / kRawPerDutyPct - kDutyOffsetPct) * kKpaPerDutyPct;
}

PilotValvePlant::PilotValvePlant(const PilotValveParams& p) : p_(p), rng_(p.seed) {
  p.validate();
  c_ = p.deadzone_mA;
  bias_ = p.bias_kPa;
  sigma_ = p.noise_sigma_kPa;
  quantize_ = p.quantize;
  two_lags_ = p.tau2_s > 0.0;
  const double e1 = std::exp(-p.dt_s / p.tau_s);
  if (two_lags_) {
    const double e2 = std::exp(-p.dt_s / p.tau2_s);
    a1_ = e1;
    b1_ = p.gain_kPa_per_mA * (1.0 - e1);
    a_ = e2;
    b_ = 1.0 - e2;
  } else {
    a_ = e1;
    b_ = p.gain_kPa_per_mA * (1.0 - e1);
  }
  reset(0.0);
}

void PilotValvePlant::reset(double steady_current_mA) noexcept {
  const double w = p_.gain_kPa_per_mA * deadzone(steady_current_mA);
  w_ = w;
  x1_ = w;
  rng_.seed(p_.seed);
  last_raw_ = 0;
  last_measured_ = 0.0;
}

}  // namespace lash
