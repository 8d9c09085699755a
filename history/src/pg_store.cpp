// The PostgreSQL history store (hoist/history/pg_store.hpp), via libpq.
//
// Same schema as SQLite (schema.hpp), created or migrated under an advisory
// lock so two daemons starting together do not race.  Parameters go as text
// (doubles in %.17g, exact); values read back are parsed and checked.
//
// Outage: a put() that cannot reach the server -- no connection, or the
// connection lost during the transaction (even during COMMIT, when it may or
// may not have committed) -- goes to the RecordQueue; every put() and
// flush() first writes the queue in order, and the idempotent insert makes
// a record that did commit before the loss a Duplicate, not a double.  The
// reconnection is tried at most every retry_seconds, so a put() while the
// server is down costs one file write.  The password is handed to libpq as a
// connection parameter, never put into the URL, a message or a log.
#include "hoist/history/pg_store.hpp"

#include <libpq-fe.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <type_traits>

#include "hoist/history/queue.hpp"
#include "hoist/history/schema.hpp"
#include "rows.hpp"

namespace hoist::history {

namespace {

struct Outage {
  std::string why;
};

struct Result {
  PGresult* r = nullptr;
  explicit Result(PGresult* p) : r(p) {}
  ~Result() { PQclear(r); }
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;
};

std::string paramText(const Value& v) {
  switch (v.kind) {
    case Kind::Real: {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.17g", v.real);
      return buf;
    }
    case Kind::Integer:
    case Kind::Boolean: return std::to_string(v.integer);
    case Kind::Text: return v.text;
  }
  return {};
}

Value columnValue(PGresult* r, int row, int col, Kind want) {
  Value v;
  if (PQgetisnull(r, row, col)) {
    v.kind = want == Kind::Real ? Kind::Real : Kind::Text;
    v.real = std::nan("");
    v.text = "NULL";
    return v;
  }
  const char* s = PQgetvalue(r, row, col);
  switch (PQftype(r, col)) {
    case 700: case 701: case 1700: {  // float4, float8, numeric
      char* end = nullptr;
      v.kind = Kind::Real;
      v.real = std::strtod(s, &end);
      if (end == s || *end) v.real = std::nan("");
      return v;
    }
    case 20: case 21: case 23: {  // int8, int2, int4
      char* end = nullptr;
      v.integer = std::strtoll(s, &end, 10);
      v.kind = want == Kind::Boolean ? Kind::Boolean : Kind::Integer;
      if (want == Kind::Real) v = Value{Kind::Real, static_cast<double>(v.integer), 0, {}};
      return v;
    }
    default:
      v.kind = Kind::Text;
      v.text = s;
      return v;
  }
}

void quietNotices(void*, const char*) {}

class PgStore final : public Store {
 public:
  explicit PgStore(const StoreOptions& o)
      : url_(o.db.target), password_(o.password), queue_(o.queue_dir), retry_(o.retry_seconds),
        name_("history database " + o.db.target) {
    if (o.queue_dir.empty()) throw StoreError(name_ + ": no queue folder for outages (history.queue_dir)");
    if (!connect(true)) {
      const std::string& e = stats_.last_error;
      if (e.find("authentication") != std::string::npos || e.find("password") != std::string::npos ||
          e.find("does not exist") != std::string::npos || e.find("invalid") != std::string::npos)
        throw StoreError(name_ + ": the server refused us: " + e);
    }
  }
  ~PgStore() override { PQfinish(conn_); }

  PutResult put(TripRecord& r) override {
    if (auto e = recordError(r); !e.empty()) throw StoreError(name_ + ": record refused: " + e);
    if (r.trip == 0) r.trip = nextTrip(r.shaft);
    if (flushQueue() == 0 && connect(false)) {
      try {
        return writeOne(r);
      } catch (const Outage& o) {
        lost(o.why);
      }
    }
    queue_.push(r);
    ++stats_.queued;
    known_max_[r.shaft] = std::max(known_max_[r.shaft], r.trip);
    return PutResult::Queued;
  }

