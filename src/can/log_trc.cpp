// PEAK TRC trace files, versions 1.0, 1.1, 1.2, 1.3, 2.0 and 2.1 (PEAK's "PCAN-Trace
// file format" description; python-can's TRCReader/TRCWriter as the reference).
// Timestamps are the offsets of the file [ms → s]; ;$STARTTIME is not added (as python-can).
// Status/warning/error-counter lines are not frames and are skipped; a frame line that
// does not parse is a reported drop.
#include <charconv>
#include <cmath>

#include <fmt/core.h>

#include "lash/io/error.hpp"
#include "log_formats.hpp"

namespace lash::can::detail {
namespace {

bool hex(std::string_view s, std::uint32_t& v) {
  if (s.empty() || s.size() > 8) return false;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v, 16);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}
bool dec(std::string_view s, std::uint32_t& v) {
  if (s.empty()) return false;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}
bool millis(std::string_view s, double& t) {
  if (s.empty()) return false;
  auto r = std::from_chars(s.data(), s.data() + s.size(), t);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(t) && t >= 0;
}


struct Layout {
  int version = 100;             ///< 100 = 1.0, 101 = 1.1, … 201 = 2.1
  std::string_view columns;      ///< 2.x: ;$COLUMNS letters
};

/// Fills the id (python-can: more than 4 hex digits = extended) and checks it.
std::string set_id(Frame& f, std::string_view s) {
  if (!hex(s, f.id)) return "bad id '" + std::string(s) + "'";
  f.extended = s.size() > 4;
  if (f.extended ? f.id > 0x1FFFFFFFu : f.id > 0x7FFu) return fmt::format("id 0x{:X} does not fit {} bits", f.id, f.extended ? 29 : 11);
  return "";
}

std::string set_data(Frame& f, const std::string_view* p, std::size_t from, std::size_t n, std::uint32_t len) {
  if (len > (f.fd ? 64u : 8u)) return fmt::format("length {} exceeds {} bytes", len, f.fd ? 64 : 8);
  f.len = static_cast<std::uint8_t>(len);
  if (f.remote) return "";
  if (n < from + len) return fmt::format("{} data bytes announced, {} present", len, n - from);
  for (std::uint32_t i = 0; i < len; ++i) {
    std::uint32_t b = 0;
    if (p[from + i].size() != 2 || !hex(p[from + i], b)) return "bad data byte '" + std::string(p[from + i]) + "'";
    f.data[i] = static_cast<std::uint8_t>(b);
  }
  return "";
}

/// One line; "" with `skip` set for non-frame lines, else the reason it does not parse.
std::string parse_line(const Layout& lay, const std::string_view* p, std::size_t n, LogEntry& e, bool& skip) {
  Frame& f = e.frame;
  skip = false;
  e.interface = "1";  // versions without a bus column: channel 1 (as python-can)
  double ms = 0;
  std::uint32_t len = 0;
  if (lay.version < 200) {  // "N)" first
    if (n < 4 || p[0].back() != ')') return "expected 'N) offset ...'";
    if (!millis(p[1], ms)) return "bad time offset '" + std::string(p[1]) + "'";
    f.timestamp_s = ms / 1000.0;
    std::size_t k = 2;
    if (lay.version >= 102) {  // bus column
      e.interface = std::string(p[k]);
      ++k;
    }
    if (lay.version >= 101) {  // type column
      if (p[k] != "Rx" && p[k] != "Tx" && p[k] != "RR") {
        skip = true;  // Warng, Error, status
        return "";
      }
      f.remote = p[k] == "RR";
      ++k;
    }
    if (n <= k + 1) return "truncated line";
    if (p[k] == "FFFFFFFF") {  // 1.0 status line
      skip = true;
      return "";
    }
    if (auto err = set_id(f, p[k]); !err.empty()) return err;
    ++k;
    if (lay.version >= 103 && p[k] == "-") ++k;  // reserved
    if (n <= k) return "truncated line";
    if (p[k] == "RTR") {
      f.remote = true;
      ++k;
    }
    if (!dec(p[k], len)) return "bad DLC '" + std::string(p[k]) + "'";
    if (n > k + 1 && p[k + 1] == "RTR") {  // remote frame: "N) time [type] id dlc RTR"
      f.remote = true;
      if (len > 8) return fmt::format("remote frame DLC {} > 8", len);
      f.len = static_cast<std::uint8_t>(len);
      return "";
    }
    return set_data(f, p, k + 1, n, len);
  }
  // 2.x: by columns
  std::size_t k = 0;
  std::string_view type;
  for (char c : lay.columns) {
    if (c == 'D') break;
    if (k >= n) return "truncated line";
    const std::string_view v = p[k];
    switch (c) {
      case 'N': break;
      case 'O':
        if (!millis(v, ms)) return "bad time offset '" + std::string(v) + "'";
        f.timestamp_s = ms / 1000.0;
        break;
      case 'T':
        type = v;
        if (type != "DT" && type != "FD" && type != "FB" && type != "FE" && type != "BI" && type != "RR" && type != "ER") {
          skip = true;  // ST, EC, EV: status, error counters, events
          return "";
        }
        f.fd = type == "FD" || type == "FB" || type == "FE" || type == "BI";
        f.brs = type == "FB" || type == "BI";
        f.esi = type == "FE" || type == "BI";
        f.remote = type == "RR";
        f.error = type == "ER";
        break;
      case 'B': e.interface = std::string(v); break;
      case 'I':
        if (f.error) {  // error frames: the id column holds '-' or an error code
          f.id = 0;
          break;
        }
        if (auto err = set_id(f, v); !err.empty()) return err;
        break;
      case 'L':
        if (!dec(v, len) || len > 15) return "bad DLC '" + std::string(v) + "'";
        if (f.fd) len = fd_len(len);
        break;
      case 'l':
        if (!dec(v, len)) return "bad data length '" + std::string(v) + "'";
        break;
      default: break;  // d (direction), R (reserved)
    }
    ++k;
  }
  if (f.error) {
    f.len = 0;
    return "";
  }
  if (f.fd && fd_len(fd_dlc(len)) != len) return fmt::format("{} is no CAN FD data length", len);
  return set_data(f, p, k, n, len);
}

}  // namespace

