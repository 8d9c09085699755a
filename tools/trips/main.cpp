// hoist-trips -- the shaft's memory on the command line (issue 32,
// docs/condition.md): the trip records in the history database (SQLite or
// PostgreSQL, hoist/history/store.hpp), listed, shown, plotted, exported,
// the baseline marked, and recorded runs ingested through the same trip
// pipeline as the daemon's (hoist/trip_pipeline.hpp).
//
//   hoist-trips list      --db URL [--format table|csv|json] [--out FILE]
//   hoist-trips show N    --db URL [--format text|json]
//   hoist-trips trend     --db URL --out FILE.png [--config FILE]
//   hoist-trips depth-map --db URL --out FILE.png [--value resid_rms|...]
//   hoist-trips baseline  --db URL [--mark N...] [--unmark N...]
//   hoist-trips export    --db URL [--format csv|json] --out FILE [--bins FILE]
//   hoist-trips ingest    --config FILE --measurements FILE.csv --db URL
//
// Exit status: 0 done, 2 bad input (an option, naming it; a bad file,
// naming file, line and key), 1 the database or a write failed.
#include "hoist/cli/app.hpp"

#include <ctime>
#include <filesystem>
#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "hoist/history/config.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/error.hpp"
#include "trips.hpp"

namespace hoist::trips {

std::unique_ptr<history::Store> openDb(const Options& o, bool read_only) {
  history::HistoryConfig cfg;
  std::string dir;  // the configuration's folder: its relative paths are relative to it
  if (!o.config.empty()) {
    cfg = history::historyConfigFromToml(io::loadTomlFile(o.config), o.config);
    dir = std::filesystem::path(o.config).parent_path().string();
    if (dir.empty()) dir = ".";
  }
  if (o.db.empty() && (o.config.empty() || cfg.url.empty()))
    throw UsageError("--db is required (or --config with a [history] url)");
  history::StoreOptions so;
  try {
    if (!o.db.empty()) {
      // --db replaces the config's url; a relative path is relative to the working directory.
      const auto u = history::parseDatabaseUrl(o.db, "--db");
      cfg.url = u.backend == history::Backend::Sqlite ? std::filesystem::absolute(u.target).string() : o.db;
      if (u.backend != history::Backend::Postgres) cfg.password_file.clear();
    }
    so = history::resolveStoreOptions(cfg, dir, o.db.empty() ? o.config + ": history.url" : "--db");
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  so.read_only = read_only;
  return history::openStore(so);
}

}  // namespace hoist::trips

namespace {

using hoist::trips::Options;

void dbOptions(CLI::App* c, Options& o) {
  c->add_option("--db", o.db,
                "the history database: sqlite:///abs/path, a path (SQLite) or postgresql://user@host/db "
                "(the password through $CREDENTIALS_DIRECTORY/history-password or [history] password_file, never here)");
  c->add_option("--config", o.config, "hoist-twind's configuration: [history] (url, password_file), [condition]")
      ->check(CLI::ExistingFile);
  c->add_option("--shaft", o.shaft, "the shaft's name (default: the default shaft, \"\")");
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "hoist-trips: the shaft's memory -- every trip's record (loads, model check, clearance, depth bins, the\n"
      "identified guide-rope preload) in the history database, listed, plotted, exported; recorded runs\n"
      "ingested through the daemon's trip pipeline (docs/condition.md).",
      "hoist-trips"};
  hoist::cli::nameProgram(app, "hoist-trips");  // usage, errors and --version name the program
  app.require_subcommand(0, 1);  // none is checked after parsing, so that an unknown option is named first
  app.footer(
      "Examples:\n"
      "  hoist-trips ingest --config shaft.toml --measurements run.csv --db sqlite:///tmp/h.sqlite\n"
      "  hoist-trips list --db /var/lib/hoist-twin/history.sqlite --format csv --out trips.csv\n"
      "  hoist-trips show 42 --db /var/lib/hoist-twin/history.sqlite\n"
      "  hoist-trips trend --config /etc/hoist-twin/hoist-twind.toml --out preload.png\n"
      "  hoist-trips depth-map --db h.sqlite --out depth.png --value resid_mean\n"
      "  hoist-trips baseline --db h.sqlite --mark 1 2 3\n"
      "  hoist-trips export --db postgresql://hoist@db.plant/twin --format json --out all.json\n"
      "Exit status: 0 done, 2 bad input (naming the option or file), 1 the database or a write failed.");

  auto* list = app.add_subcommand("list", "one row per trip (table, or CSV/JSON for analysis)");
  dbOptions(list, o);
  list->add_option("--format", o.format, "table (default), csv or json")->check(CLI::IsMember({"table", "csv", "json"}));
  list->add_option("--out", o.out, "write to FILE instead of stdout");
  list->add_flag("--all-shafts", o.all_shafts, "every shaft's trips, not only --shaft's");

  auto* show = app.add_subcommand("show", "one trip's record with its depth-bin table");
  show->add_option("trip", o.trip, "the trip number")->required()->check(CLI::PositiveNumber);
  dbOptions(show, o);
  show->add_option("--format", o.format, "text (default) or json")->check(CLI::IsMember({"text", "json"}));
  show->add_option("--out", o.out, "write to FILE instead of stdout");

  auto* trend = app.add_subcommand("trend", "PNG: the identified preload scale over the trips, its band and the thresholds");
  dbOptions(trend, o);
  trend->add_option("--out", o.out, "the PNG to write (FILE.dat and FILE.gp go beside it)")->required();
  trend->add_option("--warning", o.warning, "the warning threshold drawn (default: [condition] preload_warning, 0.85)")
      ->check(CLI::Range(0.0, 2.0));
  trend->add_option("--critical", o.critical, "the critical threshold drawn (default: [condition] preload_critical, 0.70)")
      ->check(CLI::Range(0.0, 2.0));
  trend->add_flag("-q,--quiet", o.quiet, "no summary line");

