// lash.monitor_log: conversion only; the work is lash::monitor::run_monitor, the call
// `lash monitor LOGFILE` makes (docs/monitor.md).
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "convert.hpp"
#include "lash/identify/config_sources.hpp"
#include "lash/monitor/monitor.hpp"

namespace lash::py {

namespace {

/// The history of one run, period by period, as it is collected from run_monitor's callback.
struct Collected {
  std::vector<double> t, samples;
  std::vector<std::string> status;
  std::vector<std::string> names;  // parameters in order of first appearance
  std::map<std::string, std::vector<double>> value, lo, hi;
  std::vector<monitor::Event> events;

  void add(const monitor::Period& p) {
    const std::size_t k = t.size();
    t.push_back(p.t);
    samples.push_back(static_cast<double>(p.samples));
    status.push_back(p.status);
    for (const auto& v : p.params) {
      if (!value.count(v.name)) {
        names.push_back(v.name);
        for (auto* col : {&value, &lo, &hi}) (*col)[v.name].assign(k, NAN);
      }
      value[v.name].push_back(v.identified ? v.value : NAN);
      lo[v.name].push_back(v.identified ? v.lo : NAN);
      hi[v.name].push_back(v.identified ? v.hi : NAN);
    }
    for (auto* col : {&value, &lo, &hi})
      for (auto& [name, c] : *col)
        if (c.size() == k) c.push_back(NAN);  // a period without this parameter (warming up)
    events.insert(events.end(), p.events.begin(), p.events.end());
  }
};

pyb::dict monitor_log(const std::string& path, const std::string& dbc, const std::string& v, const std::string& y,
                      const std::string& model, const std::string& preset, double every, double dt, double window,
                      double stale_timeout, const std::string& record, const std::string& db,
                      const std::string& jsonl, const std::string& estimate, double init,
                      const pyb::kwargs& settings) {
  monitor::MonitorSettings s;
  s.source = path;
  s.dbc = dbc;
  s.v = v;
  s.y = y;
  s.every_s = every;
  s.dt_s = dt;
  s.window_s = window;
  s.mode = checked("estimate", [&] { return monitor::parse_estimate_mode(estimate); });
  s.online.init_s = init;
  s.stale_timeout_s = stale_timeout;
  s.record_csv = record;
  s.db = db;
  s.jsonl = jsonl;
  s.estimator.model = checked("model", [&] { return parse_model_kind(model); });
  s.estimator.preset = checked("preset", [&] { return parse_preset(preset); });
  monitor::apply_monitor_table(to_toml(settings), "<settings>", s);  // [alarms], [drift], estimator keys
  Collected c;
  monitor::MonitorResult r;
  {
    pyb::gil_scoped_release nogil;
    r = monitor::run_monitor(s, nullptr, [&c](const monitor::Period& p, const monitor::MonitorCounts&) { c.add(p); });
  }
  pyb::dict out;
  out["t"] = to_numpy(std::move(c.t));
  out["samples"] = to_numpy(std::move(c.samples));
  out["status"] = c.status;
  for (const auto& n : c.names) {
    out[pyb::str(n)] = to_numpy(std::move(c.value[n]));
    out[pyb::str(n + "_lo")] = to_numpy(std::move(c.lo[n]));
    out[pyb::str(n + "_hi")] = to_numpy(std::move(c.hi[n]));
  }
  std::vector<double> et, eb, ea;
  std::vector<std::string> ek, ep;
  for (const auto& e : c.events) {
    et.push_back(e.t);
    ek.push_back(e.kind);
    ep.push_back(e.param);
    eb.push_back(e.before);
    ea.push_back(e.after);
  }
  pyb::dict ev;
  ev["t"] = to_numpy(std::move(et));
  ev["kind"] = ek;
  ev["param"] = ep;
  ev["before"] = to_numpy(std::move(eb));
  ev["after"] = to_numpy(std::move(ea));
  out["events"] = ev;
  const auto& n = r.counts;
  pyb::dict counts;
  for (const auto& [k, x] : {std::pair{"frames", n.frames}, {"other", n.other}, {"samples", n.samples},
                             {"garbage", n.garbage}, {"bad_dlc", n.bad_dlc}, {"out_of_range", n.out_of_range},
                             {"counter_jumps", n.counter_jumps}, {"stale", n.stale}, {"time_back", n.time_back},
                             {"gaps", n.gaps}, {"restarts", n.restarts}, {"reguesses", n.reguesses}, {"bus_dropped", n.bus_dropped},
                             {"periods", n.periods}, {"events", n.events}})
    counts[k] = x;
  out["counts"] = counts;
  out["t0_unix_s"] = r.t0_unix_s;
  out["last"] = r.last_json.empty() ? pyb::object(pyb::none())
                                    : pyb::module_::import("json").attr("loads")(r.last_json);
  return out;
}

}  // namespace

void bind_monitor(pyb::module_& m) {
  m.def("monitor_log", &monitor_log, pyb::arg("path"), pyb::arg("dbc"), pyb::arg("v"), pyb::arg("y"), pyb::kw_only(),
        pyb::arg("model") = "deadzone-deadband", pyb::arg("preset") = "lash", pyb::arg("every") = 1.0,
        pyb::arg("dt") = 0.0, pyb::arg("window") = 120.0, pyb::arg("stale_timeout") = 0.5,
        pyb::arg("record") = "", pyb::arg("db") = "", pyb::arg("jsonl") = "", pyb::arg("estimate") = "window",
        pyb::arg("init") = 10.0,
        "monitor_log(path, dbc, v, y, *, model='deadzone-deadband', preset='lash', every=1.0, dt=0.0,\n"
        "            window=120.0, stale_timeout=0.5, record='', db='', jsonl='', estimate='online', init=10.0,\n"
        "            **settings) -> dict\n\n"
        "`lash monitor LOGFILE` as a library call (docs/monitor.md): a CAN log (candump, ASC, BLF, TRC) read\n"
        "through the DBC `dbc`; v, y: 'MSG.SIG' or 'MSG.SIG-MSG.SIG'; every: period of the estimates [s];\n"
        "dt > 0: zero-order-hold resampling [s]; window: each estimate covers the samples of the last\n"
        "`window` seconds (0 = all; online: the final one); record / db / jsonl: the files of --record, --db,\n"
        "--jsonl ('' = none); estimate: 'online' (one persistent estimator, settings chosen from the first\n"
        "`init` seconds) or 'window' (each period re-estimates its window), as lash monitor --estimate.\n"
        "settings: the keys of a monitor config: the estimator's (as lash.estimate) and the tables alarms={...}\n"
        "and drift={...}. Returns the history, one entry per period: 't' [s since the first sample],\n"
        "'samples' (that the estimate used), 'status' (list of str), per parameter (c_r, c_l, d_r, d_l, K_r,\n"
        "K_l, tau_s_r, tau_s_l; linear: K, tau_s) its value, '<param>_lo' and '<param>_hi' (95 %), NaN while\n"
        "not identified; 'events' (dict of columns t, kind, param, before, after), 'counts' (dict),\n"
        "'t0_unix_s' and 'last' (the last estimate as lash.estimate's dict, None if none).\n"
        "Raises lash.InputError (a ValueError) naming the file, option or signal.");
}

}  // namespace lash::py
