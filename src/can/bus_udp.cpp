// UDP multicast bus, wire-compatible with python-can's udp_multicast interface.
//
// Address: udp:[GROUP[:PORT]][,iface=NAME|IPV4][,ttl=N]
//   default group 239.74.163.2, port 43113 (python-can's defaults).
//   By default the bus stays on this host: it joins the group and sends on the
//   loopback interface (127.0.0.1) with TTL 0. `iface=` names another interface
//   (by name or IPv4 address) explicitly; `ttl=` sets the multicast TTL.
// Own frames: sending uses a second socket bound to (interface address, ephemeral
// port); received datagrams whose source equals that address are ours and are
// skipped, so a node never receives its own frames while other processes on the
// same host (multicast loop on) do.
#include <arpa/inet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <mutex>

#include <fmt/core.h>

#include "bus_internal.hpp"
#include "lash/can/datagram.hpp"
#include "lash/io/error.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::can::detail {
namespace {

[[noreturn]] void fail(const std::string& msg) { throw InputError("", 0, "bus", "udp: " + msg); }

double realtime_now() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

struct UdpOptions {
  std::string group = "239.74.163.2";
  std::uint16_t port = 43113;
  std::string iface = "127.0.0.1";
  int ttl = 0;
};

UdpOptions parse_options(const std::string& spec) {
  UdpOptions o;
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= spec.size()) {
    auto comma = spec.find(',', start);
    if (comma == std::string::npos) comma = spec.size();
    parts.push_back(spec.substr(start, comma - start));
    start = comma + 1;
  }
  const std::string& addr = parts[0];
  if (!addr.empty()) {
    const auto colon = addr.find(':');
    o.group = addr.substr(0, colon);
    if (colon != std::string::npos) {
      const std::string p = addr.substr(colon + 1);
      unsigned v = 0;
      auto r = std::from_chars(p.data(), p.data() + p.size(), v);
      if (r.ec != std::errc() || r.ptr != p.data() + p.size() || v == 0 || v > 65535)
        fail("bad port '" + p + "' (1..65535)");
      o.port = static_cast<std::uint16_t>(v);
    }
  }
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const auto eq = parts[i].find('=');
    const std::string key = parts[i].substr(0, eq);
    const std::string val = eq == std::string::npos ? std::string() : parts[i].substr(eq + 1);
    if (key == "iface" && !val.empty()) {
      o.iface = val;
    } else if (key == "ttl") {
      int v = -1;
      auto r = std::from_chars(val.data(), val.data() + val.size(), v);
      if (r.ec != std::errc() || r.ptr != val.data() + val.size() || v < 0 || v > 255)
        fail("bad ttl '" + val + "' (0..255)");
      o.ttl = v;
    } else {
      fail("unknown option '" + parts[i] + "' (iface=NAME|IPV4, ttl=N)");
    }
  }
  in_addr g{};
  if (inet_pton(AF_INET, o.group.c_str(), &g) != 1 || (ntohl(g.s_addr) >> 28) != 0xE)
    fail("'" + o.group + "' is not an IPv4 multicast group (224.0.0.0/4)");
  return o;
}

/// IPv4 address of an interface given by address or name.
in_addr interface_address(const std::string& iface) {
  in_addr a{};
  if (inet_pton(AF_INET, iface.c_str(), &a) == 1) return a;
  if (iface.size() >= IFNAMSIZ) fail("interface name too long: " + iface);
  const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (s < 0) fail(std::string("socket: ") + std::strerror(errno));
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, iface.c_str(), iface.size());
  const int rc = ::ioctl(s, SIOCGIFADDR, &ifr);
  const int err = errno;
  ::close(s);
  if (rc < 0) fail("interface '" + iface + "' has no IPv4 address: " + std::strerror(err));
  sockaddr_in sin{};
  std::memcpy(&sin, &ifr.ifr_addr, sizeof sin);
  return sin.sin_addr;
}

