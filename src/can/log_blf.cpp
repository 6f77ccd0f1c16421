// Vector BLF (binary logging format): a 144-byte "LOGG" file header, then "LOBJ"
// objects; LOG_CONTAINER objects (type 10) hold further objects, zlib-compressed
// (method 2) or stored (method 0), and an object may continue in the next container.
// Frames: CAN_MESSAGE (1), CAN_MESSAGE2 (86), CAN_ERROR_EXT (73), CAN_FD_MESSAGE (100),
// CAN_FD_MESSAGE_64 (101); other objects are skipped. Layouts as python-can's BLFReader.
// Times: the header's start SYSTEMTIME (read as UTC) + the object's offset (10 µs or 1 ns).
#include <zlib.h>

#include <cstring>
#include <string>

#include <fmt/core.h>

#include "lash/io/error.hpp"
#include "log_formats.hpp"

namespace lash::can::detail {
namespace {

constexpr std::uint32_t kCanMessage = 1, kLogContainer = 10, kCanErrorExt = 73, kCanMessage2 = 86, kCanFd = 100,
                        kCanFd64 = 101;
constexpr std::size_t kFileHeader = 144;

template <class T>
T get(std::string_view d, std::size_t at) {
  T v{};
  std::memcpy(&v, d.data() + at, sizeof(T));  // BLF is little-endian, as the x86/ARM hosts lash runs on
  return v;
}
template <class T>
void put(std::string& d, T v) {
  d.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// SYSTEMTIME (year, month, weekday, day, hour, minute, second, ms) → seconds; 0 if not a date.
double systemtime(std::string_view d, std::size_t at) {
  std::uint16_t s[8];
  for (int i = 0; i < 8; ++i) s[i] = get<std::uint16_t>(d, at + 2 * static_cast<std::size_t>(i));
  if (s[0] < 1970 || s[1] < 1 || s[1] > 12 || s[3] < 1 || s[3] > 31 || s[4] > 23 || s[5] > 59 || s[6] > 59 || s[7] > 999) return 0;
  const std::int64_t days = days_from_civil(s[0], s[1], s[3]);
  return static_cast<double>(days * 86400 + s[4] * 3600 + s[5] * 60 + s[6]) + s[7] / 1000.0;
}

void put_systemtime(std::string& d, double t) {
  std::uint16_t s[8] = {};
  if (t >= 631152000.0) {  // as python-can: earlier times are offsets, not dates
    const auto ms_total = static_cast<std::int64_t>(t * 1000.0);
    std::int64_t days = ms_total / 86400000;
    std::int64_t ms = ms_total % 86400000;
    // civil_from_days (Howard Hinnant)
    days += 719468;
    const std::int64_t era = days / 146097;
    const auto doe = static_cast<unsigned>(days - era * 146097);
    const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    const unsigned mp = (5 * doy + 2) / 153;
    const unsigned day = doy - (153 * mp + 2) / 5 + 1;
    const unsigned month = mp < 10 ? mp + 3 : mp - 9;
    const std::int64_t year = static_cast<std::int64_t>(yoe) + era * 400 + (month <= 2);
    s[0] = static_cast<std::uint16_t>(year);
    s[1] = static_cast<std::uint16_t>(month);
    s[2] = static_cast<std::uint16_t>((ms_total / 86400000 + 4) % 7);  // 1970-01-01 was a Thursday
    s[3] = static_cast<std::uint16_t>(day);
    s[4] = static_cast<std::uint16_t>(ms / 3600000);
    s[5] = static_cast<std::uint16_t>(ms / 60000 % 60);
    s[6] = static_cast<std::uint16_t>(ms / 1000 % 60);
    s[7] = static_cast<std::uint16_t>(ms % 1000);
  }
  for (auto v : s) put(d, v);
}



/// The common part of CAN_FD_MESSAGE and CAN_FD_MESSAGE_64: flags, then `valid` data bytes
/// from `data` (the rest of the object); a remote frame's length is `remote_len`.
/// False (a reported drop) when the bytes do not fit the object or a classic frame.
bool fd_payload(Frame& f, bool remote, bool fd, bool brs, bool esi, unsigned remote_len, unsigned valid,
                std::string_view data, LogReadReport* report, const std::string& file, std::size_t pos) {
  f.remote = remote;
  f.fd = fd;
  f.brs = brs;
  f.esi = esi;
  if (valid > 64 || valid > data.size() || (!fd && valid > 8)) {
    drop(report, file, static_cast<long>(pos), "valid bytes", fmt::format("{} data bytes do not fit the object", valid));
    return false;
  }
  f.len = static_cast<std::uint8_t>(remote ? remote_len : valid);
  std::memcpy(f.data.data(), data.data(), valid);
  return true;
}

/// The first 16 bytes of every object: signature, header size, header version 1, size, type.
void put_object_base(std::string& d, std::uint16_t header_size, std::uint32_t object_size, std::uint32_t type) {
  d.append("LOBJ", 4);
  put<std::uint16_t>(d, header_size);
  put<std::uint16_t>(d, 1);
  put<std::uint32_t>(d, object_size);
  put<std::uint32_t>(d, type);
}

/// Parses the objects of the concatenated container payloads.
void parse_objects(std::string_view d, double start, const std::string& file, LogReadReport* report,
                   std::vector<LogEntry>& out) {
  std::size_t pos = 0;
  while (pos + 16 <= d.size()) {
    // objects are 4-byte aligned inside containers: skip up to 3 padding bytes
    std::size_t k = 0;
    while (k < 8 && pos + k + 4 <= d.size() && std::memcmp(d.data() + pos + k, "LOBJ", 4) != 0) ++k;
    if (k == 8 || pos + k + 16 > d.size()) {
      if (d.size() - pos >= 8) drop(report, file, static_cast<long>(pos), "LOBJ", "no object signature in the container data; rest skipped");
      return;
    }
    pos += k;
    const auto hdr_ver = get<std::uint16_t>(d, pos + 6);
    const auto size = get<std::uint32_t>(d, pos + 8);
    const auto type = get<std::uint32_t>(d, pos + 12);
    if (size < 32 || pos + size > d.size()) {
      drop(report, file, static_cast<long>(pos), "LOBJ", fmt::format("object of {} bytes does not fit the data ({} left); rest skipped", size, d.size() - pos));
      return;
    }
    const std::size_t next = pos + size;
    std::size_t p = pos + 16;
    std::uint32_t tflags = 0;
    std::uint64_t ts = 0;
    if (hdr_ver == 1) {
      tflags = get<std::uint32_t>(d, p);
      ts = get<std::uint64_t>(d, p + 8);
      p += 16;
    } else if (hdr_ver == 2) {
      tflags = get<std::uint32_t>(d, p);
      ts = get<std::uint64_t>(d, p + 8);
      p += 24;
    } else {
      pos = next;
      continue;
    }
    const double t = start + static_cast<double>(ts) * (tflags == 1 ? 1e-5 : 1e-9);
    LogEntry e;
    Frame& f = e.frame;
    f.timestamp_s = t;
    const auto need = [&](std::size_t n) {
      if (p + n <= next) return true;
      drop(report, file, static_cast<long>(pos), "LOBJ", fmt::format("object type {} is {} bytes, too short", type, size));
      return false;
    };
    std::uint16_t channel = 0;
    std::uint32_t id = 0;
    if (type == kCanMessage || type == kCanMessage2) {
      if (!need(16)) {
        pos = next;
        continue;
      }
      channel = get<std::uint16_t>(d, p);
      const auto flags = get<std::uint8_t>(d, p + 2);
      const auto dlc = get<std::uint8_t>(d, p + 3);
      id = get<std::uint32_t>(d, p + 4);
      f.remote = (flags & 0x80) != 0;
      f.len = dlc;
      if (dlc > 8 && !f.remote) {
        drop(report, file, static_cast<long>(pos), "DLC", fmt::format("classic frame DLC {} > 8", dlc));
        pos = next;
        continue;
      }
      if (!f.remote) std::memcpy(f.data.data(), d.data() + p + 8, dlc);
    } else if (type == kCanErrorExt) {
      if (!need(32)) {
        pos = next;
        continue;
      }
      channel = get<std::uint16_t>(d, p);
      const auto dlc = get<std::uint8_t>(d, p + 10);
      id = get<std::uint32_t>(d, p + 16);
      f.error = true;
      f.len = dlc > 8 ? 8 : dlc;
      std::memcpy(f.data.data(), d.data() + p + 24, f.len);
    } else if (type == kCanFd) {
      if (!need(84)) {
        pos = next;
        continue;
      }
      channel = get<std::uint16_t>(d, p);
      const auto flags = get<std::uint8_t>(d, p + 2);
      const auto dlc = get<std::uint8_t>(d, p + 3);
      id = get<std::uint32_t>(d, p + 4);
      const auto fdf = get<std::uint8_t>(d, p + 13);
      const bool fd = (fdf & 1) != 0;
      if (!fd_payload(f, (flags & 0x80) != 0, fd, (fdf & 2) != 0, (fdf & 4) != 0, fd ? fd_len(dlc & 15u) : dlc,
                      get<std::uint8_t>(d, p + 14), d.substr(p + 20, next - (p + 20)), report, file, pos)) {
        pos = next;
        continue;
      }
    } else if (type == kCanFd64) {
      if (!need(40)) {
        pos = next;
        continue;
      }
      channel = get<std::uint8_t>(d, p);
      const auto dlc = get<std::uint8_t>(d, p + 1);
      id = get<std::uint32_t>(d, p + 4);
      const auto fdf = get<std::uint32_t>(d, p + 12);
      if (!fd_payload(f, (fdf & 0x10) != 0, (fdf & 0x1000) != 0, (fdf & 0x2000) != 0, (fdf & 0x4000) != 0, fd_len(dlc & 15u),
                      get<std::uint8_t>(d, p + 2), d.substr(p + 40, next - (p + 40)), report, file, pos)) {
        pos = next;
        continue;
      }
    } else {
      pos = next;  // not a CAN frame (markers, statistics, other buses)
      continue;
    }
    f.extended = (id & 0x80000000u) != 0 && !f.error;
    f.id = id & 0x1FFFFFFFu;
    if (f.error) f.extended = false;
    e.interface = std::to_string(channel);
    if (!f.valid()) {
      drop(report, file, static_cast<long>(pos), "frame", fmt::format("invalid frame (id 0x{:X}, {} bytes)", f.id, f.len));
    } else {
      out.push_back(std::move(e));
    }
    pos = next;
  }
}

}  // namespace

double blf_start_of(double t0) noexcept {
  return t0 >= 631152000.0 ? static_cast<double>(static_cast<std::int64_t>(t0 * 1000.0)) / 1000.0 : 0.0;
}

std::vector<LogEntry> parse_blf(std::string_view d, const std::string& file, LogReadReport* report) {
  if (d.size() < 72 || std::memcmp(d.data(), "LOGG", 4) != 0)
    throw InputError(file, 0, "LOGG", "not a BLF file (no LOGG header)");
  const auto header_size = get<std::uint32_t>(d, 4);
  if (header_size < 72 || header_size > d.size()) throw InputError(file, 0, "LOGG", fmt::format("bad header size {}", header_size));
  const double start = systemtime(d, 40);
  std::string stream;  // concatenated container payloads
  std::vector<LogEntry> out;
  std::size_t pos = header_size;
  while (pos < d.size()) {
    if (d.size() - pos < 16 || std::memcmp(d.data() + pos, "LOBJ", 4) != 0) {
      drop(report, file, static_cast<long>(pos), "LOBJ", fmt::format("no object at offset {} ({} bytes left); rest skipped", pos, d.size() - pos));
      break;
    }
    const auto size = get<std::uint32_t>(d, pos + 8);
    const auto type = get<std::uint32_t>(d, pos + 12);
    if (size < 16 || size > d.size() - pos) {
      drop(report, file, static_cast<long>(pos), "LOBJ", fmt::format("object of {} bytes at offset {} runs past the end of the file ({} bytes): truncated", size, pos, d.size()));
      break;
    }
    if (type == kLogContainer) {
      if (size < 32) {
        drop(report, file, static_cast<long>(pos), "LOG_CONTAINER", "container too short");
      } else {
        const auto method = get<std::uint16_t>(d, pos + 16);
        const auto raw_size = get<std::uint32_t>(d, pos + 24);
        const std::string_view payload = d.substr(pos + 32, size - 32);
        if (method == 0) {
          stream.append(payload);
        } else if (method == 2) {
          if (raw_size > (1u << 30)) {
            drop(report, file, static_cast<long>(pos), "LOG_CONTAINER", fmt::format("implausible uncompressed size {}", raw_size));
          } else {
            std::string buf(raw_size, '\0');
            uLongf got = raw_size;
            const int rc = uncompress(reinterpret_cast<Bytef*>(buf.data()), &got,
                                      reinterpret_cast<const Bytef*>(payload.data()), static_cast<uLong>(payload.size()));
            if (rc != Z_OK || got != raw_size) {
              drop(report, file, static_cast<long>(pos), "LOG_CONTAINER",
                   fmt::format("zlib data does not inflate to {} bytes ({}): container skipped", raw_size, zError(rc)));
            } else {
              stream.append(buf);
            }
          }
        } else {
          drop(report, file, static_cast<long>(pos), "LOG_CONTAINER", fmt::format("unknown compression method {}", method));
        }
      }
    } else {
      // a top-level frame object (uncompressed files)
      parse_objects(d.substr(pos, size), start, file, report, out);
    }
    pos += size + size % 4;
  }
  parse_objects(stream, start, file, report, out);
  return out;
}

void write_blf(std::ostream& os, const std::vector<LogEntry>& entries) {
  check_writable_times(entries, LogFormat::blf, "");
  // The header's start time is the earliest frame's (logs may go backwards), so that no
  // object time is negative.
  double t0 = entries.empty() ? 0.0 : entries.front().frame.timestamp_s;
  for (const auto& e : entries) t0 = std::min(t0, e.frame.timestamp_s);
  const double start = blf_start_of(t0);
  const double stop = entries.empty() ? 0.0 : entries.back().frame.timestamp_s;
  std::string objs;
  for (const auto& e : entries) {
    const Frame& f = e.frame;
    std::string body;
    std::uint16_t ch = 1;
    try {
      const int c = std::stoi(e.interface);
      if (c > 0 && c < 65536) ch = static_cast<std::uint16_t>(c);
    } catch (...) {
    }
    const std::uint32_t id = f.id | (f.extended ? 0x80000000u : 0u);
    std::uint32_t type = kCanMessage;
    if (f.error) {
      type = kCanErrorExt;
      put<std::uint16_t>(body, ch);
      put<std::uint16_t>(body, 0);
      put<std::uint32_t>(body, 0);
      put<std::uint8_t>(body, 0);
      put<std::uint8_t>(body, 0);
      put<std::uint8_t>(body, f.len);
      put<std::uint8_t>(body, 0);
      put<std::uint32_t>(body, 0);
      put<std::uint32_t>(body, id);
      put<std::uint16_t>(body, 0);
      put<std::uint16_t>(body, 0);
      body.append(reinterpret_cast<const char*>(f.data.data()), 8);
    } else if (f.fd) {
      type = kCanFd;
      put<std::uint16_t>(body, ch);
      put<std::uint8_t>(body, f.remote ? 0x80 : 0);
      put<std::uint8_t>(body, static_cast<std::uint8_t>(fd_dlc(f.len)));
      put<std::uint32_t>(body, id);
      put<std::uint32_t>(body, 0);
      put<std::uint8_t>(body, 0);
      put<std::uint8_t>(body, static_cast<std::uint8_t>(1 | (f.brs ? 2 : 0) | (f.esi ? 4 : 0)));
      put<std::uint8_t>(body, f.len);
      body.append(5, '\0');
      body.append(reinterpret_cast<const char*>(f.data.data()), 64);
    } else {
      put<std::uint16_t>(body, ch);
      put<std::uint8_t>(body, f.remote ? 0x80 : 0);
      put<std::uint8_t>(body, f.len);
      put<std::uint32_t>(body, id);
      body.append(reinterpret_cast<const char*>(f.data.data()), 8);
    }
    const double rel = f.timestamp_s - start;
    // In range: check_writable_times bounds rel to [0, writable_times(blf).max_offset_s).
    const auto ns = static_cast<std::uint64_t>(rel > 0 ? rel * 1e9 + 0.5 : 0.0);
    put_object_base(objs, 32, static_cast<std::uint32_t>(32 + body.size()), type);
    put<std::uint32_t>(objs, 2);  // TIME_ONE_NANS
    put<std::uint16_t>(objs, 0);
    put<std::uint16_t>(objs, 0);
    put<std::uint64_t>(objs, ns);
    objs += body;
    objs.append(body.size() % 4, '\0');
  }
  std::string file;
  constexpr std::size_t kChunk = 128 * 1024;
  for (std::size_t at = 0; at < objs.size(); at += kChunk) {
    const std::size_t n = std::min(kChunk, objs.size() - at);
    uLongf zn = compressBound(static_cast<uLong>(n));
    std::string z(zn, '\0');
    compress2(reinterpret_cast<Bytef*>(z.data()), &zn, reinterpret_cast<const Bytef*>(objs.data() + at), static_cast<uLong>(n), 6);
    z.resize(zn);
    const auto size = static_cast<std::uint32_t>(32 + z.size());
    put_object_base(file, 16, size, kLogContainer);
    put<std::uint16_t>(file, 2);
    file.append(6, '\0');
    put<std::uint32_t>(file, static_cast<std::uint32_t>(n));
    file.append(4, '\0');
    file += z;
    file.append(size % 4, '\0');
  }
  std::string h;
  h.append("LOGG", 4);
  put<std::uint32_t>(h, kFileHeader);
  for (const int b : {5, 0, 0, 0, 2, 6, 8, 1}) put<std::uint8_t>(h, static_cast<std::uint8_t>(b));
  put<std::uint64_t>(h, kFileHeader + file.size());
  put<std::uint64_t>(h, kFileHeader + objs.size());
  put<std::uint32_t>(h, static_cast<std::uint32_t>(entries.size()));
  put<std::uint32_t>(h, 0);
  put_systemtime(h, start);
  put_systemtime(h, stop);
  h.append(kFileHeader - h.size(), '\0');
  os.write(h.data(), static_cast<std::streamsize>(h.size()));
  os.write(file.data(), static_cast<std::streamsize>(file.size()));
}

}  // namespace lash::can::detail
