#include "lash/hil/schedule.hpp"

#include <fstream>

#include <cmath>
#include <deque>
#include <stdexcept>
#include <string>

#include "lash/io/error.hpp"
#include "lash/io/table.hpp"

namespace lash::hil {
namespace {

/// A node's bus in the replay: it receives what the replay queued for its step and keeps what it sent.
class FeedBus final : public can::Bus {
 public:
  std::deque<can::Frame> in;
  std::vector<can::Frame> out;
  bool send(const can::Frame& frame) noexcept override {
    out.push_back(frame);
    ++stats_.sent;
    return true;
  }
  std::optional<can::Frame> receive(std::chrono::nanoseconds) noexcept override {
    if (in.empty()) return std::nullopt;
    can::Frame f = in.front();
    in.pop_front();
    ++stats_.received;
    return f;
  }
  void set_filters(std::vector<can::Filter>) override {}
  can::BusStats stats() const noexcept override { return stats_; }
  std::string address() const override { return "schedule"; }

 private:
  can::BusStats stats_;
};

/// A frame with the message's identifier and a wrong length: dropped by the DLC check.
can::Frame implausible(can::Frame f) {
  f.len = f.len > 0 ? static_cast<std::uint8_t>(f.len - 1) : 1;
  return f;
}

std::string step_name(const char* node, std::int64_t step) {
  return std::string(node) + (node[0] == 'm' ? " control step " : " step ") + std::to_string(step);
}

/// Queues what a node received at a step that used frame `use.seq` after `last` (and sets last).
void feed(FeedBus& bus, const FrameUse& use, std::int64_t& last, const std::vector<can::Frame>& sent,
          const can::Frame& bad, const char* node, std::int64_t step) {
  if (use.seq < -1)
    throw std::invalid_argument("hil schedule: " + step_name(node, step) + " uses frame " + std::to_string(use.seq));
  if (use.seq >= 0 && use.seq <= last)
    throw std::invalid_argument("hil schedule: " + step_name(node, step) + " uses frame " + std::to_string(use.seq) +
                                ", not newer than frame " + std::to_string(last) + " it used before");
  if (use.dropped) bus.in.push_back(bad);
  if (use.seq < 0) return;
  for (std::int64_t q = last + 1; q <= use.seq; ++q) bus.in.push_back(sent[static_cast<std::size_t>(q)]);
  last = use.seq;
}

/// Moves the frames with identifier `id` from bus.out to `to` (the others — CCP — need no delivery
/// once connected: the master ignores a DTO after the handshake).
void collect(FeedBus& bus, std::uint32_t id, std::vector<can::Frame>& to) {
  for (const auto& f : bus.out)
    if (!f.extended && f.id == id) to.push_back(f);
  bus.out.clear();
}

std::int64_t integer_cell(const Table& t, std::string_view col, std::size_t row, double min) {
  const double v = t[col][row];
  if (!(v >= min) || v != std::floor(v) || v > 9e15)
    throw InputError(t.file, t.line_of_row[row], std::string(col),
                     "must be an integer >= " + std::to_string(static_cast<long long>(min)) + ", got " +
                         std::to_string(v));
  return static_cast<std::int64_t>(v);
}

// The calibration columns of a master.csv (calibration_fields(), when the log has them): the
// page of the first control step and every change after it.
void read_calibration(const std::filesystem::path& master_csv, FrameSchedule& s) {
  std::string header;
  {
    std::ifstream in(master_csv);
    std::getline(in, header);
  }
  const auto fields = calibration_fields();
  if (header.find(std::string(",") + fields[0].name + ",") == std::string::npos &&
      header.find(std::string(",") + fields[0].name) == std::string::npos)
    return;
  TableOptions o;
  o.columns = {"control_step"};
  for (const auto& f : fields) o.columns.emplace_back(f.name);
  o.strict = true;
  const Table t = read_table(master_csv, o);
  for (std::size_t i = 0; i < t.rows(); ++i) {
    const std::int64_t c = integer_cell(t, "control_step", i, -1);
    if (c < 0) continue;
    CalibrationPage p;
    for (const auto& f : fields) p.*f.member = t[f.name][i];
    if (s.calibration.empty() || !(s.calibration.back().page == p)) s.calibration.push_back({c, p});
  }
}

}  // namespace

FrameSchedule ideal_schedule(std::size_t control_steps) {
  FrameSchedule s;
  for (std::size_t k = 0; k < control_steps; ++k) {
    s.master.push_back(FrameUse{static_cast<std::int64_t>(k), false});
    s.slave.push_back(FrameUse{static_cast<std::int64_t>(k) - 1, false});
  }
  return s;
}

FrameSchedule observed_schedule(const std::vector<MasterStepLog>& master, const std::vector<SlaveStepLog>& slave) {
  FrameSchedule s;
  for (const auto& l : master)
    if (l.control_step >= 0) {
      s.master.push_back(FrameUse{l.sensor_seq, l.dropped > 0});
      if (s.calibration.empty() || !(s.calibration.back().page == l.calibration))
        s.calibration.push_back({l.control_step, l.calibration});
    }
  for (const auto& l : slave)
    s.slave.push_back(FrameUse{l.command_fresh ? static_cast<std::int64_t>(l.command_counter) : -1, l.dropped > 0});
  return s;
}

FrameSchedule read_schedule(const std::filesystem::path& master_csv, const std::filesystem::path& slave_csv) {
  TableOptions mo;
  mo.columns = {"control_step", "sensor_seq", "dropped"};
  mo.strict = true;
  const Table m = read_table(master_csv, mo);
  TableOptions so;
  so.columns = {"step", "command_counter", "command_fresh", "dropped"};
  so.strict = true;
  const Table sl = read_table(slave_csv, so);
  FrameSchedule s;
  for (std::size_t i = 0; i < m.rows(); ++i) {
    const std::int64_t c = integer_cell(m, "control_step", i, -1);
    if (c < 0) continue;
    if (c != static_cast<std::int64_t>(s.master.size()))
      throw InputError(m.file, m.line_of_row[i], "control_step",
                       "control steps must count 0, 1, 2, … (expected " + std::to_string(s.master.size()) + ")");
    s.master.push_back(FrameUse{integer_cell(m, "sensor_seq", i, -1), integer_cell(m, "dropped", i, 0) > 0});
  }
  read_calibration(master_csv, s);
  if (s.master.empty()) throw InputError(m.file, 0, "control_step", "no control step (control_step >= 0) in the log");
  for (std::size_t i = 0; i < sl.rows(); ++i) {
    if (integer_cell(sl, "step", i, 0) != static_cast<std::int64_t>(i))
      throw InputError(sl.file, sl.line_of_row[i], "step", "slave steps must count 0, 1, 2, … (expected " +
                                                              std::to_string(i) + ")");
    const std::int64_t fresh = integer_cell(sl, "command_fresh", i, 0);
    if (fresh > 1) throw InputError(sl.file, sl.line_of_row[i], "command_fresh", "must be 0 or 1");
    const std::int64_t counter = integer_cell(sl, "command_counter", i, 0);
    s.slave.push_back(FrameUse{fresh ? counter : -1, integer_cell(sl, "dropped", i, 0) > 0});
  }
  return s;
}

std::vector<MasterStepLog> read_master_trace(const std::filesystem::path& master_csv) {
  TableOptions o;
  o.columns = {"control_step", "measured_kPa", "current_mA"};
  o.strict = true;
  const Table t = read_table(master_csv, o);
  std::vector<MasterStepLog> log;
  for (std::size_t i = 0; i < t.rows(); ++i) {
    MasterStepLog l;
    l.control_step = integer_cell(t, "control_step", i, -1);
    if (l.control_step < 0) continue;
    l.measured_kPa = t["measured_kPa"][i];
    l.current_mA = t["current_mA"][i];
    log.push_back(l);
  }
  return log;
}

SimulationResult simulate_bench(const BenchLayout& layout, const MasterConfig& master_cfg,
                                const SlaveConfig& slave_cfg, const FrameSchedule& schedule) {
  const std::size_t N = schedule.master.size();
  MasterConfig mc = master_cfg;
  mc.log_capacity = N + 1;
  if (!schedule.calibration.empty()) mc.calibration_schedule = schedule.calibration;
  SlaveConfig sc = slave_cfg;
  sc.log_capacity = std::max(N, schedule.slave.size());
  MasterNode master(layout, mc);
  SlaveNode slave(layout, sc);
  const double T = mc.controller.pid.dt_s;
  FeedBus mb, sb;
  // Handshake: CRO → slave, DTO → master.
  master.step(mb, 0.0);
  sb.in.assign(mb.out.begin(), mb.out.end());
  mb.out.clear();
  if (!slave.wait_connect(sb, std::chrono::nanoseconds(0)))
    throw std::invalid_argument("hil simulate: the slave did not see the master's CCP CONNECT");
  mb.in.assign(sb.out.begin(), sb.out.end());
  sb.out.clear();

  const can::Frame bad_sensor = implausible(layout.pack_sensors(SensorMsg{}));
  const can::Frame bad_command = implausible(layout.pack_command(CommandMsg{}));
  std::vector<can::Frame> sensors, commands;  // sent by slave step s / control step m
  std::int64_t m = 0, s = 0, m_used = -1, s_used = -1;
  const auto S = static_cast<std::int64_t>(schedule.slave.size());
  auto slave_ready = [&] {
    return s < S && schedule.slave[static_cast<std::size_t>(s)].seq < static_cast<std::int64_t>(commands.size());
  };
  auto slave_step = [&] {
    feed(sb, schedule.slave[static_cast<std::size_t>(s)], s_used, commands, bad_command, "slave", s);
    slave.step(sb, (static_cast<double>(s) + 0.5) * T);
    collect(sb, layout.sensors_id, sensors);
    ++s;
  };
  while (m < static_cast<std::int64_t>(N)) {
    const FrameUse& u = schedule.master[static_cast<std::size_t>(m)];
    if (u.seq < s) {
      feed(mb, u, m_used, sensors, bad_sensor, "master", m);
      if (!master.step(mb, static_cast<double>(m + 1) * T)) break;
      collect(mb, layout.command_id, commands);
      ++m;
    } else if (slave_ready()) {
      slave_step();
    } else {
      throw std::invalid_argument(
          "hil schedule: not causal: master control step " + std::to_string(m) + " uses slave frame " +
          std::to_string(u.seq) + ", but slave step " + std::to_string(s) +
          (s < S ? " uses command " + std::to_string(schedule.slave[static_cast<std::size_t>(s)].seq) +
                       " of a later control step"
                 : " is past the end of the slave's schedule (" + std::to_string(S) + " steps)"));
    }
  }
  // The slave steps of the control steps run (for the plant pressure of each control step).
  while (s < static_cast<std::int64_t>(N) && slave_ready()) slave_step();
  if (N > 0 && (master.state() == MasterState::startup || master.state() == MasterState::failed))
    throw std::invalid_argument(std::string("hil simulate: the master ended in state ") + to_string(master.state()) +
                                " (is the recorded DTO a positive CONNECT reply?)");

  SimulationResult r;
  r.master.assign(master.log().begin(), master.log().end());
  r.slave.assign(slave.log().begin(), slave.log().end());
  r.compensation = master.compensation();
  r.events.assign(master.events().begin(), master.events().end());
  return r;
}

}  // namespace lash::hil
