// open_bus() and the in-memory bus.
#include <condition_variable>
#include <map>
#include <mutex>

#include "bus_internal.hpp"
#include "lash/io/error.hpp"

namespace lash::can {

BatchResult Bus::receive_batch(std::span<Frame> out, std::size_t max_reads) noexcept {
  // receive(0) applies the filters itself and reports only what passes: each call is one read
  // of a delivered frame; nothing returned means the queue had nothing (more) for us.
  BatchResult r;
  while (r.reads < max_reads && r.stored < out.size()) {
    auto f = receive(std::chrono::nanoseconds(0));
    if (!f) {
      r.drained = true;
      break;
    }
    ++r.reads;
    out[r.stored++] = *f;
  }
  return r;
}

namespace detail {
namespace {

class MemBus;

/// Every node attached to one name. Delivery order is the send order: deterministic.
struct MemHub {
  std::mutex mu;
  std::vector<MemBus*> nodes;
};

std::mutex g_registry_mu;
std::map<std::string, std::weak_ptr<MemHub>> g_registry;

class MemBus final : public Bus {
 public:
  static constexpr std::size_t kCapacity = 4096;  ///< frames queued per node before drops

  MemBus(std::string name, std::shared_ptr<MemHub> hub) : name_(std::move(name)), hub_(std::move(hub)), ring_(kCapacity) {
    std::lock_guard lk(hub_->mu);
    hub_->nodes.push_back(this);
  }
  ~MemBus() override {
    std::lock_guard lk(hub_->mu);
    std::erase(hub_->nodes, this);
  }

  bool send(const Frame& frame) noexcept override {
    if (!frame.valid()) return false;
    {
      std::lock_guard lk(hub_->mu);
      for (MemBus* n : hub_->nodes)
        if (n != this) n->push(frame);
    }
    stats_.sent.fetch_add(1, std::memory_order_relaxed);
    return true;
  }

  std::optional<Frame> receive(std::chrono::nanoseconds timeout) noexcept override {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::unique_lock lk(mu_);
    for (;;) {
      while (count_ == 0) {
        if (timeout <= std::chrono::nanoseconds::zero()) return std::nullopt;
        if (cv_.wait_until(lk, deadline) == std::cv_status::timeout && count_ == 0) return std::nullopt;
      }
      const Frame f = ring_[head_];
      head_ = (head_ + 1) % kCapacity;
      --count_;
      if (!accept(filters_, f, stats_)) continue;
      return f;
    }
  }

  void set_filters(std::vector<Filter> filters) override {
    std::lock_guard lk(mu_);
    filters_ = std::move(filters);
  }
  BusStats stats() const noexcept override { return stats_.load(); }
  std::string address() const override { return "mem:" + name_; }

 private:
  void push(const Frame& f) noexcept {
    {
      std::lock_guard lk(mu_);
      if (count_ == kCapacity) {
        stats_.dropped.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      ring_[(head_ + count_) % kCapacity] = f;
      ++count_;
    }
    cv_.notify_one();
  }

  std::string name_;
  std::shared_ptr<MemHub> hub_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Frame> ring_;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::vector<Filter> filters_;
  AtomicStats stats_;
};

}  // namespace

std::unique_ptr<Bus> open_mem_bus(const std::string& name) {
  std::shared_ptr<MemHub> hub;
  {
    std::lock_guard lk(g_registry_mu);
    auto& w = g_registry[name];
    hub = w.lock();
    if (!hub) {
      hub = std::make_shared<MemHub>();
      w = hub;
    }
  }
  return std::make_unique<MemBus>(name, std::move(hub));
}

}  // namespace detail

std::unique_ptr<Bus> open_bus(const std::string& address) {
  const auto colon = address.find(':');
  const std::string scheme = address.substr(0, colon);
  const std::string rest = colon == std::string::npos ? std::string() : address.substr(colon + 1);
  if (scheme == "mem") {
    if (rest.empty()) throw InputError("", 0, "bus", "mem: needs a name, e.g. mem:bench");
    return detail::open_mem_bus(rest);
  }
  if (scheme == "udp") return detail::open_udp_bus(rest);
  if (scheme == "socketcan") {
    if (rest.empty()) throw InputError("", 0, "bus", "socketcan: needs an interface, e.g. socketcan:vcan0");
    return detail::open_socketcan_bus(rest);
  }
  throw InputError("", 0, "bus",
                   "unknown bus address '" + address + "' (use mem:NAME, udp:GROUP:PORT or socketcan:IFACE)");
}

}  // namespace lash::can
