#include <cmath>
#include <cstring>
#include <stdexcept>

#include "lash/can/xcp.hpp"

namespace lash::can::xcp {

const char* to_string(Err e) noexcept {
  switch (e) {
    case Err::cmd_synch: return "ERR_CMD_SYNCH";
    case Err::cmd_busy: return "ERR_CMD_BUSY";
    case Err::daq_active: return "ERR_DAQ_ACTIVE";
    case Err::pgm_active: return "ERR_PGM_ACTIVE";
    case Err::cmd_unknown: return "ERR_CMD_UNKNOWN";
    case Err::cmd_syntax: return "ERR_CMD_SYNTAX";
    case Err::out_of_range: return "ERR_OUT_OF_RANGE";
    case Err::write_protected: return "ERR_WRITE_PROTECTED";
    case Err::access_denied: return "ERR_ACCESS_DENIED";
    case Err::access_locked: return "ERR_ACCESS_LOCKED";
    case Err::page_not_valid: return "ERR_PAGE_NOT_VALID";
    case Err::mode_not_valid: return "ERR_MODE_NOT_VALID";
    case Err::segment_not_valid: return "ERR_SEGMENT_NOT_VALID";
    case Err::sequence: return "ERR_SEQUENCE";
    case Err::daq_config: return "ERR_DAQ_CONFIG";
    case Err::memory_overflow: return "ERR_MEMORY_OVERFLOW";
    case Err::generic: return "ERR_GENERIC";
    case Err::verify: return "ERR_VERIFY";
  }
  return "ERR_?";
}

std::size_t size_of(Type t) noexcept {
  switch (t) {
    case Type::u8: case Type::i8: return 1;
    case Type::u16: case Type::i16: return 2;
    case Type::u32: case Type::i32: case Type::f32: return 4;
    case Type::f64: return 8;
  }
  return 0;
}

const char* a2l_name(Type t) noexcept {
  switch (t) {
    case Type::u8: return "UBYTE";
    case Type::i8: return "SBYTE";
    case Type::u16: return "UWORD";
    case Type::i16: return "SWORD";
    case Type::u32: return "ULONG";
    case Type::i32: return "SLONG";
    case Type::f32: return "FLOAT32_IEEE";
    case Type::f64: return "FLOAT64_IEEE";
  }
  return "?";
}

double decode(Type t, std::span<const std::uint8_t> b) noexcept {
  std::uint64_t u = 0;
  const std::size_t n = size_of(t);
  for (std::size_t i = 0; i < n && i < b.size(); ++i) u |= static_cast<std::uint64_t>(b[i]) << (8 * i);
  switch (t) {
    case Type::u8: return static_cast<double>(static_cast<std::uint8_t>(u));
    case Type::i8: return static_cast<double>(static_cast<std::int8_t>(u));
    case Type::u16: return static_cast<double>(static_cast<std::uint16_t>(u));
    case Type::i16: return static_cast<double>(static_cast<std::int16_t>(u));
    case Type::u32: return static_cast<double>(static_cast<std::uint32_t>(u));
    case Type::i32: return static_cast<double>(static_cast<std::int32_t>(u));
    case Type::f32: {
      const auto v = static_cast<std::uint32_t>(u);
      float f;
      std::memcpy(&f, &v, 4);
      return static_cast<double>(f);
    }
    case Type::f64: {
      double d;
      std::memcpy(&d, &u, 8);
      return d;
    }
  }
  return 0.0;
}

void encode(Type t, double v, std::span<std::uint8_t> out) noexcept {
  std::uint64_t u = 0;
  switch (t) {
    case Type::f32: {
      const float f = static_cast<float>(v);
      std::uint32_t w;
      std::memcpy(&w, &f, 4);
      u = w;
      break;
    }
    case Type::f64: std::memcpy(&u, &v, 8); break;
    default: u = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::llround(v))); break;
  }
  const std::size_t n = size_of(t);
  for (std::size_t i = 0; i < n && i < out.size(); ++i) out[i] = static_cast<std::uint8_t>(u >> (8 * i));
}

