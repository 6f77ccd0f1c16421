#include "lash/control/gains_file.hpp"

#include <sstream>
#include <stdexcept>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/toml_util.hpp"

namespace lash {

ControllerConfig load_controller_config(const std::filesystem::path& path) {
  const toml::table root = parse_toml_file(path);
  TomlTable top(root, path.string());
  ControllerConfig c;
  TomlTable pid = top.table("pid");
  auto nonneg = [](TomlTable& t, std::string_view key, double fallback, bool required) {
    const double v = required ? t.number(key) : t.number_or(key, fallback);
    if (!(v >= 0)) t.fail(key, "must be >= 0");
    return v;
  };
  c.pid.gains.kp = nonneg(pid, "kp", 0, true);
  c.pid.gains.ki_per_s = nonneg(pid, "ki", 0, true);
  c.pid.gains.kd_s = nonneg(pid, "kd", 0, true);
  c.pid.gains.n_per_s = nonneg(pid, "n", 0, false);
  c.pid.dt_s = pid.number_or("dt", 0.005);
  if (!(c.pid.dt_s > 0)) pid.fail("dt", "must be > 0 [s]");
  if (auto m = pid.string_opt("integrator")) {
    try {
      c.pid.integrator = parse_integrator_method(m->c_str());
    } catch (const std::invalid_argument& e) {
      pid.fail("integrator", e.what());
    }
  }
  if (auto aw = pid.string_opt("anti_windup")) {
    if (*aw == "none") c.pid.anti_windup = AntiWindup::none;
    else if (*aw == "clamp") c.pid.anti_windup = AntiWindup::clamp;
    else pid.fail("anti_windup", "must be \"none\" or \"clamp\"");
  }
  if (auto v = pid.number_opt("output_min")) c.pid.output_min = *v;
  if (auto v = pid.number_opt("output_max")) c.pid.output_max = *v;
  if (!(c.pid.output_min <= c.pid.output_max)) pid.fail("output_max", "needs output_min <= output_max");
  pid.finish();
  if (auto dz = top.table_opt("deadzone_inverse")) {
    if (auto off = dz->number_opt("offset_mA")) {
      if (!(*off >= 0)) dz->fail("offset_mA", "must be >= 0");
      if (dz->has("deadzone_mA") || dz->has("fraction"))
        dz->fail("offset_mA", "give either offset_mA or deadzone_mA/fraction, not both");
      c.dz_inverse = {*off, *off};
    } else {
      const double d = nonneg(*dz, "deadzone_mA", 288.0, false);
      const double f = nonneg(*dz, "fraction", 0.97, false);
      c.dz_inverse = DeadzoneInverseParams::from_deadzone(d, f);
    }
    dz->finish();
  }
  if (auto s = top.table_opt("saturation")) {
    c.current_min_mA = s->number_or("min_mA", 0.0);
    c.current_max_mA = s->number_or("max_mA", 2000.0);
    if (!(c.current_min_mA <= c.current_max_mA)) s->fail("max_mA", "needs min_mA <= max_mA");
    s->finish();
  }
  top.finish();
  try {
    ClosedLoopDiscrete check(c);
  } catch (const std::invalid_argument& e) {
    throw InputError(path.string(), 0, "", e.what());
  }
  return c;
}

std::string controller_config_toml(const ControllerConfig& c, const std::string& comment) {
  std::ostringstream o;
  std::istringstream lines(comment);
  for (std::string l; std::getline(lines, l);) o << "# " << l << "\n";
  o << "[pid]\n";
  o << "kp = " << format_double(c.pid.gains.kp) << "  # [mA/kPa]\n";
  o << "ki = " << format_double(c.pid.gains.ki_per_s) << "  # [mA/(kPa s)]\n";
  o << "kd = " << format_double(c.pid.gains.kd_s) << "  # [mA s/kPa]\n";
  o << "n = " << format_double(c.pid.gains.n_per_s) << "  # derivative filter [1/s]; 0 = unfiltered\n";
  o << "dt = " << format_double(c.pid.dt_s) << "  # [s]\n";
  o << "integrator = \"" << to_string(c.pid.integrator) << "\"\n";
  if (c.pid.anti_windup == AntiWindup::clamp) {
    o << "anti_windup = \"clamp\"\noutput_min = " << format_double(c.pid.output_min)
      << "\noutput_max = " << format_double(c.pid.output_max) << "\n";
  }
  o << "\n[deadzone_inverse]\n";
  if (c.dz_inverse.offset_right == DeadzoneInverseParams::from_deadzone(288.0, 0.97).offset_right)
    o << "deadzone_mA = 288  # identified deadzone [mA]\nfraction = 0.97  # offset = 0.97 x deadzone (thesis)\n";
  else
    o << "offset_mA = " << format_double(c.dz_inverse.offset_right) << "  # added in the direction of the command [mA]\n";
  o << "\n[saturation]\nmin_mA = " << format_double(c.current_min_mA) << "\nmax_mA = " << format_double(c.current_max_mA)
    << "\n";
  return o.str();
}

}  // namespace lash
