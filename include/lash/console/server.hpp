#pragma once
/// @file server.hpp
/// The live console (docs/console.md): an HTTP server (cpp-httplib) on its own thread that
/// serves the page, the decimated signals, the status and the events, and takes calibration
/// changes. Endpoints: GET /api/meta (signals, params), GET /api/frame (the decimated window as
/// binary float32 min/max per column on a fixed grid; from=J: only the columns from J on, the page's
/// stream), GET
/// /api/status (JSON: status, events and estimates since an id, params), POST /api/tune. It is fed through a Feed (a lock-free SPSC ring, feed.hpp) that its drain thread
/// empties into a Decimator every 10 ms; the producer never waits for the console.
///
/// Security: bound to 127.0.0.1 unless told otherwise; a random token per run (getrandom);
/// every /api request needs it in the X-Lash-Token header, and every request that changes
/// anything also a same-origin Origin header and a Host naming this server, else 403; with
/// read_only every change is refused (403). The page loads only from this server.
/// Not real-time code (except feed().push()).
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <atomic>
#include <vector>

#include "lash/console/decimator.hpp"
#include "lash/console/feed.hpp"

namespace lash::console {

/// A tunable object (an A2L CHARACTERISTIC).
struct TuneParam {
  std::string name, unit, doc;
  double min = 0.0, max = 0.0;
};
/// What the tuner answers: the value read back after the write, or the ECU's error.
struct TuneResult {
  bool ok = false;
  double readback = 0.0;
  std::string error;
};
/// Called on an HTTP thread; may block (it talks to the ECU). Must be thread-safe.
using Tuner = std::function<TuneResult(const std::string& name, double value)>;

struct ConsoleOptions {
  std::string bind = "127.0.0.1";
  int port = 0;                              ///< 0: any free port
  bool read_only = false;
  std::filesystem::path uplot_dir;           ///< holds uPlot.iife.min.js and uPlot.min.css
  std::string title = "lash";
  std::vector<std::string> signals;          ///< names of Sample::values of feed 0, at most kMaxSignals
  /// Further feeds (each its own ring, producer and decimator; same decimation settings), their
  /// signals listed after `signals` (e.g. the slave's frames beside the master's DAQ).
  std::vector<std::vector<std::string>> extra_feeds;
  std::vector<TuneParam> params;             ///< the tuning panel
  DecimatorConfig decimation;                ///< `signals` is set from the list above
  /// Throws InputError naming the option.
  void validate() const;
};

struct ConsoleEvent {
  std::uint64_t id = 0;
  double t_s = 0.0;
  std::string kind, text;
};

/// One estimate of a parameter at a time (the monitor's periods): drawn with its 95 % band and
/// coloured by its verdict.
struct ConsoleEstimate {
  std::uint64_t id = 0;
  double t_s = 0.0;
  std::string name;
  double value = 0.0, lo = 0.0, hi = 0.0;  ///< NaN when unknown
  bool identified = false;
};

class Server {
 public:
  /// Binds the socket (so it lives in the network namespace of the caller) and makes the token;
  /// threads start with start(). Throws InputError when the address cannot be bound.
  Server(ConsoleOptions options, Tuner tuner);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  void start();
  void stop();  ///< idempotent; joins the threads

  int port() const noexcept { return port_; }
  const std::string& token() const noexcept { return token_; }
  /// http://HOST:PORT/?token=TOKEN
  std::string url() const;

  /// Feed i (0: `signals`, i >= 1: extra_feeds[i - 1]); one producer thread per feed.
  Feed& feed(std::size_t i = 0) noexcept;
  /// Status shown in the page (non-RT; any thread).
  void set_status(const std::string& key, double value);
  /// Several values at once (a page never sees half of them updated).
  void set_statuses(const std::vector<std::pair<std::string, double>>& values);
  void set_status_text(const std::string& key, const std::string& value);
  /// An event marker (non-RT; any thread). The newest 1000 are kept.
  void add_event(double t_s, const std::string& kind, const std::string& text);
  /// The latest value of every param (for the form's initial values), non-RT.
  void set_param_value(const std::string& name, double value);
  /// An estimate (non-RT; any thread). The newest 20000 are kept.
  void add_estimate(double t_s, const std::string& name, double value, double lo, double hi, bool identified);

  std::uint64_t drops() const noexcept;  ///< over all feeds
  std::uint64_t requests() const noexcept { return requests_.load(); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  ConsoleOptions o_;
  Tuner tuner_;
  struct Group;  // a feed and its decimator
  std::vector<std::unique_ptr<Group>> groups_;
  std::vector<std::string> all_signals_;
  int port_ = 0;
  std::string token_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> requests_{0};
  std::mutex m_;  // guards everything below (and the groups' decimators)
  std::map<std::string, double> status_;
  std::map<std::string, std::string> status_text_;
  std::map<std::string, double> param_values_;
  std::deque<ConsoleEvent> events_;
  std::uint64_t next_event_ = 1;
  std::deque<ConsoleEstimate> estimates_;
  std::uint64_t next_estimate_ = 1;
  std::uint64_t frames_served_ = 0;
  std::thread http_thread_, drain_thread_;
  bool started_ = false;
  friend struct Handlers;
};

/// A random token of `bytes` bytes from getrandom(2), as lowercase hex.
std::string random_token(std::size_t bytes = 16);

}  // namespace lash::console
