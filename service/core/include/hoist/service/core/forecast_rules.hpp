// hoist/service/core/forecast_rules.hpp -- the daemon's rules around the model's
// look-ahead engine (docs/lookahead.md), pure (no I/O, no
// allocation): which trip plans are accepted, what a forecast predicts
// (PREDICTED_CLEARANCE / PREDICTED_SLACK), and the slack threshold.
#pragma once

#include <cstdint>

#include "hoist/forecast.hpp"
#include "hoist/params.hpp"
#include "hoist/shaft_model.hpp"
#include "hoist/service/core/config.hpp"

namespace hoist::service::inline core {

/// Reasons a HOIST_TRIP_PLAN message is rejected: undecodable, an old
/// sequence number, then every hoist::PlanError (after None), in order, then
/// limits beyond the winder's.
enum class PlanReject : int {
  Decode = 0,
  OldSeq,
  NotFinite,
  NonPositiveLimit,
  TargetOutsideShaft,
  SpeedAboveVmax,
  AccelAboveAmax,
  WrongDirection,
  OvershootsVmax,
  OvershootsStop,
  Unreachable,
  AboveLimits,  ///< vmax, amax or jerk above the winder's ([forecast] vmax, amax, jerk)
};
inline constexpr int kPlanRejectReasons = 12;
/// "plan_decode", "plan_old_seq", "plan_not_finite", ... (HOIST_HEALTH reason names).
const char* toString(PlanReject r);
PlanReject planReject(PlanError e);

/// Checks a plan against the shaft and the current motion (t, k): planProfile
/// into `scratch` (allocation-free).  ok() when the plan can be followed.
PlanCheck checkPlan(const TripPlan& plan, double t, const Kinematics& k, const ShaftParams& shaft,
                    MotionProfile& scratch);

/// The slack threshold of PREDICTED_SLACK [N]: the live ROPE_SLACK alarm's,
/// [alarms] slack_fraction x ShaftModel::staticRopeForce(l) at the rope
/// length l the forecast starts from (so the forecast warns of exactly what
/// ROPE_SLACK would raise).
double slackThreshold(const TwinConfig& cfg, const ShaftModel& model, double l);

/// What one forecast predicts.  Times are seconds after the forecast's start.
struct ForecastVerdict {
  bool clearance = false;        ///< a scenario crosses CRITICAL clearance within the horizon
  double clearance_s = -1.0;     ///< the earliest such crossing
  int clearance_scenario = -1;   ///< which scenario (index)
  bool slack = false;            ///< a scenario's lambda_0 falls below the slack threshold
  double slack_s = -1.0;         ///< the end of the first series bucket where it does (<= 1 bucket late)
  int slack_scenario = -1;
};

/// Judges `n` scenario summaries.  A scenario whose model went non-finite
/// predicts nothing (its figures are not a prediction of the shaft).
ForecastVerdict judgeForecast(const ForecastSummary* const* scenarios, int n, double slack_threshold);

}  // namespace hoist::service::core
