// The daemon's rules around the look-ahead engine: see hoist/service/core/forecast_rules.hpp.
#include "hoist/service/core/forecast_rules.hpp"

#include <cmath>

namespace hoist::service::inline core {

const char* toString(PlanReject r) {
  switch (r) {
    case PlanReject::Decode: return "plan_decode";
    case PlanReject::OldSeq: return "plan_old_seq";
    case PlanReject::NotFinite: return "plan_not_finite";
    case PlanReject::NonPositiveLimit: return "plan_non_positive_limit";
    case PlanReject::TargetOutsideShaft: return "plan_target_outside_shaft";
    case PlanReject::SpeedAboveVmax: return "plan_speed_above_vmax";
    case PlanReject::AccelAboveAmax: return "plan_accel_above_amax";
    case PlanReject::WrongDirection: return "plan_wrong_direction";
    case PlanReject::OvershootsVmax: return "plan_overshoots_vmax";
    case PlanReject::OvershootsStop: return "plan_overshoots_stop";
    case PlanReject::Unreachable: return "plan_unreachable";
    case PlanReject::AboveLimits: return "plan_above_limits";
  }
  return "plan_?";
}

PlanReject planReject(PlanError e) {
  switch (e) {
    case PlanError::None:
    case PlanError::NotFinite: return PlanReject::NotFinite;
    case PlanError::NonPositiveLimit: return PlanReject::NonPositiveLimit;
    case PlanError::TargetOutsideShaft: return PlanReject::TargetOutsideShaft;
    case PlanError::SpeedAboveVmax: return PlanReject::SpeedAboveVmax;
    case PlanError::AccelAboveAmax: return PlanReject::AccelAboveAmax;
    case PlanError::WrongDirection: return PlanReject::WrongDirection;
    case PlanError::OvershootsVmax: return PlanReject::OvershootsVmax;
    case PlanError::OvershootsStop: return PlanReject::OvershootsStop;
    case PlanError::Unreachable: return PlanReject::Unreachable;
  }
  return PlanReject::NotFinite;
}

PlanCheck checkPlan(const TripPlan& plan, double t, const Kinematics& k, const ShaftParams& shaft,
                    MotionProfile& scratch) {
  return planProfile(t, k, plan, shaft.maxRopeLength(), scratch);
}

double slackThreshold(const TwinConfig& cfg, const ShaftModel& model, double l) {
  return cfg.alarms.slack_fraction * model.staticRopeForce(l);
}

ForecastVerdict judgeForecast(const ForecastSummary* const* scenarios, int n, double slack_threshold) {
  ForecastVerdict v;
  for (int i = 0; i < n; ++i) {
    const ForecastSummary& s = *scenarios[i];
    if (s.status == ForecastStatus::NonFinite) continue;
    if (s.t_critical >= 0.0 && (!v.clearance || s.t_critical < v.clearance_s)) {
      v.clearance = true;
      v.clearance_s = s.t_critical;
      v.clearance_scenario = i;
    }
    if (s.series_count > 0 && s.lambda0_min < slack_threshold) {
      for (int b = 0; b < s.series_count; ++b) {
        if (s.series_lambda0_min[static_cast<std::size_t>(b)] < slack_threshold) {
          const double when = s.series_t[static_cast<std::size_t>(b)];
          if (!v.slack || when < v.slack_s) {
            v.slack = true;
            v.slack_s = when;
            v.slack_scenario = i;
          }
          break;
        }
      }
    }
  }
  return v;
}

}  // namespace hoist::service::core
