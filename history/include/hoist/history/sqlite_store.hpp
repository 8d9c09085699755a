// hoist/history/sqlite_store.hpp -- the embedded back end of Store
// (store.hpp): one SQLite file, WAL, synchronous=FULL (sqlite_store.cpp
// says why).  Use openStore(); this is its SQLite half (and the tests').
#pragma once

#include <memory>
#include <string>

#include "hoist/history/store.hpp"

namespace hoist::history {

std::unique_ptr<Store> openSqliteStore(const std::string& path, bool read_only = false);

}  // namespace hoist::history
