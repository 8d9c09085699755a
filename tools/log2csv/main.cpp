// hoist-log2csv -- an LCM log file (as written by lcm-logger) to CSV, one file
// per channel: DIR/<CHANNEL>.csv.
//
//   hoist-log2csv LOGFILE --out-dir DIR [--lenient]
//
// The log is read with hoist::io::LcmLogReader (not liblcm's reader): every
// event header is validated against the file before anything is allocated,
// and a corrupted event is skipped by resynchronising on the next sync word.
// Every payload is validated by hoist::msg::checkedDecode before decoding.
//
// Messages are recognized by their LCM type fingerprint (the first 8 bytes),
// not by channel name, so prefixed or renamed channels decode too.  Events of
// unknown types, and events that fail to decode, are counted and skipped; a
// note on stderr lists them.  A channel whose messages change type midway is
// written to DIR/<CHANNEL>.<type>.csv for the later type.
//
// Columns: those that hoist_msgs_codec generates from msgs/*.lcm
// (hoist::msg::csvHeader / csvRow; docs/codec.md): one per member in the
// .lcm file's order, a fixed array NAME_0.., no columns for variable-length
// arrays; doubles with 17 significant digits (round-trip exact), strings
// quoted, alarm levels and events by name.  Per type:
//   hoist.cage_state_t  t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4 first (exactly
//                       as hoist-sim's output; `@csvfirst` in cage_state_t.lcm),
//                       then the other members in order
//   hoist.winder_t      the members, then log_utime (the log event's timestamp)
//   hoist.guide_shape_t t,x,y1,y2,l,utime (one row per depth sample, like
//                       hoist-sim --shape-out)
//   hoist.alarm_t       the members (event_type in a column "event")
//   hoist.alarm_ack_t, hoist.trip_plan_t  the members
//   hoist.estimate_t    the members (lambdas_0..4, sigma_lambdas_0..4; the
//                       booleans 0/1; a sigma < 0 means "not observed")
//   hoist.cage_imu_t, hoist.rope_load_t  the members
//   hoist.health_t      the members, then rejected_<reason> per reason
//   hoist.forecast_t    one row per scenario: the forecast's columns with
//                       num_scenarios replaced by the scenario's index
//                       "scenario", then the scenario's (name,status,...,
//                       peak_lambda_1..peak_lambda_4,lambda0_min,lambda0_max,
//                       num_points; times in s after t_start, -1 = none
//                       within the horizon).  The decimated series go to
//                       DIR/<CHANNEL>.series.csv, one row per point:
//                       utime,seq,scenario,name,i,t,min_clearance,
//                       lambda0_min,lambda0_max.
// Exit status: 0 on success; 1 if the log cannot be read, a file cannot be
// written to its last byte (the path and the errno text are printed), or --
// unless --lenient -- the log had corrupt regions (bytes skipped, events
// lost) or events that carry a hoist fingerprint but fail the checked decode;
// 2 for a bad command line.
//
// This file parses and runs; the conversion is converter.* (Converter: the
// files, the columns, the summary; Writer: one checked output file).
#include "hoist/cli/app.hpp"

#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>
#include <utility>

#include <CLI/CLI.hpp>

#include "converter.hpp"
#include "hoist/io/lcm_log.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-log2csv: convert an LCM log (lcm-logger) of the hoist channels to CSV,\n"
      "one file per channel (DIR/<CHANNEL>.csv).  Types are recognized by fingerprint;\n"
      "for HOIST_CAGE the first columns are t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4\n"
      "(as hoist-sim writes them).  Corrupted events are skipped (resynchronising on\n"
      "the next event) and reported; the exit status is then 1 unless --lenient.\n"
      "Exit status: 0 ok, 1 unreadable log / unwritable file / data lost, 2 bad usage."};
  hoist::cli::nameProgram(app, "hoist-log2csv");
  std::string log_path, out_dir;
  bool lenient = false;
  // Required, but checked after parsing: CLI11 reports a missing LOGFILE
  // before an unknown option, and "--bogus-opt" must be named.
  app.add_option("LOGFILE", log_path, "LCM log file (required)")->check(CLI::ExistingFile);
  app.add_option("--out-dir", out_dir, "output directory (created if missing; required)");
  app.add_flag("--lenient", lenient,
               "exit 0 even when corrupt events were skipped or events failed to decode");
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  for (const auto& [given, what] : {std::pair{!log_path.empty(), "LOGFILE"}, std::pair{!out_dir.empty(), "--out-dir"}})
    if (!given) {
      std::cerr << "hoist-log2csv: " << what << " is required\nRun with --help for more information.\n";
      return 2;
    }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    std::cerr << "hoist-log2csv: cannot create " << out_dir << ": " << ec.message() << "\n";
    return 1;
  }
  hoist::io::LcmLogReader log(log_path);
  if (!log.ok()) {
    std::cerr << "hoist-log2csv: " << log.error() << "\n";
    return 1;
  }
  hoist::log2csv::Converter conv(out_dir);
  hoist::io::LcmLogEvent ev;
  while (log.next(ev)) conv.handle(ev);
  const bool files_ok = conv.finish(std::cerr);
  if (!log.ok()) {
    std::cerr << "hoist-log2csv: error: " << log.error() << "\n";
    return 1;
  }
  std::cerr << "hoist-log2csv: " << log_path << ": " << log.summary() << "\n";
  if (!files_ok) return 1;
  const bool lost = log.stats().lost() || conv.badCount() > 0;
  if (lost) {
    std::cerr << "hoist-log2csv: " << (lenient ? "warning" : "error") << ": data lost ("
              << log.stats().bytes_skipped << " bytes skipped, about " << log.stats().events_lost
              << " event(s) lost, " << conv.badCount() << " undecodable)"
              << (lenient ? " -- ignored (--lenient)" : "; use --lenient to accept") << "\n";
    if (!lenient) return 1;
  }
  return 0;
}
