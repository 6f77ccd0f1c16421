// The master's TET with and without an attached console, in one run (issue 27; docs/console.md).
//
// The master step (hil::MasterNode past its handshake, on a scripted bus: no system calls) runs in
// an rt::PeriodicLoop at 1 ms, with its XcpLink attached as in `lash hil run`: a second thread,
// standing in for the master's XCP thread, pops the step's measurements. Blocks of 2000 steps
// alternate (A B A B ...):
//   A  without console: nothing else;
//   B  with console: that thread also pushes each sample (13 signals) into a console::Server's
//      ring (lock-free SPSC), the server's drain and HTTP threads run, and a client on loopback
//      polls /api/frame (10 s window, 1000 columns) 60 times a second and /api/status 4 times.
// Prints the TET mean, p99 and max of A and B over all their blocks and the difference of the
// means; exit 1 when B's mean exceeds A's by more than 1 us (the bound), 77 without uPlot.
// Usage: lash_console_tet [blocks per phase, default 5]
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "lash/console/server.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/rt/periodic.hpp"
#include "hil_master_fixture.hpp"

namespace {
using namespace lash;
using namespace lash::hil;

using bench::ScriptedBus;

std::filesystem::path uplot_dir() {
  if (const char* e = std::getenv("LASH_UPLOT_DIR"); e && *e) return e;
#ifdef LASH_UPLOT_DIR
  return LASH_UPLOT_DIR;
#else
  return {};
#endif
}

struct Tet {
  std::vector<double> us;
};

}  // namespace

int main(int argc, char** argv) {
  const int blocks = argc > 1 ? std::atoi(argv[1]) : 5;
  constexpr std::size_t kSteps = 2000;
  const auto ud = uplot_dir();
  if (!std::filesystem::exists(ud / "uPlot.iife.min.js")) {
    std::printf("SKIP: uPlot not found in '%s' (scripts/install-deps.sh, or set LASH_UPLOT_DIR)\n", ud.c_str());
    return 77;
  }
  BenchLayout L;
  ScriptedBus bus;
  MasterNode master = bench::connected_master(L, bus, 0.001);
  auto link = std::make_unique<XcpLink>();
  master.attach(link.get());

  std::atomic<console::Server*> attached{nullptr};
  std::atomic<bool> stop{false};
  std::thread xcp_thread([&] {  // the master's XCP thread: pops each step's measurements
    MeasurementSample m;
    const auto fields = measurement_fields();
    while (!stop.load(std::memory_order_relaxed)) {
      while (link->samples.pop(m)) {
        if (console::Server* s = attached.load(std::memory_order_acquire)) {
          console::Sample smp;
          smp.t_s = static_cast<double>(m.t_us) * 1e-6;
          smp.count = static_cast<std::uint32_t>(fields.size());
          for (std::size_t i = 0; i < fields.size(); ++i) smp.values[i] = m.page.*fields[i].member;
          s->feed().push(smp);
        }
      }
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });

  console::ConsoleOptions co;
  co.uplot_dir = ud;
  co.title = "lash_console_tet";
  for (const auto& f : measurement_fields()) co.signals.emplace_back(f.name);
  co.decimation.base_s = 0.001;

  Tet a, b;
  std::uint64_t polls = 0, bytes = 0, console_drops = 0;
  std::uint16_t c = 0;
  double t_s = 0.0;
  for (int blk = 0; blk < 2 * blocks; ++blk) {
    const bool with = blk % 2 == 1;
    std::unique_ptr<console::Server> server;
    std::atomic<bool> client_stop{false};
    std::thread client;
    if (with) {
      server = std::make_unique<console::Server>(co, console::Tuner{});
      server->start();
      attached.store(server.get(), std::memory_order_release);
      client = std::thread([&, port = server->port(), token = server->token()] {
        httplib::Client cli("127.0.0.1", port);
        cli.set_keep_alive(true);
        const httplib::Headers h{{"X-Lash-Token", token}};
        for (int i = 0; !client_stop.load(); ++i) {
          if (auto r = cli.Get("/api/frame?window=10&columns=1000", h); r && r->status == 200) {
            ++polls;
            bytes += r->body.size();
          }
          if (i % 15 == 0) (void)cli.Get("/api/status", h);
          std::this_thread::sleep_for(std::chrono::microseconds(16667));
        }
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the client is connected and polling
    }
    rt::LoopConfig lc;
    lc.period_ns = 1'000'000;
    lc.max_steps = kSteps;
    rt::PeriodicLoop loop(lc);
    const std::atomic<bool> never{false};
    loop.run(
        [&](std::size_t, std::int64_t) noexcept {
          bus.next = L.pack_sensors({static_cast<std::uint16_t>(17000 + (c & 255)), 0, c});
          bus.pending = true;
          ++c;
          t_s += 0.001;
          master.step(bus, t_s);
          return true;
        },
        never);
    for (const auto& r : loop.records()) (with ? b : a).us.push_back(static_cast<double>(r.tet_ns) * 1e-3);
    if (with) {
      client_stop.store(true);
      client.join();
      attached.store(nullptr, std::memory_order_release);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // the XCP thread let go of the server
      console_drops += server->drops();
      server->stop();
    }
  }
  stop.store(true);
  xcp_thread.join();
  const rt::Summary sa = rt::summarize(a.us), sb = rt::summarize(b.us);
  std::printf("master step TET [us] over %zu steps each, %d blocks of %zu steps per phase, interleaved:\n", sa.n,
              blocks, kSteps);
  std::printf("  without console: mean %.3f p99 %.3f max %.3f\n", sa.mean, sa.p99, sa.max);
  std::printf("  with console   : mean %.3f p99 %.3f max %.3f (client: %llu frames polled, %.1f MB; ring drops %llu)\n",
              sb.mean, sb.p99, sb.max, static_cast<unsigned long long>(polls), static_cast<double>(bytes) / 1e6,
              static_cast<unsigned long long>(console_drops));
  const double d = sb.mean - sa.mean;
  std::printf("  difference of the means: %+.3f us (bound: +1 us) %s\n", d, d <= 1.0 ? "ok" : "EXCEEDED");
  return d <= 1.0 ? 0 : 1;
}
