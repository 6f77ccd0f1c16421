#include "estimate_settings.hpp"

#include <stdexcept>
#include <type_traits>
#include <variant>

#include "lash/identify/config_fields.hpp"
#include "lash/io/error.hpp"

namespace lash::cli {

namespace {

std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto end = text.find(',', start);
    out.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  for (const auto& n : out)
    if (n.empty()) throw InputError("", 0, "--columns", "empty column name in '" + text + "'");
  if (out.size() != 3) throw InputError("", 0, "--columns", "expected three names t,v,y, got '" + text + "'");
  return out;
}

/// How --help shows the value of a field.
const char* type_name(const ConfigField::Ref& r) {
  return std::visit(
      [](auto* p) -> const char* {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, double>) return "NUMBER";
        else if constexpr (std::is_same_v<T, std::size_t> || std::is_same_v<T, std::uint32_t>) return "INT";
        else if constexpr (std::is_same_v<T, std::array<double, 3>>) return "A1,B1,E";
        else return "NAME";
      },
      r);
}

}  // namespace

void add_setting_options(CLI::App& sub, EstimateOptions& o) {
  EstimatorConfig probe;
  for (const ConfigField& f : estimator_fields()) {
    if (*f.flag == '\0') continue;
    const std::string name = std::string("--") + f.flag;
    const auto ref = f.at(probe);
    if (std::holds_alternative<bool*>(ref))
      sub.add_flag(name, o.switches[f.flag], f.doc);
    else
      sub.add_option(name, o.texts[f.flag], f.doc)->type_name(type_name(ref));
  }
}

SettingsSources settings_sources(const CLI::App& sub, const EstimateOptions& o) {
  SettingsSources s;
  if (!o.model.empty()) {
    try {
      s.model = parse_model_kind(o.model);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--model", e.what());
    }
  }
  if (sub.get_option("--preset")->count() > 0) {  // else a `preset` key in --config, else lash
    try {
      s.preset = parse_preset(o.preset);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--preset", e.what());
    }
  }
  s.config_file = o.config;
  for (const ConfigField& f : estimator_fields()) {
    if (*f.flag == '\0' || sub.get_option(std::string("--") + f.flag)->count() == 0) continue;
    if (const auto sw = o.switches.find(f.flag); sw != o.switches.end())
      s.options.emplace_back(f.flag, sw->second ? "true" : "false");
    else
      s.options.emplace_back(f.flag, o.texts.at(f.flag));
  }
  if (!o.columns.empty()) s.columns = split_names(o.columns);
  if (!o.nrmse_window.empty()) {
    if (o.nrmse_window.size() != 2)
      throw InputError("", 0, "--nrmse-window", "expected T0 T1 with 0 <= T0 < T1, finite [s]");
    s.nrmse_window_s = std::pair{o.nrmse_window[0], o.nrmse_window[1]};
  }
  return s;
}

}  // namespace lash::cli
