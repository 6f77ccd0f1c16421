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

}  // namespace lash::hil
