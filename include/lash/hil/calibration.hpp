#pragma once
/// @file calibration.hpp
/// The master ECU's measurement and calibration objects as **one table** (in the style of
/// io/field_table.hpp): name, member, type, unit, limits, description. Generated from it: the
/// XCP slave's memory map (hil/xcp_server.hpp), the A2L file (`lash hil a2l`), the calibration
/// columns of master.csv and their replay by `hil simulate --schedule` (schedule.hpp).
///
/// Calibration page: the values the control law reads. A write over XCP lands in the slave's
/// image (the shadow), is checked against the limits below as a whole, and is handed to the
/// real-time step as a complete page through a lock-free queue (rt/spsc_queue.hpp); the step
/// takes the newest page at its start (a step boundary), so the law never sees a value or a
/// block half-written, and the step never waits.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "lash/rt/spsc_queue.hpp"

namespace lash::hil {

/// The calibration page (trivially copyable; it crosses the hand-over and is logged per step).
struct CalibrationPage {
  double kp = 0.0;                    ///< PID proportional gain [mA/kPa]
  double ki_per_s = 0.0;              ///< PID integral gain [mA/(kPa s)]
  double kd_s = 0.0;                  ///< PID derivative gain [mA s/kPa]
  double n_per_s = 0.0;               ///< PID derivative filter [1/s]; 0 = unfiltered
  double dz_right_mA = 0.0;           ///< the deadzone inverse's nominal right edge c_r [mA]
  double dz_left_mA = 0.0;            ///< the deadzone inverse's nominal left edge, magnitude |c_l| [mA]
  double reference_offset_kPa = 0.0;  ///< added to the reference r(m) [kPa]
  double compensation = 1.0;          ///< CompensationMode as a number: 0 none, 1 fixed, 2 adaptive
  double adapt_rate_mA_per_s = 100.0; ///< AdaptationSettings::rate_limit_per_s ρ [mA/s] (scenario law)
  double adapt_tolerance = 0.08;      ///< AdaptationSettings::tolerance_ratio, the dead band [-] (scenario law)
  double adapt_settle_s = 0.5;        ///< AdaptationSettings::settle_s [s] (scenario law)
  double dither_mA = 0.0;             ///< AdaptationSettings::dither_amplitude A [mA] (scenario law)
  bool operator==(const CalibrationPage&) const = default;
};

/// One row of the calibration table.
struct CalibrationField {
  const char* name;   ///< A2L CHARACTERISTIC name, `lash xcp get/set NAME`, master.csv column
  double CalibrationPage::*member;
  const char* unit;
  double min, max;    ///< A2L limits; XCP writes outside are refused with ERR_OUT_OF_RANGE
  const char* doc;
  /// Named values (A2L COMPU_METHOD TAB_VERB, value i ↔ names[i]); the value must then be an
  /// integer in [min, max] (XCP refuses a fraction with ERR_OUT_OF_RANGE). Empty: a number.
  std::span<const char* const> names;
};
std::span<const CalibrationField> calibration_fields() noexcept;
const CalibrationField* find_calibration_field(std::string_view name) noexcept;

/// The measurements of one master step that XCP DAQ samples (the signals of master.csv).
struct MeasurementPage {
  double reference_kPa = 0.0;
  double measured_kPa = 0.0;
  double current_mA = 0.0;
  double integrator_mA = 0.0;
  double control_step = -1.0;   ///< m (−1 before the handshake)
  double state = 0.0;           ///< NodeState as a number
  double sensor_fresh = 0.0;    ///< 1 when a plausible new sensor frame was used
  double dropped = 0.0;         ///< implausible sensor frames dropped in the step
  // The loop's figures, for the live console's status panel (docs/console.md); not master.csv columns.
  double tet_us = 0.0;            ///< TET of the previous step [µs] (0 in the first)
  double wake_latency_us = 0.0;   ///< wake-up latency of this step [µs]
  double overruns = 0.0;          ///< overruns of the loop so far
  double frames_late = 0.0;       ///< sensor frames accepted late so far (SeqTracker::late)
  double frames_lost = 0.0;       ///< sensor frames lost so far (SeqTracker::lost)
};

struct MeasurementField {
  const char* name;   ///< A2L MEASUREMENT name = master.csv column
  double MeasurementPage::*member;
  const char* unit;
  double min, max;
  const char* doc;
};
std::span<const MeasurementField> measurement_fields() noexcept;

/// What the step hands to the XCP thread each step (DAQ event channel 0).
struct MeasurementSample {
  std::uint32_t step = 0;       ///< loop step k
  std::int64_t t_us = 0;        ///< the step's release time since the loop's start [µs] (DAQ timestamp)
  MeasurementPage page;
};

/// A calibration write that took effect, for master.events.csv: at loop step k, `field` went
/// from old to new.
struct CalibrationEvent {
  std::uint32_t step = 0;
  double t_s = 0.0;
  std::uint16_t field = 0;      ///< index into calibration_fields()
  double old_value = 0.0, new_value = 0.0;
};

/// The lock-free link between the master's step and its XCP thread.
struct XcpLink {
  rt::SpscQueue<CalibrationPage, 16> pages;          ///< XCP thread → step (complete pages)
  rt::SpscQueue<MeasurementSample, 1024> samples;    ///< step → XCP thread (one per step)
  std::atomic<std::uint64_t> samples_lost{0};        ///< pushes refused (the XCP thread fell behind)
};

}  // namespace lash::hil