  std::vector<TripRecord> list(const ListFilter& f) override {
    return online([&] {
      std::string sql = "SELECT " + tripColumnList() + " FROM trips WHERE TRUE";
      std::vector<std::string> p;
      if (f.shaft) p.push_back(*f.shaft), sql += " AND shaft = $" + std::to_string(p.size());
      if (f.from_trip > 0) p.push_back(std::to_string(f.from_trip)), sql += " AND trip >= $" + std::to_string(p.size());
      if (f.to_trip > 0) p.push_back(std::to_string(f.to_trip)), sql += " AND trip <= $" + std::to_string(p.size());
      sql += " ORDER BY shaft, trip";
      if (f.limit > 0) p.push_back(std::to_string(f.limit)), sql += " LIMIT $" + std::to_string(p.size());
      Result res(run(sql, p, PGRES_TUPLES_OK));
      std::vector<TripRecord> out;
      for (int row = 0; row < PQntuples(res.r); ++row)
        out.push_back(detail::readTripRow([&](int i, Kind k) { return columnValue(res.r, row, i, k); }, name_));
      if (f.with_bins)
        for (auto& r : out) readBins(r);
      return out;
    });
  }

  std::optional<TripRecord> get(const std::string& shaft, std::int64_t trip) override {
    if (trip <= 0) return std::nullopt;
    ListFilter f;
    f.shaft = shaft;
    f.from_trip = f.to_trip = trip;
    f.with_bins = true;
    auto v = list(f);
    if (v.empty()) return std::nullopt;
    return std::move(v.front());
  }

  void markBaseline(const std::string& shaft, std::int64_t trip, bool on, std::int64_t now_us) override {
    online([&] {
      Result ex(run("SELECT 1 FROM trips WHERE shaft = $1 AND trip = $2", {shaft, std::to_string(trip)}, PGRES_TUPLES_OK));
      if (PQntuples(ex.r) == 0) throw StoreError(name_ + ": no " + detail::tripName(shaft, trip));
      if (on)
        Result(run("INSERT INTO baseline (shaft, trip, marked_us) VALUES ($1, $2, $3) ON CONFLICT DO NOTHING",
                   {shaft, std::to_string(trip), std::to_string(now_us)}, PGRES_COMMAND_OK));
      else
        Result(run("DELETE FROM baseline WHERE shaft = $1 AND trip = $2", {shaft, std::to_string(trip)},
                   PGRES_COMMAND_OK));
      return 0;
    });
  }

  std::vector<std::int64_t> baseline(const std::string& shaft) override {
    return online([&] {
      Result res(run("SELECT trip FROM baseline WHERE shaft = $1 ORDER BY trip", {shaft}, PGRES_TUPLES_OK));
      std::vector<std::int64_t> out;
      for (int row = 0; row < PQntuples(res.r); ++row) {
        const Value v = columnValue(res.r, row, 0, Kind::Integer);
        detail::checked(name_ + ": baseline", "trip", Kind::Integer, v);
        out.push_back(v.integer);
      }
      return out;
    });
  }

  std::int64_t prune(int keep_days, std::int64_t now_us) override {
    if (keep_days <= 0) return 0;
    return online([&] {
      const std::int64_t cut = now_us - static_cast<std::int64_t>(keep_days) * 86400LL * 1000000LL;
      Result res(run("DELETE FROM trips WHERE wall_end_us < $1", {std::to_string(cut)}, PGRES_COMMAND_OK));
      return static_cast<std::int64_t>(std::atoll(PQcmdTuples(res.r)));
    });
  }

  std::int64_t nextTrip(const std::string& shaft) override {
    // Records a previous run left in the queue count too: read once per shaft
    // (this process's own pushes update known_max_).
    if (scanned_.insert(shaft).second) known_max_[shaft] = std::max(known_max_[shaft], queue_.maxTrip(shaft));
    std::int64_t m = known_max_[shaft];
    if (connect(false)) {
      try {
        Result res(run("SELECT COALESCE(MAX(trip), 0) FROM trips WHERE shaft = $1", {shaft}, PGRES_TUPLES_OK));
        known_max_[shaft] = std::max(known_max_[shaft], static_cast<std::int64_t>(std::atoll(PQgetvalue(res.r, 0, 0))));
        m = std::max(m, known_max_[shaft]);
      } catch (const Outage& o) {
        lost(o.why);
      }
    }
    return m + 1;
  }

