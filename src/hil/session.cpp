#include "lash/hil/session.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "lash/hil/handover.hpp"
#include "lash/hil/launch.hpp"
#include "lash/hil/netns.hpp"
#include "lash/hil/report_logs.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/hil/simulate.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/rt/periodic.hpp"
#include "process.hpp"

namespace lash::hil {

namespace {
std::atomic<int> g_stop_signal{0};
extern "C" void on_session_signal(int sig) { g_stop_signal.store(sig); }

double since_s(std::int64_t t0_ns) { return static_cast<double>(rt::monotonic_ns() - t0_ns) * 1e-9; }

std::string slave_name(std::size_t n) { return n == 1 ? "slave" : "slave." + std::to_string(n); }
}  // namespace

std::atomic<int>& stop_signal() noexcept { return g_stop_signal; }

void install_session_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_session_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaction(s, &sa, nullptr);
}

std::vector<std::string> session_files() {
  std::vector<std::string> f{"report.json", "master.csv", "master.json", "master.events.csv", "master_bus.log",
                             "master.launch.json", "slave.csv", "slave.json", "slave.events.csv", "slave.launch.json"};
  for (std::size_t i = 2; i <= 100; ++i)
    for (const char* ext : {".csv", ".events.csv", ".json", ".launch.json"}) f.push_back(slave_name(i) + ext);
  return f;
}

void SessionOptions::validate() const {
  try {
    (void)parse_reference(reference);
  } catch (const InputError& e) {
    throw InputError(e.file(), e.line(), "reference", e.message());
  }
  LoopOptions l = loop;
  l.step_s = settings.step_s;
  l.validate();
  (void)steps_for(duration_s, settings.step_s, "duration_s");
  if (slave_cpu < -1) throw InputError("", 0, "slave_cpu", "must be a CPU number >= 0");
  if (node_command.empty()) throw InputError("", 0, "node_command", "no command to start the nodes with");
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir))
    throw InputError(out_dir.string(), 0, "out_dir", "cannot create the output directory" +
                                                         (ec ? " (" + ec.message() + ")" : std::string()));
  if (access(out_dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(out_dir.string(), 0, "out_dir", std::string("not writable (") + std::strerror(errno) + ")");
}

namespace {
/// One run per output directory: an flock on `<dir>/.lash-run.lock` (holding the owner's pid),
/// released by the kernel when the run ends or dies, so a lock is never stale.
class OutDirLock {
 public:
  explicit OutDirLock(const std::filesystem::path& dir) {
    const auto path = dir / ".lash-run.lock";
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_ < 0)
      throw InputError(dir.string(), 0, "out_dir", std::string("cannot create its lock file (") + std::strerror(errno) + ")");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      char buf[32] = {};
      const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
      ::close(fd_);
      throw InputError(dir.string(), 0, "out_dir",
                       "in use by another lash hil run (pid " + std::string(buf, n > 0 ? static_cast<std::size_t>(n) : 0) +
                           "): its files would be replaced; give another output directory");
    }
    const std::string pid = std::to_string(::getpid());
    if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
      // the lock is what matters; the pid is only for the message of a second run
    }
  }
  OutDirLock(const OutDirLock&) = delete;
  OutDirLock& operator=(const OutDirLock&) = delete;
  ~OutDirLock() { ::close(fd_); }

 private:
  int fd_ = -1;
};

using detail::NodeProcess;

/// One `lash hil run` from start to report, by phase: launch (what each node gets), process
/// control (start, supervise, stop), hand-over (statistics and logs back, a killed node's
/// recovered), report.
class SessionRun {
 public:
  SessionRun(const SessionOptions& o, const std::function<void(const std::string&)>& progress)
      : o_(o), progress_(progress), dir_(o.out_dir) {}

  RunReport run() {
    const BenchLayout L = BenchLayout::from_dbc(o_.settings.dbc_file);
    const MasterConfig mc = master_config(o_.settings, o_.reference);
    const SlaveConfig sc = slave_config(o_.settings, L);
    const OutDirLock lock(dir_);  // held until the run's files are written
    for (const auto& f : session_files()) {
      std::error_code ec;
      std::filesystem::remove(dir_ / f, ec);
    }
    begin_report();
    t0_ = rt::monotonic_ns();
    start_nodes();
    supervise();
    stop_slaves();
    collect();
    report(L, mc, sc);
    struct rusage ru {};
    if (getrusage(RUSAGE_SELF, &ru) == 0) rep_.session_peak_rss_kB = ru.ru_maxrss;
    AtomicFile f(dir_ / "report.json");
    f.stream() << run_report_json(rep_);
    f.commit();
    return rep_;
  }

 private:
  void say(const std::string& s) const {
    if (progress_) progress_(s);
  }

