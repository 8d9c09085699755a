// The load estimator's band blocks and its load changes at rest: the CUSUM
// on each channel's blocks that finds a change without a 6-sigma sample, the
// step solver that carries a change's ringing, and the re-opening of both
// loads as one event (hoist/load_estimator.hpp, "Load changes";
// docs/estimation.md, "Gating and load changes").
#include "hoist/load_estimator.hpp"

#include "load_estimator_detail.hpp"

#include <algorithm>
#include <cmath>

namespace hoist {

using namespace estimator_detail;

void LoadEstimator::band(int ch, double nu, double S, double e) {
  if (!band_[ch].add(t_, nu, S, e)) return;
  const double s = band_[ch].statistic();
  tick_nis_ += s * s;
  tick_dof_ += 1;
  // f_y carries the moment's evidence at rest (the static tilt); omega only its transient.
  ChangeDetector* c = ch == kRope ? &cusum_fa_ : ch == kImuAccel ? &cusum_m_ : nullptr;
  if (c && changeAtRest(*c, s)) loadChange(std::max(c->onset() - set_.band_block, rest_since_));
}

bool LoadEstimator::changeAtRest(ChangeDetector& c, double z) {
  if (moving() || t_ - rest_since_ + kTimeEps < set_.change_holdoff) return false;
  return c.add(z, t_);
}

void LoadEstimator::foldStep() {
  // The transient has decayed: the step's response is the steady one's.
  stepping_ = false;
  o_Fa_ = Fa_c_;
  o_M_ = M_c_;
}

void LoadEstimator::loadChange(double onset) {
  if (knownLoad()) {  // a declared known load does not change: the offset explains the rest
    run_fa_ = run_m_ = 0;
    return;
  }
  // One load changed: both its force and its moment re-open, whichever
  // channel saw it (the rope load sees Fa at once, f_y the moment slowly).
  if (!moving()) {
    // At rest the change is a step at `onset`: the ropes ring, and the step
    // solver carries it.  The shaft is time-invariant at rest, so starting
    // it at rest and stepping it to now at the rest kinematics is the same
    // as having started it at the onset.
    const double t0 = std::max(onset, t_ - kMaxCatchUp);
    if (stepping_) foldStep();  // a change during a change's transient: the first one's ringing is dropped
    step_->initialize(t0, kin_, InitialState::Rest);
    const int n = t_ > t0 ? std::max(1, static_cast<int>(std::ceil((t_ - t0) / sub_h_ - 1e-9))) : 0;
    for (int j = 1; j <= n; ++j) step_->step(t0 + (t_ - t0) * j / n, kin_);
    stepping_ = true;
    step_fresh_ = true;
    step_t_ = t0;
    o_Fa_ = Fa_;
    o_M_ = M_;
  }
  change_t_ = t_;
  change_Fa0_ = Fa_;
  change_M0_ = M_;
  PFa_ = std::max(PFa_, set_.fa_sigma0 * set_.fa_sigma0);
  Pl_(0, 0) = std::max(Pl_(0, 0), set_.moment_sigma0 * set_.moment_sigma0);
  Pl_(0, 1) = Pl_(1, 0) = 0.0;  // the new moment owes nothing to the offset
  FaF_ = Fa_;
  PFaF_ = PFa_;
  MF_ = M_;
  PlF_ = Pl_;
  cF_ = c_;
  run_fa_ = run_m_ = 0;
  cusum_fa_.reset();
  cusum_m_.reset();
  rest_since_ = t_;  // the CUSUM waits change_holdoff again: the filters settle first
  ++counts_.load_changes;
  // A load cannot change while the cage moves: a change then is evidence of mismatch.
  if (moving()) trip_drift_ = std::max(trip_drift_, set_.drift_sigma + 1.0);
}

}  // namespace hoist