  std::int64_t flush() override { return flushQueue(); }

  StoreStats stats() const override {
    StoreStats s = stats_;
    s.pending = static_cast<std::int64_t>(queue_.pending().size());
    s.queue_rejected = queue_.rejected();
    return s;
  }

  int schemaVersion() override {
    return online([&] { return readVersion(); });
  }

  std::string describe() const override { return "postgresql " + url_; }

 private:
  /// Connects (at most every retry_ seconds unless `force`) and checks or
  /// migrates the schema.  false: down (stats_.last_error says why).
  bool connect(bool force) {
    if (conn_ && PQstatus(conn_) == CONNECTION_OK) return true;
    const auto now = std::chrono::steady_clock::now();
    if (!force && tried_ && now - last_try_ < std::chrono::duration<double>(retry_)) return false;
    tried_ = true;
    last_try_ = now;
    PQfinish(conn_);
    const char* keys[] = {"dbname", "password", "connect_timeout", "application_name", "tcp_user_timeout", nullptr};
    const char* vals[] = {url_.c_str(), password_.empty() ? nullptr : password_.c_str(), "5", "hoist-twin", "10000",
                          nullptr};
    if (password_.empty()) keys[1] = "connect_timeout", vals[1] = "5";
    conn_ = PQconnectdbParams(keys, vals, 1);
    if (PQstatus(conn_) != CONNECTION_OK) {
      lost(conn_ ? PQerrorMessage(conn_) : "out of memory");
      return false;
    }
    PQsetNoticeProcessor(conn_, quietNotices, nullptr);
    try {
      openSchema();
    } catch (const Outage& o) {
      lost(o.why);
      return false;
    } catch (...) {  // a schema we must not touch (StoreError): no connection kept, none leaked
      lost("refused");
      throw;
    }
    stats_.connected = true;
    stats_.last_error.clear();
    return true;
  }

  void lost(std::string why) {
    while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
    stats_.connected = false;
    stats_.last_error = why;
    PQfinish(conn_);
    conn_ = nullptr;
  }

  /// Runs `f` connected (forcing a connection attempt); StoreError if down.
  template <class F>
  std::invoke_result_t<F&> online(F&& f) {
    if (!connect(true)) throw StoreError(name_ + ": the server is unreachable: " + stats_.last_error);
    try {
      return f();
    } catch (const Outage& o) {
      lost(o.why);
      throw StoreError(name_ + ": the connection was lost: " + stats_.last_error);
    }
  }

  /// One statement; Outage when the connection is gone, StoreError on any
  /// other failure.
  PGresult* run(const std::string& sql, const std::vector<std::string>& params, ExecStatusType want) {
    std::vector<const char*> v;
    for (const auto& p : params) v.push_back(p.c_str());
    PGresult* r = PQexecParams(conn_, sql.c_str(), static_cast<int>(v.size()), nullptr, v.empty() ? nullptr : v.data(),
                               nullptr, nullptr, 0);
    if (r && PQresultStatus(r) == want) return r;
    std::string why = r ? PQresultErrorMessage(r) : PQerrorMessage(conn_);
    if (why.empty() && r) why = std::string("unexpected result ") + PQresStatus(PQresultStatus(r)) + " for: " + sql;
    PQclear(r);
    if (PQstatus(conn_) != CONNECTION_OK) throw Outage{why};
    while (!why.empty() && why.back() == '\n') why.pop_back();
    PQclear(PQexec(conn_, "ROLLBACK"));
    throw StoreError(name_ + ": " + why);
  }
  void command(const std::string& sql, const std::vector<std::string>& params = {}) {
    Result(run(sql, params, PGRES_COMMAND_OK));
  }

  int readVersion() {
    Result res(run("SELECT version FROM schema_version", {}, PGRES_TUPLES_OK));
    if (PQntuples(res.r) != 1) throw StoreError(name_ + ": schema_version must hold one row");
    const Value v = columnValue(res.r, 0, 0, Kind::Integer);
    if (v.kind != Kind::Integer || v.integer < 1) throw StoreError(name_ + ": schema_version holds no valid version");
    return static_cast<int>(v.integer);
  }