namespace {
std::size_t id_area(const SlaveConfig& c) { return c.epk.size() + c.ascii_id.size() + c.a2l_name.size(); }
}  // namespace

void SlaveConfig::validate() const {
  if (cmd_id > 0x7FF || res_id > 0x7FF || cmd_id == res_id)
    throw std::invalid_argument("xcp: CAN ids must be distinct 11-bit ids");
  if (epk.size() > 255 || ascii_id.size() > 255 || a2l_name.size() > 255)
    throw std::invalid_argument("xcp: identification strings are at most 255 bytes");
  if (max_daq == 0 || max_odt == 0 || max_odt > 0xFC || max_entries == 0)
    throw std::invalid_argument("xcp: DAQ pools must be non-empty (at most 252 ODTs: PIDs 0xFC..0xFF are reserved)");
  const std::uint64_t lo = static_cast<std::uint64_t>(epk_address) + id_area(*this);
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const Object& a = objects[i];
    if (a.name.empty()) throw std::invalid_argument("xcp: an object without a name");
    if (!std::isfinite(a.min) || !std::isfinite(a.max) || a.min > a.max)
      throw std::invalid_argument("xcp: object " + a.name + ": limits must be finite with min <= max");
    if (a.address < lo) throw std::invalid_argument("xcp: object " + a.name + " overlaps the identification area");
    for (std::size_t j = 0; j < i; ++j) {
      const Object& b = objects[j];
      if (a.name == b.name) throw std::invalid_argument("xcp: two objects named " + a.name);
      if (a.address < b.address + size_of(b.type) && b.address < a.address + size_of(a.type))
        throw std::invalid_argument("xcp: objects " + a.name + " and " + b.name + " overlap");
    }
  }
}

Slave::Slave(SlaveConfig config, Send send, OnWrite on_write)
    : cfg_(std::move(config)), send_(std::move(send)), on_write_(std::move(on_write)) {
  cfg_.validate();
  std::size_t size = id_area(cfg_);
  for (const auto& o : cfg_.objects) size = std::max<std::size_t>(size, o.address - cfg_.epk_address + size_of(o.type));
  image_.assign(size, 0);
  std::size_t at = 0;
  for (const std::string* s : {&cfg_.epk, &cfg_.ascii_id, &cfg_.a2l_name}) {
    std::memcpy(image_.data() + at, s->data(), s->size());
    at += s->size();
  }
  lists_.resize(cfg_.max_daq);
  odts_.resize(cfg_.max_odt);
  entries_.resize(cfg_.max_entries);
}

const Object* Slave::find(std::string_view name) const noexcept {
  for (const auto& o : cfg_.objects)
    if (o.name == name) return &o;
  return nullptr;
}

double Slave::get(const Object& o) const noexcept {
  return decode(o.type, std::span<const std::uint8_t>(image_).subspan(o.address - cfg_.epk_address, size_of(o.type)));
}

void Slave::set(const Object& o, double v) noexcept {
  encode(o.type, v, std::span<std::uint8_t>(image_).subspan(o.address - cfg_.epk_address, size_of(o.type)));
}

bool Slave::daq_running() const noexcept {
  for (std::uint16_t i = 0; i < n_lists_; ++i)
    if (lists_[i].running) return true;
  return false;
}

void Slave::disconnect() noexcept {
  connected_ = false;
  block_left_ = 0;
  for (auto& l : lists_) l.running = l.selected = false;
}

void Slave::respond(std::span<const std::uint8_t> bytes) {
  Frame f;
  f.id = cfg_.res_id;
  f.len = static_cast<std::uint8_t>(std::min<std::size_t>(bytes.size(), kMaxCto));
  std::memcpy(f.data.data(), bytes.data(), f.len);
  send_(f);
}

void Slave::error(Err e, std::span<const std::uint8_t> extra) {
  std::uint8_t b[kMaxCto] = {kPidError, static_cast<std::uint8_t>(e)};
  const std::size_t n = std::min<std::size_t>(extra.size(), kMaxCto - 2);
  std::memcpy(b + 2, extra.data(), n);
  ++errors_;
  respond({b, 2 + n});
}

