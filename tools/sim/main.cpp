// hoist-sim -- run the cable-guided hoist model of Wang et al. (2016) over a
// whole hoist profile as fast as possible and write the cage response.
//
//   hoist-sim [--config FILE] --profile FILE|SPEC --out FILE.csv [--dt 0.01]
//             [--modes N] [--initial static|rest|config] [--method fast|paper]
//             [--static-correction on|off]
//             [--shape-out FILE.csv --shape-times 18,36,60]
//             [--write-measurements FILE.csv [--sensor-noise A,W,F] [--seed N]]
//   hoist-sim study ...        (runs hoist-study: the paper's parameter studies)
//
// Phases, each timed in the summary: load (config, profile), setup (mode
// integrals, solver), solve (time stepping), output (formatting and writing
// the rows, which are streamed to the file as they are computed: memory
// stays flat whatever --t-end).  Before a large run (over 1e7 rows, 1 GB or
// an estimated 30 s) one line states the estimated rows, size and time; a
// run whose output cannot fit the free space of --out's file system is
// refused.  Every file is written to its last byte or the run fails naming
// it (hoist/io/checked_file.hpp).
// --write-measurements: what a cage IMU and a rope load cell would read on
// this run (hoist::sensorModel on the solver's response, plus seeded
// Gaussian noise), in the measurement CSV of hoist-estimate
// (t,l,v,a,f_y,omega,rope_load; hoist/io/estimator_config.hpp).  The run's
// load is the config's: a "truth" config with another [load] makes data for
// hoist-estimate run with the real config.  Its t is rounded to the whole
// microsecond (a sensor clock's utime), so that hoist-replay --measurements
// gives hoist-twind the very times hoist-estimate reads.
// Exit status: 0 done, 2 bad input (config, profile, options), 1 the run
// failed (non-finite or implausible state -- the message names the time, the
// quantity and its value --, write error, out of memory).
//
// Parse -> check -> run: this file parses (the options: sim_options.*) and
// maps failures to the exit status; sim_run.* checks the options against the
// configuration and profile and runs.
#include "hoist/cli/app.hpp"
#include "hoist/version.hpp"
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/error.hpp"
#include "hoist/io/sim_run.hpp"
#include "sim_options.hpp"
#include "sim_run.hpp"

namespace {

/// The command line, for the messages of unexpected failures (out of memory).
std::string g_command_line;

/// Runs `hoist-study` (next to this executable) with the remaining arguments.
int runStudy(int argc, char** argv) {
  std::string self(4096, '\0');
  const ssize_t n = ::readlink("/proc/self/exe", self.data(), self.size() - 1);
  std::string dir = n > 0 ? self.substr(0, static_cast<std::size_t>(n)) : std::string(argv[0]);
  dir = dir.substr(0, dir.find_last_of('/') + 1);
  const std::string study = dir + "hoist-study";
  std::vector<char*> args;
  args.push_back(const_cast<char*>(study.c_str()));
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  ::execv(study.c_str(), args.data());
  std::cerr << "hoist-sim: cannot run " << study << ": " << std::strerror(errno) << "\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "study") return runStudy(argc, argv);
  hoist::sim::Options o;
  CLI::App app{
      "hoist-sim: lateral, torsional and longitudinal vibration of a cable-guided hoist\n"
      "(Wang, Cao, Zhu, Peng & Li 2016) over a whole hoist profile, as fast as possible.\n"
      "Writes t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4 per output step.\n"
      "Also: 'hoist-sim study NAME ...' runs the paper's parameter studies (hoist-study --help).",
      "hoist-sim"};
  hoist::cli::nameProgram(app, "hoist-sim");
  addOptions(app, o);
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  for (int i = 0; i < argc; ++i) {
    if (i) g_command_line += ' ';
    g_command_line += i == 0 ? std::string("hoist-sim") : std::string(argv[i]);
  }
  try {
    return hoist::sim::run(o);
  } catch (const hoist::io::InputError& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::sim::UsageError& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::io::OptionError& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::io::WriteError& e) {
    // Names the option and the file, with the errno text.
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "hoist-sim: error: out of memory (std::bad_alloc) in: " << g_command_line
              << "\n  (the memory grows with --modes, --shape-points and the profile's length; the output rows are "
                 "streamed and cost none)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n  in: " << g_command_line << "\n";
    return 1;
  } catch (...) {
    std::cerr << "hoist-sim: error: unexpected failure in: " << g_command_line << "\n";
    return 1;
  }
}
