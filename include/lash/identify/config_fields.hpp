#pragma once
/// @file config_fields.hpp
/// The field table of EstimatorConfig: one row per setting with its TOML key, its command-line
/// flag, its help text (with unit), the struct it lives in (hence the models that read it), a
/// reference to the member and, for integers, its range. The TOML reader (config_file.hpp), the
/// `--print-config` writer and `lash estimate`'s option registration are all generated from it,
/// so a setting is added in one place. Not real-time safe.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "lash/identify/config.hpp"
#include "lash/io/toml_util.hpp"

namespace lash {

struct ConfigField {
  /// A reference to the member inside one config (min_updates is a std::uint64_t = std::size_t).
  using Ref = std::variant<double*, bool*, std::size_t*, std::uint32_t*, std::array<double, 3>*, ModelKind*,
                           EstimationMethod*, Forgetting*>;
  const char* table;  ///< TOML table: "" (top level), "rls" or "noise"
  const char* key;    ///< TOML key ("lambda")
  const char* flag;   ///< command-line option without the dashes ("lambda"); "" = none
  const char* doc;    ///< help text, unit included
  ModelSet models;    ///< the models that read the field: its struct's `models`
  Ref (*at)(EstimatorConfig&);
  std::int64_t lo = 0, hi = 0;  ///< integer fields: the accepted range
};

/// Every field of EstimatorConfig, in the order `--print-config` writes them (top-level keys,
/// then [rls], then [noise]).
std::span<const ConfigField> estimator_fields() noexcept;

/// The field with command-line flag `flag` (no dashes), or nullptr.
const ConfigField* find_field_by_flag(std::string_view flag) noexcept;

/// Whether `model` reads the setting named by `flag` (as in `lash estimate`'s options without the
/// dashes: "guess-left", "method", "pooled", …): from the struct the field belongs to. An unknown
/// name returns true.
bool model_uses(ModelKind model, std::string_view flag) noexcept;

/// Reads `f` from `t` (the table the field's `table` names) into `cfg` when the key is present.
/// Errors are InputError naming the file, line and key.
void read_field(TomlTable& t, const ConfigField& f, EstimatorConfig& cfg);

/// Sets `f` from a command-line text (numbers as written, "a,b,c" for the three-number fields,
/// names for the enumerations, true/false for switches). Throws std::invalid_argument.
void parse_field(const ConfigField& f, std::string_view text, EstimatorConfig& cfg);

/// The TOML value of `f` in `cfg` (numbers with 17 significant digits, exact round trip);
/// a non-finite number is written as ±inf (callers comment such a line out: TOML files hold
/// finite numbers only, and ±inf is the default of every such field).
std::string field_toml_value(const ConfigField& f, const EstimatorConfig& cfg);
/// A number as TOML text with 17 significant digits (always with a '.', 'e' or "inf").
std::string toml_number(double x);
/// A TOML basic string, quoted and escaped.
std::string toml_string(std::string_view s);
/// Whether the value of `f` in `cfg` is finite (every number of it).
bool field_finite(const ConfigField& f, const EstimatorConfig& cfg);

}  // namespace lash
