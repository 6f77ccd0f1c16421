// Vector ASC (ASCII logging format) reader and writer, following python-can's
// ASCReader/ASCWriter: classic frames `t ch ID[x] Rx|Tx d|r dlc data`, error frames
// `t ch ErrorFrame`, CAN FD `t CANFD ch Rx|Tx ID [name] brs esi dlc len data …`.
// Timestamps are relative to the trigger block (python-can's default).
#include <charconv>
#include <cmath>

#include <fmt/core.h>

#include "lash/io/error.hpp"
#include "log_formats.hpp"

namespace lash::can::detail {

namespace {

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

bool to_uint(std::string_view s, int base, std::uint32_t& v) {
  if (s.empty()) return false;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v, base);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool to_seconds(std::string_view s, double& t) {
  // digits '.' digits, as python-can's pattern \d+\.\d+
  const auto dot = s.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 >= s.size()) return false;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (i != dot && (s[i] < '0' || s[i] > '9')) return false;
  auto r = std::from_chars(s.data(), s.data() + s.size(), t);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}


/// Parses the frame part of a line; "" on success, else why not.
std::string parse_frame_line(const std::string_view* p, std::size_t n, int base, LogEntry& e) {
  Frame& f = e.frame;
  const auto id_of = [&](std::string_view s) -> std::string {
    if (!s.empty() && (s.back() == 'x' || s.back() == 'X')) {
      f.extended = true;
      s.remove_suffix(1);
    }
    if (!to_uint(s, base, f.id)) return "bad id '" + std::string(s) + "'";
    if (f.extended ? f.id > 0x1FFFFFFFu : f.id > 0x7FFu) return fmt::format("id 0x{:X} does not fit {} bits", f.id, f.extended ? 29 : 11);
    return "";
  };
  const auto bytes = [&](std::size_t from, std::size_t count) -> std::string {
    if (n < from + count) return fmt::format("{} data bytes announced, {} present", count, n - from);
    for (std::size_t i = 0; i < count; ++i) {
      std::uint32_t b = 0;
      if (!to_uint(p[from + i], base, b) || b > 255) return "bad data byte '" + std::string(p[from + i]) + "'";
      f.data[i] = static_cast<std::uint8_t>(b);
    }
    return "";
  };
  if (iequals(p[1], "CANFD")) {  // t CANFD ch dir id [name] brs esi dlc len data…
    f.fd = true;
    if (n < 5) return "truncated CANFD line";
    e.interface = std::string(p[2]);
    if (n >= 4 && p[4].size() >= 10 && iequals(p[4].substr(0, 10), "errorframe")) {
      f.fd = false;
      f.error = true;
      return "";
    }
    if (auto err = id_of(p[4]); !err.empty()) return err;
    std::size_t k = 5;
    if (n > k && !(p[k].size() == 1 && p[k][0] >= '0' && p[k][0] <= '9')) ++k;  // symbolic name
    if (n < k + 4) return "truncated CANFD line";
    f.brs = p[k] == "1";
    f.esi = p[k + 1] == "1";
    std::uint32_t dlc = 0, len = 0;
    if (!to_uint(p[k + 2], base, dlc) || dlc > 15) return "bad DLC '" + std::string(p[k + 2]) + "'";
    if (!to_uint(p[k + 3], 10, len) || len > 64) return "bad data length '" + std::string(p[k + 3]) + "'";
    if (len == 0 && dlc != 0) {
      // python-can reads this as a remote frame; CAN FD has no remote frames, so it is a
      // classic remote frame logged on an FD channel.
      f.remote = true;
      f.fd = false;
      f.brs = f.esi = false;
      if (dlc > 8) return "remote frame DLC > 8";
      f.len = static_cast<std::uint8_t>(dlc);
      return "";
    }
    if (fd_len(fd_dlc(len)) != len) return fmt::format("{} is no CAN FD data length", len);
    f.len = static_cast<std::uint8_t>(len);
    return bytes(k + 4, len);
  }
  // t ch ErrorFrame | t ch id dir d|r dlc data…
  e.interface = std::string(p[1]);
  if (p[2].size() >= 10 && iequals(p[2].substr(0, 10), "errorframe")) {
    f.error = true;
    return "";
  }
  if (n < 5) return "truncated frame line";
  if (auto err = id_of(p[2]); !err.empty()) return err;
  std::uint32_t dlc = 0;
  if (p[4] == "r" || p[4] == "R") {
    f.remote = true;
    // an optional DLC; "Length = …" and other trailing fields are not one (as python-can)
    if (n > 5 && !to_uint(p[5], base, dlc)) dlc = 0;
    if (dlc > 8) dlc = 8;  // DLC 9–15 of a classic frame means 8 bytes
    f.len = static_cast<std::uint8_t>(dlc);
    return "";
  }
  if (p[4] != "d" && p[4] != "D") return "expected 'd' or 'r', found '" + std::string(p[4]) + "'";
  if (n < 6 || !to_uint(p[5], base, dlc)) return "bad DLC";
  if (dlc > 15) return fmt::format("classic frame DLC {} (0x{:X}) is more than 4 bits", dlc, dlc);
  const std::uint32_t len = std::min<std::uint32_t>(8, dlc);  // DLC 9–15 of a classic frame means 8 bytes
  f.len = static_cast<std::uint8_t>(len);
  return bytes(6, len);
}

}  // namespace

