#include "lash/console/xcp_bridge.hpp"

#include <chrono>
#include <cmath>

#include <fmt/core.h>

#include "lash/can/bus.hpp"
#include "lash/can/xcp_client.hpp"
#include "lash/console/live_stats.hpp"

namespace lash::console {
namespace xcp = can::xcp;
using namespace std::chrono_literals;

double steady_s() noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

XcpBridge::XcpBridge(XcpBridgeOptions o) : o_(std::move(o)) {
  for (const auto& ob : o_.objects) (ob.kind == xcp::Kind::measurement ? meas_ : cal_).push_back(ob);
  if (meas_.size() > kMaxSignals) meas_.resize(kMaxSignals);
}

XcpBridge::~XcpBridge() { stop(); }

std::vector<std::string> XcpBridge::signals() const {
  std::vector<std::string> s;
  for (const auto& m : meas_) s.push_back(m.name);
  return s;
}

std::vector<TuneParam> XcpBridge::params() const {
  std::vector<TuneParam> p;
  for (const auto& c : cal_) p.push_back({c.name, c.unit, c.description, c.min, c.max});
  return p;
}

void XcpBridge::start(Server& server) {
  thread_ = std::thread([this, &server] { run(server); });
}

void XcpBridge::stop() {
  if (stop_.exchange(true)) return;
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lk(m_);
  for (auto& r : queue_) {
    r->done = true;
    r->result = {false, 0.0, "the console is stopping"};
  }
  cv_.notify_all();
}

TuneResult XcpBridge::tune(const std::string& name, double value) {
  auto r = std::make_shared<Request>();
  r->name = name;
  r->value = value;
  std::unique_lock lk(m_);
  if (!connected_) return {false, 0.0, "not connected to the ECU (XCP)"};
  queue_.push_back(r);
  if (!cv_.wait_for(lk, 3s, [&] { return r->done; })) return {false, 0.0, "no answer from the XCP thread within 3 s"};
  return r->result;
}

void XcpBridge::run(Server& server) {
  std::unique_ptr<can::Bus> bus;
  try {
    bus = can::open_bus(o_.bus);
    bus->set_filters({{o_.info.res_id, 0x7FF, false}});
  } catch (const std::exception& e) {
    server.set_status_text("xcp", std::string("cannot open the bus: ") + e.what());
    return;
  }
  const auto index_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < meas_.size(); ++i)
      if (meas_[i].name == name) return i;
    return meas_.size();
  };
  const std::size_t state_i = index_of(o_.state_signal), step_i = index_of("control_step");
  // The loop's figures (hil/calibration.hpp): TET and wake-up latency per step [us], counters.
  const std::size_t tet_i = index_of("tet_us"), wake_i = index_of("wake_latency_us"), over_i = index_of("overruns");
  const std::size_t late_i = index_of("frames_late"), lost_i = index_of("frames_lost");
  LiveStats tet(0.05), wake(0.5, 40000);  // bins: 0.05 us up to 2.5 ms; 0.5 us up to 20 ms
  double last_overruns = 0.0, last_overrun_t = -1.0;
  double tet_from_step = NAN, tet_to_step = NAN;  // control steps of the first and last TET sample
  double last_step = NAN;
  std::uint64_t samples = 0, gaps = 0, reconnects = 0;
  while (!stop_.load()) {
    xcp::Client client(*bus, o_.info.cmd_id, o_.info.res_id, 300ms);
    try {
      server.set_status_text("xcp", "connecting");
      client.connect();
      for (const auto& c : cal_) server.set_param_value(c.name, client.read(c));
      client.start_daq(meas_);
    } catch (const std::exception&) {
      std::this_thread::sleep_for(100ms);
      continue;
    }
    {
      std::lock_guard lk(m_);
      connected_ = true;
    }
    server.set_status_text("xcp", "connected, DAQ running");
    std::uint64_t wraps = 0;
    std::uint32_t last_ts = 0;
    double last_state = NAN;
    auto t_rate = std::chrono::steady_clock::now();
    std::uint64_t rate_n = 0;
    double t_now = 0.0;
    int silent = 0;
    try {
      while (!stop_.load()) {
        std::deque<std::shared_ptr<Request>> work;
        {
          std::lock_guard lk(m_);
          work.swap(queue_);
        }
        for (auto& r : work) {
          TuneResult res;
          const xcp::Object* ob = nullptr;
          for (const auto& c : cal_)
            if (c.name == r->name) ob = &c;
          if (!ob) {
            res = {false, 0.0, "no CHARACTERISTIC " + r->name};
          } else {
            try {
              const double old = client.read(*ob);
              client.write(*ob, r->value);
              res = {true, client.read(*ob), ""};
              server.add_event(t_now, "calibration", fmt::format("{} {} -> {}", ob->name, old, res.readback));
            } catch (const xcp::XcpError& e) {
              const auto c = e.code();
              res.error = c ? fmt::format("xcp: set {} {} (limits {} .. {}): {} (0x{:02X})", ob->name, r->value,
                                          ob->min, ob->max, xcp::to_string(*c), static_cast<int>(*c))
                            : std::string(e.what());
            }
          }
          std::lock_guard lk(m_);
          r->result = res;
          r->done = true;
          cv_.notify_all();
        }
        auto smp = client.next_sample(20ms);
        if (!smp) {
          if (++silent > 50) throw xcp::XcpError("no DAQ sample for 1 s", std::nullopt);  // the ECU is gone
          continue;
        }
        silent = 0;
        if (samples > 0 && smp->timestamp_us < last_ts) ++wraps;
        last_ts = smp->timestamp_us;
        Sample s;
        t_now = s.t_s = (static_cast<double>(wraps) * 4294967296.0 + smp->timestamp_us) * 1e-6;
        s.count = static_cast<std::uint32_t>(std::min(smp->values.size(), kMaxSignals));
        for (std::size_t i = 0; i < s.count; ++i) s.values[i] = smp->values[i];
        server.feed().push(s);
        if (const double off = steady_s() - s.t_s, cur = offset_.load(); std::isnan(cur) || off < cur)
          offset_.store(off);
        if (step_i < s.count) {  // a control step the DAQ did not deliver
          if (!std::isnan(last_step) && last_step >= 0 && s.values[step_i] > last_step + 1)
            gaps += static_cast<std::uint64_t>(s.values[step_i] - last_step - 1);
          last_step = s.values[step_i];
        }
        ++samples;
        ++rate_n;
        if (tet_i < s.count && s.values[tet_i] > 0.0) {  // 0: the first step (no previous)
          tet.add(s.values[tet_i]);
          if (step_i < s.count) {
            if (tet.count() == 1) tet_from_step = s.values[step_i];
            tet_to_step = s.values[step_i];
          }
        }
        if (wake_i < s.count) wake.add(s.values[wake_i]);
        // overruns as markers: at most one per 0.5 s of ECU time (a loaded machine overruns in bursts)
        if (over_i < s.count && s.values[over_i] > last_overruns && !(s.t_s - last_overrun_t < 0.5)) {
          server.add_event(s.t_s, "overrun", fmt::format("{} overrun(s) so far", s.values[over_i]));
          last_overruns = s.values[over_i];
          last_overrun_t = s.t_s;
        }
        if (state_i < s.count && s.values[state_i] != last_state) {
          if (!std::isnan(last_state))
            server.add_event(s.t_s, "state",
                             o_.state_name ? o_.state_name(s.values[state_i]) : fmt::format("{}", s.values[state_i]));
          last_state = s.values[state_i];
          server.set_status_text("state", o_.state_name ? o_.state_name(last_state) : fmt::format("{}", last_state));
        }
        const auto now = std::chrono::steady_clock::now();
        if (now - t_rate >= 1s) {
          const double dt = std::chrono::duration<double>(now - t_rate).count();
          server.set_status("daq_samples_per_s", static_cast<double>(rate_n) / dt);
          server.set_status("daq_samples", static_cast<double>(samples));
          server.set_status("daq_incomplete", static_cast<double>(client.samples_incomplete()));
          server.set_status("daq_gaps", static_cast<double>(gaps));
          if (tet.count())  // with the control steps they cover (one update: the page sees all or none)
            server.set_statuses({{"tet_mean_us", tet.mean()}, {"tet_max_us", tet.max()},
                                 {"tet_p99_us", tet.quantile(0.99)}, {"tet_steps", static_cast<double>(tet.count())},
                                 {"tet_from_step", tet_from_step}, {"tet_to_step", tet_to_step}});
          if (wake.count()) {
            server.set_status("wake_latency_mean_us", wake.mean());
            server.set_status("wake_latency_max_us", wake.max());
            server.set_status("wake_latency_p99_us", wake.quantile(0.99));
          }
          if (over_i < s.count) server.set_status("overruns", s.values[over_i]);
          if (late_i < s.count) server.set_status("frames_late", s.values[late_i]);
          if (lost_i < s.count) server.set_status("frames_lost", s.values[lost_i]);
          t_rate = now;
          rate_n = 0;
        }
      }
      try {
        client.stop_daq();
        client.disconnect();
      } catch (const std::exception&) {
      }
    } catch (const std::exception& e) {
      server.set_status_text("xcp", std::string("lost: ") + e.what());
      ++reconnects;
      server.set_status("xcp_reconnects", static_cast<double>(reconnects));
    }
    std::lock_guard lk(m_);
    connected_ = false;
    for (auto& r : queue_) {
      r->done = true;
      r->result = {false, 0.0, "the XCP connection was lost"};
    }
    queue_.clear();
    cv_.notify_all();
  }
}

}  // namespace lash::console
