#pragma once
/// @file history.hpp
/// The monitor's history in SQLite (libsqlite3), WAL journal, one transaction per period: a
/// `kill -9` loses at most the period in progress and leaves a database that passes
/// `PRAGMA integrity_check`. Schema (docs/monitor.md, "Database"):
///
///   meta(key TEXT PRIMARY KEY, value TEXT)            source, dbc, v, y, model, t0_unix_s, …
///   periods(id INTEGER PRIMARY KEY, t REAL, samples INTEGER, status TEXT, json TEXT)
///   estimates(period INTEGER, t REAL, param TEXT, value REAL, lo REAL, hi REAL, identified INTEGER)
///   events(id INTEGER PRIMARY KEY, period INTEGER, t REAL, kind TEXT, param TEXT,
///          before REAL, after REAL)
///
/// t: seconds since the first sample; value/lo/hi in the parameter's unit (NULL when none).
/// Not real-time code.
#include <map>
#include <string>
#include <vector>

#include "lash/monitor/events.hpp"

struct sqlite3;

namespace lash::monitor {

/// One period as the monitor writes it.
struct Period {
  double t = 0.0;                 ///< [s] since the first sample
  std::uint64_t samples = 0;      ///< samples the estimate used
  std::string status;             ///< ok | stale | warming_up | final
  std::string json;               ///< `lash estimate --json` of the samples so far ("" = none yet)
  std::vector<ParamValue> params;
  std::vector<Event> events;      ///< raised in this period
};

class HistoryDb {
 public:
  /// Opens or creates `path` (tables created if missing, WAL mode) and stores `meta`.
  /// InputError naming the file when SQLite refuses it.
  HistoryDb(const std::string& path, const std::map<std::string, std::string>& meta);
  ~HistoryDb();
  HistoryDb(const HistoryDb&) = delete;
  HistoryDb& operator=(const HistoryDb&) = delete;
  /// One transaction: the period's row, its parameters and its events.
  void write(const Period& p);
  /// Stores (or replaces) keys of `meta` in one transaction.
  void set_meta(const std::map<std::string, std::string>& meta);
  /// Checkpoints and closes (also done by the destructor).
  void close() noexcept;

 private:
  void exec(const char* sql);
  sqlite3* db_ = nullptr;
  std::string path_;
};

/// What `lash monitor --report` plots: every row of `estimates` and `events`.
struct History {
  struct Row {
    double t;
    std::string param;
    double value, lo, hi;  ///< NaN for NULL
    bool identified;
  };
  std::vector<Row> estimates;
  std::vector<Event> events;
  std::map<std::string, std::string> meta;
};
/// Reads a monitor database (read-only). InputError naming the file when it is not one.
History read_history(const std::string& path);

}  // namespace lash::monitor
