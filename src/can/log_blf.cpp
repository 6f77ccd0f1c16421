// Vector BLF (binary logging format): a 144-byte "LOGG" file header, then "LOBJ"
// objects; LOG_CONTAINER objects (type 10) hold further objects, zlib-compressed
// (method 2) or stored (method 0), and an object may continue in the next container.
// Frames: CAN_MESSAGE (1), CAN_MESSAGE2 (86), CAN_ERROR_EXT (73), CAN_FD_MESSAGE (100),
// CAN_FD_MESSAGE_64 (101); other objects are skipped. Layouts as python-can's BLFReader.
// Times: the header's start SYSTEMTIME (read as UTC) + the object's offset (10 µs or 1 ns).
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <deque>
#include <string>

#include <fmt/core.h>

#include "lash/io/error.hpp"
#include "log_formats.hpp"

namespace lash::can::detail {
namespace {

constexpr std::uint32_t kCanMessage = 1, kLogContainer = 10, kCanErrorExt = 73, kCanMessage2 = 86, kCanFd = 100,
                        kCanFd64 = 101;
constexpr std::size_t kFileHeader = 144;
constexpr std::size_t kChunk = 128 * 1024;  // uncompressed bytes per container (as python-can)

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



/// The first 16 bytes of every object: signature, header size, header version 1, size, type.
void put_object_base(std::string& d, std::uint16_t header_size, std::uint32_t object_size, std::uint32_t type) {
  d.append("LOBJ", 4);
  put<std::uint16_t>(d, header_size);
  put<std::uint16_t>(d, 1);
  put<std::uint32_t>(d, object_size);
  put<std::uint32_t>(d, type);
}

/// A bad object, reported when its object is taken (BlfStream::Objects::commit).
struct Drop {
  long at = 0;
  std::string field, why;
};
/// What one object gives: a frame, a drop, or nothing (not a CAN frame).
struct ObjectResult {
  bool have_entry = false;
  LogEntry entry;
  bool have_drop = false;
  Drop drop;
};

/// The common part of CAN_FD_MESSAGE and CAN_FD_MESSAGE_64: flags, then `valid` data bytes
/// from `data` (`room` = the bytes the object has from there on); a remote frame's length is
/// `remote_len`. False (a drop) when the bytes do not fit the object or a classic frame.
bool fd_payload(Frame& f, bool remote, bool fd, bool brs, bool esi, unsigned remote_len, unsigned valid,
                const char* data, std::size_t room, ObjectResult& r, long at) {
  f.remote = remote;
  f.fd = fd;
  f.brs = brs;
  f.esi = esi;
  if (valid > 64 || valid > room || (!fd && valid > 8)) {
    r.have_drop = true;
    r.drop = {at, "valid bytes", fmt::format("{} data bytes do not fit the object", valid)};
    return false;
  }
  f.len = static_cast<std::uint8_t>(remote ? remote_len : valid);
  std::memcpy(f.data.data(), data, valid);
  return true;
}

/// Bytes of an object read before it is complete (the most any frame type reads).
constexpr std::size_t kObjectPrefix = 256;

/// One object (python-can's BLFReader layouts): `d` holds its first min(size, kObjectPrefix)
/// bytes at least, `size` (>= 32) is its declared size, `at` its offset (in messages).
ObjectResult parse_object(std::string_view d, std::size_t size, double start, long at) {
  ObjectResult r;
  const std::size_t pos = 0;
  const auto hdr_ver = get<std::uint16_t>(d, pos + 6);
  const auto type = get<std::uint32_t>(d, pos + 12);
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
    return r;
  }
  const double t = start + static_cast<double>(ts) * (tflags == 1 ? 1e-5 : 1e-9);
  LogEntry& e = r.entry;
  Frame& f = e.frame;
  f.timestamp_s = t;
  const auto need = [&](std::size_t n) {
    if (p + n <= next) return true;
    r.have_drop = true;
    r.drop = {at, "LOBJ", fmt::format("object type {} is {} bytes, too short", type, size)};
    return false;
  };
  std::uint16_t channel = 0;
  std::uint32_t id = 0;
  if (type == kCanMessage || type == kCanMessage2) {
    if (!need(16)) return r;
    channel = get<std::uint16_t>(d, p);
    const auto flags = get<std::uint8_t>(d, p + 2);
    const auto dlc = get<std::uint8_t>(d, p + 3);
    id = get<std::uint32_t>(d, p + 4);
    f.remote = (flags & 0x80) != 0;
    f.len = dlc;
    if (dlc > 8 && !f.remote) {
      r.have_drop = true;
      r.drop = {at, "DLC", fmt::format("classic frame DLC {} > 8", dlc)};
      return r;
    }
    if (!f.remote) std::memcpy(f.data.data(), d.data() + p + 8, dlc);
  } else if (type == kCanErrorExt) {
    if (!need(32)) return r;
    channel = get<std::uint16_t>(d, p);
    const auto dlc = get<std::uint8_t>(d, p + 10);
    id = get<std::uint32_t>(d, p + 16);
    f.error = true;
    f.len = dlc > 8 ? 8 : dlc;
    std::memcpy(f.data.data(), d.data() + p + 24, f.len);
  } else if (type == kCanFd) {
    if (!need(84)) return r;
    channel = get<std::uint16_t>(d, p);
    const auto flags = get<std::uint8_t>(d, p + 2);
    const auto dlc = get<std::uint8_t>(d, p + 3);
    id = get<std::uint32_t>(d, p + 4);
    const auto fdf = get<std::uint8_t>(d, p + 13);
    const bool fd = (fdf & 1) != 0;
    if (!fd_payload(f, (flags & 0x80) != 0, fd, (fdf & 2) != 0, (fdf & 4) != 0, fd ? fd_len(dlc & 15u) : dlc,
                    get<std::uint8_t>(d, p + 14), d.data() + p + 20, next - (p + 20), r, at))
      return r;
  } else if (type == kCanFd64) {
    if (!need(40)) return r;
    channel = get<std::uint8_t>(d, p);
    const auto dlc = get<std::uint8_t>(d, p + 1);
    id = get<std::uint32_t>(d, p + 4);
    const auto fdf = get<std::uint32_t>(d, p + 12);
    if (!fd_payload(f, (fdf & 0x10) != 0, (fdf & 0x1000) != 0, (fdf & 0x2000) != 0, (fdf & 0x4000) != 0, fd_len(dlc & 15u),
                    get<std::uint8_t>(d, p + 2), d.data() + p + 40, next - (p + 40), r, at))
      return r;
  } else {
    return r;  // not a CAN frame (markers, statistics, other buses)
  }
  f.extended = (id & 0x80000000u) != 0 && !f.error;
  f.id = id & 0x1FFFFFFFu;
  if (f.error) f.extended = false;
  e.interface = std::to_string(channel);
  if (!f.valid()) {
    r.have_drop = true;
    r.drop = {at, "frame", fmt::format("invalid frame (id 0x{:X}, {} bytes)", f.id, f.len)};
  } else {
    r.have_entry = true;
  }
  return r;
}

std::string does_not_fit(std::uint64_t size, std::uint64_t left) {
  return fmt::format("object of {} bytes does not fit the data ({} left); rest skipped", size, left);
}

}  // namespace

