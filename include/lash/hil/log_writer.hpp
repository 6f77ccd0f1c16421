#pragma once
/// @file log_writer.hpp
/// A node's logs on their way to disk while it runs (docs/hil.md, "Logs that survive the node").
///
/// The real-time step pushes each step's row (with its loop record), the frames it logged, its
/// state events and its calibration writes into a bounded lock-free ring (rt::SpscQueue); a
/// writer thread pops them, formats the lines of master.csv / slave.csv, the events CSV and the
/// candump bus log exactly as the files were written before, and writes them out every
/// kLogFlushPeriod (and whenever a file's batch exceeds 1 MiB). A node killed outright
/// (kill -9) therefore leaves its logs on disk up to at most the last kLogFlushPeriod plus what
/// sat in the ring. The step never waits on the disk: a full ring refuses the item, which is
/// counted (LogStats::ring_full) and reported in the node's JSON; it never blocks.
/// The writer also keeps the loop statistics (TET, I/O, cycle, wake-up latency) over every row
/// in rt::StreamSummary: a node's memory does not grow with its duration.
/// Lines are written whole (a batch is a run of whole lines), so a reader of a killed node's
/// log sees whole rows only (LogReader, in handover.hpp, drops a cut last line anyway).
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "lash/hil/calibration.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/rt/periodic.hpp"
#include "lash/rt/spsc_queue.hpp"

namespace lash::hil {

/// One step of the master / the slave with its loop record (t_s and timing columns).
struct MasterRow {
  MasterStepLog log;
  rt::StepRecord rec;
};
struct SlaveRow {
  SlaveStepLog log;
  rt::StepRecord rec;
};
/// What a step hands to its writer.
using LogItem = std::variant<MasterRow, SlaveRow, LoggedFrame, NodeEvent, CalibrationEvent>;

/// Items the ring holds (≈ 2 MB): 3 items a step at the shortest step of 0.1 ms is 30 000 items/s;
/// the writer drains the ring every kLogPollPeriod (1500 items then), so the ring holds 0.27 s of
/// the fastest run before a stalled writer loses items.
inline constexpr std::size_t kLogRing = 8192;
/// How often the writer thread wakes to drain the ring: rarely, so that it seldom runs (and
/// pollutes the caches) between two of the node's steps.
inline constexpr std::chrono::milliseconds kLogPollPeriod{50};
/// Longest time between two writes of a file's pending lines (≤ 1 s, as docs/hil.md promises).
inline constexpr std::chrono::milliseconds kLogFlushPeriod{200};

/// What the writer did (trivially copyable: it crosses the hand-over in NodeStats).
struct LogStats {
  std::uint64_t rows = 0;       ///< step rows written
  std::uint64_t frames = 0;     ///< bus-log lines written
  std::uint64_t events = 0;     ///< event lines written (state events and calibration writes)
  std::uint64_t ring_full = 0;  ///< items the step could not push (ring full): missing from the logs
  std::uint64_t writes = 0;     ///< batches written (write(2) calls)
  double last_t_s = -1.0;       ///< t_s of the last row written [s]; −1: none
};

/// The files of one node; an empty path is not written.
struct LogPaths {
  std::filesystem::path csv;      ///< master.csv / slave.csv
  std::filesystem::path events;   ///< <log>.events.csv
  std::filesystem::path bus_log;  ///< candump -L (master only)
};

/// The loop statistics of a run [µs], from its rows.
struct LoopSummaries {
  rt::Summary tet_us, io_us, cycle_us, wake_latency_us;
};

class NodeLogWriter {
 public:
  enum class Node : std::uint8_t { master, slave };
  /// Opens (truncates) the files, writes their headers and starts the thread. max_steps sizes
  /// the percentile tails (rt::StreamSummary). Throws SystemError naming the file it cannot open.
  /// Not real-time safe.
  NodeLogWriter(Node node, LogPaths paths, std::size_t max_steps);
  ~NodeLogWriter();
  NodeLogWriter(const NodeLogWriter&) = delete;
  NodeLogWriter& operator=(const NodeLogWriter&) = delete;

  /// Producer (one thread: the step's): false when the ring is full (counted). noexcept,
  /// allocation-free, never blocks.
  bool push(const LogItem& item) noexcept {
    if (ring_->push(item)) return true;
    ring_full_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  /// CLOCK_REALTIME of the loop's r_0 [s]: a sent frame is logged at epoch + its loop time (a
  /// received one carries the bus's wall-clock receive time). Set before the loop runs.
  void set_epoch(double epoch_s) noexcept { epoch_s_.store(epoch_s, std::memory_order_relaxed); }
  /// Writes everything pushed, stops the thread, closes the files. Idempotent. Not real-time safe.
  void stop();
  /// After stop(): what was written, and the loop statistics over the rows.
  LogStats stats() const noexcept { return stats_; }
  LoopSummaries loop() const;

 private:
  struct File {
    int fd = -1;
    std::string path, pending;
  };
  void run() noexcept;
  void drain();
  void take(const LogItem& item);
  void count_step(const rt::StepRecord& r) noexcept;  ///< a row written: counts and loop statistics
  void flush_events(std::uint32_t through_step);
  void write_out(File& f);
  void write_all();

  Node node_;
  std::unique_ptr<rt::SpscQueue<LogItem, kLogRing>> ring_;
  std::atomic<std::uint64_t> ring_full_{0};
  std::atomic<double> epoch_s_{0.0};
  std::atomic<bool> done_{false};
  File csv_, events_, bus_;
  std::vector<NodeEvent> pending_events_;          ///< this step's, written with its row
  std::vector<CalibrationEvent> pending_calibration_;
  rt::StreamSummary tet_, io_, cycle_, wake_;
  LogStats stats_;
  std::string error_;                              ///< first write error (reported by stop())
  std::thread thread_;
  bool stopped_ = false;
};

}  // namespace lash::hil
