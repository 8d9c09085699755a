// The SQLite history store (hoist/history/store.hpp, sqlite_store.hpp).
//
// Durability: WAL journal (readers -- hoist-trips, the dashboard -- never
// block the writer) with synchronous=FULL: every commit syncs the WAL, so a
// trip that put() returned for survives a power failure, not only a kill -9
// (NORMAL would be safe against a crash of the process but could lose the
// last commits on a power loss).  A trip is written every minute or so: the
// fsync per record costs nothing that matters.
#include "hoist/history/sqlite_store.hpp"

#include <sqlite3.h>
#include <sys/stat.h>

#include <cmath>

#include "hoist/history/schema.hpp"
#include "rows.hpp"

namespace hoist::history {

namespace {

class Stmt {
 public:
  Stmt(sqlite3* db, const std::string& sql, const std::string& name) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s_, nullptr) != SQLITE_OK)
      throw StoreError(name + ": " + sqlite3_errmsg(db));
  }
  ~Stmt() { sqlite3_finalize(s_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  sqlite3_stmt* get() { return s_; }
  void bind(int i, const Value& v) {
    int rc = SQLITE_OK;
    switch (v.kind) {
      case Kind::Real: rc = sqlite3_bind_double(s_, i, v.real); break;
      case Kind::Integer:
      case Kind::Boolean: rc = sqlite3_bind_int64(s_, i, v.integer); break;
      case Kind::Text: rc = sqlite3_bind_text(s_, i, v.text.data(), static_cast<int>(v.text.size()), SQLITE_TRANSIENT); break;
    }
    if (rc != SQLITE_OK) throw StoreError(std::string("history database: bind: ") + sqlite3_errmsg(db_));
  }
  void bind(int i, const std::string& s) { bind(i, Value{Kind::Text, 0.0, 0, s}); }
  void bind(int i, std::int64_t n) { bind(i, Value{Kind::Integer, 0.0, n, {}}); }
  /// true: a row; false: done.  Throws on an error.
  bool step(const std::string& name) {
    const int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw StoreError(name + ": " + sqlite3_errmsg(db_));
  }
  Value column(int i, Kind want) const {
    Value v;
    switch (sqlite3_column_type(s_, i)) {
      case SQLITE_INTEGER:
        v.integer = sqlite3_column_int64(s_, i);
        v.kind = want == Kind::Boolean ? Kind::Boolean : Kind::Integer;
        if (want == Kind::Real) v = Value{Kind::Real, static_cast<double>(v.integer), 0, {}};
        break;
      case SQLITE_FLOAT:
        v.kind = Kind::Real;
        v.real = sqlite3_column_double(s_, i);
        break;
      case SQLITE_TEXT: {
        v.kind = Kind::Text;
        const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(s_, i));
        v.text.assign(p ? p : "", static_cast<std::size_t>(sqlite3_column_bytes(s_, i)));
        break;
      }
      case SQLITE_NULL:  // SQLite stores a NaN as NULL
        v.kind = want == Kind::Real ? Kind::Real : Kind::Text;
        v.real = std::nan("");
        v.text = "NULL";
        break;
      default:
        v.kind = Kind::Text;
        v.text = "(a blob)";
        if (want == Kind::Text) v.kind = Kind::Real;  // a blob is never right
        break;
    }
    return v;
  }

 private:
  sqlite3* db_;
  sqlite3_stmt* s_ = nullptr;
};