/// The objects of the concatenated container payloads (or of one top-level object), parsed as
/// their bytes arrive: an object is taken once it is whole (objects may continue in the next
/// container); one larger than LogReader::kMaxHeldObjectBytes is parsed from its first bytes and
/// its rest skipped as it arrives. Every decision is the one the whole data would give.
struct BlfStream::Objects {
  enum class State : std::uint8_t { run, skipping, dead, dead_count };
  const std::string& file;
  LogReadReport* report;
  double start;
  std::string buf;           ///< bytes not taken yet (buf[pos] on)
  std::size_t pos = 0;
  std::uint64_t base = 0;    ///< stream offset of buf[0]
  std::uint64_t total = 0;   ///< bytes fed so far
  State state = State::run;
  std::uint64_t skip_left = 0, held_at = 0, held_size = 0;  ///< skipping: the rest of a large object
  ObjectResult held;
  std::uint64_t dead_at = 0, dead_size = 0;  ///< dead_count: a bad size, reported with the bytes left at the end

  Objects(const std::string& f, LogReadReport* r, double s) : file(f), report(r), start(s) {}

  void commit(ObjectResult& r, std::deque<LogEntry>& out) {
    if (r.have_drop) drop(report, file, r.drop.at, r.drop.field, r.drop.why);
    if (r.have_entry) out.push_back(std::move(r.entry));
  }

