// `lash hil run`'s report from the nodes' CSV logs, streaming (report_logs.hpp). Each figure is
// computed as report.cpp computes it over the logs read back whole, in the same order of
// operations, so that the two give the same numbers bit for bit.
#include "lash/hil/report_logs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

namespace lash::hil {

namespace {

// ----------------------------------------------------------------------------- loop figures

/// rt::summarize() of the four loop quantities over rows given twice: pass 1 (sum, min, max,
/// count), pass 2 (squared deviations from the mean of pass 1, the largest values for the
/// nearest-rank 99th percentile, whose number needs the count of pass 1).
class LoopSummaries {
 public:
  static std::array<double, 4> values(const rt::StepRecord& r) {
    return {static_cast<double>(r.tet_ns) * 1e-3, static_cast<double>(r.io_ns) * 1e-3,
            static_cast<double>(r.io_ns + r.tet_ns) * 1e-3, static_cast<double>(r.wake_latency_ns) * 1e-3};
  }
  void first(const rt::StepRecord& r) {
    const auto v = values(r);
    for (std::size_t q = 0; q < 4; ++q) {
      if (n_ == 0) {
        min_[q] = max_[q] = v[q];
      } else {
        min_[q] = std::min(min_[q], v[q]);
        max_[q] = std::max(max_[q], v[q]);
      }
      sum_[q] += v[q];
    }
    ++n_;
  }
  void begin_second() {
    for (std::size_t q = 0; q < 4; ++q) {
      mean_[q] = sum_[q] / static_cast<double>(n_);
      tails_[q] = rt::StreamSummary(n_);
    }
  }
  void second(const rt::StepRecord& r) {
    const auto v = values(r);
    for (std::size_t q = 0; q < 4; ++q) {
      ss_[q] += (v[q] - mean_[q]) * (v[q] - mean_[q]);
      tails_[q].add(v[q]);
    }
  }
  void result(NodeLogScan& s) const {
    rt::Summary* out[4] = {&s.tet_us, &s.io_us, &s.cycle_us, &s.wake_latency_us};
    for (std::size_t q = 0; q < 4; ++q) {
      rt::Summary r;
      r.n = n_;
      if (n_ > 0) {
        r.min = min_[q];
        r.max = max_[q];
        r.mean = mean_[q];
        if (n_ > 1) r.std = std::sqrt(ss_[q] / static_cast<double>(n_ - 1));
        r.p99 = tails_[q].result().p99;
      }
      *out[q] = r;
    }
  }

 private:
  std::size_t n_ = 0;
  std::array<double, 4> sum_{}, min_{}, max_{}, mean_{}, ss_{};
  std::array<rt::StreamSummary, 4> tails_;
};

template <class Row, class OnRow>
NodeLogScan scan_log(const std::filesystem::path& path, OnRow on_row) {
  NodeLogScan s;
  s.file = path;
  LoopSummaries loop;
  Row l;
  rt::StepRecord rec;
  {
    LogReader<Row> in(path);
    while (in.next(l, rec)) {
      loop.first(rec);
      s.last_state = l.state;
      on_row(l);
    }
    s.read = in.read_back();
  }
  if (s.read.rows > 0) {
    loop.begin_second();
    LogReader<Row> in(path);
    while (in.next(l, rec)) loop.second(rec);
  }
  loop.result(s);
  return s;
}

// ----------------------------------------------------------------------------- readers

/// The rows of a node's log that `keep` takes (all without it), one ahead.
template <class Row>
class RowsAhead {
 public:
  explicit RowsAhead(const std::filesystem::path& p, bool (*keep)(const Row&) = nullptr) : in_(p), keep_(keep) {
    advance();
  }
  bool done() const noexcept { return done_; }
  const Row& row() const noexcept { return row_; }
  void advance() {
    rt::StepRecord r;
    while (in_.next(row_, r))
      if (!keep_ || keep_(row_)) return;
    done_ = true;
  }

 private:
  LogReader<Row> in_;
  bool (*keep_)(const Row&);
  Row row_;
  bool done_ = false;
};

bool is_control_row(const MasterStepLog& l) { return l.control_step >= 0; }

/// The control rows of a master log (control_step ≥ 0), one ahead.
class ControlRows : public RowsAhead<MasterStepLog> {
 public:
  explicit ControlRows(const std::filesystem::path& p) : RowsAhead(p, is_control_row) {}
};

/// The rows of a slave log, one ahead.
using SlaveRows = RowsAhead<SlaveStepLog>;

/// compare_with_simulation() of the master log (control rows in ascending control step, as the
/// nodes write them) with simulated rows given one at a time, also in ascending control step.
class StreamCompare {
 public:
  explicit StreamCompare(const std::filesystem::path& master_csv) : rows_(master_csv) {}
  void add(const MasterStepLog& sim) {
    if (sim.control_step < 0) return;
    while (!rows_.done() && rows_.row().control_step < sim.control_step) rows_.advance();
    while (!rows_.done() && rows_.row().control_step == sim.control_step) {
      const MasterStepLog& e = rows_.row();
      d_.add(e.control_step, e.measured_kPa, sim.measured_kPa, e.current_mA, sim.current_mA);
      rows_.advance();
    }
  }
  const SimulationDiff& result() const noexcept { return d_; }