bool AscLines::line(std::string_view line, long lineno, const std::string& file, LogReadReport* report, LogEntry& out) {
  constexpr std::size_t kMax = 96;
  std::string_view p[kMax];
  const std::size_t n = split_blank(line, p, kMax);
  if (n == 0) return false;
  if (iequals(p[0], "base") && n >= 2) {
    if (iequals(p[1], "dec")) base_ = 10;
    else if (iequals(p[1], "hex")) base_ = 16;
    else drop(report, file, lineno, "base", "expected hex or dec");
    return false;
  }
  double t = 0;
  if (n < 3 || !to_seconds(p[0], t)) return false;  // header, comment, trigger block, event text
  // python-can's frame pattern: t ch (id dir | ErrorFrame) | t CANFD …
  const bool digit_channel = !p[1].empty() && p[1].find_first_not_of("0123456789") == std::string_view::npos;
  const bool is_frame = iequals(p[1], "CANFD") ||
                        (digit_channel && ((p[2].size() >= 10 && iequals(p[2].substr(0, 10), "errorframe")) ||
                                           (n >= 4 && (p[3] == "Rx" || p[3] == "Tx" || iequals(p[3], "rx") || iequals(p[3], "tx")))));
  if (!is_frame) return false;  // statistics, events, other buses
  LogEntry e;
  e.frame.timestamp_s = t;
  const std::string why = parse_frame_line(p, n, base_, e);
  if (!why.empty()) {
    drop(report, file, lineno, "frame", why);
    return false;
  }
  out = std::move(e);
  return true;
}

std::vector<LogEntry> parse_asc(std::string_view text, const std::string& file, LogReadReport* report) {
  LogReader r(text, LogFormat::asc, file, report);
  std::vector<LogEntry> out;
  for (LogEntry e; r.next(e);) out.push_back(e);
  return out;
}

void asc_header(std::ostream& os) {
  os << "date Thu Jan 01 00:00:00.000 am 1970\nbase hex  timestamps absolute\ninternal events logged\n";
  os << "// version 9.0.0\nBegin Triggerblock Thu Jan 01 00:00:00.000 am 1970\n";
  os << fmt::format("{: 9.6f} Start of measurement\n", 0.0);
}

void asc_entry(std::ostream& os, const LogEntry& e, double t0) {
  // Times from the earliest frame (logs may go backwards), so that none is negative.
  const Frame& f = e.frame;
  const double t = f.timestamp_s - t0;
  std::uint32_t ch = 1;
  if (!to_uint(e.interface, 10, ch) || ch == 0) ch = 1;
  if (f.error) {
    os << fmt::format("{: 9.6f} {}  ErrorFrame\n", t, ch);
    return;
  }
  std::string id = fmt::format("{:X}{}", f.id, f.extended ? "x" : "");
  std::string data;
  for (std::size_t i = 0; i < f.len && !f.remote; ++i) data += fmt::format("{}{:02X}", i ? " " : "", f.data[i]);
  if (f.fd) {
    const unsigned flags = (1u << 12) | (f.brs ? 1u << 13 : 0u) | (f.esi ? 1u << 14 : 0u);
    os << fmt::format("{: 9.6f} CANFD {:>3} {:<4} {:>8}  {:>32} {} {} {:x} {:>2} {} {:>8} {:>4} {:>8X} {:>8} {:>8} {:>8} {:>8} {:>8}\n",
                      t, ch, "Rx", id, "", f.brs ? 1 : 0, f.esi ? 1 : 0, fd_dlc(f.len), f.len, data, 0, 0, flags, 0, 0, 0, 0, 0);
  } else if (f.remote) {
    os << fmt::format("{: 9.6f} {}  {:<15} {:<4} r {:x} \n", t, ch, id, "Rx", f.len);
  } else {
    os << fmt::format("{: 9.6f} {}  {:<15} {:<4} d {:x} {}\n", t, ch, id, "Rx", f.len, data);
  }
}

void asc_trailer(std::ostream& os) { os << "End TriggerBlock\n"; }

void write_asc(std::ostream& os, const std::vector<LogEntry>& entries) {
  check_writable_times(entries, LogFormat::asc, "");
  LogTimes times;
  for (const auto& e : entries) times.add(e.frame.timestamp_s);
  LogWriter w(os, LogFormat::asc, times);
  for (const auto& e : entries) w.write(e);
  w.finish();
}

}  // namespace lash::can::detail