bool Slave::in_image(std::uint32_t address, std::size_t len) const noexcept {
  return address >= cfg_.epk_address && static_cast<std::uint64_t>(address - cfg_.epk_address) + len <= image_.size();
}

// A write is taken whole or not at all: every byte must belong to a calibration object, and
// every object it touches must hold, with the new bytes merged in, a value inside its limits.
Err Slave::check_write(std::uint32_t address, std::span<const std::uint8_t> bytes) const {
  if (!in_image(address, bytes.size())) return Err::access_denied;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const std::uint32_t a = address + static_cast<std::uint32_t>(i);
    const Object* hit = nullptr;
    for (const auto& o : cfg_.objects)
      if (a >= o.address && a < o.address + size_of(o.type)) hit = &o;
    if (!hit) return a < cfg_.epk_address + id_area(cfg_) ? Err::write_protected : Err::access_denied;
    if (hit->kind != Kind::characteristic) return Err::write_protected;
  }
  for (const auto& o : cfg_.objects) {
    const std::size_t n = std::min<std::size_t>(size_of(o.type), 8);
    if (o.kind != Kind::characteristic || o.address + n <= address || address + bytes.size() <= o.address) continue;
    std::uint8_t merged[8];
    std::memcpy(merged, image_.data() + (o.address - cfg_.epk_address), n);
    for (std::size_t k = 0; k < n && k < sizeof merged; ++k) {
      const std::int64_t at = static_cast<std::int64_t>(o.address + k) - address;
      if (at >= 0 && at < static_cast<std::int64_t>(bytes.size())) merged[k] = bytes[static_cast<std::size_t>(at)];
    }
    const double v = decode(o.type, {merged, n});
    if (!std::isfinite(v) || v < o.min || v > o.max) return Err::out_of_range;
    if (!o.names.empty() && v != std::floor(v)) return Err::out_of_range;  // a named value: an integer
  }
  return Err::cmd_synch;  // "no error" (cmd_synch is never a write's verdict)
}

void Slave::finish_download() {
  const std::span<const std::uint8_t> bytes(block_.data(), block_len_);
  block_left_ = 0;
  const Err e = check_write(block_address_, bytes);
  if (e != Err::cmd_synch) return error(e);
  std::memcpy(image_.data() + (block_address_ - cfg_.epk_address), bytes.data(), bytes.size());
  mta_ = block_address_ + static_cast<std::uint32_t>(bytes.size());
  if (on_write_) on_write_(block_address_, bytes.size());
  const std::uint8_t ok[] = {kPidResponse};
  respond(ok);
}

bool Slave::on_frame(const Frame& f) {
  if (f.id != cfg_.cmd_id || f.extended || f.remote || f.error || f.fd) return false;
  ++commands_;
  if (f.len == 0) {  // no command code: nothing to answer but a syntax error
    if (connected_) error(Err::cmd_syntax);
    return true;
  }
  const std::uint8_t code = f.data[0];
  if (!connected_ && code != cmd::connect) return true;  // DISCONNECTED answers CONNECT only (Part 2, state machine)
  // A block transfer is interrupted by any command but its DOWNLOAD_NEXT.
  if (code != cmd::download_next) block_left_ = 0;
  command(f);
  return true;
}

