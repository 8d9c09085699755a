// openStore (hoist/history/store.hpp): the back end the URL names.
#include "hoist/history/store.hpp"

#include "hoist/history/pg_store.hpp"
#include "hoist/history/sqlite_store.hpp"

namespace hoist::history {

const char* toString(PutResult r) {
  switch (r) {
    case PutResult::Stored: return "stored";
    case PutResult::Duplicate: return "duplicate";
    case PutResult::Queued: return "queued";
  }
  return "?";
}

std::unique_ptr<Store> openStore(const StoreOptions& o) {
  if (o.db.backend == Backend::Postgres) return openPgStore(o);
  return openSqliteStore(o.db.target, o.read_only);
}

}  // namespace hoist::history
