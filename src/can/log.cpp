#include "lash/can/log.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/core.h>

#include "lash/io/atomic_file.hpp"
#include "lash/io/error.hpp"
#include "lash/can/log_reader.hpp"
#include "log_formats.hpp"

namespace lash::can {

namespace detail {

void drop(LogReadReport* report, const std::string& file, long line, const std::string& field, const std::string& why) {
  if (!report) throw InputError(file, static_cast<int>(line), field, why);
  ++report->dropped;
  report->problems.push_back(fmt::format("{}:{}: {}: {}", file, line, field, why));
}

std::size_t split_blank(std::string_view line, std::string_view* out, std::size_t max) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::size_t n = 0, i = 0;
  while (i < line.size() && n < max) {
    while (i < line.size() && blank(line[i])) ++i;
    if (i >= line.size()) break;
    std::size_t j = i;
    while (j < line.size() && !blank(line[j])) ++j;
    out[n++] = line.substr(i, j - i);
    i = j;
  }
  return n;
}

std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

}  // namespace detail

namespace {

int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_hex_u32(std::string_view s, std::uint32_t& v) noexcept {
  if (s.empty() || s.size() > 8) return false;
  v = 0;
  for (char c : s) {
    const int h = hex_value(c);
    if (h < 0) return false;
    v = (v << 4) | static_cast<std::uint32_t>(h);
  }
  return true;
}

constexpr char kHex[] = "0123456789ABCDEF";

}  // namespace

std::optional<Frame> parse_frame_text(std::string_view text, std::string& error) noexcept {
  try {
    const auto hash = text.find('#');
    if (hash == std::string_view::npos) {
      error = "expected ID#DATA";
      return std::nullopt;
    }
    const std::string_view id_text = text.substr(0, hash);
    std::string_view rest = text.substr(hash + 1);
    Frame f;
    if (id_text.size() != 3 && id_text.size() != 8) {
      error = "the id must have 3 (11-bit) or 8 (29-bit) hex digits, got '" + std::string(id_text) + "'";
      return std::nullopt;
    }
    if (!parse_hex_u32(id_text, f.id)) {
      error = "bad hex id '" + std::string(id_text) + "'";
      return std::nullopt;
    }
    f.extended = id_text.size() == 8;
    if (f.extended && (f.id & 0x20000000u) && !(f.id & 0xC0000000u)) {  // SocketCAN CAN_ERR_FLAG
      f.error = true;
      f.extended = false;
      f.id &= 0x1FFFFFFFu;
    } else if (f.extended && f.id > 0x1FFFFFFFu) {
      error = "29-bit id out of range: '" + std::string(id_text) + "'";
      return std::nullopt;
    }
    if (!f.extended && !f.error && f.id > 0x7FFu) {
      error = "11-bit id out of range: '" + std::string(id_text) + "'";
      return std::nullopt;
    }
    if (!rest.empty() && rest.front() == '#') {  // CAN FD: ##<flags><data>
      const int flags = rest.size() >= 2 ? hex_value(rest[1]) : -1;
      if (flags < 0 || flags > 3) {
        error = "CAN FD frame needs a flags digit 0-3 (1 = BRS, 2 = ESI) after '##'";
        return std::nullopt;
      }
      f.fd = true;
      f.brs = (flags & 1) != 0;
      f.esi = (flags & 2) != 0;
      rest.remove_prefix(2);
    }
    if (!f.fd && !rest.empty() && (rest.front() == 'R' || rest.front() == 'r')) {
      f.remote = true;
      rest.remove_prefix(1);
      if (rest.empty()) {
        f.len = 0;
      } else if (rest.size() == 1 && rest[0] >= '0' && rest[0] <= '8') {
        f.len = static_cast<std::uint8_t>(rest[0] - '0');
      } else {
        error = "remote frame: expected R or R<dlc 0-8>, got '" + std::string(rest) + "'";
        return std::nullopt;
      }
      return f;
    }
    std::size_t n = 0;
    for (std::size_t i = 0; i < rest.size();) {
      if (rest[i] == '.') {  // cansend allows '.' separators
        ++i;
        continue;
      }
      if (i + 1 >= rest.size() || hex_value(rest[i]) < 0 || hex_value(rest[i + 1]) < 0) {
        error = "bad hex data '" + std::string(rest) + "'";
        return std::nullopt;
      }
      if (n >= (f.fd ? Frame::kMaxFdLen : Frame::kMaxClassicLen)) {
        error = fmt::format("too many data bytes (at most {})", f.fd ? Frame::kMaxFdLen : Frame::kMaxClassicLen);
        return std::nullopt;
      }
      f.data[n++] = static_cast<std::uint8_t>(hex_value(rest[i]) * 16 + hex_value(rest[i + 1]));
      i += 2;
    }
    if (f.fd && n > 8 && n != 12 && n != 16 && n != 20 && n != 24 && n != 32 && n != 48 && n != 64) {
      error = fmt::format("{} data bytes is no CAN FD length", n);
      return std::nullopt;
    }
    f.len = static_cast<std::uint8_t>(n);
    return f;
  } catch (...) {
    error = "out of memory";
    return std::nullopt;
  }
}

