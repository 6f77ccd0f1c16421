// lash can dbc check | list: parse, call lash::can::dbc, print.
#include <memory>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cmd_can.hpp"
#include "lash/can/dbc.hpp"

namespace lash::cli::can_cmd {
namespace {

using can::dbc::Diagnostic;

struct DbcArgs {
  std::string file;
  bool strict = false;
  bool json = false;
};

int run_check(const DbcArgs& a) {
  std::vector<Diagnostic> diags;
  const auto db = can::dbc::load_dbc(a.file, {a.strict}, &diags);
  std::erase_if(diags, [](const Diagnostic& d) { return d.line == 0; });  // layout findings: redone below with overlaps
  for (const auto& m : db.messages)
    for (auto& d : can::dbc::check_layout(m, a.file, true)) diags.push_back(std::move(d));
  std::size_t errors = 0;
  for (const auto& d : diags) {
    fmt::print("{}\n", d.format());
    if (d.severity == Diagnostic::Severity::error) ++errors;
  }
  fmt::print("{}: {} messages, {} warnings, {} errors\n", a.file, db.messages.size(), diags.size() - errors, errors);
  return errors ? kExitFailed : kExitOk;
}

const char* mux_text(const can::dbc::Signal& s) {
  switch (s.mux) {
    case can::dbc::MuxRole::multiplexor: return "multiplexor";
    case can::dbc::MuxRole::multiplexed: return s.mux_switch ? "multiplexed multiplexor" : "multiplexed";
    default: return "";
  }
}

nlohmann::json to_json(const can::dbc::Database& db) {
  nlohmann::json msgs = nlohmann::json::array();
  for (const auto& m : db.messages) {
    nlohmann::json sigs = nlohmann::json::array();
    for (const auto& s : m.signals) {
      nlohmann::json j{{"name", s.name},
                       {"start_bit", s.start_bit},
                       {"length", s.length},
                       {"byte_order", s.byte_order == can::dbc::ByteOrder::intel ? "intel" : "motorola"},
                       {"signed", s.is_signed},
                       {"value_type", s.value_type == can::dbc::ValueType::integer ? "integer"
                                      : s.value_type == can::dbc::ValueType::float32 ? "float32" : "float64"},
                       {"factor", s.factor},
                       {"offset", s.offset},
                       {"minimum", s.minimum},
                       {"maximum", s.maximum},
                       {"unit", s.unit},
                       {"receivers", s.receivers},
                       {"multiplexing", mux_text(s)}};
      if (s.mux == can::dbc::MuxRole::multiplexed) {
        const auto* p = m.multiplexor_of(s);
        j["multiplexor"] = p ? p->name : "";
        nlohmann::json ranges = nlohmann::json::array();
        if (s.mux_ranges.empty()) ranges.push_back({s.mux_value, s.mux_value});
        for (const auto& r : s.mux_ranges) ranges.push_back({r.lo, r.hi});
        j["mux_values"] = ranges;
      }
      sigs.push_back(std::move(j));
    }
    msgs.push_back({{"id", m.id},
                    {"extended", m.extended},
                    {"name", m.name},
                    {"length", m.size},
                    {"senders", m.transmitter.empty() ? nlohmann::json::array() : nlohmann::json::array({m.transmitter})},
                    {"signals", std::move(sigs)}});
  }
  return {{"messages", std::move(msgs)}, {"nodes", db.nodes}};
}

int run_list(const DbcArgs& a) {
  std::vector<Diagnostic> diags;
  const auto db = can::dbc::load_dbc(a.file, {a.strict}, &diags);
  for (const auto& d : diags) fmt::print(stderr, "{}\n", d.format());
  if (a.json) {
    fmt::print("{}\n", to_json(db).dump(1, ' ', false, nlohmann::json::error_handler_t::replace));
    return kExitOk;
  }
  for (const auto& m : db.messages) {
    fmt::print("{} 0x{:0{}X} {} bytes, sender {}\n", m.name, m.id, m.extended ? 8 : 3, m.size, m.transmitter);
    for (const auto& s : m.signals) {
      std::string mux = mux_text(s);
      if (s.mux == can::dbc::MuxRole::multiplexed) {
        const auto* p = m.multiplexor_of(s);
        mux += fmt::format(" by {} =", p ? p->name : "?");
        if (s.mux_ranges.empty()) mux += fmt::format(" {}", s.mux_value);
        for (const auto& r : s.mux_ranges) mux += r.lo == r.hi ? fmt::format(" {}", r.lo) : fmt::format(" {}-{}", r.lo, r.hi);
      }
      fmt::print("  {} start {} len {} {} {} x{} {:+} [{}|{}] \"{}\"{}{}\n", s.name, s.start_bit, s.length,
                 s.byte_order == can::dbc::ByteOrder::intel ? "intel" : "motorola", s.is_signed ? "signed" : "unsigned",
                 format_double(s.factor), s.offset, format_double(s.minimum), format_double(s.maximum), s.unit,
                 mux.empty() ? "" : " ", mux);
    }
  }
  return kExitOk;
}

}  // namespace

std::vector<Sub> add_dbc_commands(CLI::App& sub) {
  auto* dbc = sub.add_subcommand("dbc", "DBC files: check the layout, list messages and signals");
  dbc->require_subcommand(1);
  auto chk = std::make_shared<DbcArgs>();
  auto* c = dbc->add_subcommand("check", "Validate every message's layout (overlaps, out of frame, length, multiplexing); exit 1 on errors");
  c->add_option("file", chk->file, "DBC file")->required();
  c->add_flag("--strict", chk->strict, "Refuse the file at the first reader warning (exit 2)");
  auto lst = std::make_shared<DbcArgs>();
  auto* l = dbc->add_subcommand("list", "List messages (id, length, sender) and signals (layout, scaling, range, unit, multiplexing)");
  l->add_option("file", lst->file, "DBC file")->required();
  l->add_flag("--json", lst->json, "Print JSON: {messages: [{id, extended, name, length, senders, signals: [...]}], nodes}");
  l->add_flag("--strict", lst->strict, "Refuse the file at the first reader warning (exit 2)");
  return {{c, [=] { return run_check(*chk); }}, {l, [=] { return run_list(*lst); }}};
}

}  // namespace lash::cli::can_cmd
