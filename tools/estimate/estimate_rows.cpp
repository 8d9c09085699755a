// hoist-estimate's output rows: see estimate_rows.hpp.
#include "estimate_rows.hpp"

#include <cmath>

#include "hoist/io/results.hpp"

namespace hoist::estimate {

const char* const kOutputHeader =
    "t,l,Fa,b,moment,sigma_Fa,sigma_moment,y_c,theta,sigma_y_c,sigma_theta,"
    "lambda_0,lambda_1,lambda_2,lambda_3,lambda_4,nis,nis_window,mismatch,"
    "sigma_b,x_c,sigma_x_c,sigma_lambda_0,sigma_lambda_1,sigma_lambda_2,sigma_lambda_3,sigma_lambda_4,"
    "theta_open,nis_dof,nis_lower,nis_upper,nis_bound,drift,nis_exceeded,drift_exceeded,sensors,"
    "fa_observed,moment_observed,accepted,gated,load_changes,implausible,"
    "plausible,fault_imu_accel,fault_imu_rate,fault_rope_load,noise_imu_accel,noise_imu_rate,noise_rope_load,"
    "change_t,change_Fa,change_moment";

namespace {

void num(std::string& s, double v) {
  if (std::isnan(v)) s += "nan";
  else hoist::io::appendNumber(s, v);
  s += ',';
}
void integer(std::string& s, long long v) {
  s += std::to_string(v);
  s += ',';
}

/// A value with its sigma; both nan when not observed (sigma < 0, or no
/// sample of its sensor yet: LoadEstimate then carries the prior).
void observed(double v, double sigma, bool seen, double& v_out, double& s_out) {
  const bool ok = seen && sigma >= 0.0;
  v_out = ok ? v : std::nan("");
  s_out = ok ? sigma : std::nan("");
}

}  // namespace

void appendRow(std::string& s, const hoist::LoadEstimate& e, const hoist::EstimatorCounters& c) {
  double Fa, sFa, b, sb, M, sM;
  observed(e.Fa, e.sigma_Fa, e.fa_observed, Fa, sFa);
  observed(e.b, e.sigma_b, e.fa_observed && e.moment_observed, b, sb);
  observed(e.moment, e.sigma_moment, e.moment_observed, M, sM);
  num(s, e.t);
  num(s, e.kin.l);
  num(s, Fa);
  num(s, b);
  num(s, M);
  num(s, sFa);
  num(s, sM);
  num(s, e.y_c);
  num(s, e.theta);
  num(s, e.sigma_y_c);
  num(s, e.sigma_theta);
  for (double l : e.lambda) num(s, l);
  num(s, e.nis);
  num(s, e.nis_window);
  integer(s, e.mismatch ? 1 : 0);
  num(s, sb);
  num(s, e.x_c);
  num(s, e.sigma_x_c);
  for (double l : e.sigma_lambda) num(s, l);
  num(s, e.theta_open);
  integer(s, e.nis_dof);
  num(s, e.nis_lower);
  num(s, e.nis_upper);
  num(s, e.nis_bound);
  num(s, e.drift);
  integer(s, e.nis_exceeded ? 1 : 0);
  integer(s, e.drift_exceeded ? 1 : 0);
  integer(s, e.sensors);
  integer(s, e.fa_observed ? 1 : 0);
  integer(s, e.moment_observed ? 1 : 0);
  integer(s, c.accepted);
  integer(s, c.gated);
  integer(s, c.load_changes);
  integer(s, c.implausible);
  integer(s, e.plausible ? 1 : 0);
  integer(s, e.fault_imu_accel);
  integer(s, e.fault_imu_rate);
  integer(s, e.fault_rope_load);
  num(s, e.noise_imu_accel);
  num(s, e.noise_imu_rate);
  num(s, e.noise_rope_load);
  num(s, e.change_t);
  num(s, e.change_Fa);
  num(s, e.change_moment);
  s.back() = '\n';
}

}  // namespace hoist::estimate
