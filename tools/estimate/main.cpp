// hoist-estimate -- the load estimator on recorded data: the eccentric
// load's force Fa, offset b and moment M = Fa b, the cage state they imply
// and the model check (NIS, MODEL_MISMATCH), from a measurement CSV of the
// winder (t,l,v,a) and the sensors (f_y, omega, rope_load; any may be
// absent).  The same code as hoist-twind's live estimator
// (hoist::estimateRecorded, hoist/load_estimator.hpp): with the same
// configuration and `hoist-twind --clock input` both give the same numbers.
//
//   hoist-estimate --config FILE --measurements FILE.csv --out FILE.csv
//                  [--modes N] [--max-step S] [--progress] [-q]
//                  [--known-load T0,T1,FA,B]... [--offset-in FILE] [--offset-out FILE]
//
// The accelerometer's offset (docs/estimation.md): --known-load declares the
// load known over [T0, T1) (the operator's calibration: an empty conveyance,
// a test weight), so the data teach the offset; --offset-in starts from a
// learned one, --offset-out writes the last row's (hoist/io/accel_offset_file.hpp).
//
// --config: a shaft TOML or hoist-twind's configuration ([service],
// [alarms], [forecast], [sensors], [estimator] are accepted; [estimator]
// enabled is not needed here).  The substep length is --max-step, else the
// file's [service] max_step, else hoist::kDefaultMaxStep (0.0025 s, the daemon's default), so that
// the live and offline estimators agree.  The NIS window is sized for the
// file's rate: [estimator] max_rate is raised to the fastest row rate when
// that is higher (the daemon sizes it for its own rate).
// Output: one row per measurement row (kOutputHeader); a value that is not
// observed (sigma < 0 in the estimate, or its sensor not seen yet:
// fa_observed / moment_observed) is written as nan with its sigma.
// A one-paragraph summary goes to stdout (not with -q).
// Exit status: 0 done, 2 bad input (naming file, line, column or option),
// 1 the run failed (model domain, write error).
//
// parse -> check -> run: estimate_options.* the options, estimate_check.*
// reads and checks the input, estimate_run.* estimates and writes (the rows'
// format in estimate_rows.*).
#include "hoist/cli/app.hpp"

#include <chrono>
#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "estimate_check.hpp"
#include "estimate_options.hpp"
#include "estimate_run.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/io/error.hpp"

int main(int argc, char** argv) {
  hoist::estimate::Options o;
  CLI::App app{
      "hoist-estimate: estimate the eccentric load (Fa, b, M = Fa b), the cage state it implies and the\n"
      "model check (NIS, MODEL_MISMATCH) from recorded winder and sensor data -- the same estimator as\n"
      "hoist-twind's [estimator] (docs/estimation.md).\n"
      "Input CSV columns: t,l,v,a and optionally f_y [m/s^2], omega [rad/s], rope_load [N] (an absent\n"
      "column: no such sensor; an empty field: no sample in that row); hoist-sim --write-measurements\n"
      "writes such files.",
      "hoist-estimate"};
  hoist::cli::nameProgram(app, "hoist-estimate");  // usage, errors and --version name the program
  hoist::estimate::addOptions(app, o);
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  if (const auto missing = hoist::estimate::missingRequired(o)) {
    std::cerr << "hoist-estimate: " << *missing << " is required\nRun with --help for more information.\n";
    return 2;
  }
  const auto started = std::chrono::steady_clock::now();
  try {
    const hoist::estimate::Input in = hoist::estimate::check(o);
    return hoist::estimate::run(o, in, started);
  } catch (const hoist::io::InputError& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::estimate::UsageError& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::io::WriteError& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "hoist-estimate: error: out of memory (std::bad_alloc)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 1;
  }
}