 private:
  ControlRows rows_;
  SimulationDiff d_;
};

/// observed_schedule() of the logs, read step by step (the replay asks in ascending order).
class LogSchedule final : public ScheduleSource {
 public:
  LogSchedule(const std::filesystem::path& master_csv, const std::filesystem::path& slave_csv, std::size_t master_steps,
              std::size_t slave_steps)
      : m_(master_csv), s_(slave_csv), nm_(master_steps), ns_(slave_steps) {}
  std::size_t master_steps() const override { return nm_; }
  std::size_t slave_steps() const override { return ns_; }
  FrameUse master_use(std::size_t m) override {
    for (; im_ < m; ++im_) m_.advance();
    if (im_ != m || m_.done()) throw std::logic_error("hil report: master schedule asked backwards or past its end");
    return FrameUse{m_.row().sensor_seq, m_.row().dropped > 0};
  }
  FrameUse slave_use(std::size_t s) override {
    for (; is_ < s; ++is_) s_.advance();
    if (is_ != s || s_.done()) throw std::logic_error("hil report: slave schedule asked backwards or past its end");
    const SlaveStepLog& l = s_.row();
    return FrameUse{l.command_fresh ? static_cast<std::int64_t>(l.command_counter) : -1, l.dropped > 0};
  }

 private:
  ControlRows m_;
  SlaveRows s_;
  std::size_t nm_, ns_, im_ = 0, is_ = 0;
};

/// What one pass over the master's control rows and the slave's rows side by side gives (row i
/// of each: control step i, slave step i): off_schedule_steps(), step_response(), the scenario's
/// tracking figures, and the control steps the slave's schedule can replay.
struct PairedFigures {
  std::size_t off_schedule = 0;
  std::optional<StepResponse> step;
  std::optional<ScenarioFigures> scenario;
  std::size_t replayable = 0;
};

PairedFigures paired_pass(const std::filesystem::path* master_csv, const std::filesystem::path* slave_csv,
                          std::size_t slave_rows, std::int64_t control_steps, double dt_s, bool with_step,
                          const BenchScenario* scenario) {
  PairedFigures out;
  std::optional<ControlRows> m;
  std::optional<SlaveRows> s;
  if (master_csv) m.emplace(*master_csv);
  if (slave_csv) s.emplace(*slave_csv);
  // off_schedule_steps(): the union of the steps either node got wrong, counted once. Both
  // streams ascend, so a step below both streams' last one can no longer come again.
  std::set<std::int64_t> off;
  constexpr std::int64_t kEnd = std::numeric_limits<std::int64_t>::max();
  std::int64_t m_last = -1, s_last = -1;
  StepResponseStream step(dt_s, true);
  std::size_t n_ref = 0, n_slave = 0;
  bool replay_cut = false;
  std::optional<ScenarioScore> figures;
  std::size_t n_pairs = 0;  // control step m pairs with slave step m
  if (scenario) figures.emplace(*scenario, dt_s);
  for (;;) {
    const bool have_m = m && !m->done(), have_s = s && !s->done();
    if (!have_m && !have_s) break;
    if (have_m) {
      const MasterStepLog& l = m->row();
      if (!l.sensor_fresh || l.sensor_counter != static_cast<std::uint16_t>(l.control_step)) off.insert(l.control_step);
      m_last = l.control_step;
      if (!replay_cut && l.sensor_seq >= static_cast<std::int64_t>(slave_rows)) replay_cut = true;
      if (!replay_cut) ++out.replayable;
    }
    if (have_s) {
      const SlaveStepLog& l = s->row();
      const auto st = static_cast<std::int64_t>(l.step);
      if (st > 0 && st < control_steps && (!l.command_fresh || l.command_counter != static_cast<std::uint64_t>(st - 1)))
        off.insert(st);
      s_last = st;
    }
    if (have_m && with_step)  // the step is found on the reference; its window needs the slave's rows
      step.add(m->row().reference_kPa, have_s ? s->row().pressure_kPa : 0.0, have_s ? s->row().measured_kPa : 0.0);
    if (have_m && have_s && figures) figures->add(n_pairs++, m->row().reference_kPa, s->row().pressure_kPa);
    if (have_m) {
      ++n_ref;
      m->advance();
    }
    if (have_s) {
      ++n_slave;
      s->advance();
    }
    const std::int64_t below = std::min(m && !m->done() ? m_last : kEnd, s && !s->done() ? s_last : kEnd);
    while (!off.empty() && *off.begin() < below) {
      off.erase(off.begin());
      ++out.off_schedule;
    }
  }
  out.off_schedule += off.size();
  if (with_step) {
    out.step = step.result();
    if (out.step && out.step->window.end > n_slave) out.step.reset();  // the slave's log ends inside the window
  }
  if (figures) out.scenario = figures->result(CompensationState{});
  return out;
}

NodeFigures figures_of(const NodeStats& stats, const LoopTrace& loop, const std::optional<NodeLogScan>& scan) {
  NodeFigures f = node_figures(stats, LoopTrace{{}, loop.overruns, loop.warnings});
  if (scan && scan->read.rows > 0) {  // the loop records are the log's rows
    f.tet_us = scan->tet_us;
    f.io_us = scan->io_us;
    f.cycle_us = scan->cycle_us;
    f.wake_latency_us = scan->wake_latency_us;
  }
  return f;
}

}  // namespace

NodeLogScan scan_master_log(const std::filesystem::path& path) {
  std::int64_t last_m = -1;
  std::size_t control_rows = 0;
  std::vector<MasterConfig::CalibrationChange> cal;
  NodeLogScan s = scan_log<MasterStepLog>(path, [&](const MasterStepLog& l) {
    last_m = std::max(last_m, l.control_step);
    if (l.control_step < 0) return;
    ++control_rows;
    if (cal.empty() || !(cal.back().page == l.calibration)) cal.push_back({l.control_step, l.calibration});
  });
  s.last_control_step = last_m;
  s.control_rows = control_rows;
  s.calibration = std::move(cal);
  return s;
}

NodeLogScan scan_slave_log(const std::filesystem::path& path) {
  return scan_log<SlaveStepLog>(path, [](const SlaveStepLog&) {});
}

void make_run_report_from_logs(RunReport& rep, const MasterRun* master, const std::vector<SlaveRun>& slaves,
                               const RunLogs& logs, const BenchLayout& L, const MasterConfig& mc,
                               const SlaveConfig& sc, const BenchScenario* scenario) {
  // make_run_report()'s figures.
  report_nodes(rep, master, slaves, [&](const NodeStats& s, const LoopTrace& l, bool is_master) {
    return figures_of(s, l, is_master ? logs.master : logs.slave);
  });
  const std::filesystem::path* master_csv = master && logs.master ? &logs.master->file : nullptr;
  const std::filesystem::path* slave_csv = rep.have_slave && logs.slave ? &logs.slave->file : nullptr;
  const std::size_t slave_rows = slave_csv ? logs.slave->read.rows : 0;
  if (!master) return;

  const PairedFigures pf = paired_pass(master_csv, slave_csv, slave_rows, rep.control_steps, rep.step_s,
                                       rep.have_slave, rep.have_slave ? scenario : nullptr);
  rep.off_schedule = pf.off_schedule;
  rep.step = pf.step;
  if (pf.scenario) {
    rep.scenario = *pf.scenario;
    rep.scenario->compensation = master->stats.compensation;
  }

  // Against the simulation of the ideal schedule, with the calibration writes the run logged.
  rep.vs_simulation = {};
  if (master->stats.control_steps <= 0) return;
  const std::vector<MasterConfig::CalibrationChange> no_cal;
  const auto& cal = logs.master ? logs.master->calibration : no_cal;
  {
    FrameSchedule ideal = lazy_ideal_schedule(static_cast<std::size_t>(master->stats.control_steps));
    ideal.calibration = cal;
    if (master_csv) {
      StreamCompare cmp(*master_csv);
      SimulationSink sink;
      sink.master = [&](const MasterStepLog& l) { cmp.add(l); };
      simulate_bench(L, mc, sc, ideal, sink);
      rep.vs_simulation = cmp.result();
    } else {
      simulate_bench(L, mc, sc, ideal, SimulationSink{});  // as make_run_report: it must simulate
    }
  }
  // Against the simulation of the schedule the nodes logged.
  if (slaves.size() != 1 || slave_rows == 0) {
    rep.observed_schedule_note = "not replayed: the schedule of one slave from start to end is needed";
    return;
  }
  try {
    const std::size_t control_rows = master_csv ? logs.master->control_rows : 0;
    const std::size_t kept = pf.replayable;
    if (kept < control_rows)
      rep.observed_schedule_note =
          "replayed the first " + std::to_string(kept) + " control steps: the slave's log ends before the master's";
    std::optional<LogSchedule> fs;
    std::optional<StreamCompare> cmp;
    if (master_csv) {
      fs.emplace(*master_csv, *slave_csv, kept, slave_rows);
      cmp.emplace(*master_csv);
    }
    SimulationSink sink;
    sink.master = [&](const MasterStepLog& l) { cmp->add(l); };
    if (fs) {
      simulate_bench(L, mc, sc, *fs, cal, sink);
      rep.vs_observed_schedule = cmp->result();
    } else {
      rep.vs_observed_schedule = SimulationDiff{};
    }
  } catch (const std::invalid_argument& e) {
    rep.observed_schedule_note = std::string("not replayed: ") + e.what();
  }
}

}  // namespace lash::hil
