// DBC writer: canonical statement order, shortest round-trip numbers, so that
// parse_dbc(write_dbc(db)) == db.
#include <fmt/core.h>

#include "lash/can/dbc.hpp"
#include "lash/io/csv.hpp"

namespace lash::can::dbc {
namespace {

std::string quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(c);
  }
  out.push_back('"');
  return out;
}

std::string value_text(const AttributeValue& v) { return v.quoted ? quote(v.text) : v.text; }

void append_values(std::string& out, const std::vector<ValueDescription>& values) {
  for (const auto& v : values) out += fmt::format(" {} {}", v.value, quote(v.text));
}

}  // namespace

std::string write_dbc(const Database& db) {
  std::string out;
  out += "VERSION " + quote(db.version) + "\n\n";
  out += "NS_ :\n";
  for (const auto& s : db.new_symbols) out += "\t" + s + "\n";
  out += "\nBS_:";
  if (!db.bit_timing.empty()) out += " " + db.bit_timing;
  out += "\n\nBU_:";
  for (const auto& n : db.nodes) out += " " + n;
  out += "\n";
  for (const auto& vt : db.value_tables) {
    out += "VAL_TABLE_ " + vt.name;
    append_values(out, vt.values);
    out += " ;\n";
  }
  out += "\n";
  for (const auto& m : db.messages) {
    out += fmt::format("BO_ {} {}: {} {}\n", m.dbc_id(), m.name, m.size, m.transmitter);
    for (const auto& s : m.signals) {
      std::string mux;
      if (s.mux == MuxRole::multiplexor) mux = " M";
      if (s.mux == MuxRole::multiplexed) mux = fmt::format(" m{}{}", s.mux_value, s.mux_switch ? "M" : "");
      out += fmt::format(" SG_ {}{} : {}|{}@{}{} ({},{}) [{}|{}] {} ", s.name, mux, s.start_bit, s.length,
                         s.byte_order == ByteOrder::intel ? 1 : 0, s.is_signed ? '-' : '+',
                         format_double(s.factor), format_double(s.offset), format_double(s.minimum),
                         format_double(s.maximum), quote(s.unit));
      if (s.receivers.empty()) {
        out += "Vector__XXX";  // DBC needs at least one receiver token
      } else {
        for (std::size_t i = 0; i < s.receivers.size(); ++i) out += (i ? "," : "") + s.receivers[i];
      }
      out += "\n";
    }
    out += "\n";
  }
  for (const auto& o : db.other_statements) out += o + "\n";
  if (!db.other_statements.empty()) out += "\n";
  if (!db.comment.empty()) out += "CM_ " + quote(db.comment) + ";\n";
  for (const auto& c : db.node_comments) out += "CM_ BU_ " + c.node + " " + quote(c.text) + ";\n";
  for (const auto& m : db.messages) {
    if (!m.comment.empty()) out += fmt::format("CM_ BO_ {} {};\n", m.dbc_id(), quote(m.comment));
    for (const auto& s : m.signals)
      if (!s.comment.empty()) out += fmt::format("CM_ SG_ {} {} {};\n", m.dbc_id(), s.name, quote(s.comment));
  }
  for (const auto& d : db.attribute_definitions)
    out += "BA_DEF_ " + (d.object.empty() ? std::string() : d.object + " ") + quote(d.name) + " " + d.type + ";\n";
  for (const auto& d : db.attribute_defaults) out += "BA_DEF_DEF_ " + quote(d.name) + " " + value_text(d.value) + ";\n";
  for (const auto& a : db.attributes) {
    out += "BA_ " + quote(a.name) + " ";
    if (a.object == "BU_" || a.object == "EV_") out += a.object + " " + a.node + " ";
    if (a.object == "BO_") out += fmt::format("BO_ {} ", a.message_dbc_id);
    if (a.object == "SG_") out += fmt::format("SG_ {} {} ", a.message_dbc_id, a.signal);
    out += value_text(a.value) + ";\n";
  }
  for (const auto& m : db.messages)
    for (const auto& s : m.signals)
      if (!s.values.empty()) {
        out += fmt::format("VAL_ {} {}", m.dbc_id(), s.name);
        append_values(out, s.values);
        out += " ;\n";
      }
  for (const auto& m : db.messages)
    for (const auto& s : m.signals)
      if (s.value_type != ValueType::integer)
        out += fmt::format("SIG_VALTYPE_ {} {} : {};\n", m.dbc_id(), s.name, static_cast<int>(s.value_type));
  for (const auto& m : db.messages)
    for (const auto& s : m.signals)
      if (!s.multiplexor.empty()) {
        out += fmt::format("SG_MUL_VAL_ {} {} {}", m.dbc_id(), s.name, s.multiplexor);
        for (std::size_t i = 0; i < s.mux_ranges.size(); ++i)
          out += fmt::format("{} {}-{}", i ? "," : "", s.mux_ranges[i].lo, s.mux_ranges[i].hi);
        out += ";\n";
      }
  return out;
}

}  // namespace lash::can::dbc
