#include "lash/control/controller_fields.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "lash/control/gains_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/field_table.hpp"

namespace lash {

namespace {

using Ref = ControllerField::Ref;
using W = ControllerField::Write;
using C = ControllerConfig;
constexpr double kAny = -std::numeric_limits<double>::infinity();
constexpr double kThesisDeadzone_mA = 288.0;
constexpr double kThesisFraction = 0.97;

// clang-format off
const ControllerField kFields[] = {
  {"pid", "kp", "", "kp", "kp", "mA/kPa", "proportional gain Kp", "[mA/kPa]",
   [](C& c) -> Ref { return &c.pid.gains.kp; }, 0.0, false, true},
  {"pid", "ki_per_s", "ki", "ki_per_s", "ki-per-s", "mA/(kPa s)", "integral gain Ki", "[mA/(kPa s)]",
   [](C& c) -> Ref { return &c.pid.gains.ki_per_s; }, 0.0, false, true},
  {"pid", "kd_s", "kd", "kd_s", "kd-s", "mA s/kPa", "derivative gain Kd", "[mA s/kPa]",
   [](C& c) -> Ref { return &c.pid.gains.kd_s; }, 0.0, false, true},
  {"pid", "n_per_s", "n", "n_per_s", "n-per-s", "1/s", "derivative filter N; 0 = unfiltered (backward difference)",
   "derivative filter [1/s]; 0 = unfiltered", [](C& c) -> Ref { return &c.pid.gains.n_per_s; }},
  {"pid", "dt_s", "dt", "", "dt-s", "s", "sample period T", "[s]",
   [](C& c) -> Ref { return &c.pid.dt_s; }, 0.0, true},
  {"pid", "integrator", "", "integrator", "integrator", "", "forward_euler | backward_euler | trapezoidal", "",
   [](C& c) -> Ref { return &c.pid.integrator; }},
  {"pid", "anti_windup", "", "", "anti-windup", "", "none | clamp (the PID output held in output_min..output_max)",
   "", [](C& c) -> Ref { return &c.pid.anti_windup; }, 0.0, false, false, W::if_changed},
  {"pid", "output_min", "", "", "output-min", "mA", "clamp anti-windup: lower limit of the PID output u", "",
   [](C& c) -> Ref { return &c.pid.output_min; }, kAny, false, false, W::if_changed},
  {"pid", "output_max", "", "", "output-max", "mA", "clamp anti-windup: upper limit of the PID output u", "",
   [](C& c) -> Ref { return &c.pid.output_max; }, kAny, false, false, W::if_changed},
  {"deadzone_inverse", "offset_mA", "", "deadzone_inverse_mA", "offset-mA", "mA",
   "deadzone inverse: offset added in the direction of u (both sides)", "added in the direction of the command [mA]",
   [](C& c) -> Ref { return &c.dz_inverse; }, 0.0, false, false, W::dz_offset},
  {"deadzone_inverse", "deadzone_mA", "", "", "", "mA", "identified deadzone; offset = fraction x deadzone_mA",
   "identified deadzone [mA]", [](C&) -> Ref { return {}; }, 0.0, false, false, W::dz_default, kThesisDeadzone_mA},
  {"deadzone_inverse", "fraction", "", "", "", "", "offset = fraction x deadzone_mA (thesis: 0.97)",
   "offset = 0.97 x deadzone (thesis)", [](C&) -> Ref { return {}; }, 0.0, false, false, W::dz_default,
   kThesisFraction},
  {"saturation", "min_mA", "", "current_min_mA", "min-mA", "mA", "lower limit of the current command", "",
   [](C& c) -> Ref { return &c.current_min_mA; }, kAny},
  {"saturation", "max_mA", "", "current_max_mA", "max-mA", "mA", "upper limit of the current command", "",
   [](C& c) -> Ref { return &c.current_max_mA; }, kAny},
};
// clang-format on
constexpr std::size_t kN = std::size(kFields);
constexpr const char* kTables[] = {"pid", "deadzone_inverse", "saturation"};

std::size_t index_of(std::string_view table, std::string_view key) {
  for (std::size_t i = 0; i < kN; ++i)
    if (table == kFields[i].table && key == kFields[i].key) return i;
  throw std::logic_error("no controller field " + std::string(table) + "." + std::string(key));
}

bool in_range(const ControllerField& f, double v) { return f.lo_open ? v > f.lo : v >= f.lo; }

std::string range_text(const ControllerField& f, bool with_unit = true) {
  std::string s = f.lo == kAny ? "must be a finite number" : fmt::format("must be {} {}", f.lo_open ? ">" : ">=", f.lo);
  if (with_unit && *f.unit != '\0') s += fmt::format(" [{}]", f.unit);
  return s;
}

AntiWindup parse_anti_windup(std::string_view s) {
  if (s == "none") return AntiWindup::none;
  if (s == "clamp") return AntiWindup::clamp;
  throw std::invalid_argument("must be \"none\" or \"clamp\"");
}
const char* to_text(AntiWindup a) { return a == AntiWindup::clamp ? "clamp" : "none"; }

/// Where a setting may be written: its canonical key, and the deprecated spellings of
/// earlier releases (accepted for one release, with a warning).
struct Spelling {
  TomlTable* table;  ///< nullptr when that table is absent
  std::string key;
  bool deprecated;
};

/// The one spelling present (a setting given twice is an error), or nullptr; warns for a
/// deprecated one.
const Spelling* pick(const std::vector<Spelling>& s, const std::string& canonical, const ControllerWarn& warn) {
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
    if (warn) warn(msg);
    else fmt::print(stderr, "lash: warning: {}\n", msg);
  }
  return found;
}

/// Reads the value of `f` at `t`.`key` into `c` (input-only fields into `input`).
/// `with_unit`: name the gains file's unit in a range error (not in a scenario, whose units vary).
void read_value(TomlTable& t, const std::string& key, const ControllerField& f, ControllerConfig& c, double& input,
                bool with_unit) {
  auto number = [&] {
    const double v = t.number(key);
    if (!in_range(f, v)) t.fail(key, range_text(f, with_unit));
    return v;
  };
  auto named = [&](auto parse) {
    const std::string s = t.string(key);
    try {
      return parse(s);
    } catch (const std::invalid_argument& e) {
      t.fail(key, e.what());
    }
  };
  std::visit(Overload{
                 [&](std::monostate) { input = number(); },
                 [&](double* p) { *p = number(); },
                 [&](DeadzoneInverseParams* p) { p->offset_right = p->offset_left = number(); },
                 [&](IntegratorMethod* p) {
                   *p = named([](const std::string& s) { return parse_integrator_method(s.c_str()); });
                 },
                 [&](AntiWindup* p) { *p = named([](const std::string& s) { return parse_anti_windup(s); }); },
             },
             f.at(c));
}

}  // namespace

