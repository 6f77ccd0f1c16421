// Step-test fit (docs/method.md §B6): recovers the parameters of the pilot-valve model that generated the data.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "lash/identify/step_fit.hpp"
#include "lash/rigs/pilot_valve_model.hpp"

namespace {
using namespace lash;

struct Record {
  std::vector<double> t, i, p;
};

Record staircase(const PilotValveParams& pp, double dwell_s, double max_mA) {
  const double levels[] = {0, 150, 350, 500, 0, 700, 900, 400, 1100, 0, 1300, 600, 1500, 200, 0, 800, 1000, 1200, 1700, 0};
  PilotValvePlant plant(pp);
  Record r;
  const auto per = static_cast<std::size_t>(std::lround(dwell_s / pp.dt_s));
  std::size_t k = 0;
  for (double level : levels)
    if (level <= max_mA)
    for (std::size_t j = 0; j < per; ++j, ++k) {
      r.t.push_back(static_cast<double>(k) * pp.dt_s);
      r.i.push_back(level);
      r.p.push_back(plant.measure());
      plant.apply(level);
    }
  return r;
}

// max_mA keeps the pressure inside the sensor's range (the uint16 code clips at 4590 kPa).
void expect_recovers(const PilotValveParams& pp, double dwell_s, double max_mA = 2000.0) {
  const Record r = staircase(pp, dwell_s, max_mA);
  const StepFit f = fit_steps(r.t, r.i, r.p);
  auto rel = [](double est, double truth) { return (est - truth) / truth; };
  std::printf("truth: bias %.3f dz %.3f gain %.4f tau %.4f sigma %.3f | fit: bias %.3f dz %.3f gain %.4f tau %.4f sigma "
              "%.3f | rel err %.2e %.2e %.2e %.2e %.2e (line pts %zu, transients %zu)\n",
              pp.bias_kPa, pp.deadzone_mA, pp.gain_kPa_per_mA, pp.tau_s, pp.noise_sigma_kPa, f.bias_kPa, f.deadzone_mA,
              f.gain_kPa_per_mA, f.tau_s, f.noise_sigma_kPa, rel(f.bias_kPa, pp.bias_kPa),
              rel(f.deadzone_mA, pp.deadzone_mA), rel(f.gain_kPa_per_mA, pp.gain_kPa_per_mA), rel(f.tau_s, pp.tau_s),
              rel(f.noise_sigma_kPa, pp.noise_sigma_kPa), f.line_points, f.transients);
  EXPECT_NEAR(f.bias_kPa, pp.bias_kPa, 0.03 * std::fabs(pp.bias_kPa));
  EXPECT_NEAR(f.deadzone_mA, pp.deadzone_mA, 0.03 * pp.deadzone_mA);
  EXPECT_NEAR(f.gain_kPa_per_mA, pp.gain_kPa_per_mA, 0.03 * pp.gain_kPa_per_mA);
  EXPECT_NEAR(f.tau_s, pp.tau_s, 0.03 * pp.tau_s);
  EXPECT_NEAR(f.noise_sigma_kPa, pp.noise_sigma_kPa, 0.03 * pp.noise_sigma_kPa);
}

TEST(StepFit, RecoversThesisPilotValve) {
  PilotValveParams pp;  // 288 mA, 2.15 kPa/mA, 0.07 s, 90.1 kPa, 7.28 kPa, sensor code on
  expect_recovers(pp, 1.5);
}

TEST(StepFit, RecoversOtherParameters) {
  PilotValveParams pp;
  pp.deadzone_mA = 150.0;
  pp.gain_kPa_per_mA = 3.3;
  pp.tau_s = 0.12;
  pp.bias_kPa = 40.0;
  pp.noise_sigma_kPa = 4.0;
  pp.dt_s = 0.002;
  pp.seed = 42;
  expect_recovers(pp, 2.0, 1500.0);
}

TEST(StepFit, RecoversLargeDeadzoneFastValve) {
  PilotValveParams pp;
  pp.deadzone_mA = 420.0;
  pp.gain_kPa_per_mA = 1.6;
  pp.tau_s = 0.03;
  pp.bias_kPa = 150.0;
  pp.noise_sigma_kPa = 10.0;
  pp.seed = 7;
  expect_recovers(pp, 1.0);
}

TEST(StepFit, ExplainsWhatIsMissing) {
  std::vector<double> t{0, 1, 2, 3}, i{500, 500, 600, 600}, p{1, 1, 2, 2};
  EXPECT_THROW(fit_steps(t, i, p), std::invalid_argument);  // no zero-current segment
  std::vector<double> bad_t{0, 0, 1, 2};
  EXPECT_THROW(fit_steps(bad_t, i, p), std::invalid_argument);
}

}  // namespace
