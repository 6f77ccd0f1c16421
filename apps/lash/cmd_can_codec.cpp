// lash can encode | decode: parse, call lash::can, print.
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include <fmt/core.h>

#include "cmd_can.hpp"
#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/encode.hpp"
#include "lash/can/log.hpp"

namespace lash::cli::can_cmd {
namespace {

/// Loads a DBC; warnings and layout errors go to stderr unless `quiet`.
can::dbc::Database load(const std::string& path, bool strict, bool quiet) {
  std::vector<can::dbc::Diagnostic> diags;
  auto db = can::dbc::load_dbc(path, {strict}, &diags);
  if (!quiet)
    for (const auto& d : diags) fmt::print(stderr, "{}\n", d.format());
  return db;
}

struct EncodeOptions {
  std::string dbc;
  std::string message;
  std::vector<std::string> assignments;
  bool clamp = false;
  bool strict = false;
};

int run_encode(const EncodeOptions& o) {
  const auto db = load(o.dbc, o.strict, true);
  const auto* m = db.message(o.message);
  if (!m) throw InputError(o.dbc, 0, "--message", "no message named '" + o.message + "'");
  can::EncodeRequest req;
  req.clamp = o.clamp;
  for (const auto& a : o.assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos) throw InputError("", 0, a, "expected SIGNAL=VALUE");
    req.values.emplace_back(a.substr(0, eq), a.substr(eq + 1));
  }
  const auto out = can::encode_message(db, *m, req, o.dbc);
  for (const auto& w : out.warnings) fmt::print(stderr, "lash can encode: warning: {}\n", w);
  fmt::print("{}\n", can::format_frame_text(out.frame));
  return kExitOk;
}

struct DecodeOptions {
  std::string dbc;
  std::string log;
  bool strict = false;
};

int run_decode(const DecodeOptions& o) {
  const auto db = load(o.dbc, o.strict, false);
  ReportingReader reader(o.log, "decode");  // one frame at a time: a line is printed as its frame is read
  std::map<std::pair<std::uint32_t, bool>, std::unique_ptr<can::MessageCodec>> codecs;
  std::map<std::pair<std::uint32_t, bool>, std::string> broken;  // messages whose layout has errors
  std::vector<double> values;
  std::string out;
  for (can::LogEntry e; reader.next(e);) {
    const auto& f = e.frame;
    out = fmt::format("{:.6f}", f.timestamp_s);
    const auto* m = db.message(f.id, f.extended);
    const std::pair key{f.id, f.extended};
    if (!m || f.remote || broken.count(key)) {
      out += " ? " + can::format_frame_text(f);
      std::puts(out.c_str());
      continue;
    }
    auto& c = codecs[key];
    if (!c) {
      try {
        c = std::make_unique<can::MessageCodec>(*m);
      } catch (const std::invalid_argument& err) {
        broken[key] = err.what();  // reported when the DBC was loaded
        codecs.erase(key);
        out += " ? " + can::format_frame_text(f);
        std::puts(out.c_str());
        continue;
      }
    }
    out += " " + m->name;
    values.assign(c->signal_count(), 0.0);
    if (!c->decode(f.payload(), values)) {
      out += fmt::format(" (frame has {} bytes, the DBC says {})", f.len, m->size);
      std::puts(out.c_str());
      continue;
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
      const auto& s = c->codec(i).signal();
      if (std::isnan(values[i]) && s.mux == can::dbc::MuxRole::multiplexed) continue;
      const std::uint64_t raw = *c->codec(i).read_raw(f.payload());
      out += " " + s.name + "=" + can::format_value(c->codec(i), raw);
      if (!s.unit.empty()) out += " " + s.unit;
      if (const std::string* text = s.value_text(raw)) out += " \"" + *text + "\"";
    }
    std::puts(out.c_str());
  }
  reader.finish();
  return kExitOk;
}

}  // namespace

std::vector<Sub> add_codec_commands(CLI::App& sub) {
  auto enc = std::make_shared<EncodeOptions>();
  auto* e = sub.add_subcommand("encode", "Encode signal values of a DBC message; prints ID#HEX");
  e->add_option("--dbc", enc->dbc, "DBC file")->required();
  e->add_option("--message", enc->message, "Message name")->required();
  e->add_flag("--clamp", enc->clamp, "Clamp values outside the DBC's [min|max] (default: encode as given, warn)");
  e->add_flag("--strict", enc->strict, "Refuse a DBC with any reader warning");
  e->add_option("signals", enc->assignments,
                "SIGNAL=VALUE: physical units, an exact raw integer (factor 1, offset 0) or a VAL_ text; "
                "unset signals take GenSigStartValue, else raw 0");
  auto dec = std::make_shared<DecodeOptions>();
  auto* c = sub.add_subcommand("decode", "Decode a log (.asc, .blf, .trc, candump) with a DBC: time message signal=value unit ...");
  c->add_option("--dbc", dec->dbc, "DBC file")->required();
  c->add_flag("--strict", dec->strict, "Refuse a DBC with any reader warning");
  c->add_option("log", dec->log, "Log file: .asc, .blf, .trc or candump")->required();
  return {{e, [=] { return run_encode(*enc); }}, {c, [=] { return run_decode(*dec); }}};
}

}  // namespace lash::cli::can_cmd
