#pragma once
/// @file dbc.hpp
/// DBC (Vector CAN database) files: a parser for what real files contain and a
/// writer whose output parses back to the same Database.
///
/// Conventions (DESIGN.md): `@1` is Intel (little-endian, start bit = LSB),
/// `@0` is Motorola (big-endian, start bit = MSB in the sawtooth numbering
/// 7..0, 15..8, …); physical = raw × factor + offset.
///
/// Supported statements: VERSION, NS_, BS_, BU_, BO_, SG_ (with multiplexor
/// `M` / `m<n>`), CM_, BA_DEF_, BA_DEF_DEF_, BA_, VAL_, VAL_TABLE_,
/// SIG_VALTYPE_. Other known DBC statements (EV_, BO_TX_BU_, SIG_GROUP_,
/// BA_DEF_REL_, …) are kept verbatim and written back unchanged.
/// Extended multiplexing (`m<n>M` switches and `SG_MUL_VAL_` ranges) is parsed into
/// Signal::mux_switch / multiplexor / mux_ranges and written back.
///
/// Tolerant by default, like the tools engineers use: what is dubious becomes a
/// Diagnostic (file:line, kind, what was done) and the rest of the file loads —
/// ids above 0x7FF without bit 31 are extended, comments/value tables naming
/// unknown objects are kept verbatim in other_statements, a statement without `;`
/// ends at the next keyword, names may start with a digit, a statement that cannot
/// be parsed is skipped. ParseOptions::strict turns every such warning into an
/// InputError naming file, line and column. Not real-time safe.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lash::can::dbc {

enum class ByteOrder : std::uint8_t { motorola = 0, intel = 1 };  ///< the digit after '@'
enum class ValueType : std::uint8_t { integer = 0, float32 = 1, float64 = 2 };  ///< SIG_VALTYPE_
enum class MuxRole : std::uint8_t { none, multiplexor, multiplexed };

/// A closed range of multiplexor raw values (SG_MUL_VAL_ `lo-hi`).
struct MuxRange {
  std::uint64_t lo = 0;
  std::uint64_t hi = 0;
  bool operator==(const MuxRange&) const = default;
};

struct ValueDescription {
  std::int64_t value = 0;
  std::string text;
  bool operator==(const ValueDescription&) const = default;
};

struct Signal {
  std::string name;
  std::uint32_t start_bit = 0;  ///< Intel: LSB position; Motorola: MSB position (sawtooth)
  std::uint32_t length = 1;     ///< [bit] 1..64
  ByteOrder byte_order = ByteOrder::intel;
  bool is_signed = false;
  ValueType value_type = ValueType::integer;
  double factor = 1.0;
  double offset = 0.0;
  double minimum = 0.0;  ///< physical; minimum == maximum == 0 means "no range given"
  double maximum = 0.0;
  std::string unit;
  std::vector<std::string> receivers;
  MuxRole mux = MuxRole::none;
  std::uint64_t mux_value = 0;  ///< for MuxRole::multiplexed: the multiplexor value selecting it
  bool mux_switch = false;      ///< multiplexed and a multiplexor itself (`m<n>M`, extended multiplexing)
  std::string multiplexor;      ///< SG_MUL_VAL_: name of the multiplexor selecting it ("" = the message's `M`)
  std::vector<MuxRange> mux_ranges;  ///< SG_MUL_VAL_: selecting raw values (empty = {mux_value})
  std::string comment;
  std::vector<ValueDescription> values;  ///< VAL_
  /// Raw bits as the integer VAL_ keys use: sign-extended for signed signals.
  std::int64_t value_key(std::uint64_t raw) const noexcept;
  /// The VAL_ text of a raw value, or nullptr.
  const std::string* value_text(std::uint64_t raw) const noexcept;
  /// The raw bits a VAL_ text names (masked to the signal's length), or nullopt.
  std::optional<std::uint64_t> value_raw(std::string_view text) const noexcept;
  bool operator==(const Signal&) const = default;
};

struct Message {
  std::uint32_t id = 0;  ///< without the DBC's extended flag bit 31
  bool extended = false;
  std::string name;
  std::uint32_t size = 8;  ///< [byte] DLC
  std::string transmitter;
  std::vector<Signal> signals;
  std::string comment;
  /// True for a classic frame length 0–8 or a CAN FD length (12, 16, 20, 24, 32, 48, 64).
  bool size_is_dlc() const noexcept {
    return size <= 8 || size == 12 || size == 16 || size == 20 || size == 24 || size == 32 || size == 48 || size == 64;
  }
  /// DBC id as written in the file (bit 31 set for extended ids).
  std::uint32_t dbc_id() const noexcept { return extended ? (id | 0x80000000u) : id; }
  const Signal* signal(std::string_view signal_name) const noexcept;
  /// The multiplexor selecting `s` (SG_MUL_VAL_ name, else the message's `M`); nullptr if none.
  const Signal* multiplexor_of(const Signal& s) const noexcept;
  bool operator==(const Message&) const = default;
};

