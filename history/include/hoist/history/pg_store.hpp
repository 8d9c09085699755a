// hoist/history/pg_store.hpp -- the PostgreSQL back end of Store (store.hpp)
// through libpq, with the on-disk outage queue (queue.hpp).  Use
// openStore(); this is its PostgreSQL half (and the tests').
#pragma once

#include <memory>

#include "hoist/history/store.hpp"

namespace hoist::history {

std::unique_ptr<Store> openPgStore(const StoreOptions& o);

}  // namespace hoist::history
