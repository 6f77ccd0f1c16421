// What a node run leaves for a person: its CSV logs written from a run in memory (tests and
// tools; the nodes stream theirs, log_writer.hpp), its events and bus log, its statistics JSON.
#include "lash/hil/node_report.hpp"

#include <nlohmann/json.hpp>

#include "lash/can/log.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "json_parts.hpp"

namespace lash::hil {

// ----------------------------------------------------------------------------- files

namespace {
void write_columns(const std::filesystem::path& path, const std::vector<std::string>& names,
                   const std::vector<std::vector<double>>& cols) {
  AtomicFile f(path);
  std::string line;
  for (std::size_t i = 0; i < names.size(); ++i) line += (i ? "," : "") + names[i];
  line += '\n';
  f.stream() << line;
  const std::size_t n = cols.empty() ? 0 : cols[0].size();
  for (std::size_t k = 0; k < n; ++k) {
    line.clear();
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (c) line += ',';
      append_double(line, cols[c][k]);
    }
    line += '\n';
    f.stream() << line;
  }
  f.commit();
}

double us(std::int64_t ns) { return static_cast<double>(ns) * 1e-3; }
}  // namespace

void write_slave_csv(const std::filesystem::path& path, const SlaveRun& r) {
  std::vector<std::vector<double>> c(13);
  const std::size_t n = std::min(r.log.size(), r.loop.records.size());
  for (std::size_t i = 0; i < n; ++i) {
    const auto& l = r.log[i];
    const auto& rec = r.loop.records[i];
    const double row[] = {static_cast<double>(l.step), static_cast<double>(rec.release_ns) * 1e-9,
                          static_cast<double>(l.state), static_cast<double>(l.command_counter),
                          l.command_fresh ? 1.0 : 0.0, static_cast<double>(l.dropped), l.current_mA,
                          l.pressure_kPa, l.measured_kPa, static_cast<double>(l.pilot_raw), us(rec.tet_ns),
                          us(rec.io_ns), us(rec.wake_latency_ns)};
    for (std::size_t j = 0; j < c.size(); ++j) c[j].push_back(row[j]);
  }
  write_columns(path,
                {"step", "t_s", "state", "command_counter", "command_fresh", "dropped", "current_mA", "pressure_kPa",
                 "measured_kPa", "pilot_raw", "tet_us", "io_us", "wake_latency_us"},
                c);
}

void write_master_csv(const std::filesystem::path& path, const MasterRun& r) {
  const auto cal = calibration_fields();
  std::vector<std::vector<double>> c(16 + cal.size());
  const std::size_t n = std::min(r.log.size(), r.loop.records.size());
  for (std::size_t i = 0; i < n; ++i) {
    const auto& l = r.log[i];
    const auto& rec = r.loop.records[i];
    const double row[] = {static_cast<double>(l.step), static_cast<double>(rec.release_ns) * 1e-9,
                          static_cast<double>(l.state), static_cast<double>(l.control_step), l.reference_kPa,
                          l.measured_kPa, static_cast<double>(l.sensor_counter), l.sensor_fresh ? 1.0 : 0.0,
                          static_cast<double>(l.sensor_seq), static_cast<double>(l.dropped), l.current_mA, l.integrator_mA,
                          l.command_sent ? static_cast<double>(l.command_counter) : -1.0,
                          us(rec.tet_ns), us(rec.io_ns), us(rec.wake_latency_ns)};
    for (std::size_t j = 0; j < 16; ++j) c[j].push_back(row[j]);
    for (std::size_t j = 0; j < cal.size(); ++j) c[16 + j].push_back(l.calibration.*cal[j].member);
  }
  std::vector<std::string> names{"step", "t_s", "state", "control_step", "reference_kPa", "measured_kPa", "sensor_counter",
                                 "sensor_fresh", "sensor_seq", "dropped", "current_mA", "integrator_mA", "command_counter",
                                 "tet_us", "io_us", "wake_latency_us"};
  for (const auto& f : cal) names.emplace_back(f.name);  // the calibration page of each step (calibration.hpp)
  write_columns(path, names, c);
}

void write_events(const std::filesystem::path& path, const std::vector<NodeEvent>& events) {
  AtomicFile f(path);
  f.stream() << "step,t_s,event,from,to\n";
  for (const auto& e : events)
    f.stream() << e.step << ',' << format_double(e.t_s) << ',' << to_string(e.kind) << ',' << to_string(e.from) << ','
               << to_string(e.to) << '\n';
  f.commit();
}

