#include "controller_options.hpp"

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

std::vector<std::string> controller_option_args(const std::vector<ControllerOverride>& overrides) {
  std::vector<std::string> a;
  for (const auto& o : overrides) a.insert(a.end(), {std::string("--") + o.field->flag, o.text});
  return a;
}

}  // namespace lash::cli