  auto* depth = app.add_subcommand("depth-map", "PNG: depth x trip heat map of the residual (or the measured f_y)");
  dbOptions(depth, o);
  depth->add_option("--out", o.out, "the PNG to write (FILE.dat and FILE.gp go beside it)")->required();
  depth->add_option("--value", o.value, "resid_rms (default), resid_mean, fy_rms or fy_hf_rms")
      ->check(CLI::IsMember({"resid_rms", "resid_mean", "fy_rms", "fy_hf_rms"}));
  depth->add_flag("-q,--quiet", o.quiet, "no summary line");

  auto* base = app.add_subcommand("baseline", "list, mark or unmark the trips of the commissioning fingerprint");
  dbOptions(base, o);
  base->add_option("--mark", o.mark, "mark these trips as baseline")->check(CLI::PositiveNumber);
  base->add_option("--unmark", o.unmark, "unmark these trips")->check(CLI::PositiveNumber);

  auto* exp = app.add_subcommand("export", "everything: every stored column (CSV) or whole records (JSON)");
  dbOptions(exp, o);
  exp->add_option("--format", o.format, "csv (default) or json")->check(CLI::IsMember({"csv", "json"}));
  exp->add_option("--out", o.out, "write to FILE instead of stdout");
  exp->add_option("--bins", o.bins_out, "also write the depth bins as CSV to FILE");
  exp->add_flag("--all-shafts", o.all_shafts, "every shaft's trips, not only --shaft's");
  exp->add_flag("-q,--quiet", o.quiet, "no summary line");

  auto* ingest = app.add_subcommand("ingest", "run the trip pipeline on a recorded measurement CSV and store the trips");
  dbOptions(ingest, o);
  ingest->add_option("--measurements", o.measurements, "measurement CSV (hoist-estimate's columns t,l,v,a,f_y,...)")
      ->required()->check(CLI::ExistingFile);
  ingest->add_option("--modes", o.modes, "assumed modes per rope n (overrides model.modes)")->check(CLI::Range(1, 60));
  ingest->add_option("--max-step", o.max_step, "largest integration step [s] (default: [service] max_step, else 0.0025)")
      ->check(CLI::Range(0.0, 10.0));
  ingest->add_option("--first-trip", o.first_trip,
                     "number the trips from N (default: the shaft's next); the same N again stores nothing twice")
      ->check(CLI::PositiveNumber);
  ingest->add_option_function<std::string>(
      "--wall-start",
      [&o](const std::string& v) {
        std::tm tm{};
        const char* end = strptime(v.c_str(), "%Y-%m-%dT%H:%M:%S", &tm);
        if (!end || !(*end == 0 || (*end == 'Z' && end[1] == 0)))
          throw CLI::ValidationError("--wall-start", "'" + v + "' is not an ISO 8601 UTC time such as 2026-12-06T08:00:00Z");
        o.wall_start_us = static_cast<std::int64_t>(timegm(&tm)) * 1000000LL;
      },
      "wall-clock time of the row t = 0 (ISO 8601 UTC; default: now)");
  ingest->add_flag("-q,--quiet", o.quiet, "no summary");

  if (argc > 1 && argv[1][0] != '-') {  // CLI11 would only say "A subcommand is required"
    bool found = false;
    std::string known;
    for (const auto* sc : app.get_subcommands({})) {
      found = found || sc->get_name() == argv[1];
      known += (known.empty() ? "" : ", ") + sc->get_name();
    }
    if (!found) {
      std::cerr << "hoist-trips: unknown subcommand '" << argv[1] << "' (" << known << ")\nRun with --help for more information.\n";
      return 2;
    }
  }
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  if (app.get_subcommands().empty()) {
    std::cerr << "hoist-trips: a subcommand is required (list, show, trend, depth-map, baseline, export, ingest)\n"
                 "Run with --help for more information.\n";
    return 2;
  }
  if (exp->parsed() && o.format == "table") o.format = "csv";
  if (show->parsed() && o.format == "table") o.format = "text";
  try {
    if (ingest->parsed() && o.config.empty()) throw hoist::trips::UsageError("ingest: --config is required (the shaft and [condition])");
    // Output paths checked before any work (a bad one is bad input: exit 2).
    for (const auto& [path, label] : {std::pair{o.out, "--out"}, std::pair{o.bins_out, "--bins"}})
      if (!path.empty() && path != "-")
        if (auto why = hoist::io::outputPathError(path, label); !why.empty()) throw hoist::trips::UsageError(why);
    if (list->parsed()) return hoist::trips::runList(o);
    if (show->parsed()) return hoist::trips::runShow(o);
    if (trend->parsed()) return hoist::trips::runTrend(o);
    if (depth->parsed()) return hoist::trips::runDepthMap(o);
    if (base->parsed()) return hoist::trips::runBaseline(o);
    if (exp->parsed()) return hoist::trips::runExport(o);
    if (ingest->parsed()) return hoist::trips::runIngest(o);
  } catch (const hoist::trips::UsageError& e) {
    std::cerr << "hoist-trips: error: " << e.what() << "\nRun with --help for more information.\n";
    return 2;
  } catch (const hoist::io::InputError& e) {
    std::cerr << "hoist-trips: error: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "hoist-trips: error: out of memory (std::bad_alloc)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hoist-trips: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
