// The field table of ControllerConfig (controller_fields.hpp): unique keys and flags, the
// writer/reader round trip, the deprecated spellings, errors with file:line:key, the CLI
// overrides and the docs' keys table.
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lash/control/controller_fields.hpp"
#include "lash/control/gains_file.hpp"
#include "lash/io/error.hpp"

namespace lash {
namespace {

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

/// Every field's value as the writer writes it: equal texts = equal values (shortest round trip).
std::vector<std::string> values(const ControllerConfig& c) {
  std::vector<std::string> v;
  for (const auto& f : controller_fields()) v.push_back(controller_field_toml_value(f, c));
  v.push_back(std::to_string(c.dz_inverse.offset_left));  // the symmetric offset: both sides
  return v;
}

TEST(ControllerFields, UniqueKeysSpellingsAndFlags) {
  std::set<std::string> keys, flat, flags;
  std::size_t with_flag = 0;
  for (const auto& f : controller_fields()) {
    EXPECT_TRUE(keys.insert(std::string(f.table) + "." + f.key).second) << f.key;
    if (*f.alias != '\0') {
      EXPECT_TRUE(keys.insert(std::string(f.table) + "." + f.alias).second) << f.alias;
    }
    if (*f.flat != '\0') {
      EXPECT_TRUE(flat.insert(f.flat).second) << f.flat;
    }
    if (*f.flag != '\0') {
      EXPECT_TRUE(flags.insert(f.flag).second) << f.flag;
      EXPECT_EQ(find_controller_field_by_flag(f.flag), &f);
      ++with_flag;
    }
    EXPECT_NE(std::string(f.doc), "");
  }
  // A flat key may not be the name of a table either.
  for (const char* t : {"pid", "deadzone_inverse", "saturation"}) EXPECT_EQ(flat.count(t), 0u);
  EXPECT_EQ(keys.size(), controller_fields().size() + 4);  // + ki, kd, n, dt
  EXPECT_EQ(flat.size(), 8u);  // the 0.1 bench settings' flat [controller] keys
  EXPECT_EQ(with_flag, 12u);   // all but deadzone_mA and fraction
  EXPECT_EQ(find_controller_field_by_flag("no-such-flag"), nullptr);
  EXPECT_EQ(find_controller_field_by_flag(""), nullptr);
}

TEST(ControllerFields, WrittenFileReadsBackEveryField) {
  std::mt19937_64 rng(20261125);
  auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  for (int trial = 0; trial < 200; ++trial) {
    ControllerConfig c;
    c.pid.gains = {u(0, 50), u(0, 3000), u(0, 1), trial % 3 == 0 ? 0.0 : u(0, 500)};
    c.pid.dt_s = u(1e-4, 0.1);
    c.pid.integrator = static_cast<IntegratorMethod>(trial % 3);
    c.pid.anti_windup = trial % 2 == 0 ? AntiWindup::clamp : AntiWindup::none;
    c.pid.output_min = u(-2000, 0);
    c.pid.output_max = u(0, 2000);
    if (trial % 4 != 0) c.dz_inverse = DeadzoneInverseParams::from_deadzone(1.0, u(0, 600));  // else the default
    c.current_min_mA = u(-100, 100);
    c.current_max_mA = u(100, 3000);
    const std::string path = write_file("round_trip.toml", controller_config_toml(c, "trial\nrandom values"));
    std::vector<std::string> warnings;
    const ControllerConfig back = load_controller_config(path, [&](const std::string& w) { warnings.push_back(w); });
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(values(back), values(c)) << "trial " << trial;
    // The members themselves (not only their texts).
    EXPECT_EQ(back.pid.gains.kp, c.pid.gains.kp);
    EXPECT_EQ(back.pid.gains.ki_per_s, c.pid.gains.ki_per_s);
    EXPECT_EQ(back.pid.dt_s, c.pid.dt_s);
    EXPECT_EQ(back.pid.output_min, c.pid.output_min);
    EXPECT_EQ(back.dz_inverse.offset_right, c.dz_inverse.offset_right);
    EXPECT_EQ(back.dz_inverse.offset_left, c.dz_inverse.offset_left);
    EXPECT_EQ(back.current_max_mA, c.current_max_mA);
  }
  // The default inverse is written as the thesis's deadzone_mA/fraction, others as offset_mA.
  ControllerConfig d;
  EXPECT_NE(controller_config_toml(d, "").find("deadzone_mA = 288  # identified deadzone [mA]\nfraction = 0.97"),
            std::string::npos);
  d.dz_inverse = DeadzoneInverseParams::from_deadzone(100.0, 1.0);
  EXPECT_NE(controller_config_toml(d, "").find("\noffset_mA = 100  #"), std::string::npos);
}

TEST(ControllerFields, EveryDeprecatedSpellingWarnsAndReadsAsTheCanonicalKey) {
  std::size_t checked = 0;
  for (const auto& f : controller_fields()) {
    const std::string v = controller_field_is_name(f) ? (f.key == std::string("integrator") ? "\"trapezoidal\"" : "\"clamp\"")
                                                      : "1.25";
    // Canonical: [pid] with the three required gains (0 unless this is one), then the key.
    auto file = [&](const std::string& key) {
      std::map<std::string, std::string> pid{{"kp", "0"}, {"ki_per_s", "0"}, {"kd_s", "0"}};
      std::string other;
      if (f.table == std::string("pid")) {
        if (key != f.key) pid.erase(f.key);
        pid[key] = v;
      } else {
        other = "[" + std::string(f.table) + "]\n" + key + " = " + v + "\n";
      }
      std::string s = "[pid]\n";
      for (const auto& [k, x] : pid) s += k + " = " + x + "\n";
      return s + other;
    };
    std::vector<std::string> w;
    auto warn = [&](const std::string& m) { w.push_back(m); };
    const ControllerConfig canon = load_controller_config(write_file("canon.toml", file(f.key)), warn);
    ASSERT_TRUE(w.empty()) << w[0];
    const std::string canonical = std::string(f.table) + "." + f.key;
    if (*f.alias != '\0') {
      const std::string text = file(f.alias);
      // The alias's line by hand: the lines of [pid] are sorted by key (std::map) after "[pid]".
      std::istringstream in(text);
      int line = 0, at = 0;
      for (std::string l; std::getline(in, l);)
        if (++line, l.rfind(std::string(f.alias) + " = ", 0) == 0) at = line;
      const ControllerConfig old = load_controller_config(write_file("alias.toml", text), warn);
      EXPECT_EQ(values(old), values(canon)) << f.alias;
      ASSERT_EQ(w.size(), 1u) << f.alias;
      EXPECT_NE(w[0].find("alias.toml:" + std::to_string(at) + ": 'pid." + f.alias + "' is deprecated, write '" +
                          canonical + "'"),
                std::string::npos)
          << w[0];
      w.clear();
      ++checked;
    }
    if (*f.flat != '\0') {
      // The 0.1 bench form: the flat key alone (line 1), no [pid]; unset gains stay 0.
      const ControllerConfig old = load_controller_config(write_file("flat.toml", std::string(f.flat) + " = " + v + "\n"), warn);
      EXPECT_EQ(values(old), values(canon)) << f.flat;
      ASSERT_EQ(w.size(), 1u) << f.flat;
      EXPECT_NE(w[0].find("flat.toml:1: '" + std::string(f.flat) + "' is deprecated, write '" + canonical + "'"),
                std::string::npos)
          << w[0];
      w.clear();
      ++checked;
    }
  }
  EXPECT_EQ(checked, 12u);  // 4 aliases + 8 flat keys
}

void expect_error(const std::string& text, int line, const std::string& field, const std::string& what) {
  const std::string path = write_file("bad.toml", text);
  try {
    load_controller_config(path, [](const std::string&) {});
    ADD_FAILURE() << "expected InputError for " << text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(ControllerFields, ErrorsNameFileLineAndKey) {
  const std::string gains = "[pid]\nkp = 1\nki_per_s = 2\nkd_s = 0\n";  // lines 1-4
  expect_error("[pid]\nkp = 1\nki_per_s = -3\nkd_s = 0\n", 3, "pid.ki_per_s", "must be >= 0 [mA/(kPa s)]");
  expect_error("[pid]\nkp = 1\nki = -3\nkd_s = 0\n", 3, "pid.ki", "must be >= 0");
  expect_error(gains + "dt_s = 0\n", 5, "pid.dt_s", "must be > 0 [s]");
  expect_error(gains + "integrator = \"euler\"\n", 5, "pid.integrator", "forward_euler");
  expect_error(gains + "anti_windup = \"soft\"\n", 5, "pid.anti_windup", "\"none\" or \"clamp\"");
  expect_error(gains + "output_min = 5\noutput_max = 1\n", 6, "pid.output_max", "output_min <= output_max");
  expect_error(gains + "[deadzone_inverse]\noffset_mA = -1\n", 6, "deadzone_inverse.offset_mA", "must be >= 0 [mA]");
  expect_error(gains + "[deadzone_inverse]\nfraction = 0.9\noffset_mA = 100\n", 7, "deadzone_inverse.offset_mA",
               "not both");
  expect_error(gains + "[saturation]\nmin_mA = 500\nmax_mA = 100\n", 7, "saturation.max_mA", "min_mA <= max_mA");
  expect_error("kp = 1\ncurrent_min_mA = 500\ncurrent_max_mA = 100\n", 3, "current_max_mA", "min_mA <= max_mA");
  expect_error("[pid]\nkp = 1\nkd_s = 0\n", 1, "pid.ki_per_s", "");  // a required gain missing: the table's line
  expect_error(gains + "ki = 2\n", 5, "pid.ki", "given twice");
}

TEST(ControllerFields, FlagsParseAsTheTomlValuesAndOverridesAreChecked) {
  for (const auto& f : controller_fields()) {
    if (*f.flag == '\0') {
      ControllerConfig c;
      EXPECT_THROW(parse_controller_field(f, "1", c), std::invalid_argument);
      continue;
    }
    const std::string text = controller_field_is_name(f) ? (f.key == std::string("integrator") ? "backward_euler" : "clamp")
                                                         : "37.5";
    const std::string toml_value = controller_field_is_name(f) ? "\"" + text + "\"" : text;
    std::string file = "[pid]\nkp = 0\nki_per_s = 0\nkd_s = 0\n";
    if (f.table == std::string("pid")) {
      if (f.required) file = "[pid]\n" + std::string(f.key == std::string("kp") ? "" : "kp = 0\n") +
                              (f.key == std::string("ki_per_s") ? "" : "ki_per_s = 0\n") +
                              (f.key == std::string("kd_s") ? "" : "kd_s = 0\n");
      file += std::string(f.key) + " = " + toml_value + "\n";
    } else {
      file += "[" + std::string(f.table) + "]\n" + f.key + " = " + toml_value + "\n";
    }
    const ControllerConfig from_file = load_controller_config(write_file("flag.toml", file));
    ControllerConfig from_flag = load_controller_config(write_file("zero.toml", "[pid]\nkp = 0\nki_per_s = 0\nkd_s = 0\n"));
    apply_controller_overrides(from_flag, {{&f, text}});
    EXPECT_EQ(values(from_flag), values(from_file)) << f.flag;
  }
  ControllerConfig c;
  auto error_field = [&](std::vector<ControllerOverride> o) {
    try {
      ControllerConfig copy = c;
      apply_controller_overrides(copy, o);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  const auto* kp = find_controller_field_by_flag("kp");
  const auto* max = find_controller_field_by_flag("max-mA");
  const auto* omin = find_controller_field_by_flag("output-min");
  EXPECT_EQ(error_field({{kp, "-1"}}), "--kp");
  EXPECT_EQ(error_field({{kp, "1x"}}), "--kp");
  EXPECT_EQ(error_field({{kp, "nan"}}), "--kp");
  EXPECT_EQ(error_field({{find_controller_field_by_flag("integrator"), "euler"}}), "--integrator");
  EXPECT_EQ(error_field({{max, "-5"}}), "--max-mA");  // below min_mA = 0
  EXPECT_EQ(error_field({{omin, "10"}, {find_controller_field_by_flag("output-max"), "5"}}), "--output-max");
  EXPECT_EQ(error_field({{kp, "2"}, {max, "1500"}}), "no error");
}

TEST(ControllerFields, InlinePidOfAScenarioUsesTheSameRows) {
  // A closed-loop scenario's [controller]: the [pid] keys inline, none required, no dt_s.
  auto read = [](const std::string& name, const std::string& text, std::vector<std::string>& w) {
    const std::string path = write_file(name, text);
    const toml::table root = parse_toml_file(path);
    TomlTable top(root, path);
    TomlTable c = top.table("controller");
    PidConfig pid;
    pid.output_min = -12.0;  // the caller's default (the scenario's min/max)
    pid.output_max = 12.0;
    read_pid_fields(c, pid, [&](const std::string& m) { w.push_back(m); });
    c.finish();
    return pid;
  };
  std::vector<std::string> w;
  const PidConfig a = read("inline.toml", "[controller]\nkp = 600\nki_per_s = 5000\nkd_s = 15\nn_per_s = 200\n", w);
  EXPECT_TRUE(w.empty());
  const PidConfig b = read("inline_old.toml", "[controller]\nkp = 600\nki = 5000\nkd = 15\nn = 200\n", w);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_NE(w[0].find("inline_old.toml:3: 'controller.ki' is deprecated, write 'controller.ki_per_s'"),
            std::string::npos)
      << w[0];
  for (const PidConfig* p : {&a, &b}) {
    EXPECT_EQ(p->gains.kp, 600.0);
    EXPECT_EQ(p->gains.ki_per_s, 5000.0);
    EXPECT_EQ(p->gains.kd_s, 15.0);
    EXPECT_EQ(p->gains.n_per_s, 200.0);
    EXPECT_EQ(p->dt_s, PidConfig{}.dt_s);  // not read here
    EXPECT_EQ(p->output_min, -12.0);       // kept when not given
    EXPECT_EQ(p->output_max, 12.0);
  }
  // dt_s is not a row of the inline table: finish() calls it unknown; a range error has no unit.
  EXPECT_THROW(read("inline_dt.toml", "[controller]\ndt_s = 0.01\n", w), InputError);
  try {
    read("inline_bad.toml", "[controller]\nkp = 1\nkd = -2\n", w);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.field(), "controller.kd");
    EXPECT_NE(std::string(e.what()).find("must be >= 0"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find("mA"), std::string::npos) << e.what();
  }
}

TEST(ControllerFields, DocsShowTheGeneratedKeysTable) {
  std::ifstream in(std::string(LASH_SOURCE_DIR) + "/docs/control.md");
  std::stringstream doc;
  doc << in.rdbuf();
  const std::string table = controller_keys_markdown();
  EXPECT_NE(doc.str().find(table), std::string::npos)
      << "docs/control.md must hold the keys table exactly as controller_keys_markdown() writes it:\n"
      << table;
  for (const auto& f : controller_fields()) {
    EXPECT_NE(table.find(std::string("`") + f.table + "." + f.key + "`"), std::string::npos) << f.key;
    if (*f.flag != '\0') {
      EXPECT_NE(table.find(std::string("`--") + f.flag + "`"), std::string::npos) << f.flag;
    }
  }
}

}  // namespace
}  // namespace lash