void Slave::command(const Frame& f) {
  const std::uint8_t code = f.data[0];
  const std::uint8_t* d = f.data.data();
  auto need = [&](std::uint8_t n) {
    if (f.len >= n) return true;
    error(Err::cmd_syntax);
    return false;
  };
  switch (code) {
    case cmd::connect: {
      if (!need(2)) return;
      if (d[1] > 1) return error(Err::out_of_range);
      connected_ = true;
      std::uint8_t r[8] = {kPidResponse, kResourceCalPag | kResourceDaq, kCommModeSlaveBlock | kCommModeOptional,
                           kMaxCto, 0, 0, 0x01, 0x01};
      put_u16(r + 4, kMaxDto);
      return respond(r);
    }
    case cmd::disconnect: {
      const std::uint8_t r[] = {kPidResponse};
      respond(r);
      disconnect();
      return;
    }
    case cmd::get_status: {
      const std::uint8_t r[] = {kPidResponse, static_cast<std::uint8_t>(daq_running() ? kSessionDaqRunning : 0), 0, 0, 0, 0};
      return respond(r);
    }
    case cmd::synch: return error(Err::cmd_synch);
    case cmd::get_comm_mode_info: {
      const std::uint8_t r[] = {kPidResponse, 0, kCommOptionalMasterBlock, 0, kMaxBs, 0, 0, 0x10};
      return respond(r);
    }
    case cmd::get_id: {
      if (!need(2)) return;
      std::uint32_t at = cfg_.epk_address;
      std::size_t len = 0;
      if (d[1] == kIdEpk) {
        len = cfg_.epk.size();
      } else if (d[1] == kIdAscii) {
        at += static_cast<std::uint32_t>(cfg_.epk.size());
        len = cfg_.ascii_id.size();
      } else if (d[1] == kIdAsamName) {
        at += static_cast<std::uint32_t>(cfg_.epk.size() + cfg_.ascii_id.size());
        len = cfg_.a2l_name.size();
      } else {
        return error(Err::out_of_range);
      }
      mta_ = at;
      std::uint8_t r[8] = {kPidResponse, 0, 0, 0};
      put_u32(r + 4, static_cast<std::uint32_t>(len));
      return respond(r);
    }
    case cmd::set_mta: {
      if (!need(8)) return;
      if (d[3] != 0) return error(Err::out_of_range);
      mta_ = get_u32(d + 4);
      const std::uint8_t r[] = {kPidResponse};
      return respond(r);
    }
    case cmd::upload:
    case cmd::short_upload: {
      const bool s = code == cmd::short_upload;
      if (!need(s ? 8 : 2)) return;
      const std::uint8_t n = d[1];
      if (n == 0 || (s && n > kMaxCto - 1)) return error(Err::out_of_range);
      if (s) {
        if (d[3] != 0) return error(Err::out_of_range);
        mta_ = get_u32(d + 4);
      }
      if (!in_image(mta_, n)) return error(Err::access_denied);
      // Slave block mode (COMM_MODE_BASIC bit 6): n bytes in ⌈n/7⌉ responses.
      const std::uint8_t* src = image_.data() + (mta_ - cfg_.epk_address);
      for (std::size_t at = 0; at < n; at += kMaxCto - 1) {
        std::uint8_t r[kMaxCto] = {kPidResponse};
        const std::size_t k = std::min<std::size_t>(n - at, kMaxCto - 1);
        std::memcpy(r + 1, src + at, k);
        respond({r, 1 + k});
      }
      mta_ += n;
      return;
    }
    case cmd::download: {
      if (!need(2)) return;
      const std::size_t n = d[1];
      if (n == 0 || n > block_.size()) return error(Err::out_of_range);
      const std::size_t k = std::min<std::size_t>(n, kMaxCto - 2);
      if (!need(static_cast<std::uint8_t>(2 + k))) return;
      std::memcpy(block_.data(), d + 2, k);
      block_len_ = k;
      block_address_ = mta_;
      block_left_ = n - k;
      if (block_left_ == 0) finish_download();  // else: master block mode, no response until the last DOWNLOAD_NEXT
      return;
    }
    case cmd::download_next: {
      if (!need(2)) return;
      if (block_left_ == 0) return error(Err::sequence);
      if (d[1] != block_left_) {  // DOWNLOAD_NEXT: ERR_SEQUENCE + the number of elements expected
        const std::uint8_t expected[] = {static_cast<std::uint8_t>(block_left_)};
        block_left_ = 0;
        return error(Err::sequence, expected);
      }
      const std::size_t k = std::min<std::size_t>(block_left_, kMaxCto - 2);
      if (f.len < 2 + k) {
        block_left_ = 0;
        return error(Err::cmd_syntax);
      }
      std::memcpy(block_.data() + block_len_, d + 2, k);
      block_len_ += k;
      block_left_ -= k;
      if (block_left_ == 0) finish_download();
      return;
    }
    default: return daq_command(f, code);
  }
}

