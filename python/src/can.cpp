// lash.can: Database (DBC) decode/encode and read_log. Conversion only; the work is
// lash::can::load_dbc, MessageCodec and read_log, the calls `lash can` makes.
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>

#include "convert.hpp"
#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/encode.hpp"
#include "lash/can/log.hpp"
#include "lash/io/error.hpp"

namespace lash::py {

namespace {

using can::dbc::MuxRole;

/// Bits of the `flags` field of read_log()'s rows.
enum : std::uint8_t { kExtended = 1, kRemote = 2, kFd = 4, kBrs = 8, kEsi = 16, kError = 32 };

std::uint8_t flags_of(const can::Frame& f) {
  return static_cast<std::uint8_t>((f.extended ? kExtended : 0) | (f.remote ? kRemote : 0) | (f.fd ? kFd : 0) |
                                   (f.brs ? kBrs : 0) | (f.esi ? kEsi : 0) | (f.error ? kError : 0));
}

/// One row of read_log() (numpy structured dtype with the same offsets).
struct LogRow {
  double timestamp;
  std::uint32_t id;
  std::uint8_t flags;
  std::uint8_t dlc;
  std::uint8_t data[can::Frame::kMaxFdLen];
};

pyb::dtype log_dtype() {
  pyb::dict d;
  d["names"] = pyb::make_tuple("timestamp", "id", "flags", "dlc", "data");
  d["formats"] = pyb::make_tuple("<f8", "<u4", "u1", "u1", pyb::make_tuple("u1", can::Frame::kMaxFdLen));
  d["offsets"] = pyb::make_tuple(offsetof(LogRow, timestamp), offsetof(LogRow, id), offsetof(LogRow, flags),
                                 offsetof(LogRow, dlc), offsetof(LogRow, data));
  d["itemsize"] = sizeof(LogRow);
  return pyb::dtype::from_args(d);
}

pyb::array read_log(const std::string& path) {
  std::vector<can::LogEntry> entries;
  {
    pyb::gil_scoped_release nogil;  // reading and parsing the file touches no Python object
    entries = can::read_log(path);
  }
  pyb::array out(log_dtype(), std::vector<pyb::ssize_t>{static_cast<pyb::ssize_t>(entries.size())}, nullptr);
  auto* rows = static_cast<LogRow*>(out.mutable_data());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& f = entries[i].frame;
    LogRow r{};
    r.timestamp = f.timestamp_s;
    r.id = f.id;
    r.flags = flags_of(f);
    r.dlc = f.len;
    std::memcpy(r.data, f.data.data(), f.data.size());
    std::memcpy(&rows[i], &r, sizeof r);
  }
  return out;
}

std::vector<std::uint8_t> bytes_of(const pyb::handle& data) {
  if (data.is_none()) throw InputError("", 0, "data", "is None (expected bytes)");
  const pyb::bytes b = pyb::bytes(pyb::module_::import("builtins").attr("bytes")(data));
  const std::string s = b;
  return {s.begin(), s.end()};
}

class Database {
 public:
  explicit Database(const std::string& path) : path_(path), db_(can::dbc::load_dbc(path)) {}

  /// decode(message, data=None): message = id (int), name (str) or a python-can can.Message.
  pyb::dict decode(const pyb::handle& message, const pyb::handle& data, std::optional<bool> extended) const {
    const can::dbc::Message* m = nullptr;
    std::vector<std::uint8_t> payload;
    if (pyb::hasattr(message, "arbitration_id")) {  // python-can's can.Message
      const auto id = message.attr("arbitration_id").cast<std::uint32_t>();
      const bool ext = message.attr("is_extended_id").cast<bool>();
      m = db_.message(id, ext);
      if (!m) throw InputError(path_, 0, "id", "no message with id " + hex(id) + (ext ? " (extended)" : ""));
      payload = bytes_of(data.is_none() ? message.attr("data") : data);
    } else {
      m = find(message, extended);
      payload = bytes_of(data);
    }
    const MessageCodec& c = codec(*m);
    std::vector<double> values(c.signal_count());
    if (!c.decode(payload, values))
      throw InputError(path_, 0, m->name,
                       "frame has " + std::to_string(payload.size()) + " bytes, the DBC says " + std::to_string(m->size));
    pyb::dict out;
    for (std::size_t i = 0; i < values.size(); ++i) {
      const auto& s = c.codec(i).signal();
      if (std::isnan(values[i]) && s.mux == MuxRole::multiplexed) continue;  // not selected
      out[text(s.name)] = values[i];
    }
    return out;
  }

  /// encode(name, values) -> bytes, as `lash can encode` (lash::can::encode_message).
  pyb::bytes encode(const pyb::handle& message, const pyb::dict& values, bool clamp) const {
    const can::dbc::Message* m = find(message, std::nullopt);
    can::EncodeRequest req;
    req.clamp = clamp;
    for (const auto& [k, val] : values) {
      // numbers as the shortest round-trip text (Python's repr), VAL_ texts as they are
      const std::string v = pyb::isinstance<pyb::str>(val) ? val.cast<std::string>()
                                                           : pyb::repr(val).cast<std::string>();
      req.values.emplace_back(pyb::str(k).cast<std::string>(), v);
    }
    const can::EncodeOutcome out = can::encode_message(db_, *m, req, path_);
    if (!out.warnings.empty()) {
      auto warn = pyb::module_::import("warnings").attr("warn");
      for (const auto& w : out.warnings) warn(text(w));
    }
    return pyb::bytes(reinterpret_cast<const char*>(out.frame.data.data()), out.frame.len);
  }

