#include "controller_options.hpp"

#include "lash/io/error.hpp"

namespace lash::cli {

void add_controller_options(CLI::App* sub, std::vector<ControllerOverride>& out, bool with_dt) {
  for (const ControllerField& f : controller_fields()) {
    if (*f.flag == '\0' || (!with_dt && std::string_view(f.flag) == "dt-s")) continue;
    const std::string unit = *f.unit != '\0' ? std::string(" [") + f.unit + "]" : "";
    sub->add_option_function<std::string>(
           std::string("--") + f.flag, [&out, &f](const std::string& v) { out.push_back({&f, v}); },
           f.doc + unit + " (file: " + f.table + "." + f.key + ")")
        ->type_name(controller_field_is_name(f) ? "NAME" : "NUMBER")
        ->group("Controller overrides (applied after the gains file)");
  }
}

std::vector<std::pair<std::string, std::string>> controller_override_keys(const std::vector<ControllerOverride>& overrides) {
  std::vector<std::pair<std::string, std::string>> k;
  for (const auto& o : overrides) k.emplace_back(std::string(o.field->table) + "." + o.field->key, o.text);
  return k;
}

std::vector<ControllerOverride> controller_overrides_from_keys(const std::vector<std::pair<std::string, std::string>>& keys,
                                                               const std::string& file) {
  std::vector<ControllerOverride> out;
  for (const auto& [key, text] : keys) {
    const ControllerField* found = nullptr;
    for (const auto& f : controller_fields())
      if (*f.flag != '\0' && std::string(f.table) + "." + f.key == key) found = &f;
    if (found == nullptr) throw InputError(file, 0, "controller", "no controller field '" + key + "' with an override");
    out.push_back(ControllerOverride{found, text});
  }
  return out;
}

}  // namespace lash::cli