void Slave::daq_command(const Frame& f, std::uint8_t code) {
  const std::uint8_t* d = f.data.data();
  auto need = [&](std::uint8_t n) {
    if (f.len >= n) return true;
    error(Err::cmd_syntax);
    return false;
  };
  const std::uint8_t ok[] = {kPidResponse};
  switch (code) {
    case cmd::free_daq:
      for (auto& l : lists_) l = DaqList{};
      n_lists_ = n_odts_ = n_entries_ = 0;
      stage_ = AllocStage::freed;
      ptr_valid_ = false;
      return respond(ok);
    case cmd::alloc_daq: {
      if (!need(4)) return;
      if (stage_ == AllocStage::odt || stage_ == AllocStage::entry) return error(Err::sequence);
      const std::uint16_t n = get_u16(d + 2);
      if (n > cfg_.max_daq) return error(Err::memory_overflow);
      n_lists_ = n;
      stage_ = AllocStage::daq;
      return respond(ok);
    }
    case cmd::alloc_odt: {
      if (!need(5)) return;
      if (stage_ != AllocStage::daq && stage_ != AllocStage::odt) return error(Err::sequence);
      const std::uint16_t l = get_u16(d + 2);
      if (l >= n_lists_) return error(Err::out_of_range);
      if (lists_[l].odts != 0) return error(Err::sequence);
      if (n_odts_ + d[4] > cfg_.max_odt) return error(Err::memory_overflow);
      lists_[l].first_odt = n_odts_;
      lists_[l].odts = d[4];
      for (std::uint8_t i = 0; i < d[4]; ++i) odts_[n_odts_ + i] = Odt{};
      n_odts_ = static_cast<std::uint16_t>(n_odts_ + d[4]);
      stage_ = AllocStage::odt;
      return respond(ok);
    }
    case cmd::alloc_odt_entry: {
      if (!need(6)) return;
      if (stage_ != AllocStage::odt && stage_ != AllocStage::entry) return error(Err::sequence);
      const std::uint16_t l = get_u16(d + 2);
      if (l >= n_lists_ || d[4] >= lists_[l].odts) return error(Err::out_of_range);
      Odt& o = odts_[lists_[l].first_odt + d[4]];
      if (o.entries != 0) return error(Err::sequence);
      if (n_entries_ + d[5] > cfg_.max_entries) return error(Err::memory_overflow);
      o.first_entry = n_entries_;
      o.entries = d[5];
      for (std::uint8_t i = 0; i < d[5]; ++i) entries_[n_entries_ + i] = Entry{};
      n_entries_ = static_cast<std::uint16_t>(n_entries_ + d[5]);
      stage_ = AllocStage::entry;
      return respond(ok);
    }
    case cmd::set_daq_ptr: {
      if (!need(6)) return;
      const std::uint16_t l = get_u16(d + 2);
      if (l >= n_lists_ || d[4] >= lists_[l].odts) return error(Err::out_of_range);
      const Odt& o = odts_[lists_[l].first_odt + d[4]];
      if (d[5] >= o.entries) return error(Err::out_of_range);
      if (lists_[l].running) return error(Err::daq_active);
      ptr_list_ = l;
      ptr_entry_ = static_cast<std::uint16_t>(o.first_entry + d[5]);
      ptr_end_ = static_cast<std::uint16_t>(o.first_entry + o.entries);
      ptr_valid_ = true;
      return respond(ok);
    }
    case cmd::write_daq: {
      if (!need(8)) return;
      if (!ptr_valid_) return error(Err::sequence);
      if (ptr_entry_ >= ptr_end_) return error(Err::out_of_range);
      if (d[1] != 0xFF || d[2] == 0 || d[2] > kMaxOdtEntrySize || d[3] != 0) return error(Err::out_of_range);
      const std::uint32_t a = get_u32(d + 4);
      if (!in_image(a, d[2])) return error(Err::access_denied);
      entries_[ptr_entry_++] = Entry{a, d[2]};
      return respond(ok);
    }
    case cmd::set_daq_list_mode: {
      if (!need(8)) return;
      const std::uint16_t l = get_u16(d + 2);
      if (l >= n_lists_ || get_u16(d + 4) != 0 || d[6] == 0) return error(Err::out_of_range);
      if (d[1] & (kDaqModePidOff | kDaqModeDirectionStim)) return error(Err::mode_not_valid);
      if (lists_[l].running) return error(Err::daq_active);
      lists_[l].mode = d[1];
      lists_[l].event = get_u16(d + 4);
      lists_[l].prescaler = d[6];
      return respond(ok);
    }
    case cmd::start_stop_daq_list: {
      if (!need(4)) return;
      const std::uint16_t l = get_u16(d + 2);
      if (l >= n_lists_ || d[1] > 2) return error(Err::out_of_range);
      DaqList& L = lists_[l];
      if (d[1] != 0) {  // start or select: every ODT must be filled and fit one DTO
        if (L.odts == 0) return error(Err::daq_config);
        for (std::uint8_t i = 0; i < L.odts; ++i) {
          const Odt& o = odts_[L.first_odt + i];
          std::size_t bytes = 1 + ((i == 0 && (L.mode & kDaqModeTimestamp)) ? kTimestampSize : 0);
          for (std::uint8_t e = 0; e < o.entries; ++e) {
            if (entries_[o.first_entry + e].size == 0) return error(Err::daq_config);
            bytes += entries_[o.first_entry + e].size;
          }
          if (o.entries == 0 || bytes > kMaxDto) return error(Err::daq_config);
        }
      }
      if (d[1] == 0) L.running = L.selected = false;
      if (d[1] == 1) { L.running = true; L.count = 0; }
      if (d[1] == 2) L.selected = true;
      const std::uint8_t r[] = {kPidResponse, static_cast<std::uint8_t>(L.first_odt)};
      return respond(r);
    }
    case cmd::start_stop_synch: {
      if (!need(2)) return;
      if (d[1] > 2) return error(Err::out_of_range);
      for (std::uint16_t i = 0; i < n_lists_; ++i) {
        DaqList& L = lists_[i];
        if (d[1] == 0) L.running = false;
        if (d[1] == 1 && L.selected) { L.running = true; L.count = 0; }
        if (d[1] == 2 && L.selected) L.running = false;
        L.selected = false;
      }
      return respond(ok);
    }
    case cmd::get_daq_processor_info: {
      std::uint8_t r[8] = {kPidResponse, kDaqPropDynamic | kDaqPropTimestamp, 0, 0, 1, 0, 0, 0x00};
      put_u16(r + 2, cfg_.max_daq);
      return respond(r);
    }
    case cmd::get_daq_resolution_info: {
      std::uint8_t r[8] = {kPidResponse, 1, kMaxOdtEntrySize, 1, 0, kTimestampMode, 0, 0};
      put_u16(r + 6, 1);
      return respond(r);
    }
    default: return error(Err::cmd_unknown);
  }
}

void Slave::sample_event(std::uint16_t event, std::uint32_t timestamp) {
  for (std::uint16_t i = 0; i < n_lists_; ++i) {
    DaqList& L = lists_[i];
    if (!L.running || L.event != event) continue;
    if (++L.count < L.prescaler) continue;
    L.count = 0;
    for (std::uint8_t k = 0; k < L.odts; ++k) {
      const Odt& o = odts_[L.first_odt + k];
      Frame f;
      f.id = cfg_.res_id;
      std::size_t at = 0;
      f.data[at++] = static_cast<std::uint8_t>(L.first_odt + k);  // absolute ODT number
      if (k == 0 && (L.mode & kDaqModeTimestamp)) {
        put_u32(f.data.data() + at, timestamp);
        at += kTimestampSize;
      }
      for (std::uint8_t e = 0; e < o.entries; ++e) {
        const Entry& en = entries_[o.first_entry + e];
        std::memcpy(f.data.data() + at, image_.data() + (en.address - cfg_.epk_address), en.size);
        at += en.size;
      }
      f.len = static_cast<std::uint8_t>(at);
      send_(f);
      ++dtos_;
    }
  }
}

}  // namespace lash::can::xcp