  void openSchema() {
    command("BEGIN");
    Result(run("SELECT pg_advisory_xact_lock(7234103849)", {}, PGRES_TUPLES_OK));  // one migrator at a time
    Result t(run("SELECT to_regclass('schema_version') IS NOT NULL, to_regclass('trips') IS NOT NULL", {},
                 PGRES_TUPLES_OK));
    const bool has_version = PQgetvalue(t.r, 0, 0)[0] == 't', has_trips = PQgetvalue(t.r, 0, 1)[0] == 't';
    if (!has_version && has_trips) {
      command("ROLLBACK");
      throw StoreError(name_ + ": not a hoist-twin history database (a trips table, but no schema_version)");
    }
    const int v = has_version ? readVersion() : 0;
    if (v > kSchemaVersion) {
      command("ROLLBACK");
      throw StoreError(name_ + ": schema version " + std::to_string(v) + " is newer than this program's (" +
                       std::to_string(kSchemaVersion) + "): use a newer hoist-twin");
    }
    for (int to = v + 1; to <= kSchemaVersion; ++to)
      for (const auto& sql : schemaSteps(to)) command(sql);
    command("COMMIT");
  }

  PutResult writeOne(const TripRecord& r) {
    command("BEGIN");
    std::vector<std::string> p = {r.shaft, std::to_string(r.trip)};
    for (const auto& f : tripFields()) p.push_back(paramText(f.get(r)));
    Result ins(run(insertTripSql(true), p, PGRES_COMMAND_OK));
    if (std::string(PQcmdTuples(ins.r)) == "0") {
      command("ROLLBACK");
      ++stats_.duplicates;
      return PutResult::Duplicate;
    }
    const std::string bin_sql = insertBinSql(true);
    for (std::size_t k = 0; k < r.bins.size(); ++k) {
      std::vector<std::string> b = {r.shaft, std::to_string(r.trip), std::to_string(k)};
      for (const auto& f : binFields()) b.push_back(paramText(f.get(r.bins[k])));
      command(bin_sql, b);
    }
    command("COMMIT");
    ++stats_.stored;
    known_max_[r.shaft] = std::max(known_max_[r.shaft], r.trip);
    return PutResult::Stored;
  }

  /// Writes the queue in order; returns how many remain.
  std::int64_t flushQueue() {
    auto entries = queue_.pending();
    if (entries.empty()) return 0;
    if (!connect(false)) return static_cast<std::int64_t>(entries.size());
    std::int64_t left = static_cast<std::int64_t>(entries.size());
    for (const auto& e : entries) {
      TripRecord r;
      std::string why;
      if (!queue_.read(e, r, why)) {
        stats_.last_error = why;
        --left;
        continue;
      }
      try {
        writeOne(r);
      } catch (const Outage& o) {
        lost(o.why);
        return left;
      }
      queue_.remove(e);
      ++stats_.flushed;
      --left;
    }
    return left;
  }

  void readBins(TripRecord& r) {
    const std::string what = name_ + ": " + detail::tripName(r.shaft, r.trip);
    Result res(run("SELECT " + binColumnList() + " FROM bins WHERE shaft = $1 AND trip = $2 ORDER BY idx",
                   {r.shaft, std::to_string(r.trip)}, PGRES_TUPLES_OK));
    const int n = PQntuples(res.r);
    if (static_cast<std::size_t>(n) > kMaxBins) throw StoreError(what + ": more than " + std::to_string(kMaxBins) + " bins");
    r.bins.clear();
    for (int row = 0; row < n; ++row)
      r.bins.push_back(detail::readBinRow([&](int i, Kind k) { return columnValue(res.r, row, i, k); }, what));
  }

  std::string url_, password_;
  mutable RecordQueue queue_;
  double retry_;
  std::string name_;
  PGconn* conn_ = nullptr;
  bool tried_ = false;
  std::chrono::steady_clock::time_point last_try_{};
  std::map<std::string, std::int64_t> known_max_;  ///< the largest trip number seen per shaft (server or queue)
  std::set<std::string> scanned_;                   ///< shafts whose queued records were read for known_max_
  StoreStats stats_;
};

}  // namespace

std::unique_ptr<Store> openPgStore(const StoreOptions& o) { return std::make_unique<PgStore>(o); }

}  // namespace hoist::history
