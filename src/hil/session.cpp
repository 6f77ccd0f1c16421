#include "lash/hil/session.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/select.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "lash/hil/netns.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/hil/simulate.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/rt/periodic.hpp"
#include "lash/io/numeric.hpp"

namespace lash::hil {

namespace {
std::atomic<int> g_stop_signal{0};
extern "C" void on_session_signal(int sig) { g_stop_signal.store(sig); }

double since_s(std::int64_t t0_ns) { return static_cast<double>(rt::monotonic_ns() - t0_ns) * 1e-9; }

/// A node process and the memory file it hands its run over in.
struct Child {
  pid_t pid = -1;
  int result_fd = -1;   ///< memfd (close-on-exec on our side)
  int stdout_fd = -1;   ///< read end of the node's stdout, or −1
  NodeExit exit;
  double started_s = 0.0;
};

int make_memfd(const char* name) {
  const int fd = memfd_create(name, MFD_CLOEXEC);
  if (fd < 0) throw SystemError(std::string("memfd_create failed: ") + std::strerror(errno));
  return fd;
}

Child spawn(const std::string& exe, std::vector<std::string> args, bool pipe_stdout, const char* name) {
  Child c;
  c.result_fd = make_memfd(name);
  int fds[2] = {-1, -1};
  if (pipe_stdout && pipe2(fds, O_CLOEXEC) != 0) throw SystemError(std::string("pipe failed: ") + std::strerror(errno));
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw SystemError(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    // The node dies with the session, whatever kills the session.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    if (pipe_stdout) dup2(fds[1], STDOUT_FILENO);
    const int fd = dup(c.result_fd);  // without close-on-exec: the node inherits it
    args.push_back("--result-fd");
    args.push_back(std::to_string(fd));
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  c.pid = pid;
  if (pipe_stdout) {
    close(fds[1]);
    c.stdout_fd = fds[0];
  }
  return c;
}

NodeExit exit_of(int status, double t_s) {
  NodeExit e;
  e.exited = true;
  e.t_s = t_s;
  if (WIFEXITED(status)) {
    e.status = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    e.signal = WTERMSIG(status);
    e.status = 128 + e.signal;
  }
  return e;
}

/// Non-blocking reap; true when the child has exited (its exit filled in).
bool reap(Child& c, std::int64_t t0) {
  if (c.pid < 0 || c.exit.exited) return c.exit.exited;
  int status = 0;
  const pid_t r = waitpid(c.pid, &status, WNOHANG);
  if (r == c.pid) {
    c.exit = exit_of(status, since_s(t0));
    return true;
  }
  return false;
}

/// Waits for the child to exit, SIGKILL after timeout_s.
void reap_blocking(Child& c, std::int64_t t0, double timeout_s) {
  const std::int64_t end = rt::monotonic_ns() + round_clamped<std::int64_t>(timeout_s * 1e9, 0, std::int64_t{1} << 62);
  while (!reap(c, t0)) {
    if (rt::monotonic_ns() > end) {
      kill(c.pid, SIGKILL);
      int status = 0;
      while (waitpid(c.pid, &status, 0) < 0 && errno == EINTR) {
      }
      c.exit = exit_of(status, since_s(t0));
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

/// Reads the node's stdout until it says "ready" (true), it exits or closes stdout, a stop
/// signal arrives, or timeout_s passes (false).
bool wait_ready(const Child& c, double timeout_s) {
  std::string got;
  const std::int64_t end = rt::monotonic_ns() + round_clamped<std::int64_t>(timeout_s * 1e9, 0, std::int64_t{1} << 62);
  char buf[256];
  while (rt::monotonic_ns() < end && g_stop_signal.load() == 0) {
    fd_set set;
    FD_ZERO(&set);
    FD_SET(c.stdout_fd, &set);
    timeval tv{0, 100000};
    if (select(c.stdout_fd + 1, &set, nullptr, nullptr, &tv) > 0) {
      const ssize_t n = read(c.stdout_fd, buf, sizeof buf);
      if (n <= 0) return false;
      got.append(buf, static_cast<std::size_t>(n));
      if (got.find("ready") != std::string::npos) return true;
    }
  }
  return false;
}

std::vector<std::string> loop_args(const LoopOptions& l, const SessionOptions& o) {
  std::vector<std::string> a{"--config", o.config.string(), "--bus", o.settings.bus, "--step-ms",
                             format_double(o.settings.step_s * 1e3)};
  if (l.fifo > 0) a.insert(a.end(), {"--fifo", std::to_string(l.fifo)});
  if (l.cpu >= 0) a.insert(a.end(), {"--cpu", std::to_string(l.cpu)});
  if (l.spin_us > 0) a.insert(a.end(), {"--spin-us", format_double(l.spin_us)});
  if (l.lock_memory) a.push_back("--lock-memory");
  if (!l.hold_dma_latency) a.push_back("--no-dma-latency");
  a.insert(a.end(), {"--overrun-policy", l.policy == rt::OverrunPolicy::stop ? "stop" : "tolerate",
                     "--max-overruns", std::to_string(l.max_overruns)});
  a.insert(a.end(), o.node_args.begin(), o.node_args.end());
  return a;
}

/// The statistics of a node known only from its log (it was killed before its hand-over).
void recover_stats(NodeStats& st, std::size_t rows, NodeState last_state) {
  st.result.steps = rows;
  st.state = last_state;
}

void close_fd(int& fd) {
  if (fd >= 0) close(fd);
  fd = -1;
}
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
                             "slave.csv",   "slave.json", "slave.events.csv"};
  for (int i = 2; i <= 100; ++i) {
    f.push_back("slave." + std::to_string(i) + ".csv");
    f.push_back("slave." + std::to_string(i) + ".events.csv");
    f.push_back("slave." + std::to_string(i) + ".json");
  }
  return f;
}

void SessionOptions::validate() const {
  (void)parse_reference(reference);
  LoopOptions l = loop;
  l.step_s = settings.step_s;
  l.validate();
  (void)steps_for(duration_s, settings.step_s, "--duration");
  if (slave_cpu < -1) throw InputError("", 0, "--slave-cpu", "must be a CPU number >= 0");
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir))
    throw InputError(out_dir.string(), 0, "--out-dir", "cannot create the output directory" +
                                                           (ec ? " (" + ec.message() + ")" : std::string()));
  if (access(out_dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(out_dir.string(), 0, "--out-dir", std::string("not writable (") + std::strerror(errno) + ")");
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
      throw InputError(dir.string(), 0, "--out-dir", std::string("cannot create its lock file (") + std::strerror(errno) + ")");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      char buf[32] = {};
      const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
      ::close(fd_);
      throw InputError(dir.string(), 0, "--out-dir",
                       "in use by another lash hil run (pid " + std::string(buf, n > 0 ? static_cast<std::size_t>(n) : 0) +
                           "): its files would be replaced; give another --out-dir");
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
}  // namespace

Session::Session(SessionOptions options) : o_(std::move(options)) {}

RunReport Session::run(const std::function<void(const std::string&)>& progress) {
  auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  o_.loop.step_s = o_.settings.step_s;
  o_.validate();
  const BenchLayout L = BenchLayout::from_dbc(o_.settings.dbc_file);
  const MasterConfig mc = master_config(o_.settings, o_.reference);
  const SlaveConfig sc = slave_config(o_.settings, L);
  const std::filesystem::path dir = o_.out_dir;
  const OutDirLock lock(dir);  // held until the run's files are written
  for (const auto& f : session_files()) {
    std::error_code ec;
    std::filesystem::remove(dir / f, ec);
  }

  RunReport rep;
  rep.duration_s = o_.duration_s;
  rep.step_s = o_.settings.step_s;
  rep.reference = o_.reference;
  rep.bus = o_.settings.bus;
  rep.out_dir = dir.string();
  rep.isolation = "host network (--no-isolate)";
  if (o_.isolate) {
    const NetnsResult ns = enter_private_netns();
    if (!ns.ok)
      throw InputError("", 0, "--no-isolate",
                       "cannot create a private network namespace (" + ns.error +
                           "); run as root or with user namespaces enabled, or pass --no-isolate to use the host "
                           "network");
    rep.isolation = "private network namespace (" + ns.how + ")";
  }

  const std::int64_t t0 = rt::monotonic_ns();
  LoopOptions slave_loop = o_.loop;
  if (o_.slave_cpu >= 0) slave_loop.cpu = o_.slave_cpu;
  auto slave_args = [&](std::size_t n) {
    const std::string name = n == 1 ? "slave" : "slave." + std::to_string(n);
    std::vector<std::string> a{"lash", "hil", "slave"};
    for (auto& x : loop_args(slave_loop, o_)) a.push_back(x);
    a.insert(a.end(), {"--duration", format_double(o_.duration_s + o_.settings.dto_timeout_s + 5.0), "--log",
                       (dir / (name + ".csv")).string(), "--stats", (dir / (name + ".json")).string(), "--seed",
                       std::to_string(o_.settings.plant.seed)});
    return a;
  };
  std::vector<Child> slaves;
  auto start_slave = [&]() -> bool {
    Child c = spawn(o_.executable, slave_args(slaves.size() + 1), true, "lash-hil-slave");
    c.started_s = since_s(t0);
    slaves.push_back(c);
    if (wait_ready(slaves.back(), 10.0)) return true;
    kill(slaves.back().pid, SIGTERM);
    reap_blocking(slaves.back(), t0, 5.0);
    return false;
  };
  auto cleanup = [&](Child& c) {
    close_fd(c.stdout_fd);
    close_fd(c.result_fd);
  };

  if (!start_slave()) {
    const int sig = g_stop_signal.load();
    for (auto& s : slaves) cleanup(s);
    if (sig != 0) throw RunError("interrupted by signal " + std::to_string(sig) + " before the slave was ready");
    throw RunError("the slave did not start (no 'ready' line within 10 s)");
  }
  std::vector<std::string> margs{"lash", "hil", "master"};
  for (auto& x : loop_args(o_.loop, o_)) margs.push_back(x);
  margs.insert(margs.end(), {"--duration", format_double(o_.duration_s), "--reference", o_.reference, "--log",
                             (dir / "master.csv").string(), "--bus-log", (dir / "master_bus.log").string(),
                             "--events", (dir / "master.events.csv").string(), "--stats",
                             (dir / "master.json").string()});
  if (!o_.xcp) margs.insert(margs.end(), {"--xcp", "off"});
  Child master = spawn(o_.executable, margs, false, "lash-hil-master");
  if (o_.on_nodes_started) o_.on_nodes_started();

  // Supervise.
  int forwarded = 0;
  for (;;) {
    const int sig = g_stop_signal.load();
    if (sig != 0 && forwarded == 0) {
      forwarded = sig;
      say("signal " + std::to_string(sig) + ": stopping both nodes");
      kill(master.pid, sig);
      if (!slaves.back().exit.exited) kill(slaves.back().pid, sig);
    }
    if (reap(master, t0)) break;
    Child& s = slaves.back();
    if (!s.exit.exited && reap(s, t0)) {
      say("the slave (pid " + std::to_string(s.pid) + ") ended with status " + std::to_string(s.exit.status) +
          " at t = " + format_double(s.exit.t_s) + " s");
      SlaveRestart gap;
      gap.died = s.exit;
      if (o_.restart_slave && forwarded == 0 && slaves.size() < 100) {
        if (start_slave()) {
          gap.restarted_s = since_s(t0);
          say("slave restarted (pid " + std::to_string(slaves.back().pid) + "), gap " +
              format_double(gap.gap_s()) + " s");
        }
      }
      rep.restarts.push_back(gap);
      if (gap.restarted_s < 0 && forwarded == 0) {
        // Nothing left to control: stop the master; the report says why.
        say("no slave: stopping the master");
        kill(master.pid, SIGTERM);
        forwarded = -1;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // The master is done: stop the slave it talked to.
  for (auto& s : slaves)
    if (!s.exit.exited) {
      kill(s.pid, SIGTERM);
      reap_blocking(s, t0, 10.0);
    }

  // Collect the runs: the statistics each node handed over (memory file), the logs from the
  // files its log writer streamed while it ran. A node killed before it could hand over
  // (kill -9) is recovered from what its writer had put on disk (at most the last second lost).
  MasterRun mrun;
  bool have_master = read_run(master.result_fd, mrun);
  const auto master_csv = dir / "master.csv";
  if (std::filesystem::exists(master_csv)) {
    const LogReadBack rb = read_master_log(master_csv, mrun.log, mrun.loop.records);
    if (!have_master && rb.rows > 0) {
      have_master = true;
      recover_stats(mrun.stats, rb.rows, mrun.log.empty() ? NodeState::startup : mrun.log.back().state);
      std::int64_t last_m = -1;
      for (const auto& l : mrun.log) last_m = std::max(last_m, l.control_step);
      mrun.stats.control_steps = last_m + 1;
      mrun.stats.period_ns = static_cast<std::int64_t>(std::llround(o_.settings.step_s * 1e9));
      rep.master_recovered = LogRecovery{master_csv.string(), rb.rows, rb.cut_lines, rb.last_t_s};
      say("the master handed nothing over (status " + std::to_string(master.exit.status) + "): recovered " +
          std::to_string(rb.rows) + " rows up to t = " + format_double(rb.last_t_s) + " s from " + master_csv.string());
    }
  }
  std::vector<SlaveRun> sruns;
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    Child& s = slaves[i];
    SlaveRun r;
    const bool handed = read_run(s.result_fd, r);
    if (!handed) r = SlaveRun{};
    const auto csv = dir / (i == 0 ? std::string("slave.csv") : "slave." + std::to_string(i + 1) + ".csv");
    if (std::filesystem::exists(csv)) {
      const LogReadBack rb = read_slave_log(csv, r.log, r.loop.records);
      if (!handed && rb.rows > 0) {
        recover_stats(r.stats, rb.rows, r.log.back().state);
        r.stats.connected = true;
        if (i == 0) rep.slave_recovered = LogRecovery{csv.string(), rb.rows, rb.cut_lines, rb.last_t_s};
        say("slave " + std::to_string(i + 1) + " handed nothing over (status " + std::to_string(s.exit.status) +
            "): recovered " + std::to_string(rb.rows) + " rows up to t = " + format_double(rb.last_t_s) + " s from " +
            csv.string());
      }
    }
    sruns.push_back(std::move(r));
    rep.slave_exits.push_back(s.exit);
    cleanup(s);
  }
  cleanup(master);
  rep.master_exit = master.exit;
  rep.interrupted = forwarded > 0;
  rep.interrupt_signal = forwarded > 0 ? forwarded : 0;

  std::vector<MasterStepLog> simulated;
  if (have_master && mrun.stats.control_steps > 0) {
    // The ideal frame schedule, with the calibration writes the run logged (XCP) at their steps.
    FrameSchedule ideal = ideal_schedule(static_cast<std::size_t>(mrun.stats.control_steps));
    ideal.calibration = observed_schedule(mrun.log, {}).calibration;
    simulated = simulate_bench(L, mc, sc, ideal).master;
  }
  make_run_report(rep, have_master ? &mrun : nullptr, sruns, simulated,
                  o_.settings.scenario ? &*o_.settings.scenario : nullptr);
  if (!simulated.empty()) {  // the same closed loop, fed the frames each node logged it used
    if (sruns.size() != 1 || sruns[0].log.empty()) {
      rep.observed_schedule_note = "not replayed: the schedule of one slave from start to end is needed";
    } else {
      try {
        FrameSchedule fs = observed_schedule(mrun.log, sruns[0].log);
        const std::size_t kept = replayable_control_steps(fs);
        if (kept < fs.master.size()) {  // a killed slave's log ends before the master's
          fs.master.resize(kept);
          rep.observed_schedule_note = "replayed the first " + std::to_string(kept) +
                                       " control steps: the slave's log ends before the master's";
        }
        rep.vs_observed_schedule = compare_with_simulation(mrun.log, simulate_bench(L, mc, sc, fs).master);
      } catch (const std::invalid_argument& e) {
        rep.observed_schedule_note = std::string("not replayed: ") + e.what();
      }
    }
  }
  AtomicFile f(dir / "report.json");
  f.stream() << run_report_json(rep);
  f.commit();
  return rep;
}

}  // namespace lash::hil