class SqliteStore final : public Store {
 public:
  SqliteStore(std::string path, bool read_only) : path_(std::move(path)), name_("history database '" + path_ + "'") {
    struct stat st {};
    const bool exists = ::stat(path_.c_str(), &st) == 0;
    if (exists && !S_ISREG(st.st_mode)) throw StoreError(name_ + ": not a regular file");
    if (!exists && read_only) throw StoreError(name_ + ": no such file");
    const int flags = read_only ? SQLITE_OPEN_READONLY : (SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
    if (sqlite3_open_v2(path_.c_str(), &db_, flags | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK) {
      const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw StoreError(name_ + ": cannot open: " + why);
    }
    try {
      sqlite3_busy_timeout(db_, 5000);
      exec("PRAGMA foreign_keys = ON");
      if (!read_only) {
        const std::string mode = pragma("PRAGMA journal_mode = WAL");
        if (mode != "wal") throw StoreError(name_ + ": cannot use WAL mode (journal_mode is '" + mode + "')");
        exec("PRAGMA synchronous = FULL");
      }
      openSchema(read_only);
    } catch (...) {
      sqlite3_close(db_);
      throw;
    }
  }
  ~SqliteStore() override { sqlite3_close(db_); }

  PutResult put(TripRecord& r) override {
    if (auto e = recordError(r); !e.empty()) throw StoreError(name_ + ": record refused: " + e);
    Txn t(*this);
    if (r.trip == 0) r.trip = nextTripLocked(r.shaft);
    {
      Stmt s(db_, insertTripSql(false), name_);
      s.bind(1, r.shaft);
      s.bind(2, r.trip);
      int i = 3;
      for (const auto& f : tripFields()) s.bind(i++, f.get(r));
      s.step(name_ + ": insert " + detail::tripName(r.shaft, r.trip));
    }
    if (sqlite3_changes(db_) == 0) {
      ++stats_.duplicates;
      return PutResult::Duplicate;  // Txn rolls back (nothing was written)
    }
    Stmt b(db_, insertBinSql(false), name_);
    for (std::size_t k = 0; k < r.bins.size(); ++k) {
      sqlite3_reset(b.get());
      b.bind(1, r.shaft);
      b.bind(2, r.trip);
      b.bind(3, static_cast<std::int64_t>(k));
      int i = 4;
      for (const auto& f : binFields()) b.bind(i++, f.get(r.bins[k]));
      b.step(name_ + ": insert a bin of " + detail::tripName(r.shaft, r.trip));
    }
    t.commit();
    ++stats_.stored;
    return PutResult::Stored;
  }

  std::vector<TripRecord> list(const ListFilter& f) override {
    std::string sql = "SELECT " + tripColumnList() + " FROM trips WHERE 1=1";
    if (f.shaft) sql += " AND shaft = ?1";
    if (f.from_trip > 0) sql += " AND trip >= ?2";
    if (f.to_trip > 0) sql += " AND trip <= ?3";
    sql += " ORDER BY shaft, trip";
    if (f.limit > 0) sql += " LIMIT ?4";
    Stmt s(db_, sql, name_);
    if (f.shaft) s.bind(1, *f.shaft);
    if (f.from_trip > 0) s.bind(2, f.from_trip);
    if (f.to_trip > 0) s.bind(3, f.to_trip);
    if (f.limit > 0) s.bind(4, f.limit);
    std::vector<TripRecord> out;
    while (s.step(name_ + ": list")) out.push_back(detail::readTripRow([&](int i, Kind k) { return s.column(i, k); }, name_));
    if (f.with_bins)
      for (auto& r : out) readBins(r);
    return out;
  }

  std::optional<TripRecord> get(const std::string& shaft, std::int64_t trip) override {
    ListFilter f;
    f.shaft = shaft;
    f.from_trip = f.to_trip = trip;
    f.with_bins = true;
    if (trip <= 0) return std::nullopt;
    auto v = list(f);
    if (v.empty()) return std::nullopt;
    return std::move(v.front());
  }

  void markBaseline(const std::string& shaft, std::int64_t trip, bool on, std::int64_t now_us) override {
    Txn t(*this);
    if (!exists(shaft, trip)) throw StoreError(name_ + ": no " + detail::tripName(shaft, trip));
    Stmt s(db_, on ? "INSERT INTO baseline (shaft, trip, marked_us) VALUES (?1, ?2, ?3) ON CONFLICT DO NOTHING"
                   : "DELETE FROM baseline WHERE shaft = ?1 AND trip = ?2",
           name_);
    s.bind(1, shaft);
    s.bind(2, trip);
    if (on) s.bind(3, now_us);
    s.step(name_ + ": baseline");
    t.commit();
  }

  std::vector<std::int64_t> baseline(const std::string& shaft) override {
    Stmt s(db_, "SELECT trip FROM baseline WHERE shaft = ?1 ORDER BY trip", name_);
    s.bind(1, shaft);
    std::vector<std::int64_t> out;
    while (s.step(name_ + ": baseline")) {
      const Value v = s.column(0, Kind::Integer);
      detail::checked(name_ + ": baseline", "trip", Kind::Integer, v);
      out.push_back(v.integer);
    }
    return out;
  }

  std::int64_t prune(int keep_days, std::int64_t now_us) override {
    if (keep_days <= 0) return 0;
    Txn t(*this);
    Stmt s(db_, "DELETE FROM trips WHERE wall_end_us < ?1", name_);
    s.bind(1, now_us - static_cast<std::int64_t>(keep_days) * 86400LL * 1000000LL);
    s.step(name_ + ": prune");
    const std::int64_t n = sqlite3_changes(db_);
    t.commit();
    return n;
  }

  std::int64_t nextTrip(const std::string& shaft) override { return nextTripLocked(shaft); }
  std::int64_t flush() override { return 0; }
  StoreStats stats() const override { return stats_; }
  int schemaVersion() override { return readVersion(); }
  std::string describe() const override { return "sqlite " + path_; }

 private:
  /// BEGIN IMMEDIATE ... COMMIT, rolled back unless commit() was called.
  class Txn {
   public:
    explicit Txn(SqliteStore& s) : s_(s) { s_.exec("BEGIN IMMEDIATE"); }
    void commit() {
      s_.exec("COMMIT");
      done_ = true;
    }
    ~Txn() {
      if (!done_) sqlite3_exec(s_.db_, "ROLLBACK", nullptr, nullptr, nullptr);
    }

   private:
    SqliteStore& s_;
    bool done_ = false;
  };

  void exec(const std::string& sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      std::string why = err ? err : sqlite3_errmsg(db_);
      sqlite3_free(err);
      if (sqlite3_errcode(db_) == SQLITE_NOTADB) why = "not an SQLite database (" + why + ")";
      throw StoreError(name_ + ": " + why);
    }
  }

  std::string pragma(const std::string& sql) {
    Stmt s(db_, sql, name_);
    if (!s.step(name_)) return {};
    const Value v = s.column(0, Kind::Text);
    return v.text;
  }

  bool hasTable(const char* table) {
    Stmt s(db_, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?1", name_);
    s.bind(1, std::string(table));
    return s.step(name_);
  }

  int readVersion() {
    Stmt s(db_, "SELECT version FROM schema_version", name_);
    if (!s.step(name_ + ": schema_version")) throw StoreError(name_ + ": schema_version is empty");
    const Value v = s.column(0, Kind::Integer);
    if (v.kind != Kind::Integer || v.integer < 1)
      throw StoreError(name_ + ": schema_version holds no valid version");
    if (s.step(name_ + ": schema_version")) throw StoreError(name_ + ": schema_version has more than one row");
    return static_cast<int>(v.integer);
  }

  void openSchema(bool read_only) {
    int tables = 0;
    {
      Stmt s(db_, "SELECT count(*) FROM sqlite_master", name_ + " (not an SQLite database?)");
      if (s.step(name_)) tables = static_cast<int>(s.column(0, Kind::Integer).integer);
    }
    if (!hasTable("schema_version")) {
      if (tables > 0) throw StoreError(name_ + ": not a hoist-twin history database (tables, but no schema_version)");
      if (read_only) throw StoreError(name_ + ": an empty database (no schema yet)");
    }
    if (read_only) {  // no write transaction on a read-only connection
      const int v = readVersion();
      if (v != kSchemaVersion)
        throw StoreError(name_ + ": schema version " + std::to_string(v) + ", this program reads " +
                         std::to_string(kSchemaVersion) + (v < kSchemaVersion ? ": open it once read-write to migrate it"
                                                                              : ": use a newer hoist-twin"));
      return;
    }
    for (;;) {
      Txn t(*this);
      const int v = hasTable("schema_version") ? readVersion() : 0;
      if (v > kSchemaVersion)
        throw StoreError(name_ + ": schema version " + std::to_string(v) + " is newer than this program's (" +
                         std::to_string(kSchemaVersion) + "): use a newer hoist-twin");
      if (v == kSchemaVersion) return;  // rolls back the empty transaction
      for (const auto& sql : schemaSteps(v + 1)) exec(sql);
      t.commit();
    }
  }

  bool exists(const std::string& shaft, std::int64_t trip) {
    Stmt s(db_, "SELECT 1 FROM trips WHERE shaft = ?1 AND trip = ?2", name_);
    s.bind(1, shaft);
    s.bind(2, trip);
    return s.step(name_);
  }

  std::int64_t nextTripLocked(const std::string& shaft) {
    Stmt s(db_, "SELECT COALESCE(MAX(trip), 0) + 1 FROM trips WHERE shaft = ?1", name_);
    s.bind(1, shaft);
    s.step(name_);
    return s.column(0, Kind::Integer).integer;
  }

  void readBins(TripRecord& r) {
    Stmt s(db_, "SELECT " + binColumnList() + " FROM bins WHERE shaft = ?1 AND trip = ?2 ORDER BY idx", name_);
    s.bind(1, r.shaft);
    s.bind(2, r.trip);
    const std::string what = name_ + ": " + detail::tripName(r.shaft, r.trip);
    r.bins.clear();
    while (s.step(what)) {
      if (r.bins.size() >= kMaxBins) throw StoreError(what + ": more than " + std::to_string(kMaxBins) + " bins");
      r.bins.push_back(detail::readBinRow([&](int i, Kind k) { return s.column(i, k); }, what));
    }
  }

  std::string path_, name_;
  sqlite3* db_ = nullptr;
  StoreStats stats_;
};

}  // namespace

std::unique_ptr<Store> openSqliteStore(const std::string& path, bool read_only) {
  return std::make_unique<SqliteStore>(path, read_only);
}

}  // namespace hoist::history
