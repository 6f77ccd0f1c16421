#pragma once
// Process control of a session's nodes (private to hil): start a node from a launch file with
// the face's command, reap it without blocking, stop it, wait for its "ready" line.
#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "lash/hil/report.hpp"

namespace lash::hil::detail {

/// A node process and the memory file it hands its run over in.
struct NodeProcess {
  pid_t pid = -1;
  int result_fd = -1;   ///< memfd; the child inherits the same descriptor number
  int stdout_fd = -1;   ///< read end of the node's stdout, or −1
  NodeExit exit;
  double started_s = 0.0;
};

/// A memory file for a node's hand-over (close-on-exec: only the child it is meant for keeps it).
int make_result_memfd(const char* name);
/// fork + exec of `command` with `launch_file` appended; the child inherits `p.result_fd`
/// (same number) and dies with the session (PR_SET_PDEATHSIG). pipe_stdout: the child's stdout
/// is read through p.stdout_fd. Throws SystemError.
void start(NodeProcess& p, const std::vector<std::string>& command, const std::filesystem::path& launch_file,
           bool pipe_stdout);
/// Non-blocking reap; true once the child has exited (its exit filled in, t since t0_ns).
bool reap(NodeProcess& p, std::int64_t t0_ns);
/// Waits for the child to exit, SIGKILL after timeout_s.
void reap_blocking(NodeProcess& p, std::int64_t t0_ns, double timeout_s);
/// Reads the node's stdout until it says "ready" (true), it exits or closes stdout, `stop`
/// becomes non-zero, or timeout_s passes (false).
bool wait_ready(const NodeProcess& p, double timeout_s, const std::atomic<int>& stop);
/// Closes the process's descriptors.
void release(NodeProcess& p);

}  // namespace lash::hil::detail
