#include "lash/hil/sim_run.hpp"

#include <cmath>
#include <deque>
#include <optional>

#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"

namespace lash::hil {

namespace {

/// The CSV of a simulation: `simulate(sink)` runs it (simulate_bench), `compare(row)` sees each
/// simulated control-step row of the master.
template <class Simulate, class Compare>
SimulationFileRun run_to_csv(double dt_s, const std::filesystem::path& out, const BenchScenario* scenario,
                             Simulate simulate, Compare compare) {
  SimulationFileRun run;
  AtomicFile f(out);
  f.stream() << "control_step,t_s,reference_kPa,measured_kPa,current_mA,pressure_kPa\n";
  StepResponseStream step(dt_s);
  std::optional<ScenarioScore> score;  // scenario figures, accumulated row by row
  if (scenario) score.emplace(*scenario, dt_s);
  // Control step m pairs with slave step m; either may come first.
  std::deque<MasterStepLog> masters;
  std::deque<SlaveStepLog> slaves;
  std::string line;
  auto emit = [&] {
    while (!masters.empty() && !slaves.empty()) {
      const MasterStepLog& ml = masters.front();
      const SlaveStepLog& sl = slaves.front();
      const auto m = static_cast<double>(run.rows);
      line.clear();
      append_double(line, static_cast<double>(ml.control_step));
      line += ',';
      append_double(line, m * dt_s);
      for (double v : {ml.reference_kPa, ml.measured_kPa, ml.current_mA, sl.pressure_kPa}) {
        line += ',';
        append_double(line, v);
      }
      line += '\n';
      f.stream() << line;
      if (score)
        score->add(run.rows, ml.reference_kPa, sl.pressure_kPa);
      else
        step.add(ml.reference_kPa, sl.pressure_kPa);
      ++run.rows;
      masters.pop_front();
      slaves.pop_front();
    }
  };
  SimulationSink sink;
  sink.master = [&](const MasterStepLog& l) {
    if (l.control_step < 0) return;
    compare(l);
    masters.push_back(l);
    emit();
  };
  sink.slave = [&](const SlaveStepLog& l) {
    slaves.push_back(l);
    emit();
  };
  const SimulationResult r = simulate(sink);
  f.commit();
  run.compensation = r.compensation;
  if (scenario) {
    run.scenario = score->result(r.compensation);
  } else {
    run.step = step.result();
  }
  return run;
}

}  // namespace

SimulationFileRun simulate_to_csv(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                                  const FrameSchedule& schedule, double dt_s, const std::filesystem::path& out,
                                  const BenchScenario* scenario, const std::vector<MasterStepLog>* compare_with) {
  SimulationDiff diff;
  SimulationFileRun run = run_to_csv(
      dt_s, out, scenario, [&](const SimulationSink& sink) { return simulate_bench(layout, master, slave, schedule, sink); },
      [&](const MasterStepLog& l) {
        if (!compare_with) return;  // compare_with_simulation(), one simulated row at a time
        const auto m = static_cast<std::size_t>(l.control_step);
        if (m < compare_with->size() && (*compare_with)[m].control_step == l.control_step) {
          const MasterStepLog& e = (*compare_with)[m];
          diff.add(l.control_step, e.measured_kPa, l.measured_kPa, e.current_mA, l.current_mA);
        }
      });
  if (compare_with) run.vs_log = diff;
  return run;
}

SimulationFileRun simulate_to_csv(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                                  ScheduleFiles& schedule, double dt_s, const std::filesystem::path& out,
                                  const BenchScenario* scenario, const std::filesystem::path& compare_with) {
  TraceCompare cmp(compare_with);
  SimulationFileRun run = run_to_csv(
      dt_s, out, scenario,
      [&](const SimulationSink& sink) {
        return simulate_bench(layout, master, slave, schedule, schedule.calibration(), sink);
      },
      [&](const MasterStepLog& l) { cmp.add(l); });
  run.vs_log = cmp.result();
  return run;
}

}  // namespace lash::hil
