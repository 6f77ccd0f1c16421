#include "lash/hil/calibration.hpp"

#include <array>

namespace lash::hil {

namespace {
// Limits: what the law accepts (gains finite and >= 0, edges inside the current range, the
// adaptation's settings inside AdaptationSettings::valid()) with a margin a tuning session
// needs; the defaults of config/control/lash_gains.toml, of AdaptationSettings and of the shipped
// scenarios lie well inside. One set of limits for both laws (the A2L does not depend on
// --scenario): objects the running law does not have are kept and logged, without effect
// (docs/xcp.md).
constexpr const char* kModeNames[] = {"none", "fixed", "adaptive"};  // CompensationMode's order
constexpr std::array<CalibrationField, 12> kCalibration{{
    {"kp", &CalibrationPage::kp, "mA/kPa", 0.0, 100.0, "PID proportional gain Kp", {}},
    {"ki_per_s", &CalibrationPage::ki_per_s, "mA/(kPa s)", 0.0, 10000.0, "PID integral gain Ki", {}},
    {"kd_s", &CalibrationPage::kd_s, "mA s/kPa", 0.0, 10.0, "PID derivative gain Kd", {}},
    {"n_per_s", &CalibrationPage::n_per_s, "1/s", 0.0, 100000.0, "PID derivative filter N (0 = unfiltered)", {}},
    {"dz_right_mA", &CalibrationPage::dz_right_mA, "mA", 0.0, 2000.0,
     "deadzone inverse: nominal right edge (fixed, and the start of adaptive)", {}},
    {"dz_left_mA", &CalibrationPage::dz_left_mA, "mA", 0.0, 2000.0,
     "deadzone inverse: nominal left edge, magnitude (fixed, and the start of adaptive)", {}},
    {"reference_offset_kPa", &CalibrationPage::reference_offset_kPa, "kPa", -4000.0, 4000.0,
     "offset added to the reference r(m)", {}},
    {"compensation", &CalibrationPage::compensation, "", 0.0, 2.0,
     "deadzone compensation: 0 none, 1 fixed, 2 adaptive (bench controller: 2 acts as 1)", kModeNames},
    {"adapt_rate_mA_per_s", &CalibrationPage::adapt_rate_mA_per_s, "mA/s", 0.001, 100000.0,
     "adaptation: rate limit of the inverse's edges (scenario law)", {}},
    {"adapt_tolerance", &CalibrationPage::adapt_tolerance, "", 0.0, 1.0,
     "adaptation: dead band, fraction of the nominal edge (scenario law)", {}},
    {"adapt_settle_s", &CalibrationPage::adapt_settle_s, "s", 0.0, 60.0,
     "adaptation: time the verdict must hold before its values are used (scenario law)", {}},
    {"dither_mA", &CalibrationPage::dither_mA, "mA", 0.0, 500.0,
     "adaptation: square-wave dither amplitude on u (scenario law, adaptive only)", {}},
}};

constexpr std::array<MeasurementField, 13> kMeasurements{{
    {"reference_kPa", &MeasurementPage::reference_kPa, "kPa", -5000.0, 5000.0, "reference r(m)"},
    {"measured_kPa", &MeasurementPage::measured_kPa, "kPa", -5000.0, 5000.0, "decoded pilot pressure y(m)"},
    {"current_mA", &MeasurementPage::current_mA, "mA", -2000.0, 2000.0, "commanded current i(m)"},
    {"integrator_mA", &MeasurementPage::integrator_mA, "mA", -1e6, 1e6, "PID integrator state"},
    {"control_step", &MeasurementPage::control_step, "", -1.0, 4e9, "control step m (-1 before the handshake)"},
    {"state", &MeasurementPage::state, "", 0.0, 5.0, "safe-state machine state (docs/hil.md)"},
    {"sensor_fresh", &MeasurementPage::sensor_fresh, "", 0.0, 1.0, "a plausible new sensor frame was used"},
    {"dropped", &MeasurementPage::dropped, "", 0.0, 64.0, "implausible sensor frames dropped in the step"},
    {"tet_us", &MeasurementPage::tet_us, "us", 0.0, 1e7, "TET of the previous step"},
    {"wake_latency_us", &MeasurementPage::wake_latency_us, "us", -1e7, 1e7, "wake-up latency of this step"},
    {"overruns", &MeasurementPage::overruns, "", 0.0, 4e9, "overruns of the loop so far"},
    {"frames_late", &MeasurementPage::frames_late, "", 0.0, 4e9, "sensor frames accepted late so far"},
    {"frames_lost", &MeasurementPage::frames_lost, "", 0.0, 4e9, "sensor frames lost so far"},
}};
}  // namespace

std::span<const CalibrationField> calibration_fields() noexcept { return kCalibration; }

const CalibrationField* find_calibration_field(std::string_view name) noexcept {
  for (const auto& f : kCalibration)
    if (name == f.name) return &f;
  return nullptr;
}

std::span<const MeasurementField> measurement_fields() noexcept { return kMeasurements; }

}  // namespace lash::hil
