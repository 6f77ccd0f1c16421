// SocketCAN bus (Linux PF_CAN / CAN_RAW) with kernel receive timestamps.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <mutex>

#include <fmt/core.h>

#include "bus_internal.hpp"
#include "lash/io/error.hpp"

namespace lash::can::detail {
namespace {

class SocketCanBus final : public Bus {
 public:
  explicit SocketCanBus(const std::string& iface) : iface_(iface) {
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) {
      const int e = errno;
      if (e == EAFNOSUPPORT || e == EPROTONOSUPPORT || e == EINVAL)
        throw InputError("", 0, "bus",
                         fmt::format("socketcan: this kernel has no CAN support ({}); load the can and can_raw "
                                     "modules (modprobe can_raw vcan) or use udp:/mem: buses",
                                     std::strerror(e)));
      throw InputError("", 0, "bus", fmt::format("socketcan: cannot open a CAN_RAW socket: {}", std::strerror(e)));
    }
    if (iface.size() >= IFNAMSIZ) fail("interface name too long: " + iface);
    ifreq ifr{};
    std::memcpy(ifr.ifr_name, iface.c_str(), iface.size());
    if (::ioctl(fd_, SIOCGIFINDEX, &ifr) < 0)
      fail(fmt::format("no CAN interface '{}' ({}); create one with `ip link add dev {} type vcan && ip link set {} up`",
                       iface, std::strerror(errno), iface, iface));
    const int one = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one);
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0)
      fail(fmt::format("cannot bind to '{}': {}", iface, std::strerror(errno)));
  }
  ~SocketCanBus() override {
    if (fd_ >= 0) ::close(fd_);
  }

  bool send(const Frame& f) noexcept override {
    if (!f.valid() || f.fd || f.error) return false;
    can_frame cf{};
    cf.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0u) | (f.remote ? CAN_RTR_FLAG : 0u);
    cf.len = f.len;
    if (!f.remote) std::memcpy(cf.data, f.data.data(), f.len);
    for (int attempt = 0; attempt < 1000; ++attempt) {
      const ssize_t n = ::write(fd_, &cf, sizeof cf);
      if (n == static_cast<ssize_t>(sizeof cf)) {
        stats_.sent.fetch_add(1, std::memory_order_relaxed);
        return true;
      }
      if (n < 0 && errno == ENOBUFS) {  // tx queue full: wait for room
        pollfd p{fd_, POLLOUT, 0};
        ::poll(&p, 1, 10);
        continue;
      }
      return false;
    }
    return false;
  }

  std::optional<Frame> receive(std::chrono::nanoseconds timeout) noexcept override {
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    const std::int64_t deadline_ns = now.tv_sec * 1000000000LL + now.tv_nsec + timeout.count();
    for (;;) {
      clock_gettime(CLOCK_MONOTONIC, &now);
      const std::int64_t left_ns = deadline_ns - (now.tv_sec * 1000000000LL + now.tv_nsec);
      timespec tmo{};
      if (left_ns > 0) {
        tmo.tv_sec = left_ns / 1000000000LL;
        tmo.tv_nsec = left_ns % 1000000000LL;
      }
      pollfd p{fd_, POLLIN, 0};
      const int pr = ::ppoll(&p, 1, &tmo, nullptr);
      if (pr < 0 && errno == EINTR) {
        if (left_ns <= 0) return std::nullopt;
        continue;
      }
      if (pr <= 0) return std::nullopt;
      can_frame cf{};
      alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
      iovec iov{&cf, sizeof cf};
      msghdr msg{};
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = control;
      msg.msg_controllen = sizeof control;
      const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
      if (n < 0) continue;
      if (n != static_cast<ssize_t>(sizeof cf) || (cf.can_id & CAN_ERR_FLAG)) {
        stats_.dropped.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      Frame f;
      f.extended = (cf.can_id & CAN_EFF_FLAG) != 0;
      f.remote = (cf.can_id & CAN_RTR_FLAG) != 0;
      f.id = cf.can_id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
      f.len = cf.len > 8 ? 8 : cf.len;
      if (!f.remote) std::memcpy(f.data.data(), cf.data, f.len);
      timespec rt{};
      clock_gettime(CLOCK_REALTIME, &rt);
      f.timestamp_s = static_cast<double>(rt.tv_sec) + static_cast<double>(rt.tv_nsec) * 1e-9;
      kernel_timestamp(msg, f.timestamp_s);
      {
        std::lock_guard lk(filter_mu_);
        if (!accept(filters_, f, stats_)) continue;
      }
      return f;
    }
  }

  /// Installs the filters in the kernel (CAN_RAW_FILTER) and checks them again in user space.
  void set_filters(std::vector<Filter> filters) override {
    std::vector<can_filter> k;
    for (const auto& f : filters) {
      can_filter cf{};
      cf.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0u);
      cf.can_mask = f.mask | CAN_EFF_FLAG;
      k.push_back(cf);
    }
    if (k.empty()) {
      can_filter all{0, 0};
      ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, &all, sizeof all);
    } else {
      ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, k.data(), static_cast<socklen_t>(k.size() * sizeof(can_filter)));
    }
    std::lock_guard lk(filter_mu_);
    filters_ = std::move(filters);
  }
  BusStats stats() const noexcept override { return stats_.load(); }
  std::string address() const override { return "socketcan:" + iface_; }

 private:
  [[noreturn]] void fail(const std::string& msg) {
    ::close(fd_);
    fd_ = -1;
    throw InputError("", 0, "bus", "socketcan: " + msg);
  }

  std::string iface_;
  int fd_ = -1;
  std::mutex filter_mu_;
  std::vector<Filter> filters_;
  AtomicStats stats_;
};

}  // namespace

std::unique_ptr<Bus> open_socketcan_bus(const std::string& interface) {
  return std::make_unique<SocketCanBus>(interface);
}

}  // namespace lash::can::detail