  void feed(std::string_view data, std::deque<LogEntry>& out) {
    total += data.size();
    if (state == State::dead || state == State::dead_count) return;
    if (state == State::skipping) {
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(skip_left, data.size()));
      skip_left -= n;
      data.remove_prefix(n);
      if (skip_left > 0) return;
      state = State::run;
      base = held_at + held_size;
      commit(held, out);
    }
    if (pos > 0) {
      buf.erase(0, pos);
      base += pos;
      pos = 0;
    }
    buf.append(data);
    run(false, out);
  }

  void finish(std::deque<LogEntry>& out) {
    switch (state) {
      case State::skipping:
        state = State::dead;
        drop(report, file, static_cast<long>(held_at), "LOBJ", does_not_fit(held_size, total - held_at));
        return;
      case State::dead_count:
        state = State::dead;
        drop(report, file, static_cast<long>(dead_at), "LOBJ", does_not_fit(dead_size, total - dead_at));
        return;
      case State::dead: return;
      case State::run: run(true, out); return;
    }
  }

  void run(bool eof, std::deque<LogEntry>& out) {
    for (;;) {
      const std::size_t n = buf.size();
      if (pos + 16 > n) return;
      if (!eof && n - pos < 24) return;  // the signature scan and the header need up to 24 bytes
      // objects are 4-byte aligned inside containers: skip up to 3 padding bytes
      std::size_t k = 0;
      while (k < 8 && pos + k + 4 <= n && std::memcmp(buf.data() + pos + k, "LOBJ", 4) != 0) ++k;
      if (k == 8 || pos + k + 16 > n) {
        state = State::dead;
        if (n - pos >= 8)
          drop(report, file, static_cast<long>(base + pos), "LOBJ", "no object signature in the container data; rest skipped");
        return;
      }
      pos += k;
      const auto size = get<std::uint32_t>(buf, pos + 8);
      if (size < 32) {
        if (eof) {
          state = State::dead;
          drop(report, file, static_cast<long>(base + pos), "LOBJ", does_not_fit(size, n - pos));
        } else {
          state = State::dead_count;
          dead_at = base + pos;
          dead_size = size;
        }
        return;
      }
      if (pos + size > n) {
        if (eof) {
          state = State::dead;
          drop(report, file, static_cast<long>(base + pos), "LOBJ", does_not_fit(size, n - pos));
          return;
        }
        if (size <= LogReader::kMaxHeldObjectBytes || n - pos < kObjectPrefix) return;  // wait for the rest
        held = parse_object(std::string_view(buf).substr(pos), size, start, static_cast<long>(base + pos));
        held_at = base + pos;
        held_size = size;
        skip_left = pos + size - n;
        state = State::skipping;
        base += n;
        buf.clear();
        pos = 0;
        return;
      }
      ObjectResult r = parse_object(std::string_view(buf).substr(pos, size), size, start, static_cast<long>(base + pos));
      pos += size;
      commit(r, out);
    }
  }
};

BlfStream::BlfStream(ByteSource& src, std::string file, LogReadReport* report)
    : src_(src), file_(std::move(file)), report_(report) {
  char h[72];
  if (src_.read_full(h, sizeof h) < sizeof h || std::memcmp(h, "LOGG", 4) != 0)
    throw InputError(file_, 0, "LOGG", "not a BLF file (no LOGG header)");
  const std::string_view d(h, sizeof h);
  const auto header_size = get<std::uint32_t>(d, 4);
  if (header_size < 72 || src_.skip(header_size - 72) < header_size - 72)
    throw InputError(file_, 0, "LOGG", fmt::format("bad header size {}", header_size));
  start_ = systemtime(d, 40);
  pos_ = header_size;
  stream_ = std::make_unique<Objects>(file_, report_, start_);
}

BlfStream::~BlfStream() = default;

void BlfStream::end_of_file(std::deque<LogEntry>& out) {
  done_ = true;
  stream_->finish(out);
}