std::span<const ControllerField> controller_fields() noexcept { return kFields; }

const ControllerField* find_controller_field_by_flag(std::string_view flag) noexcept {
  return find_by_flag<ControllerField>(kFields, flag);
}

bool controller_field_is_name(const ControllerField& f) noexcept {
  ControllerConfig scratch;
  const Ref r = f.at(scratch);
  return std::holds_alternative<IntegratorMethod*>(r) || std::holds_alternative<AntiWindup*>(r);
}

void parse_controller_field(const ControllerField& f, std::string_view text, ControllerConfig& c) {
  auto number = [&] {
    double v = 0.0;
    if (!parse_double(text, v)) throw std::invalid_argument("expected a finite number, got '" + std::string(text) + "'");
    if (!in_range(f, v)) throw std::invalid_argument(range_text(f) + ", got '" + std::string(text) + "'");
    return v;
  };
  std::visit(Overload{
                 [&](std::monostate) -> void {
                   throw std::invalid_argument(std::string(f.table) + "." + f.key + " has no command-line flag");
                 },
                 [&](double* p) { *p = number(); },
                 [&](DeadzoneInverseParams* p) { p->offset_right = p->offset_left = number(); },
                 [&](IntegratorMethod* p) { *p = parse_integrator_method(std::string(text).c_str()); },
                 [&](AntiWindup* p) { *p = parse_anti_windup(text); },
             },
             f.at(c));
}