std::string format_frame_text(const Frame& f) {
  std::string out;
  const int digits = f.extended || f.error ? 8 : 3;
  const std::uint32_t id = f.error ? (f.id | 0x20000000u) : f.id;
  for (int i = digits - 1; i >= 0; --i) out.push_back(kHex[(id >> (4 * i)) & 0xF]);
  out.push_back('#');
  if (f.remote) {
    out.push_back('R');
    if (f.len > 0 && f.len <= 8) out.push_back(static_cast<char>('0' + f.len));
    return out;
  }
  if (f.fd) {
    out.push_back('#');
    out.push_back(kHex[(f.brs ? 1 : 0) | (f.esi ? 2 : 0)]);
  }
  for (std::size_t i = 0; i < f.len && i < f.data.size(); ++i) {
    out.push_back(kHex[f.data[i] >> 4]);
    out.push_back(kHex[f.data[i] & 0xF]);
  }
  return out;
}

namespace {

/// "(seconds.fraction)" → seconds; false on bad text.
bool parse_seconds(std::string_view num, double& out, std::string& error) {
  const auto dot = num.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 >= num.size()) {
    error = "timestamp must look like (seconds.microseconds)";
    return false;
  }
  std::uint64_t sec = 0;
  for (std::size_t k = 0; k < dot; ++k) {
    if (num[k] < '0' || num[k] > '9' || sec > 100000000000ull) {
      error = "bad seconds in timestamp";
      return false;
    }
    sec = sec * 10 + static_cast<std::uint64_t>(num[k] - '0');
  }
  const std::string_view frac = num.substr(dot + 1);
  if (frac.size() > 9) {
    error = "too many fraction digits in timestamp";
    return false;
  }
  std::uint64_t ns = 0;
  for (std::size_t k = 0; k < 9; ++k) {
    std::uint64_t d = 0;
    if (k < frac.size()) {
      if (frac[k] < '0' || frac[k] > '9') {
        error = "bad fraction in timestamp";
        return false;
      }
      d = static_cast<std::uint64_t>(frac[k] - '0');
    }
    ns = ns * 10 + d;
  }
  out = static_cast<double>(sec) + static_cast<double>(ns) * 1e-9;
  return true;
}

/// "2020-12-19" "12:04:45.485261" (UTC) → seconds since the epoch.
bool parse_date_time(std::string_view date, std::string_view time, double& out, std::string& error) {
  int y = 0, mo = 0, d = 0, h = 0, mi = 0;
  if (std::sscanf(std::string(date).c_str(), "%4d-%2d-%2d", &y, &mo, &d) != 3 || mo < 1 || mo > 12 || d < 1 || d > 31) {
    error = "bad date in timestamp";
    return false;
  }
  const auto c1 = time.find(':');
  const auto c2 = time.find(':', c1 == std::string_view::npos ? 0 : c1 + 1);
  if (c1 == std::string_view::npos || c2 == std::string_view::npos) {
    error = "bad time in timestamp";
    return false;
  }
  h = std::atoi(std::string(time.substr(0, c1)).c_str());
  mi = std::atoi(std::string(time.substr(c1 + 1, c2 - c1 - 1)).c_str());
  double sec = 0;
  if (!parse_seconds(time.substr(c2 + 1), sec, error)) return false;
  out = static_cast<double>(detail::days_from_civil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d)) * 86400 + h * 3600 + mi * 60) + sec;
  return true;
}

