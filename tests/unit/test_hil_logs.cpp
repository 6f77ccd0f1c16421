// The nodes' streamed logs (hil/log_writer.hpp), read back (hil/handover.hpp), and a node's
// launch file (hil/launch.hpp).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "lash/hil/handover.hpp"
#include "lash/hil/launch.hpp"
#include "lash/hil/log_writer.hpp"
#include "lash/hil/node_report.hpp"
#include "lash/io/error.hpp"
#include "hil_log_read.hpp"

using namespace lash;
using namespace lash::hil;
using test::read_master_log;

namespace {

std::filesystem::path temp_dir() {
  const auto d = std::filesystem::temp_directory_path() / ("lash_hil_logs_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

std::string text_of(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

MasterRun some_master_run() {
  MasterRun r;
  for (std::uint32_t k = 0; k < 300; ++k) {
    MasterStepLog l;
    l.step = k;
    l.control_step = static_cast<std::int64_t>(k) - 1;
    l.state = k == 0 ? NodeState::startup : NodeState::running;
    l.reference_kPa = 500.0 + k;
    l.measured_kPa = 0.1 * k + 1.0 / 3.0;
    l.sensor_counter = static_cast<std::uint16_t>(k);
    l.sensor_fresh = k % 7 != 0;
    l.sensor_seq = l.sensor_fresh ? k : -1;
    l.dropped = static_cast<std::uint16_t>(k % 5 == 0);
    l.current_mA = 312.5 + 0.01 * k;
    l.integrator_mA = -2.0 * k;
    l.command_counter = static_cast<std::uint16_t>(k);
    l.command_sent = k > 0;
    l.calibration.kp = 0.5 + (k > 150 ? 0.25 : 0.0);
    r.log.push_back(l);
    r.loop.records.push_back(rt::StepRecord{5'000'000LL * k, 1000 + k, 2000 + 3 * k, 40'000 + k});
  }
  r.events.push_back(NodeEvent{1, 0.005, NodeEventKind::connected, NodeState::startup, NodeState::connected});
  r.events.push_back(NodeEvent{151, 0.755, NodeEventKind::input_implausible, NodeState::running, NodeState::degraded});
  r.calibration.push_back(CalibrationEvent{151, 0.755, 0, 0.5, 0.75});
  return r;
}

}  // namespace

// The writer's CSV and events file equal, byte for byte, those written from the whole run in
// memory (write_master_csv / write_events, the formats before streaming); the rows read back
// equal what was pushed, a cut last line (a killed node) is dropped and counted.
TEST(HilLogWriter, StreamedFilesEqualTheWholeRunFilesAndReadBack) {
  const auto dir = temp_dir();
  const MasterRun r = some_master_run();
  {
    NodeLogWriter w(NodeLogWriter::Node::master, {dir / "m.csv", dir / "m.events.csv", {}}, r.log.size());
    for (std::size_t k = 0; k < r.log.size(); ++k) {
      for (const auto& e : r.events)
        if (e.step == k) {
          ASSERT_TRUE(w.push(e));
        }
      for (const auto& c : r.calibration)
        if (c.step == k) {
          ASSERT_TRUE(w.push(c));
        }
      ASSERT_TRUE(w.push(MasterRow{r.log[k], r.loop.records[k]}));
    }
    w.stop();
    EXPECT_EQ(w.stats().rows, 300u);
    EXPECT_EQ(w.stats().events, 3u);
    EXPECT_EQ(w.stats().ring_full, 0u);
    EXPECT_EQ(w.stats().last_t_s, 299 * 0.005);
    // The writer's statistics are those of the records [µs].
    const LoopSummaries s = w.loop();
    EXPECT_EQ(s.tet_us.n, 300u);
    EXPECT_DOUBLE_EQ(s.tet_us.min, 2.0);    // 2000 ns at step 0
    EXPECT_DOUBLE_EQ(s.tet_us.max, 2.897);  // 2000 + 3·299 ns
    EXPECT_DOUBLE_EQ(s.io_us.max, 40.299);
    EXPECT_DOUBLE_EQ(s.cycle_us.max, 40.299 + 2.897);
    EXPECT_DOUBLE_EQ(s.wake_latency_us.mean, 1.1495);  // 1000 + mean(0..299) = 1149.5 ns
  }
  write_master_csv(dir / "whole.csv", r);
  write_events(dir / "whole.events.csv", r.events, r.calibration);
  EXPECT_EQ(text_of(dir / "m.csv"), text_of(dir / "whole.csv"));
  EXPECT_EQ(text_of(dir / "m.events.csv"), text_of(dir / "whole.events.csv"));

  std::vector<MasterStepLog> back;
  std::vector<rt::StepRecord> rec;
  LogReadBack rb = read_master_log(dir / "m.csv", back, rec);
  ASSERT_EQ(rb.rows, 300u);
  EXPECT_EQ(rb.cut_lines, 0u);
  for (std::size_t k = 0; k < back.size(); ++k) {
    EXPECT_EQ(back[k].control_step, r.log[k].control_step);
    EXPECT_EQ(back[k].measured_kPa, r.log[k].measured_kPa);
    EXPECT_EQ(back[k].current_mA, r.log[k].current_mA);
    EXPECT_EQ(back[k].sensor_seq, r.log[k].sensor_seq);
    EXPECT_EQ(back[k].calibration.kp, r.log[k].calibration.kp);
    EXPECT_EQ(rec[k].release_ns, r.loop.records[k].release_ns);
    EXPECT_EQ(rec[k].tet_ns, r.loop.records[k].tet_ns);
  }
  {  // a node killed mid-write: half a line at the end
    std::ofstream out(dir / "m.csv", std::ios::app);
    out << "300,1.5,2,299,799";
  }
  back.clear();
  rec.clear();
  rb = read_master_log(dir / "m.csv", back, rec);
  EXPECT_EQ(rb.rows, 300u);
  EXPECT_EQ(rb.cut_lines, 1u);
  EXPECT_EQ(rb.last_t_s, 299 * 0.005);
  {  // a bad value inside the log names file, line and column
    std::ofstream out(dir / "bad.csv");
    out << text_of(dir / "whole.csv").substr(0, text_of(dir / "whole.csv").find('\n') + 1) << "0,0,x\n";
  }
  try {
    read_master_log(dir / "bad.csv", back, rec);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.field(), "column 3");
  }
  std::filesystem::remove_all(dir);
}

// A launch file holds every field of the launch, and a missing or mistyped one is named.
TEST(HilLaunch, RoundTripAndFieldNamedErrors) {
  const auto dir = temp_dir();
  NodeLaunch l;
  l.role = NodeLaunch::Role::master;
  l.config = "config/hil/bench.toml";
  l.bus = "udp:239.74.163.2:43113";
  l.step_s = 0.002;
  l.seed = 42;
  l.scenario = "s.toml";
  l.compensation = "fixed";
  l.controller = {{"pid.kp", "0.5"}, {"saturation.max_mA", "1800"}};
  l.loop.step_s = 0.002;
  l.loop.fifo = 50;
  l.loop.cpu = 1;
  l.loop.spin_us = 200;
  l.loop.lock_memory = true;
  l.loop.policy = rt::OverrunPolicy::stop;
  l.loop.max_overruns = 3;
  l.loop.hold_dma_latency = false;
  l.duration_s = 12.5;
  l.connect_timeout_s = 3;
  l.reference = "sine:amplitude=100,offset=1000,frequency_hz=1";
  l.dto_timeout_s = 1.5;
  l.xcp = false;
  l.logs = {"a/master.csv", "a/master.events.csv", "a/master_bus.log"};
  l.stats = "a/master.json";
  l.result_fd = 7;
  write_launch(dir / "m.launch.json", l);
  const NodeLaunch b = read_launch(dir / "m.launch.json");
  EXPECT_EQ(b.role, l.role);
  EXPECT_EQ(b.config, l.config);
  EXPECT_EQ(b.bus, l.bus);
  EXPECT_EQ(b.step_s, l.step_s);
  EXPECT_EQ(b.seed, l.seed);
  EXPECT_EQ(b.scenario, l.scenario);
  EXPECT_EQ(b.compensation, l.compensation);
  EXPECT_EQ(b.controller, l.controller);
  EXPECT_EQ(b.loop.step_s, l.loop.step_s);
  EXPECT_EQ(b.loop.fifo, 50);
  EXPECT_EQ(b.loop.cpu, 1);
  EXPECT_EQ(b.loop.spin_us, 200);
  EXPECT_TRUE(b.loop.lock_memory);
  EXPECT_EQ(b.loop.policy, rt::OverrunPolicy::stop);
  EXPECT_EQ(b.loop.max_overruns, 3u);
  EXPECT_FALSE(b.loop.hold_dma_latency);
  EXPECT_EQ(b.duration_s, 12.5);
  EXPECT_EQ(b.connect_timeout_s, 3);
  EXPECT_EQ(b.reference, l.reference);
  EXPECT_EQ(b.dto_timeout_s, 1.5);
  EXPECT_FALSE(b.xcp);
  EXPECT_EQ(b.logs.csv, l.logs.csv);
  EXPECT_EQ(b.logs.events, l.logs.events);
  EXPECT_EQ(b.logs.bus_log, l.logs.bus_log);
  EXPECT_EQ(b.stats, l.stats);
  EXPECT_EQ(b.result_fd, 7);

  auto field_of = [&](const std::string& from, const std::string& to) {
    std::string text = launch_json(l);
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(dir / "bad.json") << text;
    try {
      (void)read_launch(dir / "bad.json");
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), (dir / "bad.json").string());
      return e.field();
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(field_of("\"fifo\": 50", "\"fifo_priority\": 50"), "loop.fifo");
  EXPECT_EQ(field_of("\"duration_s\": 12.5", "\"duration_s\": \"long\""), "duration_s");
  EXPECT_EQ(field_of("\"policy\": \"stop\"", "\"policy\": \"never\""), "loop.policy");
  EXPECT_EQ(field_of("\"role\": \"master\"", "\"role\": \"boss\""), "role");
  // The loop's own checks name the same fields.
  LoopOptions bad = l.loop;
  bad.fifo = 500;
  try {
    bad.validate();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "loop.fifo");
  }
  std::filesystem::remove_all(dir);
}
