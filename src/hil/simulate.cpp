#include "lash/hil/simulate.hpp"

#include <stdexcept>

namespace lash::hil {
namespace {

struct Queue {
  std::deque<can::Frame> frames;
};

class LinkEnd final : public can::Bus {
 public:
  LinkEnd(std::shared_ptr<Queue> in, std::shared_ptr<Queue> out) : in_(std::move(in)), out_(std::move(out)) {}
  bool send(const can::Frame& frame) noexcept override {
    out_->frames.push_back(frame);
    ++stats_.sent;
    return true;
  }
  std::optional<can::Frame> receive(std::chrono::nanoseconds) noexcept override {
    while (!in_->frames.empty()) {
      can::Frame f = in_->frames.front();
      in_->frames.pop_front();
      if (accept(f)) {
        ++stats_.received;
        return f;
      }
      ++stats_.filtered;
    }
    return std::nullopt;
  }
  void set_filters(std::vector<can::Filter> filters) override { filters_ = std::move(filters); }
  can::BusStats stats() const noexcept override { return stats_; }
  std::string address() const override { return "memlink"; }

 private:
  bool accept(const can::Frame& f) const noexcept {
    if (filters_.empty()) return true;
    for (const auto& flt : filters_)
      if (flt.extended == f.extended && (f.id & flt.mask) == (flt.id & flt.mask)) return true;
    return false;
  }
  std::shared_ptr<Queue> in_, out_;
  std::vector<can::Filter> filters_;
  can::BusStats stats_;
};

}  // namespace

MemLink::MemLink() {
  auto ab = std::make_shared<Queue>();
  auto ba = std::make_shared<Queue>();
  a_ = std::make_unique<LinkEnd>(ba, ab);
  b_ = std::make_unique<LinkEnd>(ab, ba);
}

SimulationResult simulate_bench(const BenchLayout& layout, const MasterConfig& master_cfg,
                                const SlaveConfig& slave_cfg, std::size_t control_steps) {
  MasterConfig mc = master_cfg;
  mc.log_capacity = control_steps + 1;
  SlaveConfig sc = slave_cfg;
  sc.log_capacity = control_steps;
  MasterNode master(layout, mc);
  SlaveNode slave(layout, sc);
  MemLink link;
  const double T = mc.controller.pid.dt_s;
  std::size_t k = 0;
  master.step(link.a(), 0.0);  // sends CRO
  if (!slave.wait_connect(link.b(), std::chrono::nanoseconds(0)))
    throw std::invalid_argument("hil simulate: the slave did not see the master's CCP CONNECT");
  for (std::size_t s = 0; s < control_steps; ++s) {
    ++k;
    const double t = static_cast<double>(k) * T;
    slave.step(link.b(), t - 0.5 * T);
    if (!master.step(link.a(), t)) break;
  }
  if (master.state() != MasterState::running)
    throw std::invalid_argument(std::string("hil simulate: the master ended in state ") + to_string(master.state()) +
                                " (is the recorded DTO a positive CONNECT reply?)");
  SimulationResult r;
  r.master.assign(master.log().begin(), master.log().end());
  r.slave.assign(slave.log().begin(), slave.log().end());
  r.events.assign(master.events().begin(), master.events().end());
  r.compensation = master.compensation();
  return r;
}

}  // namespace lash::hil
