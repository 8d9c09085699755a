// history_writer -- the kill -9 test's victim: writes sample trip records
// (sample_record.hpp, 200 bins each) to an SQLite history database in a
// loop, numbered on from the database's next trip, and prints
// "committed N" after each put() returned.
//   history_writer DB COUNT
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "hoist/history/sqlite_store.hpp"
#include "sample_record.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: history_writer DB COUNT\n");
    return 2;
  }
  try {
    auto s = hoist::history::openSqliteStore(argv[1]);
    const long n = std::atol(argv[2]);
    for (long i = 0; i < n; ++i) {
      auto r = hoist::test::sampleRecord(s->nextTrip(""), "", 200);
      s->put(r);
      std::printf("committed %lld\n", static_cast<long long>(r.trip));
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "history_writer: %s\n", e.what());
    return 1;
  }
  return 0;
}
