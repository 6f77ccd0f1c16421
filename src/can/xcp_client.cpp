#include "lash/can/xcp_client.hpp"

#include <cstring>

namespace lash::can::xcp {

Client::Client(Bus& bus, std::uint32_t cmd_id, std::uint32_t res_id, std::chrono::milliseconds timeout)
    : bus_(bus), cmd_id_(cmd_id), res_id_(res_id), timeout_(timeout) {}

namespace {
const char* name_of(std::uint8_t code) {
  switch (code) {
    case cmd::connect: return "CONNECT";
    case cmd::disconnect: return "DISCONNECT";
    case cmd::get_id: return "GET_ID";
    case cmd::set_mta: return "SET_MTA";
    case cmd::upload: return "UPLOAD";
    case cmd::download: return "DOWNLOAD";
    case cmd::download_next: return "DOWNLOAD_NEXT";
    default: return "command";
  }
}
}  // namespace

// A DTO (PID below 0xFC) that arrives while a command waits is kept for the DAQ reader.
bool Client::take_dto(const Frame& f) {
  if (f.id != res_id_ || f.len == 0 || f.data[0] >= 0xFC) return false;
  if (odts_.empty()) return true;
  const std::size_t k = static_cast<std::size_t>(f.data[0]) - first_pid_;
  if (f.data[0] < first_pid_ || k >= odts_.size()) return true;
  std::size_t at = 1;
  if (k == 0) {
    if (next_odt_ != 0) ++incomplete_;
    if (f.len < 1 + kTimestampSize) return true;
    ts_ = get_u32(f.data.data() + 1);
    at += kTimestampSize;
    next_odt_ = 0;
  } else if (k != next_odt_) {  // an ODT lost: drop the sample
    if (next_odt_ != 0) ++incomplete_;
    next_odt_ = 0;
    return true;
  }
  for (const Piece& p : odts_[k]) {
    if (at + p.size > f.len) {
      ++incomplete_;
      next_odt_ = 0;
      return true;
    }
    std::memcpy(raw_.data() + raw_at_[p.object] + p.offset, f.data.data() + at, p.size);
    at += p.size;
  }
  next_odt_ = k + 1;
  if (next_odt_ == odts_.size()) {
    DaqSample s;
    s.timestamp_us = ts_;
    for (std::size_t i = 0; i < daq_objects_.size(); ++i)
      s.values.push_back(decode(daq_objects_[i].type, {raw_.data() + raw_at_[i], size_of(daq_objects_[i].type)}));
    ready_.push_back(std::move(s));
    next_odt_ = 0;
  }
  return true;
}

std::vector<std::uint8_t> Client::command(std::span<const std::uint8_t> cto) {
  Frame f;
  f.id = cmd_id_;
  f.len = static_cast<std::uint8_t>(cto.size());
  std::memcpy(f.data.data(), cto.data(), cto.size());
  if (!bus_.send(f)) throw XcpError(std::string("xcp: cannot send ") + name_of(cto[0]), std::nullopt);
  const auto deadline = std::chrono::steady_clock::now() + timeout_;
  for (;;) {
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds(0)) break;
    auto r = bus_.receive(std::chrono::duration_cast<std::chrono::nanoseconds>(left));
    if (!r || r->extended || r->id != res_id_ || r->len == 0) continue;
    if (take_dto(*r)) continue;
    if (r->data[0] == kPidResponse) return {r->data.begin(), r->data.begin() + r->len};
    if (r->data[0] == kPidError) {
      const auto e = static_cast<Err>(r->len > 1 ? r->data[1] : 0x31);
      throw XcpError(std::string("xcp: ") + name_of(cto[0]) + " refused: " + to_string(e), e);
    }
  }
  throw XcpError(std::string("xcp: no response to ") + name_of(cto[0]) + " within " +
                     std::to_string(timeout_.count()) + " ms (is the ECU connected to this bus?)",
                 std::nullopt);
}

ConnectInfo Client::connect() {
  const std::uint8_t c[] = {cmd::connect, 0x00};
  const auto r = command(c);
  if (r.size() < 8) throw XcpError("xcp: short CONNECT response", std::nullopt);
  ConnectInfo i{r[1], r[2], r[3], get_u16(r.data() + 4), r[6], r[7]};
  if (i.comm_mode_basic & 0x01) throw XcpError("xcp: the slave is Motorola byte order; only Intel is read", std::nullopt);
  return i;
}

void Client::disconnect() {
  const std::uint8_t c[] = {cmd::disconnect};
  command(c);
}

std::vector<std::uint8_t> Client::upload(std::uint32_t address, std::size_t n) {
  std::uint8_t m[8] = {cmd::set_mta, 0, 0, 0};
  put_u32(m + 4, address);
  command(m);
  std::vector<std::uint8_t> out;
  while (out.size() < n) {
    const auto k = static_cast<std::uint8_t>(std::min<std::size_t>(n - out.size(), 7));
    const std::uint8_t u[] = {cmd::upload, k};
    const auto r = command(u);
    out.insert(out.end(), r.begin() + 1, r.end());
  }
  out.resize(n);
  return out;
}

std::string Client::get_id(std::uint8_t type) {
  const std::uint8_t c[] = {cmd::get_id, type};
  const auto r = command(c);
  const std::uint32_t len = r.size() >= 8 ? get_u32(r.data() + 4) : 0;
  std::string s;
  while (s.size() < len) {  // the MTA points at the identification
    const auto k = static_cast<std::uint8_t>(std::min<std::size_t>(len - s.size(), 7));
    const std::uint8_t u[] = {cmd::upload, k};
    const auto p = command(u);
    s.append(p.begin() + 1, p.end());
  }
  s.resize(len);
  return s;
}