void write_events(const std::filesystem::path& path, const std::vector<NodeEvent>& events,
                  const std::vector<CalibrationEvent>& calibration) {
  AtomicFile f(path);
  f.stream() << "step,t_s,event,from,to,name,old,new\n";
  std::size_t j = 0;
  const auto fields = calibration_fields();
  auto cal_row = [&](const CalibrationEvent& c) {
    f.stream() << c.step << ',' << format_double(c.t_s) << ",calibration,,," << fields[c.field].name << ','
               << format_double(c.old_value) << ',' << format_double(c.new_value) << '\n';
  };
  for (const auto& e : events) {
    while (j < calibration.size() && calibration[j].step < e.step) cal_row(calibration[j++]);
    f.stream() << e.step << ',' << format_double(e.t_s) << ',' << to_string(e.kind) << ',' << to_string(e.from) << ','
               << to_string(e.to) << ",,,\n";
  }
  while (j < calibration.size()) cal_row(calibration[j++]);
  f.commit();
}

void write_bus_log(const std::filesystem::path& path, const MasterRun& r) {
  std::vector<can::LogEntry> entries;
  entries.reserve(r.bus_log.size());
  for (const auto& f : r.bus_log) {
    can::LogEntry e;
    e.frame = f.frame;
    // Sent frames carry the loop time of their step; received ones the bus's wall-clock
    // receive time (kernel timestamp), which must not get the epoch a second time.
    if (f.sent) e.frame.timestamp_s = r.stats.epoch_s + f.frame.timestamp_s;
    e.interface = "hil0";
    entries.push_back(e);
  }
  can::write_log(path, entries);
}

namespace {
using nlohmann::json;
using detail::summary_json;

json loop_json(const NodeStats& st, const LoopTrace& t) {
  json j;
  j["steps"] = st.result.steps;
  j["stop_reason"] = rt::to_string(st.result.reason);
  const bool kept = !t.records.empty();  // else: the writer's statistics over every step
  j["tet_us"] = summary_json(kept ? rt::tet_us(t.records) : st.tet_us);
  j["io_us"] = summary_json(kept ? rt::io_us(t.records) : st.io_us);
  j["cycle_us"] = summary_json(kept ? rt::cycle_us(t.records) : st.cycle_us);
  j["wake_latency_us"] = summary_json(kept ? rt::wake_latency_us(t.records) : st.wake_latency_us);
  j["overruns"] = st.result.overruns;
  json ov = json::array();
  for (const auto& e : t.overruns)
    ov.push_back({{"step", e.step}, {"t_s", static_cast<double>(e.t_ns) * 1e-9}, {"late_us", us(e.late_ns)}});
  j["overrun_events"] = ov;  // the first rt::kMaxOverrunEvents
  j["logs"] = {{"rows", st.logs.rows}, {"frames", st.logs.frames}, {"events", st.logs.events},
               {"ring_full", st.logs.ring_full}, {"writes", st.logs.writes}, {"last_t_s", st.logs.last_t_s},
               {"peak_rss_kB", st.peak_rss_kB}};
  j["warnings"] = t.warnings;
  j["step_s"] = static_cast<double>(st.period_ns) * 1e-9;
  j["dma_latency_held"] = st.dma_latency_held;
  const auto& cs = st.controller;
  j["can_controller"] = {{"rx_overflows", cs.rx_overflows}, {"tx_overflows", cs.tx_overflows},
                         {"tx_failures", cs.tx_failures},   {"rx_reads", cs.rx_reads},
                         {"pulls_cut", cs.pulls_cut}};
  j["frames"] = detail::frames_json(st.frames);
  return j;
}
}  // namespace

std::string slave_stats_json(const SlaveRun& r) {
  json j = loop_json(r.stats, r.loop);
  j["state"] = to_string(r.stats.state);
  j["events"] = detail::events_json(r.events);
  j["dto_replies"] = r.stats.dto_replies;
  j["seed"] = r.stats.seed;
  j["connected"] = r.stats.connected;
  return j.dump(2) + "\n";
}

std::string master_stats_json(const MasterRun& r, const std::string& reference) {
  json j = loop_json(r.stats, r.loop);
  j["frames"]["bus_log_dropped"] = r.stats.frames.bus_log_dropped;
  j["state"] = to_string(r.stats.state);
  j["control_steps"] = r.stats.control_steps;
  j["handshake_s"] = r.stats.handshake_s;
  j["events"] = detail::events_json(r.events);
  j["reference"] = reference;
  if (r.stats.xcp)
    j["xcp"] = {{"commands", r.stats.xcp_commands}, {"errors", r.stats.xcp_errors}, {"dtos", r.stats.xcp_dtos},
                {"samples_lost", r.stats.xcp_samples_lost}, {"pages", r.stats.xcp_pages},
                {"calibration_events", r.calibration.size()}};
  return j.dump(2) + "\n";
}

}  // namespace lash::hil
