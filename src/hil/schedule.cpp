#include "lash/hil/schedule.hpp"

#include <fstream>

#include <cmath>
#include <deque>
#include <optional>
#include <stdexcept>
#include <string>

#include "lash/io/error.hpp"
#include "lash/io/table.hpp"
#include "csv_lines.hpp"

namespace lash::hil {

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

namespace {
/// A frame with the message's identifier and a wrong length: dropped by the DLC check.
can::Frame implausible(can::Frame f) {
  f.len = f.len > 0 ? static_cast<std::uint8_t>(f.len - 1) : 1;
  return f;
}

std::string step_name(const char* node, std::int64_t step) {
  return std::string(node) + (node[0] == 'm' ? " control step " : " step ") + std::to_string(step);
}

}  // namespace

/// The frames one node sent, numbered 0, 1, …; those a receiver has used are let go.
class FrameHistory {
 public:
  void push(const can::Frame& f) { d_.push_back(f); }
  std::int64_t size() const noexcept { return base_ + static_cast<std::int64_t>(d_.size()); }
  const can::Frame& at(std::int64_t q) const { return d_[static_cast<std::size_t>(q - base_)]; }
  void drop_through(std::int64_t q) {
    while (base_ <= q && !d_.empty()) {
      d_.pop_front();
      ++base_;
    }
  }

