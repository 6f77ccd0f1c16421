#pragma once
// The bench of the HIL replay tests (test_hil_schedule, test_hil_report_logs): a 5 ms PID loop
// (1.2, 12, 0.004) on a 900 ± 400 kPa square reference of levels held 1 s (a step the report
// finds), and the slave's plant with seed 7 answering CONNECT with the recorded DTO.
#include <numbers>

#include "lash/hil/nodes.hpp"
#include "recorded_dto.hpp"

namespace lash::test {

inline constexpr double kT = 0.005;

inline hil::MasterConfig master_cfg() {
  hil::MasterConfig m;
  m.controller.pid.dt_s = kT;
  m.controller.pid.gains.kp = 1.2;
  m.controller.pid.gains.ki_per_s = 12.0;
  m.controller.pid.gains.kd_s = 0.004;
  m.reference.kind = Waveform::square;
  m.reference.amplitude = 400.0;
  m.reference.offset = 900.0;
  m.reference.frequency_rad_s = std::numbers::pi;
  return m;
}

inline hil::SlaveConfig slave_cfg() {
  hil::SlaveConfig s;
  s.plant.dt_s = kT;
  s.plant.seed = 7;
  s.dto_reply = {recorded_dto()};
  return s;
}

}  // namespace lash::test
