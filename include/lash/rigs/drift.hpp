#pragma once
/// @file drift.hpp
/// A rig's parameters changing during a run (docs/compensation.md, `[[drift]]` of a closed-loop
/// scenario): steps and linear ramps, kept as segments and interpolated in place when a step
/// asks for them, so that a ramp costs the same memory whatever its length. One implementation
/// for every user: the HIL slave's rig (its drifts), the HIL master's oracle (the true edges)
/// and the closed-loop scenario runner's carts.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lash/rigs/coupled_carts.hpp"
#include "lash/rigs/pilot_valve_rig.hpp"

namespace lash::rigs {

/// One change of a rig's parameters, in control steps k (t = k·T): a step at k0 (n = 0: the rig
/// is `after` from k0 on) or a linear ramp from `before` (at k0) to `after` (at k0 + n), the
/// parameters at k0 < k < k0 + n being lerp(before, after, (k − k0)/n).
template <class Params>
struct DriftSegment {
  std::int64_t k0 = 0;  ///< first control step of the change
  std::int64_t n = 0;   ///< ramp length [control steps]; 0 = a step
  Params before;        ///< the rig before k0 (earlier segments included)
  Params after;         ///< the rig from k0 + n on
};

/// a + (b − a)·f, and b exactly at f ≥ 1 (x + (x − x)·f = x exactly for an unchanged value).
inline double lerp(double a, double b, double f) noexcept { return f >= 1.0 ? b : a + (b - a) * f; }

/// Every real-valued parameter moved the share f of the way (only the drifted one differs
/// between a and b; the integer ones are a's).
inline PilotValveRigParams lerp(const PilotValveRigParams& a, const PilotValveRigParams& b, double f) noexcept {
  PilotValveRigParams p = a;
  for (double PilotValveRigParams::*m :
       {&PilotValveRigParams::deadzone_right_mA, &PilotValveRigParams::deadzone_left_mA,
        &PilotValveRigParams::gain_right_kPa_mA, &PilotValveRigParams::gain_left_kPa_mA, &PilotValveRigParams::tau0_s,
        &PilotValveRigParams::tau_half_pressure_kPa, &PilotValveRigParams::solenoid_tau_s,
        &PilotValveRigParams::bias_kPa, &PilotValveRigParams::noise_sigma_kPa, &PilotValveRigParams::quantum_kPa})
    p.*m = lerp(a.*m, b.*m, f);
  return p;
}
inline CoupledCartsParams lerp(const CoupledCartsParams& a, const CoupledCartsParams& b, double f) noexcept {
  CoupledCartsParams p = a;
  for (double CoupledCartsParams::*m :
       {&CoupledCartsParams::free_mass_kg, &CoupledCartsParams::free_coulomb_N, &CoupledCartsParams::free_static_N,
        &CoupledCartsParams::half_clearance_m, &CoupledCartsParams::restitution, &CoupledCartsParams::lock_speed_m_s})
    p.*m = lerp(a.*m, b.*m, f);
  return p;
}

/// Walks a list of segments (in time order, not overlapping: a segment starts at or after the
/// previous one's k0 + n) with non-decreasing k. O(1) memory; advance() is noexcept,
/// allocation-free and amortised O(1) (real-time safe).
template <class Params>
class DriftCursor {
 public:
  /// The parameters at control step k when they changed since the previous call (a step's k0,
  /// every step k0 + 1 … k0 + n of a ramp, and any such change skipped over since then: the
  /// latest wins), else nullptr. k must not decrease between calls.
  const Params* advance(const std::vector<DriftSegment<Params>>& segments, std::int64_t k) noexcept {
    bool changed = false;
    while (next_ < segments.size()) {
      const DriftSegment<Params>& d = segments[next_];
      if (k < (d.n == 0 ? d.k0 : d.k0 + 1)) break;  // a ramp's k0 is still `before`
      if (d.n == 0 || k >= d.k0 + d.n) {
        now_ = d.after;
        changed = true;
        ++next_;
        continue;
      }
      now_ = lerp(d.before, d.after, static_cast<double>(k - d.k0) / static_cast<double>(d.n));
      changed = true;
      break;
    }
    return changed ? &now_ : nullptr;
  }

 private:
  std::size_t next_ = 0;  ///< the first segment not yet finished
  Params now_{};
};

}  // namespace lash::rigs
