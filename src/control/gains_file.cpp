#include "lash/control/gains_file.hpp"

#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash {

namespace {

/// Where a setting may be written: its canonical key, and the deprecated spellings of
/// earlier releases (accepted for one release, with a warning).
struct Spelling {
  TomlTable* table;      ///< nullptr when that table is absent
  std::string key;
  bool deprecated;
};

class Reader {
 public:
  explicit Reader(const ControllerWarn& warn) : warn_(warn) {}

  /// The one spelling present (a setting given twice is an error), or nullptr.
  const Spelling* pick(std::vector<Spelling>& s, const std::string& canonical) {
    const Spelling* found = nullptr;
    for (const auto& sp : s) {
      if (sp.table == nullptr || !sp.table->has(sp.key)) continue;
      if (found != nullptr)
        sp.table->fail(sp.key, "given twice (also as '" + found->table->path(found->key) + "'); write only '" +
                                   canonical + "'");
      found = &sp;
    }
    if (found != nullptr && found->deprecated) {
      const std::string msg = found->table->file() + ":" + std::to_string(found->table->line(found->key)) + ": '" +
                              found->table->path(found->key) + "' is deprecated, write '" + canonical +
                              "' (the old key is accepted until lash 0.3)";
      if (warn_) warn_(msg);
      else fmt::print(stderr, "lash: warning: {}\n", msg);
    }
    return found;
  }
  std::optional<double> number(std::vector<Spelling> s, const std::string& canonical, bool nonneg) {
    const Spelling* sp = pick(s, canonical);
    if (sp == nullptr) return std::nullopt;
    const double v = sp->table->number(sp->key);
    if (nonneg && !(v >= 0)) sp->table->fail(sp->key, "must be >= 0");
    return v;
  }
  std::optional<std::string> string(std::vector<Spelling> s, const std::string& canonical, const Spelling** where) {
    const Spelling* sp = pick(s, canonical);
    *where = sp;
    if (sp == nullptr) return std::nullopt;
    return sp->table->string(sp->key);
  }

 private:
  const ControllerWarn& warn_;
};

}  // namespace

