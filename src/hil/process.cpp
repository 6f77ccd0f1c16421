#include "process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/select.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "lash/io/error.hpp"
#include "lash/io/numeric.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::hil::detail {

namespace {
double since_s(std::int64_t t0_ns) { return static_cast<double>(rt::monotonic_ns() - t0_ns) * 1e-9; }

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
}  // namespace

int make_result_memfd(const char* name) {
  const int fd = memfd_create(name, MFD_CLOEXEC);
  if (fd < 0) throw SystemError(std::string("memfd_create failed: ") + std::strerror(errno));
  return fd;
}

void start(NodeProcess& p, const std::vector<std::string>& command, const std::filesystem::path& launch_file,
           bool pipe_stdout) {
  if (command.empty()) throw SystemError("no command to start a node with (SessionOptions::node_command)");
  std::vector<std::string> args = command;
  args.push_back(launch_file.string());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
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
    if (p.result_fd >= 0) fcntl(p.result_fd, F_SETFD, 0);  // inherited across exec, same number
    execv(argv[0], argv.data());
    _exit(127);
  }
  p.pid = pid;
  if (pipe_stdout) {
    close(fds[1]);
    p.stdout_fd = fds[0];
  }
}

bool reap(NodeProcess& p, std::int64_t t0) {
  if (p.pid < 0 || p.exit.exited) return p.exit.exited;
  int status = 0;
  const pid_t r = waitpid(p.pid, &status, WNOHANG);
  if (r == p.pid) {
    p.exit = exit_of(status, since_s(t0));
    return true;
  }
  return false;
}

void reap_blocking(NodeProcess& p, std::int64_t t0, double timeout_s) {
  const std::int64_t end = rt::monotonic_ns() + round_clamped<std::int64_t>(timeout_s * 1e9, 0, std::int64_t{1} << 62);
  while (!reap(p, t0)) {
    if (rt::monotonic_ns() > end) {
      kill(p.pid, SIGKILL);
      int status = 0;
      while (waitpid(p.pid, &status, 0) < 0 && errno == EINTR) {
      }
      p.exit = exit_of(status, since_s(t0));
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

bool wait_ready(const NodeProcess& p, double timeout_s, const std::atomic<int>& stop) {
  std::string got;
  const std::int64_t end = rt::monotonic_ns() + round_clamped<std::int64_t>(timeout_s * 1e9, 0, std::int64_t{1} << 62);
  char buf[256];
  while (rt::monotonic_ns() < end && stop.load() == 0) {
    fd_set set;
    FD_ZERO(&set);
    FD_SET(p.stdout_fd, &set);
    timeval tv{0, 100000};
    if (select(p.stdout_fd + 1, &set, nullptr, nullptr, &tv) > 0) {
      const ssize_t n = read(p.stdout_fd, buf, sizeof buf);
      if (n <= 0) return false;
      got.append(buf, static_cast<std::size_t>(n));
      if (got.find("ready") != std::string::npos) return true;
    }
  }
  return false;
}

void release(NodeProcess& p) {
  if (p.stdout_fd >= 0) close(p.stdout_fd);
  if (p.result_fd >= 0) close(p.result_fd);
  p.stdout_fd = p.result_fd = -1;
}

}  // namespace lash::hil::detail
