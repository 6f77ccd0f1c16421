// Tiny msgpack subset for python-can's udp_multicast datagrams.
// Spec: https://github.com/msgpack/msgpack/blob/master/spec.md
#include "lash/can/datagram.hpp"

#include <bit>
#include <cstring>
#include <string_view>

namespace lash::can::udp {
namespace {

class Writer {
 public:
  explicit Writer(std::span<std::uint8_t> out) : out_(out) {}
  bool ok() const { return ok_; }
  std::size_t size() const { return n_; }
  void byte(std::uint8_t b) {
    if (n_ >= out_.size()) {
      ok_ = false;
      return;
    }
    out_[n_++] = b;
  }
  void be(std::uint64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) byte(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void str(std::string_view s) {  // keys are < 32 chars: fixstr
    byte(static_cast<std::uint8_t>(0xa0 | s.size()));
    for (char c : s) byte(static_cast<std::uint8_t>(c));
  }
  void boolean(bool b) { byte(b ? 0xc3 : 0xc2); }
  void uint(std::uint64_t v) {  // smallest encoding, as msgpack-python does
    if (v < 128) {
      byte(static_cast<std::uint8_t>(v));
    } else if (v <= 0xff) {
      byte(0xcc);
      be(v, 1);
    } else if (v <= 0xffff) {
      byte(0xcd);
      be(v, 2);
    } else if (v <= 0xffffffffu) {
      byte(0xce);
      be(v, 4);
    } else {
      byte(0xcf);
      be(v, 8);
    }
  }
  void f64(double d) {
    byte(0xcb);
    be(std::bit_cast<std::uint64_t>(d), 8);
  }
  void bin(const std::uint8_t* p, std::size_t n) {
    byte(0xc4);
    byte(static_cast<std::uint8_t>(n));
    for (std::size_t i = 0; i < n; ++i) byte(p[i]);
  }
  void nil() { byte(0xc0); }

 private:
  std::span<std::uint8_t> out_;
  std::size_t n_ = 0;
  bool ok_ = true;
};

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> in) : in_(in) {}
  bool at_end() const { return pos_ == in_.size(); }
  bool get(std::uint8_t& b) {
    if (pos_ >= in_.size()) return false;
    b = in_[pos_++];
    return true;
  }
  bool be(std::uint64_t& v, int bytes) {
    v = 0;
    for (int i = 0; i < bytes; ++i) {
      std::uint8_t b;
      if (!get(b)) return false;
      v = (v << 8) | b;
    }
    return true;
  }
  bool take(std::size_t n, const std::uint8_t*& p) {
    if (in_.size() - pos_ < n) return false;
    p = in_.data() + pos_;
    pos_ += n;
    return true;
  }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
};

enum class Kind { nil, boolean, integer, floating, string, binary, array, map, invalid };

struct Value {
  Kind kind = Kind::invalid;
  bool b = false;
  bool negative = false;
  std::uint64_t u = 0;  ///< integer magnitude bits (two's complement when negative)
  double d = 0;
  const std::uint8_t* p = nullptr;  ///< string/binary bytes
  std::size_t n = 0;                ///< string/binary length, array/map count
};

/// Reads one value header (and the payload of scalars/strings/binaries).
bool read_value(Reader& r, Value& v) {
  std::uint8_t t;
  if (!r.get(t)) return false;
  std::uint64_t x = 0;
  if (t <= 0x7f) {
    v.kind = Kind::integer;
    v.u = t;
    return true;
  }
  if (t >= 0xe0) {
    v.kind = Kind::integer;
    v.negative = true;
    v.u = static_cast<std::uint64_t>(static_cast<std::int64_t>(static_cast<std::int8_t>(t)));
    return true;
  }
  if ((t & 0xf0) == 0x80) {
    v.kind = Kind::map;
    v.n = t & 0x0f;
    return true;
  }
  if ((t & 0xf0) == 0x90) {
    v.kind = Kind::array;
    v.n = t & 0x0f;
    return true;
  }
  if ((t & 0xe0) == 0xa0) {
    v.kind = Kind::string;
    v.n = t & 0x1f;
    return r.take(v.n, v.p);
  }
  switch (t) {
    case 0xc0: v.kind = Kind::nil; return true;
    case 0xc2: v.kind = Kind::boolean; v.b = false; return true;
    case 0xc3: v.kind = Kind::boolean; v.b = true; return true;
    case 0xc4: case 0xc5: case 0xc6:
    case 0xd9: case 0xda: case 0xdb: {
      const int lenbytes = (t == 0xc4 || t == 0xd9) ? 1 : (t == 0xc5 || t == 0xda) ? 2 : 4;
      if (!r.be(x, lenbytes)) return false;
      v.kind = t <= 0xc6 ? Kind::binary : Kind::string;
      v.n = static_cast<std::size_t>(x);
      return r.take(v.n, v.p);
    }
    case 0xca:
      if (!r.be(x, 4)) return false;
      v.kind = Kind::floating;
      v.d = static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(x)));
      return true;
    case 0xcb:
      if (!r.be(x, 8)) return false;
      v.kind = Kind::floating;
      v.d = std::bit_cast<double>(x);
      return true;
    case 0xcc: case 0xcd: case 0xce: case 0xcf: {
      const int bytes = 1 << (t - 0xcc);
      if (!r.be(x, bytes)) return false;
      v.kind = Kind::integer;
      v.u = x;
      return true;
    }
    case 0xd0: case 0xd1: case 0xd2: case 0xd3: {
      const int bytes = 1 << (t - 0xd0);
      if (!r.be(x, bytes)) return false;
      v.kind = Kind::integer;
      const int sh = 64 - 8 * bytes;
      const std::int64_t s = sh ? static_cast<std::int64_t>(x << sh) >> sh : static_cast<std::int64_t>(x);
      v.negative = s < 0;
      v.u = static_cast<std::uint64_t>(s);
      return true;
    }
    case 0xdc: case 0xdd:
      if (!r.be(x, t == 0xdc ? 2 : 4)) return false;
      v.kind = Kind::array;
      v.n = static_cast<std::size_t>(x);
      return true;
    case 0xde: case 0xdf:
      if (!r.be(x, t == 0xde ? 2 : 4)) return false;
      v.kind = Kind::map;
      v.n = static_cast<std::size_t>(x);
      return true;
    default:
      return false;  // ext types, 0xc1
  }
}