  pyb::dict messages() const {
    pyb::dict out;
    for (const auto& m : db_.messages) {
      pyb::dict sigs;
      for (const auto& s : m.signals) {
        pyb::dict d;
        d["start_bit"] = s.start_bit;
        d["length"] = s.length;
        d["byte_order"] = s.byte_order == can::dbc::ByteOrder::intel ? "intel" : "motorola";
        d["is_signed"] = s.is_signed;
        d["factor"] = s.factor;
        d["offset"] = s.offset;
        d["minimum"] = s.minimum;
        d["maximum"] = s.maximum;
        d["unit"] = text(s.unit);
        d["multiplexor"] = s.mux == MuxRole::multiplexor;
        d["mux_value"] = s.mux == MuxRole::multiplexed ? pyb::object(pyb::int_(s.mux_value)) : pyb::none();
        sigs[text(s.name)] = d;
      }
      pyb::dict d;
      d["id"] = m.id;
      d["extended"] = m.extended;
      d["size"] = m.size;
      d["signals"] = sigs;
      out[text(m.name)] = d;
    }
    return out;
  }

  pyb::str path() const { return text(path_); }

 private:
  using MessageCodec = can::MessageCodec;

  static std::string hex(std::uint32_t id) {
    char b[16];
    std::snprintf(b, sizeof b, "0x%X", id);
    return b;
  }

  const can::dbc::Message* find(const pyb::handle& message, std::optional<bool> extended) const {
    if (pyb::isinstance<pyb::str>(message)) {
      const std::string name = message.cast<std::string>();
      const auto* m = db_.message(name);
      if (!m) throw InputError(path_, 0, name, "no message of that name");
      return m;
    }
    if (!PyIndex_Check(message.ptr())) throw InputError("", 0, "message", "expected an id (int), a name or a can.Message");
    const auto id = pyb::int_(pyb::reinterpret_borrow<pyb::object>(message)).cast<std::uint32_t>();
    const can::dbc::Message* m = nullptr;
    if (extended) m = db_.message(id, *extended);
    else {
      m = db_.message(id, id > 0x7FFu);
      if (!m) m = db_.message(id, !(id > 0x7FFu));
    }
    if (!m) throw InputError(path_, 0, "id", "no message with id " + hex(id));
    return m;
  }

  const MessageCodec& codec(const can::dbc::Message& m) const {
    auto& c = codecs_[&m];
    if (!c) {
      try {
        c = std::make_unique<MessageCodec>(m);
      } catch (const std::invalid_argument& e) {
        throw InputError(path_, 0, m.name, e.what());
      }
    }
    return *c;
  }

  std::string path_;
  can::dbc::Database db_;
  mutable std::map<const can::dbc::Message*, std::unique_ptr<MessageCodec>> codecs_;
};

}  // namespace

void bind_can(pyb::module_& root) {
  auto m = root.def_submodule("_can", "CAN bindings (use lash.can)");
  m.attr("FLAG_EXTENDED") = static_cast<int>(kExtended);
  m.attr("FLAG_REMOTE") = static_cast<int>(kRemote);
  m.attr("FLAG_FD") = static_cast<int>(kFd);
  m.attr("FLAG_BRS") = static_cast<int>(kBrs);
  m.attr("FLAG_ESI") = static_cast<int>(kEsi);
  m.attr("FLAG_ERROR") = static_cast<int>(kError);
  pyb::class_<Database>(m, "Database", "Database(path): a DBC file (Vector CAN database) loaded by lash's reader.")
      .def(pyb::init<const std::string&>(), pyb::arg("path"))
      .def("decode", &Database::decode, pyb::arg("message"), pyb::arg("data") = pyb::none(), pyb::kw_only(),
           pyb::arg("extended") = pyb::none(),
           "decode(message, data=None, *, extended=None) -> dict signal -> physical value\n\n"
           "message: the frame's id (int; ids above 0x7FF are looked up as extended first), the message name, or a\n"
           "python-can can.Message (then data defaults to its data). Multiplexed signals not selected are left out.\n"
           "physical = raw * factor + offset, in each signal's unit (messages[name]['signals'][s]['unit']).")
      .def("encode", &Database::encode, pyb::arg("message"), pyb::arg("values"), pyb::kw_only(),
           pyb::arg("clamp") = false,
           "encode(name, values, *, clamp=False) -> bytes, as `lash can encode`: values = {signal: physical value\n"
           "or VAL_ text}; a signal not given takes its GenSigStartValue (else raw 0). A value outside [min|max]\n"
           "that fits the field is encoded with a warning (clamp=True clamps it); one that does not fit raises.")
      .def_property_readonly("messages", &Database::messages,
                             "dict name -> {id, extended, size [byte], signals: {name: {start_bit, length, byte_order,\n"
                             "is_signed, factor, offset, minimum, maximum, unit, multiplexor, mux_value}}}")
      .def_property_readonly("path", &Database::path);
  m.def("read_log", &read_log, pyb::arg("path"),
        "read_log(path) -> numpy structured array (timestamp [s], id, flags, dlc [byte], data[64]);\n"
        "the format by extension: .asc (Vector ASCII), .blf (Vector binary), .trc (PEAK), else candump.");
}

}  // namespace lash::py
