#include "lash/hil/settings.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "lash/can/log.hpp"
#include "lash/control/gains_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/toml_util.hpp"

namespace lash::hil {

void BenchSettings::set_step(double step_s_new) {
  step_s = step_s_new;
  plant.dt_s = step_s_new;
  controller.pid.dt_s = step_s_new;
}

std::filesystem::path default_settings_path(const std::string& source_dir) {
  return std::filesystem::path(source_dir) / "config" / "hil" / "bench.toml";
}

BenchSettings load_bench_settings(const std::filesystem::path& file) {
  const toml::table root = parse_toml_file(file);
  TomlTable t(root, file.string());
  BenchSettings s;
  const auto dir = file.parent_path();
  s.dbc_file = dir / t.string("dbc");
  s.dto_log = dir / t.string("dto_log");
  s.bus = t.string_opt("bus").value_or(s.bus);
  const double step_ms = t.number_or("step_ms", 5.0);
  if (!(step_ms > 0)) t.fail("step_ms", "must be > 0 [ms]");

  if (auto p = t.table_opt("plant")) {
    s.plant.deadzone_mA = p->number_or("deadzone_mA", s.plant.deadzone_mA);
    s.plant.gain_kPa_per_mA = p->number_or("gain_kPa_per_mA", s.plant.gain_kPa_per_mA);
    s.plant.tau_s = p->number_or("tau_s", s.plant.tau_s);
    s.plant.bias_kPa = p->number_or("bias_kPa", s.plant.bias_kPa);
    s.plant.noise_sigma_kPa = p->number_or("noise_sigma_kPa", s.plant.noise_sigma_kPa);
    if (auto seed = p->integer_opt("seed")) {
      if (*seed < 0) p->fail("seed", "must be >= 0");
      s.plant.seed = static_cast<std::uint64_t>(*seed);
    }
    p->finish();
  }
  const toml::node* cnode = t.has("controller") ? root.get("controller") : nullptr;
  if (cnode != nullptr && cnode->is_string()) {
    // The control module's gains file (e.g. config/control/thesis_gains.toml).
    const double dt_keep = s.controller.pid.dt_s;
    s.controller =
        load_controller_config(dir / t.string("controller"), [&](const std::string& w) { s.warnings.push_back(w); });
    s.controller.pid.dt_s = dt_keep;
  } else if (auto c = t.table_opt("controller")) {
    // The same schema as a gains file (control/gains_file.hpp), inline.
    const double dt_keep = s.controller.pid.dt_s;
    s.controller = read_controller_config(*c, [&](const std::string& w) { s.warnings.push_back(w); });
    s.controller.pid.dt_s = dt_keep;
    c->finish();
  }
  if (auto m = t.table_opt("master")) {
    s.dto_timeout_s = m->number_or("dto_timeout_s", s.dto_timeout_s);
    if (!(s.dto_timeout_s > 0)) m->fail("dto_timeout_s", "must be > 0 [s]");
    const auto fm = m->integer_opt("fault_missed_periods").value_or(3);
    if (fm < 1 || fm > 1000000) m->fail("fault_missed_periods", "must be in 1..1000000");
    s.fault_missed_periods = static_cast<std::uint32_t>(fm);
    const auto cr = m->integer_opt("cro_retry_steps").value_or(10);
    if (cr < 1 || cr > 1000000) m->fail("cro_retry_steps", "must be in 1..1000000");
    s.cro_retry_steps = static_cast<std::uint32_t>(cr);
    m->finish();
  }
  t.finish();
  s.set_step(step_ms * 1e-3);
  try {
    s.plant.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(file.string(), t.line("plant"), "plant", e.what());
  }
  return s;
}

std::vector<can::Frame> load_dto_reply(const std::filesystem::path& log, const BenchLayout& layout) {
  const auto entries = can::read_log(log);
  std::vector<can::Frame> out;
  bool seen_cro = false;
  for (const auto& e : entries) {
    if (!seen_cro) {
      seen_cro = layout.is_connect(e.frame);
      continue;
    }
    if (!e.frame.extended && e.frame.id == layout.dto_id) {
      can::Frame f = e.frame;
      f.timestamp_s = 0.0;
      out.push_back(f);
    } else if (layout.is_connect(e.frame)) {
      break;  // only the reply to the first CONNECT
    }
  }
  if (out.empty())
    throw InputError(log.string(), 0, "DTO",
                     "no DTO frame (id 0x" + [&] {
                       char b[16];
                       std::snprintf(b, sizeof b, "%X", layout.dto_id);
                       return std::string(b);
                     }() + ") after a CCP CONNECT CRO in the recorded log");
  return out;
}

SignalSpec parse_reference(const std::string& text, const std::string& option) {
  auto bad = [&](const std::string& msg) { return InputError("", 0, option, msg + " (in '" + text + "')"); };
  SignalSpec s;
  const auto colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  bool is_step = false;
  double from = 0.0, to = 0.0, time = 1.0;
  if (kind == "step") {
    is_step = true;
    s.kind = Waveform::steps;
  } else if (kind == "random") {
    s.kind = Waveform::randomized;
  } else {
    try {
      s.kind = parse_waveform(kind);
    } catch (const std::invalid_argument&) {
      throw bad("unknown reference kind '" + kind + "' (expected step, square, sine, triangle, random, constant)");
    }
    if (s.kind == Waveform::steps) throw bad("use 'step:from=…,to=…,time=…'");
  }
  s.amplitude = 0.0;
  if (colon != std::string::npos) {
    std::size_t start = colon + 1;
    while (start < text.size()) {
      auto end = text.find(',', start);
      if (end == std::string::npos) end = text.size();
      const std::string item = text.substr(start, end - start);
      start = end + 1;
      const auto eq = item.find('=');
      double v = 0.0;
      if (eq == std::string::npos || !parse_double(item.substr(eq + 1), v) || !std::isfinite(v))
        throw bad("expected key=number, got '" + item + "'");
      const std::string key = item.substr(0, eq);
      if (is_step && key == "from") from = v;
      else if (is_step && key == "to") to = v;
      else if (is_step && key == "time") time = v;
      else if (key == "amplitude") s.amplitude = v;
      else if (key == "offset") s.offset = v;
      else if (key == "frequency") s.frequency_rad_s = v;
      else if (key == "frequency_hz") s.frequency_rad_s = 2.0 * std::numbers::pi * v;
      else if (key == "phase") s.phase_rad = v;
      else if (key == "variance") s.variance = v;
      else if (key == "tau") s.tau_s = v;
      else if (key == "seed" && v >= 0) s.seed = static_cast<std::uint64_t>(v);
      else throw bad("unknown or misplaced key '" + key + "'");
    }
  }
  if (is_step) {
    if (!(time >= 0)) throw bad("time must be >= 0 [s]");
    s.amplitude = 1.0;
    if (time > 0)
      s.steps = {{0.0, from}, {time, to}};
    else
      s.steps = {{0.0, to}};
  }
  if (s.kind == Waveform::randomized && !(s.variance > 0 && s.tau_s > 0))
    throw bad("random needs variance > 0 and tau > 0");
  if ((s.kind == Waveform::sine || s.kind == Waveform::square || s.kind == Waveform::triangle) &&
      !(s.frequency_rad_s > 0))
    throw bad("frequency must be > 0");
  return s;
}

}  // namespace lash::hil
