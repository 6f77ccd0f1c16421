#include "lash/control/pid.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "lash/control/controller.hpp"
#include "lash/control/deadzone_inverse.hpp"

namespace lash {
namespace {
void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}
bool nonneg(double x) { return std::isfinite(x) && x >= 0.0; }
}  // namespace

void validate(const PidGains& g) {
  require(nonneg(g.kp), "pid kp must be a finite number >= 0");
  require(nonneg(g.ki_per_s), "pid ki must be a finite number >= 0");
  require(nonneg(g.kd_s), "pid kd must be a finite number >= 0");
  require(nonneg(g.n_per_s), "pid derivative filter n must be a finite number >= 0 (0 = unfiltered)");
}

IntegratorMethod parse_integrator_method(const char* text) {
  if (std::strcmp(text, "forward_euler") == 0) return IntegratorMethod::forward_euler;
  if (std::strcmp(text, "backward_euler") == 0) return IntegratorMethod::backward_euler;
  if (std::strcmp(text, "trapezoidal") == 0) return IntegratorMethod::trapezoidal;
  throw std::invalid_argument(std::string("integrator must be forward_euler, backward_euler or trapezoidal, got '") +
                              text + "'");
}

const char* to_string(IntegratorMethod m) noexcept {
  switch (m) {
    case IntegratorMethod::forward_euler: return "forward_euler";
    case IntegratorMethod::backward_euler: return "backward_euler";
    case IntegratorMethod::trapezoidal: return "trapezoidal";
  }
  return "?";
}

Pid::Pid(const PidConfig& config) : cfg_(config) {
  validate(config.gains);
  require(std::isfinite(config.dt_s) && config.dt_s > 0, "pid dt must be > 0 [s]");
  require(!std::isnan(config.output_min) && !std::isnan(config.output_max) && config.output_min <= config.output_max,
          "pid output limits need output_min <= output_max");
}

ClosedLoopDiscrete::ClosedLoopDiscrete(const ControllerConfig& config)
    : cfg_(config),
      pid_(config.pid),
      dzi_(config.dz_inverse),
      sat_(config.current_min_mA, config.current_max_mA) {
  require(std::isfinite(config.current_min_mA) && std::isfinite(config.current_max_mA),
          "current saturation limits must be finite [mA]");
}

}  // namespace lash
