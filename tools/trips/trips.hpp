// trips.hpp -- hoist-trips' shared pieces: the options of every subcommand,
// the database they name, and the subcommands (one file each):
//   report.cpp  list, show, export, baseline (text, CSV, JSON)
//   plots.cpp   trend and depth-map (gnuplot PNGs)
//   ingest.cpp  the trip pipeline on a measurement CSV, stored
// Errors: UsageError (exit 2: a bad option value, naming it), io::InputError
// (exit 2: a bad file), history::StoreError / io::WriteError / anything
// else (exit 1).
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "hoist/history/store.hpp"

namespace hoist::trips {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Options {
  std::string db;        ///< --db URL
  std::string config;    ///< --config FILE ([history], [condition], the shaft)
  std::string shaft;     ///< --shaft NAME ("" = the default shaft)
  bool all_shafts = false;
  std::string format = "table";
  std::string out;       ///< --out FILE ("" / "-": stdout where allowed)
  std::string bins_out;  ///< export --bins FILE
  std::int64_t trip = 0; ///< show N
  std::vector<std::int64_t> mark, unmark;
  std::string value = "resid_rms";  ///< depth-map --value
  double warning = -1.0, critical = -1.0;  ///< trend thresholds (< 0: [condition] or defaults)
  std::string measurements;  ///< ingest
  int modes = 0;
  double max_step = -1.0;
  std::int64_t first_trip = 0;     ///< ingest --first-trip (0: the shaft's next)
  std::int64_t wall_start_us = 0;  ///< ingest --wall-start (0: now)
  bool quiet = false;
};

/// Opens the database --db names (else --config's [history] url); read_only
/// for the commands that only read (SQLite: never created or migrated).
std::unique_ptr<history::Store> openDb(const Options& o, bool read_only);

int runList(const Options& o);
int runShow(const Options& o);
int runExport(const Options& o);
int runBaseline(const Options& o);
int runTrend(const Options& o);
int runDepthMap(const Options& o);
int runIngest(const Options& o);

/// The records the options select (one shaft, or every shaft with --all-shafts).
std::vector<TripRecord> selected(history::Store& s, const Options& o, bool with_bins);

/// ISO 8601 UTC with milliseconds ("2026-12-06T16:17:13.250Z").
std::string isoTime(std::int64_t us);
/// "%.*g" of a number; "" for a sigma < 0 (not observed).
std::string num(double v, int digits = 10);
std::string sigma(double s, int digits = 6);

}  // namespace hoist::trips
