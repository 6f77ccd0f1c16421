#include "lash/control/gains_file.hpp"

// The reader and the writer are generated from the field table: controller_fields.cpp.

namespace lash {

ControllerConfig load_controller_config(const std::filesystem::path& path, const ControllerWarn& warn) {
  const toml::table root = parse_toml_file(path);
  TomlTable top(root, path.string());
  ControllerConfig c = read_controller_config(top, warn);
  top.finish();
  return c;
}

}  // namespace lash
