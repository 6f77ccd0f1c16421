#pragma once
// JSON pieces shared by the node statistics and the run report (private to src/hil).
#include <nlohmann/json.hpp>

#include "lash/hil/node_run.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::hil::detail {

inline nlohmann::json summary_json(const rt::Summary& s) {
  return nlohmann::json{{"n", s.n}, {"mean", s.mean}, {"min", s.min}, {"max", s.max}, {"std", s.std}, {"p99", s.p99}};
}

inline nlohmann::json frames_json(const FrameStats& f) {
  return nlohmann::json{{"sent", f.sent},
                        {"received", f.received},
                        {"late", f.late},
                        {"lost", f.lost},
                        {"duplicates", f.duplicates},
                        {"resyncs", f.resyncs},
                        {"ignored", f.ignored},
                        {"send_failures", f.send_failures},
                        {"bus_filtered", f.bus_filtered},
                        {"bus_dropped", f.bus_dropped}};
}

}  // namespace lash::hil::detail
