#pragma once
/// @file controller_fields.hpp
/// The field table of ControllerConfig: one row per setting with its TOML table and key, the
/// deprecated spellings of lash 0.1 (an alias in the same table, a flat key directly in the
/// controller table), its command-line override flag, its help text with unit, a reference to
/// the member and its accepted range. Generated from it: the gains-file reader
/// (read_controller_config, gains_file.hpp; also the bench settings' `[controller]` table),
/// the writer of `lash tune -o` (controller_config_toml), the override flags of
/// `lash closed-loop` and `lash hil master|slave|run|simulate` (`--kp`, `--ki-per-s`, …), and
/// the keys table of docs/control.md (controller_keys_markdown). Not real-time safe.
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "lash/control/controller.hpp"
#include "lash/control/gains_file.hpp"
#include "lash/io/toml_util.hpp"

namespace lash {

struct ControllerField {
  /// A reference to the member; DeadzoneInverseParams* = the symmetric offset (offset_right =
  /// offset_left); std::monostate = an input-only key (deadzone_mA, fraction: offset_mA =
  /// fraction × deadzone_mA), with `input_default` as its value when absent.
  using Ref = std::variant<std::monostate, double*, IntegratorMethod*, AntiWindup*, DeadzoneInverseParams*>;
  /// When the writer writes the row: always; only when it differs from ControllerConfig{};
  /// the deadzone inverse as offset_mA (any offset but the default) or as deadzone_mA/fraction
  /// (the default 0.97 × 288 mA).
  enum class Write { always, if_changed, dz_offset, dz_default };

  const char* table;  ///< "pid", "deadzone_inverse" or "saturation"
  const char* key;    ///< the key inside `table` ("ki_per_s")
  const char* alias;  ///< deprecated key in the same table ("ki"), "" = none
  const char* flat;   ///< deprecated key directly in the controller table ("ki_per_s"), "" = none
  const char* flag;   ///< command-line override without the dashes ("ki-per-s"), "" = none
  const char* unit;   ///< "mA/kPa", "" for names
  const char* doc;    ///< help text
  const char* note;   ///< the comment the writer puts after the value ("" = none)
  Ref (*at)(ControllerConfig&);
  double lo = 0.0;        ///< numbers: value >= lo (> lo when lo_open); -inf = any finite number
  bool lo_open = false;
  bool required = false;  ///< must be given when the [pid] table is present (the gains)
  Write write = Write::always;
  double input_default = 0.0;  ///< input-only keys: the value when absent
};

/// Every field, in the order the writer writes them ([pid], [deadzone_inverse], [saturation]).
std::span<const ControllerField> controller_fields() noexcept;
/// The field with command-line flag `flag` (no dashes), or nullptr.
const ControllerField* find_controller_field_by_flag(std::string_view flag) noexcept;

/// Reads the [pid] rows (but dt_s) of the field table from `t` into `pid`: a PID written inline,
/// as the `[controller]` table of a closed-loop scenario (experiments/closed_loop_scenario.hpp)
/// does, at the caller's sample period and in the caller's units. Only keys given change `pid`;
/// none is required; deprecated aliases (ki, kd, n) warn as in a gains file (`warn` empty:
/// stderr); then output_min <= output_max. Errors are InputError naming file, line and key.
/// Leaves `t`'s unknown keys to the caller's finish().
void read_pid_fields(TomlTable& t, PidConfig& pid, const ControllerWarn& warn = {});

/// Whether `f` takes a name (integrator, anti_windup) rather than a number.
bool controller_field_is_name(const ControllerField& f) noexcept;

/// Sets `f` in `c` from a command-line text (a number in the field's range, or a name).
/// Throws std::invalid_argument; input-only fields have no flag and throw too.
void parse_controller_field(const ControllerField& f, std::string_view text, ControllerConfig& c);
/// The TOML text of `f`'s value in `c` (shortest round-trip numbers, quoted names).
std::string controller_field_toml_value(const ControllerField& f, const ControllerConfig& c);

/// Command-line overrides, in the order given: applied after the file.
struct ControllerOverride {
  const ControllerField* field;
  std::string text;
};
/// Applies `o` to `c`, then checks output_min <= output_max, min_mA <= max_mA and the whole
/// controller. Throws InputError naming the flag ("--kp").
void apply_controller_overrides(ControllerConfig& c, const std::vector<ControllerOverride>& o);

/// The keys table of docs/control.md (Markdown), generated from the field table.
std::string controller_keys_markdown();

}  // namespace lash