ControllerConfig read_controller_config(TomlTable& top, const ControllerWarn& warn) {
  static const char* const kFlat[] = {"kp",         "ki_per_s",           "kd_s",           "n_per_s",
                                      "integrator", "deadzone_inverse_mA", "current_min_mA", "current_max_mA"};
  bool flat = false;
  for (const char* k : kFlat) flat = flat || top.has(k);
  std::optional<TomlTable> pid = top.table_opt("pid");
  if (!pid && !flat) pid = top.table("pid");  // throws: missing [pid]
  std::optional<TomlTable> dz = top.table_opt("deadzone_inverse");
  std::optional<TomlTable> sat = top.table_opt("saturation");
  TomlTable* P = pid ? &*pid : nullptr;
  TomlTable* D = dz ? &*dz : nullptr;
  TomlTable* S = sat ? &*sat : nullptr;
  TomlTable* F = flat ? &top : nullptr;
  Reader r(warn);
  const std::string pfx = top.path("");
  auto full = [&](const std::string& k) { return pfx.empty() ? k : pfx + "." + k; };

  ControllerConfig c;
  auto& g = c.pid.gains;
  // The gains must be given in the [pid] table; the deprecated flat form defaults them.
  auto gain = [&](std::vector<Spelling> s, const std::string& key, double fallback) {
    const auto v = r.number(std::move(s), full("pid." + key), true);
    if (!v && P != nullptr) P->number(key);  // throws: missing key, named in [pid]
    return v.value_or(fallback);
  };
  g.kp = gain({{P, "kp", false}, {F, "kp", true}}, "kp", g.kp);
  g.ki_per_s = gain({{P, "ki_per_s", false}, {P, "ki", true}, {F, "ki_per_s", true}}, "ki_per_s", g.ki_per_s);
  g.kd_s = gain({{P, "kd_s", false}, {P, "kd", true}, {F, "kd_s", true}}, "kd_s", g.kd_s);
  g.n_per_s = r.number({{P, "n_per_s", false}, {P, "n", true}, {F, "n_per_s", true}}, full("pid.n_per_s"), true).value_or(0.0);
  c.pid.dt_s = r.number({{P, "dt_s", false}, {P, "dt", true}}, full("pid.dt_s"), false).value_or(0.005);
  if (!(c.pid.dt_s > 0)) (P->has("dt_s") ? P->fail("dt_s", "must be > 0 [s]") : P->fail("dt", "must be > 0 [s]"));
  const Spelling* where = nullptr;
  if (auto m = r.string({{P, "integrator", false}, {F, "integrator", true}}, full("pid.integrator"), &where)) {
    try {
      c.pid.integrator = parse_integrator_method(m->c_str());
    } catch (const std::invalid_argument& e) {
      where->table->fail(where->key, e.what());
    }
  }
  if (P != nullptr) {
    if (auto aw = P->string_opt("anti_windup")) {
      if (*aw == "none") c.pid.anti_windup = AntiWindup::none;
      else if (*aw == "clamp") c.pid.anti_windup = AntiWindup::clamp;
      else P->fail("anti_windup", "must be \"none\" or \"clamp\"");
    }
    if (auto v = P->number_opt("output_min")) c.pid.output_min = *v;
    if (auto v = P->number_opt("output_max")) c.pid.output_max = *v;
    if (!(c.pid.output_min <= c.pid.output_max)) P->fail("output_max", "needs output_min <= output_max");
    P->finish();
  }
  if (auto off = r.number({{D, "offset_mA", false}, {F, "deadzone_inverse_mA", true}}, full("deadzone_inverse.offset_mA"),
                          true)) {
    if (D != nullptr && (D->has("deadzone_mA") || D->has("fraction")))
      D->fail("offset_mA", "give either offset_mA or deadzone_mA/fraction, not both");
    c.dz_inverse = {*off, *off};
  } else if (D != nullptr) {
    const double d = r.number({{D, "deadzone_mA", false}}, full("deadzone_inverse.deadzone_mA"), true).value_or(288.0);
    const double f = r.number({{D, "fraction", false}}, full("deadzone_inverse.fraction"), true).value_or(0.97);
    c.dz_inverse = DeadzoneInverseParams::from_deadzone(d, f);
  }
  if (D != nullptr) D->finish();
  c.current_min_mA = r.number({{S, "min_mA", false}, {F, "current_min_mA", true}}, full("saturation.min_mA"), false).value_or(0.0);
  c.current_max_mA =
      r.number({{S, "max_mA", false}, {F, "current_max_mA", true}}, full("saturation.max_mA"), false).value_or(2000.0);
  if (!(c.current_min_mA <= c.current_max_mA)) {
    if (S != nullptr && S->has("max_mA")) S->fail("max_mA", "needs min_mA <= max_mA");
    top.fail(S != nullptr ? "saturation" : "current_max_mA", "needs min_mA <= max_mA");
  }
  if (S != nullptr) S->finish();
  try {
    ClosedLoopDiscrete check(c);
  } catch (const std::invalid_argument& e) {
    throw InputError(top.file(), top.line(), top.path(""), e.what());
  }
  return c;
}

ControllerConfig load_controller_config(const std::filesystem::path& path, const ControllerWarn& warn) {
  const toml::table root = parse_toml_file(path);
  TomlTable top(root, path.string());
  ControllerConfig c = read_controller_config(top, warn);
  top.finish();
  return c;
}

std::string controller_config_toml(const ControllerConfig& c, const std::string& comment) {
  std::ostringstream o;
  std::istringstream lines(comment);
  for (std::string l; std::getline(lines, l);) o << "# " << l << "\n";
  o << "[pid]\n";
  o << "kp = " << format_double(c.pid.gains.kp) << "  # [mA/kPa]\n";
  o << "ki_per_s = " << format_double(c.pid.gains.ki_per_s) << "  # [mA/(kPa s)]\n";
  o << "kd_s = " << format_double(c.pid.gains.kd_s) << "  # [mA s/kPa]\n";
  o << "n_per_s = " << format_double(c.pid.gains.n_per_s) << "  # derivative filter [1/s]; 0 = unfiltered\n";
  o << "dt_s = " << format_double(c.pid.dt_s) << "  # [s]\n";
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
