#pragma once
// JSON pieces shared by the node statistics and the run report (private to src/hil).
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "lash/hil/node_run.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::hil::detail {

inline nlohmann::json summary_json(const rt::Summary& s) {
  return nlohmann::json{{"n", s.n}, {"mean", s.mean}, {"min", s.min}, {"max", s.max}, {"std", s.std}, {"p99", s.p99}};
}

/// Receive statistics of one node's input message, with the plausibility drops per reason (e2e.hpp).
inline nlohmann::json frames_json(const FrameStats& f) {
  nlohmann::json drops = nlohmann::json::object();
  for (std::size_t i = 0; i < kDropReasons; ++i) drops[to_string(static_cast<Drop>(i))] = f.dropped_by_reason[i];
  return nlohmann::json{{"sent", f.sent},
                        {"received", f.received},
                        {"accepted", f.accepted},
                        {"late", f.late},
                        {"lost", f.lost},
                        {"duplicates", f.duplicates},
                        {"resyncs", f.resyncs},
                        {"ignored", f.ignored},
                        {"send_failures", f.send_failures},
                        {"bus_filtered", f.bus_filtered},
                        {"bus_dropped", f.bus_dropped},
                        {"dropped", f.dropped},
                        {"dropped_by_reason", drops}};
}

/// The safe-state machine's transitions (nodes.hpp).
inline nlohmann::json events_json(const std::vector<NodeEvent>& events) {
  nlohmann::json ev = nlohmann::json::array();
  for (const auto& e : events)
    ev.push_back({{"step", e.step}, {"t_s", e.t_s}, {"event", to_string(e.kind)}, {"from", to_string(e.from)},
                  {"to", to_string(e.to)}});
  return ev;
}

}  // namespace lash::hil::detail