bool key_is(const Value& k, std::string_view name) {
  return k.n == name.size() && std::memcmp(k.p, name.data(), name.size()) == 0;
}

}  // namespace

const char* to_string(DecodeStatus s) noexcept {
  switch (s) {
    case DecodeStatus::ok: return "ok";
    case DecodeStatus::oversized: return "oversized";
    case DecodeStatus::malformed: return "malformed";
    case DecodeStatus::unknown_key: return "unknown key";
    case DecodeStatus::invalid: return "invalid frame";
    case DecodeStatus::error_frame: return "error frame";
  }
  return "?";
}

std::size_t encode_datagram(const Frame& f, double timestamp_s, std::span<std::uint8_t> out) noexcept {
  if (!f.valid() || f.error) return 0;
  Writer w(out);
  w.byte(0x8b);  // fixmap, 11 entries, in python-can's order
  w.str("timestamp");
  w.f64(timestamp_s);
  w.str("arbitration_id");
  w.uint(f.id);
  w.str("is_extended_id");
  w.boolean(f.extended);
  w.str("is_remote_frame");
  w.boolean(f.remote);
  w.str("is_error_frame");
  w.boolean(false);
  w.str("channel");
  w.nil();
  w.str("dlc");
  w.uint(f.len);
  w.str("data");
  w.bin(f.data.data(), f.remote ? 0 : f.len);
  w.str("is_fd");
  w.boolean(f.fd);
  w.str("bitrate_switch");
  w.boolean(f.brs);
  w.str("error_state_indicator");
  w.boolean(f.esi);
  return w.ok() ? w.size() : 0;
}