bool BlfStream::fill(std::deque<LogEntry>& out) {
  if (done_) return false;
  char oh[32];
  const std::size_t got = src_.read_full(oh, 16);
  if (got == 0) {
    end_of_file(out);
    return true;
  }
  const auto truncated = [&](std::uint64_t size, std::uint64_t read_so_far) {
    const std::uint64_t total = pos_ + read_so_far + src_.skip(~std::uint64_t{0});
    done_ = true;
    drop(report_, file_, static_cast<long>(pos_), "LOBJ",
         fmt::format("object of {} bytes at offset {} runs past the end of the file ({} bytes): truncated", size, pos_, total));
    stream_->finish(out);
  };
  if (got < 16 || std::memcmp(oh, "LOBJ", 4) != 0) {
    const std::uint64_t left = got + src_.skip(~std::uint64_t{0});
    done_ = true;
    drop(report_, file_, static_cast<long>(pos_), "LOBJ", fmt::format("no object at offset {} ({} bytes left); rest skipped", pos_, left));
    stream_->finish(out);
    return true;
  }
  const std::string_view oh16(oh, 16);
  const auto size = get<std::uint32_t>(oh16, 8);
  const auto type = get<std::uint32_t>(oh16, 12);
  if (size < 16) {
    truncated(size, 16);
    return true;
  }
  /// Reads the object's bytes from `from` (bytes of the object already read) on into payload_,
  /// growing it as they arrive; false when the file ends first.
  const auto read_rest = [&](std::size_t from) {
    const std::size_t want = size - from;
    payload_.clear();
    while (payload_.size() < want) {
      const std::size_t have = payload_.size();
      const std::size_t step = std::min(want - have, std::max<std::size_t>(have, std::size_t{1} << 16));
      payload_.resize(have + step);
      const std::size_t n = src_.read_full(payload_.data() + have, step);
      payload_.resize(have + n);
      if (n < step) return false;
    }
    return true;
  };
  if (type == kLogContainer) {
    if (size < 32) {
      const std::uint64_t n = src_.skip(size - 16);
      if (n < size - 16) {
        truncated(size, 16 + n);
        return true;
      }
      drop(report_, file_, static_cast<long>(pos_), "LOG_CONTAINER", "container too short");
    } else {
      const std::size_t n = src_.read_full(oh + 16, 16);
      if (n < 16) {
        truncated(size, 16 + n);
        return true;
      }
      if (!read_rest(32)) {
        truncated(size, 32 + payload_.size());
        return true;
      }
      const std::string_view c(oh, 32);
      const auto method = get<std::uint16_t>(c, 16);
      const auto raw_size = get<std::uint32_t>(c, 24);
      const std::string_view payload(payload_.data(), payload_.size());
      if (method == 0) {
        stream_->feed(payload, out);
      } else if (method == 2) {
        if (raw_size > (1u << 30)) {
          drop(report_, file_, static_cast<long>(pos_), "LOG_CONTAINER", fmt::format("implausible uncompressed size {}", raw_size));
        } else {
          if (raw_cap_ < raw_size || !raw_) {  // not initialised: only what zlib writes is touched
            raw_.reset(new unsigned char[std::max<std::size_t>(raw_size, 1)]);
            raw_cap_ = std::max<std::size_t>(raw_size, 1);
          }
          uLongf got_raw = raw_size;
          const int rc = uncompress(raw_.get(), &got_raw, reinterpret_cast<const Bytef*>(payload.data()),
                                    static_cast<uLong>(payload.size()));
          if (rc != Z_OK || got_raw != raw_size) {
            drop(report_, file_, static_cast<long>(pos_), "LOG_CONTAINER",
                 fmt::format("zlib data does not inflate to {} bytes ({}): container skipped", raw_size, zError(rc)));
          } else {
            stream_->feed(std::string_view(reinterpret_cast<const char*>(raw_.get()), raw_size), out);
          }
        }
      } else {
        drop(report_, file_, static_cast<long>(pos_), "LOG_CONTAINER", fmt::format("unknown compression method {}", method));
      }
    }
  } else {
    // a top-level frame object (uncompressed files): a stream of its own, offsets from the object
    Objects one(file_, report_, start_);
    std::deque<LogEntry> got_entries;
    one.feed(oh16, got_entries);
    std::uint64_t have = 16;
    while (have < size) {
      const std::size_t step = static_cast<std::size_t>(std::min<std::uint64_t>(size - have, std::size_t{1} << 16));
      payload_.resize(step);
      const std::size_t n = src_.read_full(payload_.data(), step);
      have += n;
      if (n < step) {
        truncated(size, have);
        return true;
      }
      one.feed(std::string_view(payload_.data(), n), got_entries);
    }
    one.finish(got_entries);
    for (auto& e : got_entries) out.push_back(std::move(e));
  }
  pos_ += size + size % 4;
  src_.skip(size % 4);
  return true;
}