std::string controller_field_toml_value(const ControllerField& f, const ControllerConfig& c) {
  return std::visit(Overload{
                        [&](std::monostate) { return format_double(f.input_default); },
                        [](double* p) { return format_double(*p); },
                        [](DeadzoneInverseParams* p) { return format_double(p->offset_right); },
                        [](IntegratorMethod* p) { return "\"" + std::string(to_string(*p)) + "\""; },
                        [](AntiWindup* p) { return "\"" + std::string(to_text(*p)) + "\""; },
                    },
                    f.at(const_cast<ControllerConfig&>(c)));  // at() only takes the member's address
}

namespace {

/// Reads the rows of one table of the field table: each from its one spelling present in `T`
/// (canonical key or alias) or `F` (the flat 0.1 key), into `c` (input-only rows into `input`);
/// `given` records where each was found.
struct RowReader {
  const ControllerWarn& warn;
  bool with_unit;
  std::string prefix;  ///< dotted path of the controller table ("controller"), "" at the top
  ControllerConfig& c;
  double input[kN];
  const Spelling* given[kN] = {};
  std::vector<Spelling> spellings[kN];

  RowReader(const ControllerWarn& w, bool u, std::string p, ControllerConfig& cfg)
      : warn(w), with_unit(u), prefix(std::move(p)), c(cfg) {
    for (std::size_t i = 0; i < kN; ++i) input[i] = kFields[i].input_default;
  }
  void read(std::string_view table, TomlTable* T, TomlTable* F, bool require, std::string_view skip = {}) {
    for (std::size_t i = 0; i < kN; ++i) {
      const ControllerField& f = kFields[i];
      if (f.table != table || f.key == skip) continue;
      auto& s = spellings[i];
      s.push_back({T, f.key, false});
      if (*f.alias != '\0') s.push_back({T, f.alias, true});
      if (*f.flat != '\0') s.push_back({F, f.flat, true});
      // The canonical name: controller.pid.ki_per_s; inline (a scenario's [controller]): controller.ki_per_s.
      const std::string where = T != nullptr ? T->path(f.key) : (prefix.empty() ? "" : prefix + ".") + f.table + "." + f.key;
      given[i] = pick(s, where, warn);
      if (given[i] == nullptr) {
        if (require && f.required && T != nullptr) T->number(f.key);  // throws: missing key, named in its table
        continue;
      }
      read_value(*given[i]->table, given[i]->key, f, c, input[i], with_unit);
    }
  }
};

void check_output_limits(const PidConfig& pid, TomlTable* T) {
  if (T != nullptr && !(pid.output_min <= pid.output_max)) T->fail("output_max", "needs output_min <= output_max");
}

}  // namespace

ControllerConfig read_controller_config(TomlTable& top, const ControllerWarn& warn) {
  bool flat = false;
  for (const auto& f : kFields) flat = flat || (*f.flat != '\0' && top.has(f.flat));
  std::optional<TomlTable> tables[std::size(kTables)];
  for (std::size_t k = 0; k < std::size(kTables); ++k) tables[k] = top.table_opt(kTables[k]);
  if (!tables[0] && !flat) top.table("pid");  // throws: missing [pid]
  TomlTable* F = flat ? &top : nullptr;

  ControllerConfig c;
  RowReader r(warn, true, top.path(""), c);
  for (std::size_t k = 0; k < std::size(kTables); ++k) {
    TomlTable* T = tables[k] ? &*tables[k] : nullptr;
    r.read(kTables[k], T, F, true);
    // The cross-field rules of this table, then its unknown keys.
    if (k == 0) check_output_limits(c.pid, T);
    if (k == 1) {
      const std::size_t d = index_of("deadzone_inverse", "deadzone_mA"), f = index_of("deadzone_inverse", "fraction");
      if (r.given[index_of("deadzone_inverse", "offset_mA")] != nullptr) {
        if (r.given[d] != nullptr || r.given[f] != nullptr)
          T->fail("offset_mA", "give either offset_mA or deadzone_mA/fraction, not both");
      } else {
        c.dz_inverse = DeadzoneInverseParams::from_deadzone(r.input[d], r.input[f]);
      }
    }
    if (k == 2 && !(c.current_min_mA <= c.current_max_mA)) {
      if (T != nullptr && T->has("max_mA")) T->fail("max_mA", "needs min_mA <= max_mA");
      top.fail(T != nullptr ? "saturation" : "current_max_mA", "needs min_mA <= max_mA");
    }
    if (T != nullptr) T->finish();
  }
  try {
    ClosedLoopDiscrete check(c);
  } catch (const std::invalid_argument& e) {
    throw InputError(top.file(), top.line(), top.path(""), e.what());
  }
  return c;
}