  // ---- launch: each node's configuration as data (launch.hpp)
  NodeLaunch base_launch() const {
    NodeLaunch l;
    l.config = o_.config;
    l.bus = o_.settings.bus;
    l.step_s = o_.settings.step_s;
    l.seed = static_cast<std::int64_t>(o_.settings.plant.seed);
    l.scenario = o_.scenario;
    l.compensation = o_.compensation;
    l.controller = o_.controller;
    l.loop = o_.loop;
    l.loop.step_s = o_.settings.step_s;
    return l;
  }
  NodeLaunch slave_launch(std::size_t n, int result_fd) const {
    NodeLaunch l = base_launch();
    const std::string name = slave_name(n);
    l.role = NodeLaunch::Role::slave;
    if (o_.slave_cpu >= 0) l.loop.cpu = o_.slave_cpu;
    l.duration_s = o_.duration_s + o_.settings.dto_timeout_s + 5.0;  // the longest it may have to run
    l.logs = {dir_ / (name + ".csv"), dir_ / (name + ".events.csv"), {}};
    l.stats = dir_ / (name + ".json");
    l.result_fd = result_fd;
    return l;
  }
  NodeLaunch master_launch(int result_fd) const {
    NodeLaunch l = base_launch();
    l.role = NodeLaunch::Role::master;
    l.duration_s = o_.duration_s;
    l.reference = o_.reference;
    l.xcp = o_.xcp;
    l.logs = {dir_ / "master.csv", dir_ / "master.events.csv", dir_ / "master_bus.log"};
    l.stats = dir_ / "master.json";
    l.result_fd = result_fd;
    return l;
  }

  // ---- process control (process.hpp)
  void begin_report() {
    rep_.duration_s = o_.duration_s;
    rep_.step_s = o_.settings.step_s;
    rep_.reference = o_.reference;
    rep_.bus = o_.settings.bus;
    rep_.out_dir = dir_.string();
    rep_.isolation = "host network (not isolated)";
    if (o_.isolate) {
      const NetnsResult ns = enter_private_netns();
      if (!ns.ok)
        throw InputError("", 0, "isolate",
                         "cannot create a private network namespace (" + ns.error +
                             "); run as root or with user namespaces enabled, or use the host network");
      rep_.isolation = "private network namespace (" + ns.how + ")";
    }
  }

  bool start_slave() {
    NodeProcess p;
    p.result_fd = detail::make_result_memfd("lash-hil-slave");
    const std::size_t n = slaves_.size() + 1;
    const auto file = dir_ / (slave_name(n) + ".launch.json");
    write_launch(file, slave_launch(n, p.result_fd));
    detail::start(p, o_.node_command, file, true);
    p.started_s = since_s(t0_);
    slaves_.push_back(p);
    if (detail::wait_ready(slaves_.back(), 10.0, g_stop_signal)) return true;
    kill(slaves_.back().pid, SIGTERM);
    detail::reap_blocking(slaves_.back(), t0_, 5.0);
    return false;
  }

  void start_nodes() {
    if (!start_slave()) {
      const int sig = g_stop_signal.load();
      for (auto& s : slaves_) detail::release(s);
      if (sig != 0) throw RunError("interrupted by signal " + std::to_string(sig) + " before the slave was ready");
      throw RunError("the slave did not start (no 'ready' line within 10 s)");
    }
    master_.result_fd = detail::make_result_memfd("lash-hil-master");
    const auto file = dir_ / "master.launch.json";
    write_launch(file, master_launch(master_.result_fd));
    detail::start(master_, o_.node_command, file, false);
    if (o_.on_nodes_started) o_.on_nodes_started();
  }