std::vector<LogEntry> parse_blf(std::string_view d, const std::string& file, LogReadReport* report) {
  LogReader r(d, LogFormat::blf, file, report);
  std::vector<LogEntry> out;
  for (LogEntry e; r.next(e);) out.push_back(e);
  return out;
}

double blf_start_of(double t0) noexcept {
  return t0 >= 631152000.0 ? static_cast<double>(static_cast<std::int64_t>(t0 * 1000.0)) / 1000.0 : 0.0;
}

BlfWriter::BlfWriter(std::ostream& os, double start) : os_(os), start_(start) {
  header_at_ = os_.tellp();
  seekable_ = header_at_ != std::ostream::pos_type(-1);
  if (seekable_) os_.write(std::string(kFileHeader, '\0').data(), kFileHeader);  // the header, filled at finish()
}

void BlfWriter::entry(const LogEntry& e) {
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
  const double rel = f.timestamp_s - start_;
  // In range: LogWriter's time check bounds rel to [0, writable_times(blf).max_offset_s).
  const auto ns = static_cast<std::uint64_t>(rel > 0 ? rel * 1e9 + 0.5 : 0.0);
  const std::size_t before = objs_.size();
  put_object_base(objs_, 32, static_cast<std::uint32_t>(32 + body.size()), type);
  put<std::uint32_t>(objs_, 2);  // TIME_ONE_NANS
  put<std::uint16_t>(objs_, 0);
  put<std::uint16_t>(objs_, 0);
  put<std::uint64_t>(objs_, ns);
  objs_ += body;
  objs_.append(body.size() % 4, '\0');
  obj_bytes_ += objs_.size() - before;
  ++count_;
  stop_ = f.timestamp_s;
  while (objs_.size() >= kChunk) flush_chunk(kChunk);
}

void BlfWriter::flush_chunk(std::size_t n) {
  uLongf zn = compressBound(static_cast<uLong>(n));
  std::string z(zn, '\0');
  compress2(reinterpret_cast<Bytef*>(z.data()), &zn, reinterpret_cast<const Bytef*>(objs_.data()), static_cast<uLong>(n), 6);
  z.resize(zn);
  const auto size = static_cast<std::uint32_t>(32 + z.size());
  std::string c;
  put_object_base(c, 16, size, kLogContainer);
  put<std::uint16_t>(c, 2);
  c.append(6, '\0');
  put<std::uint32_t>(c, static_cast<std::uint32_t>(n));
  c.append(4, '\0');
  c += z;
  c.append(size % 4, '\0');
  file_bytes_ += c.size();
  if (seekable_) os_.write(c.data(), static_cast<std::streamsize>(c.size()));
  else held_ += c;
  objs_.erase(0, n);
}

void BlfWriter::finish() {
  if (!objs_.empty()) flush_chunk(objs_.size());
  std::string h;
  h.append("LOGG", 4);
  put<std::uint32_t>(h, kFileHeader);
  for (const int b : {5, 0, 0, 0, 2, 6, 8, 1}) put<std::uint8_t>(h, static_cast<std::uint8_t>(b));
  put<std::uint64_t>(h, kFileHeader + file_bytes_);
  put<std::uint64_t>(h, kFileHeader + obj_bytes_);
  put<std::uint32_t>(h, count_);
  put<std::uint32_t>(h, 0);
  put_systemtime(h, start_);
  put_systemtime(h, stop_);
  h.append(kFileHeader - h.size(), '\0');
  if (seekable_) {
    const auto end = os_.tellp();
    os_.seekp(header_at_);
    os_.write(h.data(), static_cast<std::streamsize>(h.size()));
    os_.seekp(end);
  } else {
    os_.write(h.data(), static_cast<std::streamsize>(h.size()));
    os_.write(held_.data(), static_cast<std::streamsize>(held_.size()));
    held_.clear();
  }
}

void write_blf(std::ostream& os, const std::vector<LogEntry>& entries) {
  check_writable_times(entries, LogFormat::blf, "");
  LogTimes times;
  for (const auto& e : entries) times.add(e.frame.timestamp_s);
  LogWriter w(os, LogFormat::blf, times);
  for (const auto& e : entries) w.write(e);
  w.finish();
}

}  // namespace lash::can::detail
