// UDP multicast bus one-way latency between two processes (see docs/can.md).
// Run inside a private network namespace:  tests/cli/can_netns.sh build/bin/lash_can_udp_latency [N]
// The parent sends N frames, each carrying its CLOCK_MONOTONIC send time (ns) in the
// payload, paced 200 us apart; a forked child receives them on another UdpBus and
// records receive_time - send_time taken right after Bus::receive() returns. The
// median, 10/90/99th percentiles and max are printed. Both processes share one clock.
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "lash/can/bus.hpp"

namespace {
std::int64_t now_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000LL + t.tv_nsec;
}
}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 10000;
  const char* addr = "udp:239.74.163.2:43150";
  int ready[2];
  if (pipe(ready) != 0) return 1;
  const pid_t child = fork();
  if (child == 0) {
    auto bus = lash::can::open_bus(addr);
    char c = 1;
    if (write(ready[1], &c, 1) != 1) return 1;
    std::vector<double> lat_us;
    lat_us.reserve(static_cast<std::size_t>(n));
    while (static_cast<int>(lat_us.size()) < n) {
      auto f = bus->receive(std::chrono::seconds(2));
      const std::int64_t t = now_ns();
      if (!f) break;
      std::int64_t sent = 0;
      std::memcpy(&sent, f->data.data(), 8);
      lat_us.push_back(static_cast<double>(t - sent) * 1e-3);
    }
    if (lat_us.empty()) {
      std::fprintf(stderr, "no frames received\n");
      return 1;
    }
    std::sort(lat_us.begin(), lat_us.end());
    auto pct = [&](double p) { return lat_us[static_cast<std::size_t>(p * static_cast<double>(lat_us.size() - 1))]; };
    std::printf("UDP one-way latency, %zu of %d frames: median %.1f us, p10 %.1f, p90 %.1f, p99 %.1f, max %.1f us\n",
                lat_us.size(), n, pct(0.5), pct(0.1), pct(0.9), pct(0.99), lat_us.back());
    return 0;
  }
  char c;
  if (read(ready[0], &c, 1) != 1) return 1;
  auto bus = lash::can::open_bus(addr);
  usleep(100000);
  lash::can::Frame f;
  f.id = 0x100;
  f.len = 8;
  for (int i = 0; i < n; ++i) {
    const std::int64_t t = now_ns();
    std::memcpy(f.data.data(), &t, 8);
    bus->send(f);
    const std::int64_t next = t + 200000;
    while (now_ns() < next) usleep(50);
  }
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}