void read_pid_fields(TomlTable& t, PidConfig& pid, const ControllerWarn& warn) {
  ControllerConfig c;
  c.pid = pid;
  RowReader r(warn, false, t.path(""), c);
  r.read("pid", &t, nullptr, false, "dt_s");
  check_output_limits(c.pid, &t);
  pid = c.pid;
}

std::string controller_config_toml(const ControllerConfig& c, const std::string& comment) {
  std::ostringstream o;
  std::istringstream lines(comment);
  for (std::string l; std::getline(lines, l);) o << "# " << l << "\n";
  const bool dz_default = c.dz_inverse.offset_right ==
                          DeadzoneInverseParams::from_deadzone(kThesisDeadzone_mA, kThesisFraction).offset_right;
  const ControllerConfig defaults;
  const char* table = nullptr;
  for (const auto& f : kFields) {
    if (table == nullptr || std::strcmp(table, f.table) != 0) {
      o << (table == nullptr ? "" : "\n") << "[" << f.table << "]\n";
      table = f.table;
    }
    const std::string v = controller_field_toml_value(f, c);
    const bool write = f.write == W::always || (f.write == W::if_changed && v != controller_field_toml_value(f, defaults)) ||
                       (f.write == W::dz_offset && !dz_default) || (f.write == W::dz_default && dz_default);
    if (!write) continue;
    o << f.key << " = " << v;
    if (*f.note != '\0') o << "  # " << f.note;
    o << "\n";
  }
  return o.str();
}

void apply_controller_overrides(ControllerConfig& c, const std::vector<ControllerOverride>& overrides) {
  if (overrides.empty()) return;
  auto flag = [](const ControllerField& f) { return std::string("--") + f.flag; };
  for (const auto& o : overrides) {
    try {
      parse_controller_field(*o.field, o.text, c);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, flag(*o.field), e.what());
    }
  }
  auto last_of = [&](std::string_view a, std::string_view b) {  // the flag of the pair given last
    for (auto it = overrides.rbegin(); it != overrides.rend(); ++it)
      if (it->field->flag == a || it->field->flag == b) return flag(*it->field);
    return std::string("--") + std::string(b);
  };
  if (!(c.pid.output_min <= c.pid.output_max))
    throw InputError("", 0, last_of("output-min", "output-max"), "needs output_min <= output_max");
  if (!(c.current_min_mA <= c.current_max_mA)) throw InputError("", 0, last_of("min-mA", "max-mA"), "needs min_mA <= max_mA");
  try {
    ClosedLoopDiscrete check(c);
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, flag(*overrides.back().field), e.what());
  }
}

std::string controller_keys_markdown() {
  const ControllerConfig defaults;
  std::string s =
      "| key | deprecated spellings (read until lash 0.3, with a warning) | flag | unit | accepted | default | meaning |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const auto& f : kFields) {
    std::string old;
    if (*f.alias != '\0') old += fmt::format("`{}.{}`", f.table, f.alias);
    if (*f.flat != '\0') old += fmt::format("{}flat `{}`", old.empty() ? "" : ", ", f.flat);
    std::string accepted = controller_field_is_name(f) ? "a name" : range_text(f).substr(std::strlen("must be "));
    if (const auto p = accepted.find(" ["); p != std::string::npos) accepted.resize(p);
    const std::string def = f.required ? "required" : controller_field_toml_value(f, defaults);
    std::string doc = f.doc;  // a '|' inside a cell is escaped
    for (std::size_t p = doc.find('|'); p != std::string::npos; p = doc.find('|', p + 2)) doc.insert(p, "\\");
    s += fmt::format("| `{}.{}` | {} | {} | {} | {} | {} | {} |\n", f.table, f.key, old.empty() ? "—" : old,
                     *f.flag != '\0' ? fmt::format("`--{}`", f.flag) : "—", *f.unit != '\0' ? f.unit : "—", accepted,
                     def, doc);
  }
  return s;
}

}  // namespace lash