/// candump's default output: [(time)] iface ID [n] B0 B1 … [ERRORFRAME | remote request].
std::optional<LogEntry> parse_plain_line(const std::string_view* p, std::size_t n, std::string& error) {
  std::size_t k = 0;
  double t = 0;
  if (n > 0 && p[0].front() == '(') {
    if (p[0].back() == ')') {
      if (!parse_seconds(p[0].substr(1, p[0].size() - 2), t, error)) return std::nullopt;
      k = 1;
    } else if (n > 1 && p[1].back() == ')') {
      if (!parse_date_time(p[0].substr(1), p[1].substr(0, p[1].size() - 1), t, error)) return std::nullopt;
      k = 2;
    } else {
      error = "bad timestamp";
      return std::nullopt;
    }
  }
  if (n < k + 3) {
    error = "expected '[(time)] iface ID [n] data' or '(time) iface ID#DATA'";
    return std::nullopt;
  }
  LogEntry e;
  e.interface = std::string(p[k]);
  const std::string_view idt = p[k + 1];
  std::uint32_t id = 0;
  if ((idt.size() != 3 && idt.size() != 8) || !parse_hex_u32(idt, id)) {
    error = "bad id '" + std::string(idt) + "' (3 or 8 hex digits)";
    return std::nullopt;
  }
  Frame& f = e.frame;
  f.extended = idt.size() == 8;
  const std::string_view lt = p[k + 2];
  const bool fd = lt.size() >= 4 && lt[0] == '[' && lt[1] == '[';
  const std::string_view ln = fd ? lt.substr(2, lt.size() - 4) : lt.substr(1, lt.size() - 2);
  unsigned len = 0;
  if (lt.size() < 3 || lt.front() != '[' || lt.back() != ']' || ln.empty() || ln.size() > 2 ||
      std::sscanf(std::string(ln).c_str(), "%u", &len) != 1) {
    error = "bad length field '" + std::string(lt) + "'";
    return std::nullopt;
  }
  std::size_t b = k + 3;
  const bool errorframe = n > 0 && p[n - 1] == "ERRORFRAME";
  const bool remote = n >= 2 && p[n - 1] == "request" && p[n - 2] == "remote";
  const std::size_t end = errorframe ? n - 1 : remote ? n - 2 : n;
  if (errorframe) {
    f.error = true;
    f.extended = false;
    id &= 0x1FFFFFFFu;
  } else if (f.extended ? id > 0x1FFFFFFFu : id > 0x7FFu) {
    error = "id out of range: '" + std::string(idt) + "'";
    return std::nullopt;
  }
  f.id = id;
  f.fd = fd;
  f.remote = remote;
  if (len > (fd ? Frame::kMaxFdLen : Frame::kMaxClassicLen)) {
    error = fmt::format("length {} exceeds {} bytes", len, fd ? Frame::kMaxFdLen : Frame::kMaxClassicLen);
    return std::nullopt;
  }
  if (!remote && end - b != len) {
    error = fmt::format("length says {} bytes, the line has {}", len, end - b);
    return std::nullopt;
  }
  for (std::size_t i = 0; b < end; ++b, ++i) {
    std::uint32_t v = 0;
    if (p[b].size() != 2 || !parse_hex_u32(p[b], v)) {
      error = "bad data byte '" + std::string(p[b]) + "'";
      return std::nullopt;
    }
    f.data[i] = static_cast<std::uint8_t>(v);
  }
  f.len = static_cast<std::uint8_t>(len);
  f.timestamp_s = t;
  return e;
}

}  // namespace

std::optional<LogEntry> parse_log_line(std::string_view line, std::string& error) noexcept {
  try {
    while (!line.empty() && (line.back() == '\r' || line.back() == '\n' || line.back() == ' ' || line.back() == '\t'))
      line.remove_suffix(1);
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    // Split on blanks.
    constexpr std::size_t kMax = 72;
    std::string_view parts[kMax];
    std::size_t n = 0;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
      if (n == kMax) {
        error = "too many fields";
        return std::nullopt;
      }
      parts[n++] = line.substr(i, j - i);
      i = j;
    }
    if (n >= 3 && parts[2].find('#') == std::string_view::npos) return parse_plain_line(parts, n, error);
    if (n == 4 && (parts[3] == "R" || parts[3] == "T" || parts[3] == "r" || parts[3] == "t")) n = 3;
    if (n != 3) {
      error = "expected '(seconds.microseconds) iface ID#DATA'";
      return std::nullopt;
    }
    const std::string_view ts = parts[0];
    if (ts.size() < 3 || ts.front() != '(' || ts.back() != ')') {
      error = "timestamp must look like (seconds.microseconds)";
      return std::nullopt;
    }
    double t = 0;
    if (!parse_seconds(ts.substr(1, ts.size() - 2), t, error)) return std::nullopt;
    LogEntry e;
    e.interface = std::string(parts[1]);
    std::string ferr;
    auto f = parse_frame_text(parts[2], ferr);
    if (!f) {
      error = ferr;
      return std::nullopt;
    }
    e.frame = *f;
    e.frame.timestamp_s = t;
    return e;
  } catch (...) {
    error = "out of memory";
    return std::nullopt;
  }
}