bool TrcLines::line(std::string_view line, long lineno, const std::string& file, LogReadReport* report, LogEntry& out) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  if (line.rfind(";$FILEVERSION=", 0) == 0) {
    const std::string_view v = line.substr(14);
    if (v == "1.1") version_ = 101;
    else if (v == "1.2") version_ = 102;
    else if (v == "1.3") version_ = 103;
    else if (v == "2.0") version_ = 200;
    else if (v == "2.1") version_ = 201;
    else if (v == "1.0") version_ = 100;
    else drop(report, file, lineno, "$FILEVERSION", "unknown version '" + std::string(v) + "'");
    return false;
  }
  if (line.rfind(";$COLUMNS=", 0) == 0) {
    columns_.clear();
    for (char c : line.substr(10))
      if (c != ',' && c != ' ') columns_.push_back(c);
    return false;
  }
  constexpr std::size_t kMax = 96;
  std::string_view p[kMax];
  const std::size_t n = split_blank(line, p, kMax);
  if (n == 0 || p[0].front() == ';') return false;
  LogEntry e;
  bool skip = false;
  const std::string why = parse_line(Layout{version_, columns_}, p, n, e, skip);
  if (skip) return false;
  if (!why.empty() || !e.frame.valid()) {
    drop(report, file, lineno, "frame", why.empty() ? "invalid frame" : why);
    return false;
  }
  out = std::move(e);
  return true;
}

std::vector<LogEntry> parse_trc(std::string_view text, const std::string& file, LogReadReport* report) {
  LogReader r(text, LogFormat::trc, file, report);
  std::vector<LogEntry> out;
  for (LogEntry e; r.next(e);) out.push_back(e);
  return out;
}

void trc_header(std::ostream& os) {
  os << ";$FILEVERSION=2.1\r\n;$STARTTIME=25569.0\r\n;$COLUMNS=N,O,T,B,I,d,R,L,D\r\n;\r\n;   Generated by lash\r\n";
  os << ";   Message   Time    Type    ID     Rx/Tx\r\n;   Number    Offset  |  Bus  [hex]  |  Reserved\r\n";
  os << ";   |         [ms]    |  |    |      |  |  Data Length Code\r\n";
  os << ";---+-- ------+------ +- +- --+----- +- +- +--- +- -- -- -- -- -- -- --\r\n";
}

void trc_entry(std::ostream& os, const LogEntry& e, double t0, std::size_t number) {
  // Offsets from the earliest frame (logs may go backwards), so that none is negative.
  const Frame& f = e.frame;
  std::uint32_t bus = 1;
  if (!dec(e.interface, bus) || bus == 0 || bus > 16) bus = 1;
  const char* type = f.error ? "ER" : f.remote ? "RR" : !f.fd ? "DT" : f.brs && f.esi ? "BI" : f.brs ? "FB" : f.esi ? "FE" : "FD";
  const std::string id = f.error ? std::string("-") : f.extended ? fmt::format("{:08X}", f.id) : fmt::format("{:04X}", f.id);
  std::string data;
  for (std::size_t i = 0; i < f.len && !f.remote && !f.error; ++i) data += fmt::format("{}{:02X}", i ? " " : "", f.data[i]);
  const std::uint32_t dlc = f.fd ? fd_dlc(f.len) : f.len;
  os << fmt::format("{:>7} {:13.3f} {} {:>2} {:>8} {:>2} -  {:<4} {}\r\n", number, (f.timestamp_s - t0) * 1000.0, type, bus,
                    id, "Rx", f.error ? 0 : dlc, data);
}

void write_trc(std::ostream& os, const std::vector<LogEntry>& entries) {
  check_writable_times(entries, LogFormat::trc, "");
  LogTimes times;
  for (const auto& e : entries) times.add(e.frame.timestamp_s);
  LogWriter w(os, LogFormat::trc, times);
  for (const auto& e : entries) w.write(e);
  w.finish();
}

}  // namespace lash::can::detail