class UdpBus final : public Bus {
 public:
  explicit UdpBus(const std::string& spec) : spec_(spec) {
    const UdpOptions o = parse_options(spec);
    opts_ = o;
    in_addr group{};
    inet_pton(AF_INET, o.group.c_str(), &group);
    const in_addr ifaddr = interface_address(o.iface);

    // Receive socket: bound to the group and port, member on the chosen interface.
    rx_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (rx_ < 0) fail(std::string("socket: ") + std::strerror(errno));
    const int one = 1;
    ::setsockopt(rx_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    ::setsockopt(rx_, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one);
    // Room for about a thousand queued datagrams (a burst, or a flood read at a bounded rate);
    // the kernel caps it at net.core.rmem_max.
    const int rcvbuf = 1 << 20;
    ::setsockopt(rx_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    sockaddr_in bind_addr{};
    bind_addr.sin_family = AF_INET;
    bind_addr.sin_port = htons(o.port);
    bind_addr.sin_addr = group;
    if (::bind(rx_, reinterpret_cast<sockaddr*>(&bind_addr), sizeof bind_addr) < 0)
      fail_close(fmt::format("cannot bind {}:{}: {}", o.group, o.port, std::strerror(errno)));
    ip_mreq mreq{};
    mreq.imr_multiaddr = group;
    mreq.imr_interface = ifaddr;
    if (::setsockopt(rx_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) < 0)
      fail_close(fmt::format("cannot join {} on {}: {} (is there a multicast route? e.g. "
                             "`ip route add 224.0.0.0/4 dev lo`)",
                             o.group, o.iface, std::strerror(errno)));

    // Send socket: its own (address, ephemeral port) identifies our datagrams.
    tx_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (tx_ < 0) fail_close(std::string("socket: ") + std::strerror(errno));
    sockaddr_in local{};
    local.sin_family = AF_INET;
    local.sin_addr = ifaddr;
    local.sin_port = 0;
    if (::bind(tx_, reinterpret_cast<sockaddr*>(&local), sizeof local) < 0)
      fail_close(fmt::format("cannot bind the send socket to {}: {}", o.iface, std::strerror(errno)));
    socklen_t len = sizeof self_;
    ::getsockname(tx_, reinterpret_cast<sockaddr*>(&self_), &len);
    const unsigned char ttl = static_cast<unsigned char>(o.ttl);
    const unsigned char loop = 1;
    ::setsockopt(tx_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
    ::setsockopt(tx_, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop);
    if (::setsockopt(tx_, IPPROTO_IP, IP_MULTICAST_IF, &ifaddr, sizeof ifaddr) < 0)
      fail_close(fmt::format("cannot send multicast on {}: {}", o.iface, std::strerror(errno)));
    dest_.sin_family = AF_INET;
    dest_.sin_port = htons(o.port);
    dest_.sin_addr = group;
  }
  ~UdpBus() override {
    if (rx_ >= 0) ::close(rx_);
    if (tx_ >= 0) ::close(tx_);
  }

  bool send(const Frame& frame) noexcept override {
    std::array<std::uint8_t, 256> buf;
    const std::size_t n = udp::encode_datagram(frame, realtime_now(), buf);
    if (n == 0) return false;
    const ssize_t w = ::sendto(tx_, buf.data(), n, 0, reinterpret_cast<const sockaddr*>(&dest_), sizeof dest_);
    if (w != static_cast<ssize_t>(n)) return false;
    stats_.sent.fetch_add(1, std::memory_order_relaxed);
    return true;
  }

  std::optional<Frame> receive(std::chrono::nanoseconds timeout) noexcept override {
    const std::int64_t deadline_ns = rt::monotonic_ns() + timeout.count();
    // A poll (timeout 0) reads at most kPollReads datagrams, so a flood of filtered frames
    // cannot keep it looping; a wait is bounded by its deadline.
    std::size_t reads = 0;
    for (;;) {
      const std::int64_t left_ns = deadline_ns - rt::monotonic_ns();
      if (timeout.count() <= 0 && reads >= kPollReads) return std::nullopt;
      pollfd p{rx_, POLLIN, 0};
      timespec tmo{};
      if (left_ns > 0) {
        tmo.tv_sec = left_ns / 1000000000LL;
        tmo.tv_nsec = left_ns % 1000000000LL;
      }
      const int pr = ::ppoll(&p, 1, &tmo, nullptr);
      if (pr < 0 && errno == EINTR) {
        if (left_ns <= 0) return std::nullopt;
        continue;
      }
      if (pr <= 0) return std::nullopt;
      Slot slot;
      slot.prepare();
      const ssize_t n = ::recvmsg(rx_, &slot.msg, MSG_TRUNC | MSG_DONTWAIT);
      if (n < 0) continue;
      ++reads;
      Frame f;
      if (take(slot.msg, static_cast<std::size_t>(n), slot, f)) return f;
    }
  }

  BatchResult receive_batch(std::span<Frame> out, std::size_t max_reads) noexcept override {
    // recvmmsg: up to kBatch datagrams per system call, none waited for.
    BatchResult r;
    while (r.stored < out.size() && r.reads < max_reads) {
      const std::size_t want = std::min({kBatch, max_reads - r.reads, out.size() - r.stored});
      std::array<Slot, kBatch> slots;
      std::array<mmsghdr, kBatch> mm{};
      for (std::size_t i = 0; i < want; ++i) {
        slots[i].prepare();
        mm[i].msg_hdr = slots[i].msg;
      }
      const int got = ::recvmmsg(rx_, mm.data(), static_cast<unsigned>(want), MSG_TRUNC | MSG_DONTWAIT, nullptr);
      if (got < 0) {
        if (errno == EINTR) continue;
        r.drained = true;  // EAGAIN: nothing queued
        break;
      }
      r.reads += static_cast<std::size_t>(got);
      for (int i = 0; i < got; ++i) {
        const auto k = static_cast<std::size_t>(i);
        if (take(mm[k].msg_hdr, mm[k].msg_len, slots[k], out[r.stored])) ++r.stored;
      }
      if (static_cast<std::size_t>(got) < want) {  // the queue is empty
        r.drained = true;
        break;
      }
    }
    return r;
  }

  void set_filters(std::vector<Filter> filters) override {
    std::lock_guard lk(filter_mu_);
    filters_ = std::move(filters);
  }
  BusStats stats() const noexcept override { return stats_.load(); }
  std::string address() const override {
    std::string a = fmt::format("udp:{}:{}", opts_.group, opts_.port);
    if (opts_.iface != "127.0.0.1") a += ",iface=" + opts_.iface;
    if (opts_.ttl != 0) a += fmt::format(",ttl={}", opts_.ttl);
    return a;
  }

 private:
  [[noreturn]] void fail_close(const std::string& msg) {
    if (rx_ >= 0) ::close(rx_);
    if (tx_ >= 0) ::close(tx_);
    rx_ = tx_ = -1;
    fail(msg);
  }

  static constexpr std::size_t kPollReads = 256;  ///< datagrams one receive(0) reads at most
  static constexpr std::size_t kBatch = 32;       ///< datagrams per recvmmsg call

  /// Buffers of one datagram read (recvmsg or one recvmmsg entry).
  struct Slot {
    std::array<std::uint8_t, udp::kMaxDatagram + 1> buf;
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
    sockaddr_in src{};
    iovec iov{};
    msghdr msg{};
    void prepare() noexcept {
      iov = {buf.data(), buf.size()};
      msg = msghdr{};
      msg.msg_name = &src;
      msg.msg_namelen = sizeof src;
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = control;
      msg.msg_controllen = sizeof control;
    }
  };

  /// Decodes one received datagram of n bytes into f; false (and counted) for our own
  /// frames, malformed or oversized datagrams and frames the filters drop.
  bool take(msghdr& msg, std::size_t n, const Slot& slot, Frame& f) noexcept {
    const auto* src = static_cast<const sockaddr_in*>(msg.msg_name);
    if (src->sin_addr.s_addr == self_.sin_addr.s_addr && src->sin_port == self_.sin_port) return false;  // own frame
    const auto st = n > udp::kMaxDatagram || (msg.msg_flags & MSG_TRUNC)
                        ? udp::DecodeStatus::oversized
                        : udp::decode_datagram({slot.buf.data(), n}, f);
    if (st != udp::DecodeStatus::ok) {
      stats_.dropped.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    f.timestamp_s = realtime_now();
    kernel_timestamp(msg, f.timestamp_s);
    std::lock_guard lk(filter_mu_);
    return accept(filters_, f, stats_);
  }

  std::string spec_;
  UdpOptions opts_;
  int rx_ = -1;
  int tx_ = -1;
  sockaddr_in self_{};
  sockaddr_in dest_{};
  std::mutex filter_mu_;
  std::vector<Filter> filters_;
  AtomicStats stats_;
};

}  // namespace

std::unique_ptr<Bus> open_udp_bus(const std::string& spec) { return std::make_unique<UdpBus>(spec); }

}  // namespace lash::can::detail