  /// Until the master ends: forwards a stop signal, reports (and with restart_slave replaces)
  /// a slave that died, stops the master when no slave is left.
  void supervise() {
    for (;;) {
      const int sig = g_stop_signal.load();
      if (sig != 0 && forwarded_ == 0) {
        forwarded_ = sig;
        say("signal " + std::to_string(sig) + ": stopping both nodes");
        kill(master_.pid, sig);
        if (!slaves_.back().exit.exited) kill(slaves_.back().pid, sig);
      }
      if (detail::reap(master_, t0_)) break;
      NodeProcess& s = slaves_.back();
      if (!s.exit.exited && detail::reap(s, t0_)) on_slave_died(s);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  void on_slave_died(const NodeProcess& s) {
    say("the slave (pid " + std::to_string(s.pid) + ") ended with status " + std::to_string(s.exit.status) +
        " at t = " + format_double(s.exit.t_s) + " s");
    SlaveRestart gap;
    gap.died = s.exit;
    if (o_.restart_slave && forwarded_ == 0 && slaves_.size() < 100 && start_slave()) {
      gap.restarted_s = since_s(t0_);
      say("slave restarted (pid " + std::to_string(slaves_.back().pid) + "), gap " + format_double(gap.gap_s()) + " s");
    }
    rep_.restarts.push_back(gap);
    if (gap.restarted_s < 0 && forwarded_ == 0) {
      // Nothing left to control: stop the master; the report says why.
      say("no slave: stopping the master");
      kill(master_.pid, SIGTERM);
      forwarded_ = -1;
    }
  }

  /// The master is done: stop the slave it talked to.
  void stop_slaves() {
    for (auto& s : slaves_)
      if (!s.exit.exited) {
        kill(s.pid, SIGTERM);
        detail::reap_blocking(s, t0_, 10.0);
      }
  }

  // ---- hand-over (handover.hpp): statistics from the memory file, logs from disk. A node
  // killed before it could hand over (kill -9) is recovered from what its log writer had put
  // on disk (at most the last second lost).
  void collect() {
    have_master_ = read_run(master_.result_fd, mrun_);
    const auto master_csv = dir_ / "master.csv";
    if (std::filesystem::exists(master_csv)) {
      logs_.master = scan_master_log(master_csv);
      const NodeLogScan& ms = *logs_.master;
      if (!have_master_ && ms.read.rows > 0) {
        have_master_ = true;
        recover(mrun_.stats, ms.read, ms.last_state);
        mrun_.stats.control_steps = ms.last_control_step + 1;
        rep_.master_recovered = LogRecovery{master_csv.string(), ms.read.rows, ms.read.cut_lines, ms.read.last_t_s};
        say("the master handed nothing over (status " + std::to_string(master_.exit.status) + "): recovered " +
            std::to_string(ms.read.rows) + " rows up to t = " + format_double(ms.read.last_t_s) + " s from " +
            master_csv.string());
      }
    }
    for (std::size_t i = 0; i < slaves_.size(); ++i) {
      NodeProcess& s = slaves_[i];
      SlaveRun r;
      const bool handed = read_run(s.result_fd, r);
      if (!handed) r = SlaveRun{};
      const auto csv = dir_ / (slave_name(i + 1) + ".csv");
      if (std::filesystem::exists(csv)) {
        NodeLogScan ss = scan_slave_log(csv);
        if (!handed && ss.read.rows > 0) {
          recover(r.stats, ss.read, ss.last_state);
          r.stats.connected = true;
          if (i == 0) rep_.slave_recovered = LogRecovery{csv.string(), ss.read.rows, ss.read.cut_lines, ss.read.last_t_s};
          say(slave_name(i + 1) + " handed nothing over (status " + std::to_string(s.exit.status) + "): recovered " +
              std::to_string(ss.read.rows) + " rows up to t = " + format_double(ss.read.last_t_s) + " s from " +
              csv.string());
        }
        if (i == 0) logs_.slave = std::move(ss);
      }
      sruns_.push_back(std::move(r));
      rep_.slave_exits.push_back(s.exit);
      detail::release(s);
    }
    detail::release(master_);
    rep_.master_exit = master_.exit;
    rep_.interrupted = forwarded_ > 0;
    rep_.interrupt_signal = forwarded_ > 0 ? forwarded_ : 0;
  }

  /// The statistics of a node known only from its log.
  void recover(NodeStats& st, const LogReadBack& rb, NodeState last_state) const {
    st.result.steps = rb.rows;
    st.state = last_state;
    st.period_ns = static_cast<std::int64_t>(std::llround(o_.settings.step_s * 1e9));
  }

  // ---- report (report_logs.hpp): from the logs on disk, read row by row (the session's memory
  // does not grow with the run), against the ideal-schedule simulation and the replay of the
  // schedule the nodes logged.
  void report(const BenchLayout& L, const MasterConfig& mc, const SlaveConfig& sc) {
    make_run_report_from_logs(rep_, have_master_ ? &mrun_ : nullptr, sruns_, logs_, L, mc, sc,
                              o_.settings.scenario ? &*o_.settings.scenario : nullptr);
  }

  const SessionOptions& o_;
  const std::function<void(const std::string&)>& progress_;
  std::filesystem::path dir_;
  RunReport rep_;
  std::int64_t t0_ = 0;
  std::vector<NodeProcess> slaves_;
  NodeProcess master_;
  int forwarded_ = 0;  ///< the signal forwarded to the nodes; −1: the master was stopped (no slave)
  MasterRun mrun_;
  bool have_master_ = false;
  std::vector<SlaveRun> sruns_;
  RunLogs logs_;
};
}  // namespace

Session::Session(SessionOptions options) : o_(std::move(options)) {}

RunReport Session::run(const std::function<void(const std::string&)>& progress) {
  o_.loop.step_s = o_.settings.step_s;
  o_.validate();
  return SessionRun(o_, progress).run();
}

}  // namespace lash::hil