std::string format_log_line(const Frame& frame, std::string_view interface) {
  return format_log_line(frame, interface, 6);
}

std::string format_log_line(const Frame& frame, std::string_view interface, unsigned fraction_digits) {
  const bool ns = fraction_digits >= 9;
  const double scale = ns ? 1e9 : 1e6;
  const auto one = static_cast<std::uint64_t>(scale);
  // A time candump cannot hold (writable_times) is written as 0: write_log refuses such frames
  // before it gets here; a live dump's times come from the clock.
  double t = frame.timestamp_s;
  const TimeSpan span = writable_times(LogFormat::candump);
  if (!(t >= span.min_abs_s && t < span.max_abs_s)) t = 0;
  auto sec = static_cast<std::uint64_t>(std::floor(t));
  auto frac = static_cast<std::uint64_t>(std::llround((t - static_cast<double>(sec)) * scale));
  if (frac >= one) {
    sec += 1;
    frac -= one;
  }
  return fmt::format("({}.{:0{}d}) {} {}", sec, frac, ns ? 9 : 6, interface.empty() ? std::string_view("can0") : interface,
                     format_frame_text(frame));
}

namespace {

/// The common candump -L line `(seconds.fraction) iface ID#HEX` of a classic data frame, parsed
/// straight into `out` (its interface string reused): true when the line is of that form, false
/// (nothing decided) otherwise; parse_log_line then reads it, with its messages. For the lines it
/// takes, the result is parse_log_line's.
bool fast_log_line(std::string_view s, LogEntry& out) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (s.size() < 3 || s[0] != '(') return false;
  const auto blank = [](char c) { return c == ' ' || c == '\t'; };  // (find_first_of calls memchr per character)
  std::size_t close = 1;
  while (close < s.size() && s[close] != ')') {
    if (blank(s[close])) return false;
    ++close;
  }
  if (close < 2 || close + 2 >= s.size() || s[close + 1] != ' ') return false;
  const std::string_view ts = s.substr(1, close - 1);
  std::size_t i = close + 2;
  std::size_t j = i;
  while (j < s.size() && !blank(s[j])) ++j;
  if (j == i || j >= s.size() || s[j] != ' ') return false;
  const std::string_view iface = s.substr(i, j - i);
  const std::string_view text = s.substr(j + 1);
  std::size_t hash = std::string_view::npos;
  for (std::size_t k = 0; k < text.size(); ++k) {
    if (blank(text[k])) return false;
    if (text[k] == '#' && hash == std::string_view::npos) hash = k;
  }
  if (hash != 3 && hash != 8) return false;
  const std::string_view hex = text.substr(hash + 1);
  if (hex.size() % 2 != 0 || hex.size() > 16) return false;
  std::uint32_t id = 0;
  if (!parse_hex_u32(text.substr(0, hash), id)) return false;
  const bool extended = hash == 8;
  if (extended ? (id > 0x1FFFFFFFu || (id & 0x20000000u)) : id > 0x7FFu) return false;  // error frames: the full reader
  std::uint8_t data[8];
  for (std::size_t k = 0; k < hex.size(); k += 2) {
    const int hi = hex_value(hex[k]), lo = hex_value(hex[k + 1]);
    if (hi < 0 || lo < 0) return false;
    data[k / 2] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  double t = 0;
  std::string error;
  if (!parse_seconds(ts, t, error)) return false;
  out.frame = Frame{};
  out.frame.id = id;
  out.frame.extended = extended;
  out.frame.len = static_cast<std::uint8_t>(hex.size() / 2);
  std::memcpy(out.frame.data.data(), data, out.frame.len);
  out.frame.timestamp_s = t;
  out.interface.assign(iface);
  return true;
}

}  // namespace

namespace detail {

bool candump_line(std::string_view line, long lineno, const std::string& file, LogReadReport* report, LogEntry& out) {
  if (line.find_first_not_of(" \t\r") == std::string_view::npos) return false;
  if (fast_log_line(line, out)) return true;  // classic frames, valid by construction
  std::string error;
  auto e = parse_log_line(line, error);
  if (e && !e->frame.valid()) {
    error = "invalid frame";
    e.reset();
  }
  if (!e) {
    drop(report, file, lineno, "candump line", error);
    return false;
  }
  out = std::move(*e);
  return true;
}

}  // namespace detail

