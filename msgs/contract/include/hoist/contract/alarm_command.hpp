// hoist/contract/alarm_command.hpp -- validation of an operator's alarm command
// (the fields of alarm_ack_t), shared by hoist-twind (commands from LCM) and
// hoist-mqtt (commands from an MQTT broker), so both accept exactly the same
// commands.  Pure: no I/O, no LCM types, no allocation.
#pragma once

#include <string>
#include <optional>
#include <string_view>

#include "hoist/contract/alarm_vocabulary.hpp"

namespace hoist::contract {

/// Operator command; values match alarm_ack_t.ACTION_*.  Reannounce changes
/// no state: it asks the daemon to announce the current state of every
/// alarm that has one (a client that just started learns of alarms raised
/// before it); the daemon honours at most one a second per shaft.
/// Calibrate declares the load known for a while (the load estimator's live
/// calibration, alarm_ack_t.ACTION_CALIBRATE).  AdoptPreload makes the live
/// twin run the guide-rope preloads scaled by preload_scale
/// (alarm_ack_t.ACTION_ADOPT_PRELOAD).
enum class AlarmAction { Ack = 1, Shelve = 2, Unshelve = 3, Reannounce = 4, Calibrate = 5, AdoptPreload = 6 };

/// Why a command was refused.
enum class CommandError { None, UnknownKind, BadLevel, BadAction, BadShelveDuration, BadCalibration, BadPreload };
inline constexpr int kCommandErrors = 7;

/// The preload scales an operator may adopt: the range the shaft's memory
/// identifies s over (hoist/preload_identification.hpp's grid).
inline constexpr double kMinPreloadScale = 0.3;
inline constexpr double kMaxPreloadScale = 1.6;
/// The rule above in words.
inline constexpr const char* kPreloadRule = "adopt_preload needs preload_scale in [0.3, 1.6] (1 = the config's)";

/// The longest calibration an operator may declare [s].
inline constexpr double kMaxCalibration = 600.0;
/// The largest known load force / |offset| a calibration may declare (a
/// bound on the number, not the conveyance's rating: the daemon checks
/// that against [load]) [N], [m].
inline constexpr double kMaxCalibrationForce = 1.0e7;
inline constexpr double kMaxCalibrationOffset = 100.0;
/// The rule above in words, for the clients' and the daemon's refusals.
inline constexpr const char* kCalibrationRule =
    "calibrate needs known_fa in [0, 1e7] N, |known_b| <= 100 m and calibrate_duration in (0, 600] s";

const char* toString(AlarmAction a);   ///< "ACK", "SHELVE", "UNSHELVE", "REANNOUNCE", "CALIBRATE", "ADOPT_PRELOAD"
/// "ok", "unknown_kind", "bad_level", "bad_action", "bad_shelve_duration",
/// "bad_calibration", "bad_preload"
const char* toString(CommandError e);

/// A validated command.  kind empty = every kind; level None = both levels.
struct AlarmCommand {
  AlarmAction action = AlarmAction::Ack;
  std::optional<AlarmKind> kind;
  AlarmLevel level = AlarmLevel::None;
  double shelve_duration = 0.0;  ///< [s], > 0 and finite for Shelve
  double known_fa = 0.0;          ///< Calibrate: the known eccentric force [N]
  double known_b = 0.0;           ///< Calibrate: its offset [m]
  double calibrate_duration = 0.0;  ///< Calibrate: for how long [s]
  double preload_scale = 1.0;     ///< AdoptPreload: the scale of the guide-rope preloads
};

/// Validates the fields of an alarm_ack_t: `kind` an alarm kind name
/// (parseAlarmKind), "" or "*" (all kinds); `level` 0 (both), 1 (WARNING) or
/// 2 (CRITICAL); `action` alarm_ack_t.ACTION_ACK/SHELVE/UNSHELVE/REANNOUNCE; for SHELVE a
/// finite `shelve_duration` > 0 (the daemon bounds it by [alarms].max_shelve).
/// Fills `out` and returns CommandError::None when valid.
CommandError validateAlarmCommand(std::string_view kind, int level, int action, double shelve_duration,
                                  AlarmCommand& out);
/// The same with the calibration fields (alarm_ack_t.known_fa, known_b,
/// calibrate_duration): for Calibrate, known_fa finite in [0,
/// kMaxCalibrationForce], |known_b| <= kMaxCalibrationOffset, duration in
/// (0, kMaxCalibration]; else BadCalibration.  For AdoptPreload,
/// preload_scale (alarm_ack_t.preload_scale) finite in [kMinPreloadScale,
/// kMaxPreloadScale]; else BadPreload.  The shorter forms refuse Calibrate
/// and AdoptPreload (a client without the fields cannot send them).
CommandError validateAlarmCommand(std::string_view kind, int level, int action, double shelve_duration,
                                  double known_fa, double known_b, double calibrate_duration, double preload_scale,
                                  AlarmCommand& out);
CommandError validateAlarmCommand(std::string_view kind, int level, int action, double shelve_duration,
                                  double known_fa, double known_b, double calibrate_duration, AlarmCommand& out);

/// The operator-name rule, one for every front end: at most this many
/// bytes (the daemon cuts a longer name from LCM to it, printable()).
inline constexpr std::size_t kMaxOperatorName = 64;
/// Why `user` is not an operator name a front end may send (hoist-mqtt,
/// hoist-dash), or nullptr: 1..kMaxOperatorName bytes, no control character
/// (C0, DEL, and the C1 controls U+0080..U+009F in UTF-8).
const char* operatorNameProblem(std::string_view user);

/// At most `max` characters of `s`, every byte outside printable ASCII
/// replaced by '?', "..." appended when cut (for network strings in logs).
std::string printable(const std::string& s, std::size_t max = 64);

}  // namespace hoist::contract