DecodeStatus decode_datagram(std::span<const std::uint8_t> in, Frame& out) noexcept {
  if (in.size() > kMaxDatagram) return DecodeStatus::oversized;
  Reader r(in);
  Value m;
  if (!read_value(r, m) || m.kind != Kind::map || m.n > 11) return DecodeStatus::malformed;
  Frame f;
  bool have_dlc = false;
  std::uint64_t dlc = 0;
  bool error_frame = false;
  bool fd_only_flag = false;
  std::size_t data_len = 0;
  std::uint8_t data[Frame::kMaxFdLen];
  bool bad_value = false;
  for (std::size_t i = 0; i < m.n; ++i) {
    Value k, v;
    if (!read_value(r, k) || k.kind != Kind::string) return DecodeStatus::malformed;
    if (!read_value(r, v)) return DecodeStatus::malformed;
    if (v.kind == Kind::map) return DecodeStatus::malformed;  // no nested maps in this format
    if (v.kind == Kind::array && !key_is(k, "data")) return DecodeStatus::malformed;
    if (key_is(k, "timestamp")) {
      if (v.kind == Kind::floating) {
        f.timestamp_s = v.d;
      } else if (v.kind == Kind::integer && !v.negative) {
        f.timestamp_s = static_cast<double>(v.u);
      } else if (v.kind != Kind::nil) {
        bad_value = true;
      }
    } else if (key_is(k, "arbitration_id")) {
      if (v.kind != Kind::integer || v.negative || v.u > 0x1FFFFFFFu) {
        bad_value = true;
      } else {
        f.id = static_cast<std::uint32_t>(v.u);
      }
    } else if (key_is(k, "is_extended_id") || key_is(k, "is_remote_frame") || key_is(k, "is_error_frame") ||
               key_is(k, "is_fd") || key_is(k, "bitrate_switch") || key_is(k, "error_state_indicator")) {
      if (v.kind != Kind::boolean) {
        bad_value = true;
        continue;
      }
      if (key_is(k, "is_extended_id")) f.extended = v.b;
      if (key_is(k, "is_remote_frame")) f.remote = v.b;
      if (key_is(k, "is_error_frame")) error_frame = v.b;
      if (key_is(k, "is_fd")) f.fd = v.b;
      if ((key_is(k, "bitrate_switch") || key_is(k, "error_state_indicator")) && v.b) fd_only_flag = true;
      if (key_is(k, "bitrate_switch")) f.brs = v.b;
      if (key_is(k, "error_state_indicator")) f.esi = v.b;
    } else if (key_is(k, "channel")) {
      // nil, a string or an int: ignored
    } else if (key_is(k, "dlc")) {
      if (v.kind != Kind::integer || v.negative) {
        bad_value = true;
      } else {
        have_dlc = true;
        dlc = v.u;
      }
    } else if (key_is(k, "data")) {
      if (v.kind == Kind::binary || v.kind == Kind::string) {
        if (v.n > Frame::kMaxFdLen) {
          bad_value = true;
          continue;
        }
        std::memcpy(data, v.p, v.n);
        data_len = v.n;
      } else if (v.kind == Kind::array) {
        if (v.n > Frame::kMaxFdLen) return DecodeStatus::malformed;
        for (std::size_t j = 0; j < v.n; ++j) {
          Value e;
          if (!read_value(r, e)) return DecodeStatus::malformed;
          if (e.kind != Kind::integer || e.negative || e.u > 255) {
            bad_value = true;
            if (e.kind == Kind::array || e.kind == Kind::map) return DecodeStatus::malformed;
            continue;
          }
          data[j] = static_cast<std::uint8_t>(e.u);
        }
        data_len = v.n;
      } else if (v.kind == Kind::nil) {
        data_len = 0;
      } else {
        bad_value = true;
      }
    } else {
      return DecodeStatus::unknown_key;
    }
  }
  if (!r.at_end()) return DecodeStatus::malformed;
  if (bad_value) return DecodeStatus::invalid;
  if (error_frame) return DecodeStatus::error_frame;
  if (fd_only_flag && !f.fd) return DecodeStatus::invalid;  // python-can: BRS/ESI need CAN FD
  if (!have_dlc) dlc = data_len;
  // python-can's Message(check=True) rules.
  if (f.remote) {
    if (f.fd || data_len != 0 || dlc > 8) return DecodeStatus::invalid;
  } else {
    if (dlc != data_len) return DecodeStatus::invalid;
    if (!f.fd && dlc > 8) return DecodeStatus::invalid;
  }
  if (!f.extended && f.id > 0x7FFu) return DecodeStatus::invalid;
  f.len = static_cast<std::uint8_t>(dlc);
  std::memcpy(f.data.data(), data, data_len);
  if (!f.valid()) return DecodeStatus::invalid;
  out = f;
  return DecodeStatus::ok;
}

}  // namespace lash::can::udp