std::vector<LogEntry> parse_log(std::string_view text, const std::string& file, LogReadReport* report) {
  LogReader r(text, LogFormat::candump, file, report);
  std::vector<LogEntry> out;
  for (LogEntry e; r.next(e);) out.push_back(e);
  return out;
}

LogFormat log_format_of(const std::filesystem::path& path) noexcept {
  std::string ext = path.extension().string();
  for (auto& c : ext) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  if (ext == ".asc") return LogFormat::asc;
  if (ext == ".blf") return LogFormat::blf;
  if (ext == ".trc") return LogFormat::trc;
  return LogFormat::candump;
}

const char* to_string(LogFormat f) noexcept {
  switch (f) {
    case LogFormat::asc: return "Vector ASC";
    case LogFormat::blf: return "Vector BLF";
    case LogFormat::trc: return "PEAK TRC";
    default: return "candump";
  }
}

std::vector<LogEntry> read_log(const std::filesystem::path& path, LogReadReport* report) {
  LogReader r(path, report);
  std::vector<LogEntry> out;
  for (LogEntry e; r.next(e);) out.push_back(e);
  return out;
}

TimeSpan writable_times(LogFormat format) noexcept {
  constexpr double inf = std::numeric_limits<double>::infinity();
  switch (format) {
    // Offsets from the earliest frame as decimal text (seconds, milliseconds): any finite.
    case LogFormat::asc:
    case LogFormat::trc: return {-inf, inf, inf};
    // Header date: a SYSTEMTIME whose year is a uint16 (before 65536-01-01 = 2005949145600 s);
    // object times: uint64 nanoseconds from the header's start (offsets below 2^64 ns, with
    // room for the rounding); before 1990 the start is 0 and times are offsets from it.
    case LogFormat::blf: return {0.0, 2005949145600.0, 18446744073.0};
    // "(seconds.microseconds)" with at most 12 digits of seconds, as read_log takes them.
    default: return {0.0, 1e12, inf};
  }
}

namespace detail {

TimeCheck::TimeCheck(LogFormat format, const LogTimes& times, std::string file)
    : format_(format), span_(writable_times(format)), t0_(times.earliest_s), origin_(0.0), file_(std::move(file)) {
  // BLF writes offsets from its header's start, the others from the earliest frame.
  const bool t0_ok = std::isfinite(t0_) && t0_ >= span_.min_abs_s && t0_ < span_.max_abs_s;
  origin_ = format == LogFormat::blf ? (t0_ok ? blf_start_of(t0_) : 0.0) : t0_;
}

void TimeCheck::check(double t, std::uint64_t index) const {
  const double offset = t - origin_;
  const char* why = nullptr;
  if (!std::isfinite(t)) why = "is not a finite number";
  else if (t < span_.min_abs_s || t >= span_.max_abs_s) why = "is outside the times the format can hold";
  else if (!(offset < span_.max_offset_s) || !std::isfinite(offset)) why = "lies too far from the log's earliest frame";
  if (why)
    throw InputError(file_, 0, fmt::format("frame {}", index + 1),
                     fmt::format("timestamp {} s {} for {} (times from {} s to {} s, at most {} s after the earliest frame at {} s); "
                                 "nothing written",
                                 t, why, to_string(format_), span_.min_abs_s, span_.max_abs_s, span_.max_offset_s, t0_));
}

}  // namespace detail

void check_writable_times(const std::vector<LogEntry>& entries, LogFormat format, const std::string& file) {
  if (entries.empty()) return;
  LogTimes times;
  for (const auto& e : entries) times.add(e.frame.timestamp_s);
  const detail::TimeCheck check(format, times, file);
  for (std::size_t i = 0; i < entries.size(); ++i) check.check(entries[i].frame.timestamp_s, i);
}

void write_log(const std::filesystem::path& path, const std::vector<LogEntry>& entries) {
  const LogFormat format = log_format_of(path);
  check_writable_times(entries, format, path.string());
  LogTimes times;
  for (const auto& e : entries) times.add(e.frame.timestamp_s);
  AtomicFile f(path);
  LogWriter w(f.stream(), format, times, path.string());
  for (const auto& e : entries) w.write(e);
  w.finish();
  f.commit();
}

}  // namespace lash::can