void Client::download(std::uint32_t address, std::span<const std::uint8_t> bytes) {
  std::uint8_t m[8] = {cmd::set_mta, 0, 0, 0};
  put_u32(m + 4, address);
  command(m);
  // Master block mode: DOWNLOAD carries the whole count, DOWNLOAD_NEXT the rest; the slave
  // answers the last packet only.
  const std::size_t n = bytes.size();
  std::size_t at = std::min<std::size_t>(n, 6);
  std::uint8_t d[8] = {cmd::download, static_cast<std::uint8_t>(n)};
  std::memcpy(d + 2, bytes.data(), at);
  if (at == n) {
    command({d, 2 + at});
    return;
  }
  Frame f;
  f.id = cmd_id_;
  f.len = static_cast<std::uint8_t>(2 + at);
  std::memcpy(f.data.data(), d, f.len);
  if (!bus_.send(f)) throw XcpError("xcp: cannot send DOWNLOAD", std::nullopt);
  while (at < n) {
    const std::size_t k = std::min<std::size_t>(n - at, 6);
    std::uint8_t x[8] = {cmd::download_next, static_cast<std::uint8_t>(n - at)};
    std::memcpy(x + 2, bytes.data() + at, k);
    at += k;
    if (at == n) {
      command({x, 2 + k});
    } else {
      Frame g;
      g.id = cmd_id_;
      g.len = static_cast<std::uint8_t>(2 + k);
      std::memcpy(g.data.data(), x, g.len);
      if (!bus_.send(g)) throw XcpError("xcp: cannot send DOWNLOAD_NEXT", std::nullopt);
    }
  }
}

double Client::read(const Object& o) {
  const auto b = upload(o.address, size_of(o.type));
  return decode(o.type, b);
}

void Client::write(const Object& o, double value) {
  std::uint8_t b[8];
  encode(o.type, value, b);
  download(o.address, {b, size_of(o.type)});
}

void Client::start_daq(std::span<const Object> objects) {
  daq_objects_.assign(objects.begin(), objects.end());
  raw_at_.clear();
  std::size_t total = 0;
  for (const auto& o : daq_objects_) {
    raw_at_.push_back(total);
    total += size_of(o.type);
  }
  raw_.assign(total, 0);
  // Lay the bytes out over ODTs: 3 data bytes in the first (after the timestamp), 7 in the others.
  odts_.assign(1, {});
  std::size_t room = kMaxDto - 1 - kTimestampSize;
  for (std::size_t i = 0; i < daq_objects_.size(); ++i) {
    std::size_t off = 0;
    const std::size_t n = size_of(daq_objects_[i].type);
    while (off < n) {
      if (room == 0) {
        odts_.emplace_back();
        room = kMaxDto - 1;
      }
      const std::size_t k = std::min(room, n - off);
      odts_.back().push_back(Piece{i, off, k});
      off += k;
      room -= k;
    }
  }
  const std::uint8_t free_daq[] = {cmd::free_daq};
  command(free_daq);
  const std::uint8_t alloc_daq[] = {cmd::alloc_daq, 0, 1, 0};
  command(alloc_daq);
  const std::uint8_t alloc_odt[] = {cmd::alloc_odt, 0, 0, 0, static_cast<std::uint8_t>(odts_.size())};
  command(alloc_odt);
  for (std::size_t k = 0; k < odts_.size(); ++k) {
    const std::uint8_t e[] = {cmd::alloc_odt_entry, 0, 0, 0, static_cast<std::uint8_t>(k),
                              static_cast<std::uint8_t>(odts_[k].size())};
    command(e);
  }
  for (std::size_t k = 0; k < odts_.size(); ++k) {
    const std::uint8_t p[] = {cmd::set_daq_ptr, 0, 0, 0, static_cast<std::uint8_t>(k), 0};
    command(p);
    for (const Piece& pc : odts_[k]) {
      std::uint8_t w[8] = {cmd::write_daq, 0xFF, static_cast<std::uint8_t>(pc.size), 0};
      put_u32(w + 4, daq_objects_[pc.object].address + static_cast<std::uint32_t>(pc.offset));
      command(w);
    }
  }
  const std::uint8_t mode[] = {cmd::set_daq_list_mode, kDaqModeTimestamp, 0, 0, 0, 0, 1, 0};
  command(mode);
  const std::uint8_t select[] = {cmd::start_stop_daq_list, 2, 0, 0};
  first_pid_ = command(select).at(1);
  next_odt_ = 0;
  ready_.clear();
  const std::uint8_t start[] = {cmd::start_stop_synch, 1};
  command(start);
}

std::optional<DaqSample> Client::next_sample(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (ready_.empty()) {
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds(0)) return std::nullopt;
    auto r = bus_.receive(std::chrono::duration_cast<std::chrono::nanoseconds>(left));
    if (r && !r->extended) take_dto(*r);
  }
  DaqSample s = std::move(ready_.front());
  ready_.pop_front();
  return s;
}

void Client::stop_daq() {
  const std::uint8_t stop[] = {cmd::start_stop_synch, 0};
  command(stop);
  odts_.clear();
}

}  // namespace lash::can::xcp
