#include "lash/monitor/history.hpp"

#include <sqlite3.h>

#include <cmath>
#include <limits>

#include "lash/io/error.hpp"

namespace lash::monitor {

namespace {

constexpr const char* kSchema =
    "CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT);"
    "CREATE TABLE IF NOT EXISTS periods(id INTEGER PRIMARY KEY, t REAL NOT NULL, samples INTEGER NOT NULL,"
    " status TEXT NOT NULL, json TEXT);"
    "CREATE TABLE IF NOT EXISTS estimates(period INTEGER NOT NULL REFERENCES periods(id), t REAL NOT NULL,"
    " param TEXT NOT NULL, value REAL, lo REAL, hi REAL, identified INTEGER NOT NULL);"
    "CREATE TABLE IF NOT EXISTS events(id INTEGER PRIMARY KEY, period INTEGER REFERENCES periods(id),"
    " t REAL NOT NULL, kind TEXT NOT NULL, param TEXT, before REAL, after REAL);"
    "CREATE INDEX IF NOT EXISTS estimates_param_t ON estimates(param, t);";

/// RAII statement.
class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql, const std::string& path) {
    if (sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) != SQLITE_OK)
      throw InputError(path, 0, "", std::string("SQLite: ") + sqlite3_errmsg(db));
  }
  ~Stmt() { sqlite3_finalize(s_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  sqlite3_stmt* get() const noexcept { return s_; }
  void real(int i, double x) {
    if (std::isfinite(x)) sqlite3_bind_double(s_, i, x);
    else sqlite3_bind_null(s_, i);
  }
  void text(int i, const std::string& x) {
    if (x.empty()) sqlite3_bind_null(s_, i);
    else sqlite3_bind_text(s_, i, x.c_str(), static_cast<int>(x.size()), SQLITE_TRANSIENT);
  }
  void integer(int i, std::int64_t x) { sqlite3_bind_int64(s_, i, x); }
  void run(sqlite3* db, const std::string& path) {
    if (sqlite3_step(s_) != SQLITE_DONE) throw SystemError(path + ": SQLite: " + sqlite3_errmsg(db));
    sqlite3_reset(s_);
    sqlite3_clear_bindings(s_);
  }

 private:
  sqlite3_stmt* s_ = nullptr;
};

double column_real(sqlite3_stmt* s, int i) {
  return sqlite3_column_type(s, i) == SQLITE_NULL ? std::numeric_limits<double>::quiet_NaN()
                                                  : sqlite3_column_double(s, i);
}
std::string column_text(sqlite3_stmt* s, int i) {
  const auto* p = sqlite3_column_text(s, i);
  return p ? reinterpret_cast<const char*>(p) : "";
}

}  // namespace

HistoryDb::HistoryDb(const std::string& path, const std::map<std::string, std::string>& meta) : path_(path) {
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    close();
    throw InputError(path, 0, "--db", "cannot open the database: " + why);
  }
  try {
    exec("PRAGMA journal_mode=WAL;");
    exec("PRAGMA synchronous=NORMAL;");  // WAL + NORMAL: a committed transaction survives a process kill
    exec(kSchema);
    set_meta(meta);
  } catch (...) {
    close();
    throw;
  }
}

HistoryDb::~HistoryDb() { close(); }

void HistoryDb::exec(const char* sql) {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string why = err ? err : sqlite3_errmsg(db_);
    sqlite3_free(err);
    throw InputError(path_, 0, "--db", "SQLite: " + why);
  }
}

void HistoryDb::set_meta(const std::map<std::string, std::string>& meta) {
  exec("BEGIN;");
  try {
    Stmt put(db_, "INSERT OR REPLACE INTO meta(key, value) VALUES(?, ?);", path_);
    for (const auto& [k, v] : meta) {
      put.text(1, k);
      put.text(2, v);
      put.run(db_, path_);
    }
    exec("COMMIT;");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK;", nullptr, nullptr, nullptr);
    throw;
  }
}

void HistoryDb::write(const Period& p) {
  exec("BEGIN;");
  try {
    Stmt per(db_, "INSERT INTO periods(t, samples, status, json) VALUES(?, ?, ?, ?);", path_);
    per.real(1, p.t);
    per.integer(2, static_cast<std::int64_t>(p.samples));
    per.text(3, p.status);
    per.text(4, p.json);
    per.run(db_, path_);
    const std::int64_t id = sqlite3_last_insert_rowid(db_);
    Stmt est(db_, "INSERT INTO estimates(period, t, param, value, lo, hi, identified) VALUES(?, ?, ?, ?, ?, ?, ?);",
             path_);
    for (const ParamValue& v : p.params) {
      est.integer(1, id);
      est.real(2, p.t);
      est.text(3, v.name);
      est.real(4, v.value);
      est.real(5, v.lo);
      est.real(6, v.hi);
      est.integer(7, v.identified ? 1 : 0);
      est.run(db_, path_);
    }
    Stmt ev(db_, "INSERT INTO events(period, t, kind, param, before, after) VALUES(?, ?, ?, ?, ?, ?);", path_);
    for (const Event& e : p.events) {
      ev.integer(1, id);
      ev.real(2, e.t);
      ev.text(3, e.kind);
      ev.text(4, e.param);
      ev.real(5, e.before);
      ev.real(6, e.after);
      ev.run(db_, path_);
    }
    exec("COMMIT;");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK;", nullptr, nullptr, nullptr);
    throw;
  }
}

void HistoryDb::close() noexcept {
  if (!db_) return;
  sqlite3_wal_checkpoint_v2(db_, nullptr, SQLITE_CHECKPOINT_TRUNCATE, nullptr, nullptr);
  sqlite3_close_v2(db_);
  db_ = nullptr;
}

History read_history(const std::string& path) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    const std::string why = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close_v2(db);
    throw InputError(path, 0, "--report", "cannot open the database: " + why);
  }
  History h;
  try {
    {
      Stmt s(db, "SELECT key, value FROM meta;", path);
      while (sqlite3_step(s.get()) == SQLITE_ROW) h.meta[column_text(s.get(), 0)] = column_text(s.get(), 1);
    }
    {
      Stmt s(db, "SELECT t, param, value, lo, hi, identified FROM estimates ORDER BY period, rowid;", path);
      while (sqlite3_step(s.get()) == SQLITE_ROW)
        h.estimates.push_back({sqlite3_column_double(s.get(), 0), column_text(s.get(), 1), column_real(s.get(), 2),
                               column_real(s.get(), 3), column_real(s.get(), 4), sqlite3_column_int(s.get(), 5) != 0});
    }
    {
      Stmt s(db, "SELECT t, kind, param, before, after FROM events ORDER BY id;", path);
      while (sqlite3_step(s.get()) == SQLITE_ROW) {
        Event e;
        e.t = sqlite3_column_double(s.get(), 0);
        e.kind = column_text(s.get(), 1);
        e.param = column_text(s.get(), 2);
        e.before = column_real(s.get(), 3);
        e.after = column_real(s.get(), 4);
        h.events.push_back(e);
      }
    }
  } catch (const InputError& e) {
    sqlite3_close_v2(db);
    throw InputError(path, 0, "--report", "not a lash monitor database (" + e.message() + ")");
  }
  sqlite3_close_v2(db);
  return h;
}

}  // namespace lash::monitor