/// BA_DEF_ [object] "name" type; — the type is kept as its text (e.g. `INT 0 100`, `ENUM "a","b"`).
struct AttributeDefinition {
  std::string object;  ///< "", "BU_", "BO_", "SG_", "EV_"
  std::string name;
  std::string type;
  bool operator==(const AttributeDefinition&) const = default;
};

/// An attribute value: a number or a quoted string, kept as written.
struct AttributeValue {
  std::string text;        ///< number text or string contents (unquoted)
  bool quoted = false;
  bool operator==(const AttributeValue&) const = default;
};

struct AttributeDefault {
  std::string name;
  AttributeValue value;
  bool operator==(const AttributeDefault&) const = default;
};

/// BA_ "name" [BU_ node | BO_ id | SG_ id signal | EV_ var] value;
struct Attribute {
  std::string name;
  std::string object;  ///< "", "BU_", "BO_", "SG_", "EV_"
  std::string node;    ///< BU_ node / EV_ variable
  std::uint32_t message_dbc_id = 0;  ///< BO_/SG_
  std::string signal;                ///< SG_
  AttributeValue value;
  bool operator==(const Attribute&) const = default;
};

struct ValueTable {
  std::string name;
  std::vector<ValueDescription> values;
  bool operator==(const ValueTable&) const = default;
};

struct NodeComment {
  std::string node;
  std::string text;
  bool operator==(const NodeComment&) const = default;
};

struct Database {
  std::string version;
  std::vector<std::string> new_symbols;  ///< NS_
  std::string bit_timing;                ///< text after "BS_:" (usually empty)
  std::vector<std::string> nodes;        ///< BU_
  std::vector<ValueTable> value_tables;
  std::vector<Message> messages;
  std::string comment;                   ///< CM_ "…"; (network)
  std::vector<NodeComment> node_comments;
  std::vector<AttributeDefinition> attribute_definitions;
  std::vector<AttributeDefault> attribute_defaults;
  std::vector<Attribute> attributes;
  std::vector<std::string> other_statements;  ///< verbatim, e.g. "BO_TX_BU_ 100 : A,B;"

  const Message* message(std::string_view name) const noexcept;
  const Message* message(std::uint32_t id, bool extended) const noexcept;
  bool operator==(const Database&) const = default;
};

/// A finding of the reader or of check_layout().
struct Diagnostic {
  enum class Severity : std::uint8_t { warning, error };
  Severity severity = Severity::warning;
  std::string file;
  int line = 0;          ///< 1-based; 0 = not tied to one line
  std::string kind;      ///< short tag, e.g. "implicit-extended-id", "missing-semicolon", "signal-out-of-frame"
  std::string message;   ///< what was found and what was done
  /// "file:line: warning: message [kind]"
  std::string format() const;
};

struct ParseOptions {
  bool strict = false;  ///< every warning is an InputError (the reader's behaviour before tolerance)
};

/// Parses DBC text; `file` names the source in errors and diagnostics. Warnings (and
/// the layout errors of check_layout(), which leave the rest of the file usable) are
/// appended to `diagnostics` when given. Throws lash::InputError only for what cannot
/// be read at all (strict mode: on the first warning).
Database parse_dbc(std::string_view text, const std::string& file = "<dbc>", const ParseOptions& options = {},
                   std::vector<Diagnostic>* diagnostics = nullptr);
/// Reads and parses a DBC file (InputError when it cannot be read).
Database load_dbc(const std::filesystem::path& path, const ParseOptions& options = {},
                  std::vector<Diagnostic>* diagnostics = nullptr);

/// Layout problems of one message. Errors: a signal outside the frame or beyond 64
/// bytes, a factor of 0, a float type with the wrong length, a multiplexed signal
/// with no multiplexor, two signals that can be active together sharing a bit
/// (only when `overlaps`). Warnings: a size that is no CAN (FD) length. A message
/// with errors cannot be coded (MessageCodec throws); the others are unaffected.
std::vector<Diagnostic> check_layout(const Message& message, const std::string& file = "", bool overlaps = true);
/// Writes a Database as DBC text; parse_dbc(write_dbc(db)) == db.
std::string write_dbc(const Database& db);

}  // namespace lash::can::dbc
