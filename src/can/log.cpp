#include "lash/can/log.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <fmt/core.h>

#include "lash/io/atomic_file.hpp"
#include "lash/io/error.hpp"

namespace lash::can {
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
    if (f.extended && f.id > 0x1FFFFFFFu) {
      error = "29-bit id out of range (error frames are not supported): '" + std::string(id_text) + "'";
      return std::nullopt;
    }
    if (!f.extended && f.id > 0x7FFu) {
      error = "11-bit id out of range: '" + std::string(id_text) + "'";
      return std::nullopt;
    }
    if (!rest.empty() && rest.front() == '#') {  // CAN FD: ##<flags><data>
      if (rest.size() < 2 || hex_value(rest[1]) < 0) {
        error = "CAN FD frame needs a flags digit after '##'";
        return std::nullopt;
      }
      f.fd = true;
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
    f.len = static_cast<std::uint8_t>(n);
    return f;
  } catch (...) {
    error = "out of memory";
    return std::nullopt;
  }
}

std::string format_frame_text(const Frame& f) {
  std::string out;
  const int digits = f.extended ? 8 : 3;
  for (int i = digits - 1; i >= 0; --i) out.push_back(kHex[(f.id >> (4 * i)) & 0xF]);
  out.push_back('#');
  if (f.remote) {
    out.push_back('R');
    if (f.len > 0 && f.len <= 8) out.push_back(static_cast<char>('0' + f.len));
    return out;
  }
  if (f.fd) out += "#0";
  for (std::size_t i = 0; i < f.len && i < f.data.size(); ++i) {
    out.push_back(kHex[f.data[i] >> 4]);
    out.push_back(kHex[f.data[i] & 0xF]);
  }
  return out;
}

std::optional<LogEntry> parse_log_line(std::string_view line, std::string& error) noexcept {
  try {
    while (!line.empty() && (line.back() == '\r' || line.back() == '\n' || line.back() == ' ' || line.back() == '\t'))
      line.remove_suffix(1);
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    // Split on blanks.
    std::string_view parts[5];
    std::size_t n = 0;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
      if (n == 5) {
        error = "too many fields (expected '(time) iface ID#DATA')";
        return std::nullopt;
      }
      parts[n++] = line.substr(i, j - i);
      i = j;
    }
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
    const std::string_view num = ts.substr(1, ts.size() - 2);
    const auto dot = num.find('.');
    if (dot == std::string_view::npos || dot == 0 || dot + 1 >= num.size()) {
      error = "timestamp must look like (seconds.microseconds)";
      return std::nullopt;
    }
    std::uint64_t sec = 0;
    for (std::size_t k = 0; k < dot; ++k) {
      if (num[k] < '0' || num[k] > '9' || sec > 100000000000ull) {
        error = "bad seconds in timestamp";
        return std::nullopt;
      }
      sec = sec * 10 + static_cast<std::uint64_t>(num[k] - '0');
    }
    const std::string_view frac = num.substr(dot + 1);
    if (frac.size() > 9) {
      error = "too many fraction digits in timestamp";
      return std::nullopt;
    }
    std::uint64_t ns = 0;
    for (std::size_t k = 0; k < 9; ++k) {
      std::uint64_t d = 0;
      if (k < frac.size()) {
        if (frac[k] < '0' || frac[k] > '9') {
          error = "bad fraction in timestamp";
          return std::nullopt;
        }
        d = static_cast<std::uint64_t>(frac[k] - '0');
      }
      ns = ns * 10 + d;
    }
    LogEntry e;
    e.interface = std::string(parts[1]);
    std::string ferr;
    auto f = parse_frame_text(parts[2], ferr);
    if (!f) {
      error = ferr;
      return std::nullopt;
    }
    e.frame = *f;
    e.frame.timestamp_s = static_cast<double>(sec) + static_cast<double>(ns) * 1e-9;
    return e;
  } catch (...) {
    error = "out of memory";
    return std::nullopt;
  }
}

std::string format_log_line(const Frame& frame, std::string_view interface) {
  double t = frame.timestamp_s;
  if (!(t >= 0) || !std::isfinite(t)) t = 0;
  auto sec = static_cast<std::uint64_t>(std::floor(t));
  auto us = static_cast<std::uint64_t>(std::llround((t - static_cast<double>(sec)) * 1e6));
  if (us >= 1000000) {
    sec += 1;
    us -= 1000000;
  }
  return fmt::format("({}.{:06d}) {} {}", sec, us, interface, format_frame_text(frame));
}

std::vector<LogEntry> parse_log(std::string_view text, const std::string& file) {
  std::vector<LogEntry> out;
  int lineno = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    auto nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    const std::string_view line = text.substr(pos, nl - pos);
    ++lineno;
    pos = nl + 1;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) {
      if (nl == text.size()) break;
      continue;
    }
    std::string error;
    auto e = parse_log_line(line, error);
    if (!e) throw InputError(file, lineno, "candump line", error);
    out.push_back(std::move(*e));
    if (nl == text.size()) break;
  }
  return out;
}

std::vector<LogEntry> read_log(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), 0, "", "cannot open log file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_log(ss.str(), path.string());
}

void write_log(const std::filesystem::path& path, const std::vector<LogEntry>& entries) {
  AtomicFile f(path);
  for (const auto& e : entries) f.stream() << format_log_line(e.frame, e.interface) << '\n';
  f.commit();
}

}  // namespace lash::can