 private:
  std::deque<can::Frame> d_;
  std::int64_t base_ = 0;
};

namespace {
/// Queues what a node received at a step that used frame `use.seq` after `last` (and sets last).
void feed(FeedBus& bus, const FrameUse& use, std::int64_t& last, FrameHistory& sent,
          const can::Frame& bad, const char* node, std::int64_t step) {
  if (use.seq < -1)
    throw std::invalid_argument("hil schedule: " + step_name(node, step) + " uses frame " + std::to_string(use.seq));
  if (use.seq >= 0 && use.seq <= last)
    throw std::invalid_argument("hil schedule: " + step_name(node, step) + " uses frame " + std::to_string(use.seq) +
                                ", not newer than frame " + std::to_string(last) + " it used before");
  if (use.dropped) bus.in.push_back(bad);
  if (use.seq < 0) return;
  for (std::int64_t q = last + 1; q <= use.seq; ++q) bus.in.push_back(sent.at(q));
  last = use.seq;
  sent.drop_through(last);
}

/// Moves the frames with identifier `id` from bus.out to `to` (the others — CCP — need no delivery
/// once connected: the master ignores a DTO after the handshake).
void collect(FeedBus& bus, std::uint32_t id, FrameHistory& to) {
  for (const auto& f : bus.out)
    if (!f.extended && f.id == id) to.push(f);
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

std::size_t replayable_control_steps(const FrameSchedule& s) noexcept {
  const auto S = static_cast<std::int64_t>(s.slave.size());
  for (std::size_t m = 0; m < s.master.size(); ++m)
    if (s.master[m].seq >= S) return m;
  return s.master.size();
}

FrameSchedule lazy_ideal_schedule(std::size_t control_steps) {
  FrameSchedule s;
  s.ideal_steps = control_steps;
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

// ----------------------------------------------------------------------------- streamed

namespace {

std::int64_t integer_value(const detail::LogLines& in, const char* col, double v, double min) {
  if (!(v >= min) || v != std::floor(v) || v > 9e15)
    throw InputError(in.file(), in.line(), col,
                     "must be an integer >= " + std::to_string(static_cast<long long>(min)) + ", got " +
                         std::to_string(v));
  return static_cast<std::int64_t>(v);
}

bool has_calibration_columns(const std::filesystem::path& master_csv) {
  std::string header;
  std::ifstream in(master_csv);
  std::getline(in, header);
  const std::string first = calibration_fields()[0].name;
  std::string cell;
  for (char c : header + ",") {
    if (c == ',') {
      if (cell == first) return true;
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  return false;
}

std::vector<std::string> master_schedule_columns(bool calibration) {
  std::vector<std::string> c{"control_step", "sensor_seq", "dropped"};
  if (calibration)
    for (const auto& f : calibration_fields()) c.emplace_back(f.name);
  return c;
}

const std::vector<std::string> kSlaveScheduleColumns{"step", "command_counter", "command_fresh", "dropped"};

}  // namespace

struct ScheduleFiles::Impl {
  std::filesystem::path master_csv, slave_csv;
  bool calibration = false;
  std::optional<detail::LogLines> m, s;
  std::size_t im = 0, is = 0;  ///< the control step / slave step of the row in mv / sv
  bool m_have = false, s_have = false;
  std::vector<double> mv, sv;
  LogReadBack rb;
  /// Reads master rows up to the m-th control row.
  void master_to(std::size_t want) {
    if (!m) {
      m.emplace(master_csv, master_schedule_columns(calibration));
      m_have = false;
    }
    while (!m_have || im < want) {
      bool got = false;
      while (m->next(mv, rb))
        if (mv[0] >= 0) {
          got = true;
          break;
        }
      if (!got) throw std::logic_error("hil schedule: master.csv read past its end");
      if (m_have) ++im;
      m_have = true;
    }
  }
  void slave_to(std::size_t want) {
    if (!s) {
      s.emplace(slave_csv, kSlaveScheduleColumns);
      s_have = false;
    }
    while (!s_have || is < want) {
      if (!s->next(sv, rb)) throw std::logic_error("hil schedule: slave.csv read past its end");
      if (s_have) ++is;
      s_have = true;
    }
  }
};

ScheduleFiles::ScheduleFiles(const std::filesystem::path& master_csv, const std::filesystem::path& slave_csv)
    : impl_(std::make_unique<Impl>()) {
  impl_->master_csv = master_csv;
  impl_->slave_csv = slave_csv;
  impl_->calibration = has_calibration_columns(master_csv);
  const auto fields = calibration_fields();
  LogReadBack rb;
  std::vector<double> v;
  {  // master.csv: the checks of read_schedule, the control steps and the calibration changes
    detail::LogLines in(master_csv, master_schedule_columns(impl_->calibration));
    while (in.next(v, rb)) {
      const std::int64_t c = integer_value(in, "control_step", v[0], -1);
      if (c < 0) continue;
      if (c != static_cast<std::int64_t>(logged_))
        throw InputError(in.file(), in.line(), "control_step",
                         "control steps must count 0, 1, 2, … (expected " + std::to_string(logged_) + ")");
      (void)integer_value(in, "sensor_seq", v[1], -1);
      (void)integer_value(in, "dropped", v[2], 0);
      ++logged_;
      if (!impl_->calibration) continue;
      CalibrationPage p;
      for (std::size_t j = 0; j < fields.size(); ++j) {
        if (!std::isfinite(v[3 + j])) throw InputError(in.file(), in.line(), fields[j].name, "not a finite number");
        p.*fields[j].member = v[3 + j];
      }
      if (calibration_.empty() || !(calibration_.back().page == p)) calibration_.push_back({c, p});
    }
    if (logged_ == 0)
      throw InputError(master_csv.string(), 0, "control_step", "no control step (control_step >= 0) in the log");
  }
  {  // slave.csv
    detail::LogLines in(slave_csv, kSlaveScheduleColumns);
    while (in.next(v, rb)) {
      if (integer_value(in, "step", v[0], 0) != static_cast<std::int64_t>(slave_steps_))
        throw InputError(in.file(), in.line(), "step",
                         "slave steps must count 0, 1, 2, … (expected " + std::to_string(slave_steps_) + ")");
      if (integer_value(in, "command_fresh", v[2], 0) > 1)
        throw InputError(in.file(), in.line(), "command_fresh", "must be 0 or 1");
      (void)integer_value(in, "command_counter", v[1], 0);
      (void)integer_value(in, "dropped", v[3], 0);
      ++slave_steps_;
    }
  }
  {  // replayable_control_steps(): the first control step using a sensor frame past the slave's end
    detail::LogLines in(master_csv, master_schedule_columns(false));
    replayable_ = logged_;
    std::size_t m = 0;
    while (in.next(v, rb)) {
      if (v[0] < 0) continue;
      if (v[1] >= static_cast<double>(slave_steps_)) {
        replayable_ = m;
        break;
      }
      ++m;
    }
  }
  steps_ = logged_;
}

ScheduleFiles::~ScheduleFiles() = default;

FrameUse ScheduleFiles::master_use(std::size_t m) {
  if (impl_->m && impl_->m_have && m < impl_->im) throw std::logic_error("hil schedule: master step asked backwards");
  impl_->master_to(m);
  return FrameUse{static_cast<std::int64_t>(impl_->mv[1]), impl_->mv[2] > 0};
}

FrameUse ScheduleFiles::slave_use(std::size_t s) {
  if (impl_->s && impl_->s_have && s < impl_->is) throw std::logic_error("hil schedule: slave step asked backwards");
  impl_->slave_to(s);
  const auto& v = impl_->sv;
  return FrameUse{v[2] != 0 ? static_cast<std::int64_t>(v[1]) : -1, v[3] > 0};
}

struct TraceCompare::Impl {
  explicit Impl(const std::filesystem::path& p) : in(p, {"control_step", "measured_kPa", "current_mA"}) { advance(); }
  void advance() {
    have = false;
    while (in.next(v, rb)) {
      const std::int64_t c = integer_value(in, "control_step", v[0], -1);
      if (c < 0) continue;
      have = true;
      return;
    }
  }
  detail::LogLines in;
  std::vector<double> v;
  LogReadBack rb;
  bool have = false;
};

TraceCompare::TraceCompare(const std::filesystem::path& master_csv) : impl_(std::make_unique<Impl>(master_csv)) {}
TraceCompare::~TraceCompare() = default;

void TraceCompare::add(const MasterStepLog& sim) {
  if (sim.control_step < 0) return;
  auto& t = *impl_;
  const auto m = static_cast<double>(sim.control_step);
  while (t.have && t.v[0] < m) t.advance();
  while (t.have && t.v[0] == m) {
    d_.add(sim.control_step, t.v[1], sim.measured_kPa, t.v[2], sim.current_mA);
    t.advance();
  }
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
  SimulationResult r;
  SimulationSink sink;
  sink.master = [&r](const MasterStepLog& l) { r.master.push_back(l); };
  sink.slave = [&r](const SlaveStepLog& l) { r.slave.push_back(l); };
  SimulationResult s = simulate_bench(layout, master_cfg, slave_cfg, schedule, sink);
  s.master = std::move(r.master);
  s.slave = std::move(r.slave);
  return s;
}

namespace {
class FrameScheduleSource final : public ScheduleSource {
 public:
  explicit FrameScheduleSource(const FrameSchedule& s) : s_(s) {}
  std::size_t master_steps() const override { return s_.master_steps(); }
  std::size_t slave_steps() const override { return s_.slave_steps(); }
  FrameUse master_use(std::size_t m) override { return s_.master_use(m); }
  FrameUse slave_use(std::size_t s) override { return s_.slave_use(s); }

 private:
  const FrameSchedule& s_;
};

MasterConfig streaming(MasterConfig mc, const std::vector<MasterConfig::CalibrationChange>& calibration) {
  mc.log_capacity = 1;  // one row, handed to the sink after each step
  mc.bus_log_capacity = 1;
  if (!calibration.empty()) mc.calibration_schedule = calibration;
  return mc;
}
SlaveConfig streaming(SlaveConfig sc) {
  sc.log_capacity = 1;
  return sc;
}
}  // namespace

BenchSimulation::BenchSimulation(const BenchLayout& layout, const MasterConfig& master_cfg,
                                 const SlaveConfig& slave_cfg, const FrameSchedule& schedule,
                                 const SimulationSink& sink)
    : BenchSimulation(layout, master_cfg, slave_cfg, std::make_unique<FrameScheduleSource>(schedule),
                      schedule.calibration, sink) {}

BenchSimulation::BenchSimulation(const BenchLayout& layout, const MasterConfig& master_cfg,
                                 const SlaveConfig& slave_cfg, ScheduleSource& schedule,
                                 const std::vector<MasterConfig::CalibrationChange>& calibration,
                                 const SimulationSink& sink)
    : BenchSimulation(layout, master_cfg, slave_cfg, std::unique_ptr<ScheduleSource>(), calibration, sink, &schedule) {}

BenchSimulation::BenchSimulation(const BenchLayout& layout, const MasterConfig& master_cfg,
                                 const SlaveConfig& slave_cfg, std::unique_ptr<ScheduleSource> owned,
                                 const std::vector<MasterConfig::CalibrationChange>& calibration,
                                 const SimulationSink& sink, ScheduleSource* borrowed)
    : layout_(layout),
      owned_(std::move(owned)),
      schedule_(borrowed ? *borrowed : *owned_),
      sink_(sink),
      master_(layout, streaming(master_cfg, calibration)),
      slave_(layout, streaming(slave_cfg)),
      T_(master_cfg.controller.pid.dt_s),
      mb_(std::make_unique<FeedBus>()),
      sb_(std::make_unique<FeedBus>()),
      sensors_(std::make_unique<FrameHistory>()),
      commands_(std::make_unique<FrameHistory>()),
      bad_sensor_(implausible(layout.pack_sensors(SensorMsg{}))),
      bad_command_(implausible(layout.pack_command(CommandMsg{}))) {
  // Handshake: CRO → slave, DTO → master.
  master_step(*mb_, 0.0);
  sb_->in.assign(mb_->out.begin(), mb_->out.end());
  mb_->out.clear();
  if (!slave_.wait_connect(*sb_, std::chrono::nanoseconds(0)))
    throw std::invalid_argument("hil simulate: the slave did not see the master's CCP CONNECT");
  mb_->in.assign(sb_->out.begin(), sb_->out.end());
  sb_->out.clear();
}

BenchSimulation::~BenchSimulation() = default;

void BenchSimulation::master_step(can::Bus& bus, double t) {
  ok_ = master_.step(bus, t);
  if (!master_.log().empty() && sink_.master) sink_.master(master_.log()[0]);
  master_.clear_step_logs();
}

bool BenchSimulation::slave_ready() {
  return s_ < static_cast<std::int64_t>(schedule_.slave_steps()) &&
         schedule_.slave_use(static_cast<std::size_t>(s_)).seq < commands_->size();
}

void BenchSimulation::slave_step() {
  feed(*sb_, schedule_.slave_use(static_cast<std::size_t>(s_)), s_used_, *commands_, bad_command_, "slave", s_);
  slave_.step(*sb_, (static_cast<double>(s_) + 0.5) * T_);
  if (!slave_.log().empty() && sink_.slave) sink_.slave(slave_.log()[0]);
  slave_.clear_step_log();
  collect(*sb_, layout_.sensors_id, *sensors_);
  ++s_;
}

bool BenchSimulation::advance() {
  if (!ok_ || m_ >= static_cast<std::int64_t>(schedule_.master_steps())) return false;
  const FrameUse u = schedule_.master_use(static_cast<std::size_t>(m_));
  while (u.seq >= s_) {
    if (!slave_ready()) {
      const auto S = static_cast<std::int64_t>(schedule_.slave_steps());
      throw std::invalid_argument(
          "hil schedule: not causal: master control step " + std::to_string(m_) + " uses slave frame " +
          std::to_string(u.seq) + ", but slave step " + std::to_string(s_) +
          (s_ < S ? " uses command " + std::to_string(schedule_.slave_use(static_cast<std::size_t>(s_)).seq) +
                        " of a later control step"
                  : " is past the end of the slave's schedule (" + std::to_string(S) + " steps)"));
    }
    slave_step();
  }
  feed(*mb_, u, m_used_, *sensors_, bad_sensor_, "master", m_);
  master_step(*mb_, static_cast<double>(m_ + 1) * T_);
  if (!ok_) return false;
  collect(*mb_, layout_.command_id, *commands_);
  ++m_;
  return true;
}

SimulationResult BenchSimulation::finish() {
  // The slave steps of the control steps run (for the plant pressure of each control step).
  const auto N = static_cast<std::int64_t>(schedule_.master_steps());
  while (s_ < N && slave_ready()) slave_step();
  if (N > 0 && (master_.state() == MasterState::startup || master_.state() == MasterState::failed))
    throw std::invalid_argument(std::string("hil simulate: the master ended in state ") + to_string(master_.state()) +
                                " (is the recorded DTO a positive CONNECT reply?)");
  SimulationResult r;
  r.compensation = master_.compensation();
  r.events.assign(master_.events().begin(), master_.events().end());
  return r;
}

SimulationResult simulate_bench(const BenchLayout& layout, const MasterConfig& master_cfg,
                                const SlaveConfig& slave_cfg, const FrameSchedule& schedule,
                                const SimulationSink& sink) {
  FrameScheduleSource src(schedule);
  return simulate_bench(layout, master_cfg, slave_cfg, src, schedule.calibration, sink);
}

SimulationResult simulate_bench(const BenchLayout& layout, const MasterConfig& master_cfg,
                                const SlaveConfig& slave_cfg, ScheduleSource& schedule,
                                const std::vector<MasterConfig::CalibrationChange>& calibration,
                                const SimulationSink& sink) {
  BenchSimulation sim(layout, master_cfg, slave_cfg, schedule, calibration, sink);
  while (sim.advance()) {
  }
  return sim.finish();
}

}  // namespace lash::hil
