// hoist/guide_rope_envelope.hpp -- the guide ropes' largest lateral
// deflection over the shaft (the e_guide of hoist/clearance.hpp), from any
// Solver's state: GuideRopeEnvelope for the real-time path (precomputed
// tables, no allocation), maxGuideRopeDeflection for one-off use.
#pragma once

#include <cstdint>

#include "hoist/solver.hpp"

namespace hoist {

/// Largest |y_i(x)| over both guide ropes, sampled at `samples` evenly spaced
/// depths (uses a precomputed table; no allocation after the first call for a
/// given solver is NOT guaranteed -- use GuideRopeEnvelope for real time).
double maxGuideRopeDeflection(const Solver& s, int samples = 401);

/// Real-time helper: precomputed sine table (and, for the static correction,
/// S_r(x) of both ropes) on a fixed depth grid; evaluate() and
/// evaluateBounded() allocate nothing.
class GuideRopeEnvelope {
 public:
  GuideRopeEnvelope(const ShaftModel& model, int samples = 401);
  /// Largest |y1|, |y2| over the grid for the solver's current state (the
  /// exact envelope: a samples x n product per rope).  Also becomes the
  /// reference of evaluateBounded().
  double evaluate(const Solver& s);
  /// The envelope without the samples x n product on most calls: an upper
  /// bound E of evaluate()'s value with  evaluate() <= E <= evaluate() +
  /// tolerance  (tolerance in metres; <= 0 or not finite: always exact).
  /// From the last exact evaluation (values E1_0, E2_0, sine coordinates
  /// q_0, sleeve loads f_0 at depths a_0), for every depth x of rope r
  ///   |y_r(x) - y_r,0(x)| <= D_r = sum_i max|U_i| |q_i - q_0,i|
  ///       + sum_k [ G_r(a_k, a_k) |f_k - f_0,k| + |f_0,k| |a_k - a_0,k| / min T_r ]
  /// (G_r(x, a) <= G_r(a, a), |dG_r/da| <= 1 / T_r(a)), so the envelope lies
  /// in [E_r0 - D_r, E_r0 + D_r]; E = max_r (E_r0 + D_r) is returned while
  /// 2 max_r D_r <= tolerance, otherwise the envelope is evaluated exactly
  /// (and becomes the new reference).  Cost of a bounded call: the solver's
  /// guide coordinates and O(n).
  double evaluateBounded(const Solver& s, double tolerance);
  /// evaluateBounded(s, tolerance), except that where the bound has grown
  /// wider than the tolerance the exact evaluation may be DEFERRED: the
  /// wider bound E = max_r (E_r0 + D_r) is returned as it is (still
  /// evaluate() <= E, now possibly more than `tolerance` above it) if
  /// E < defer_below; otherwise, or without a reference or bound (a changed
  /// set of sleeve loads, a non-finite state), the evaluation is exact.
  /// For a caller that must spread exact evaluations over time (the daemon's
  /// per-tick budget, [service] max_exact_envelopes_per_tick) and knows a
  /// level below which the value changes no decision (an alarm's clear
  /// level).  defer_below = -inf: never defer (the two-argument form).
  double evaluateBounded(const Solver& s, double tolerance, double defer_below);
  /// Whether the last evaluate()/evaluateBounded() was exact.
  bool lastExact() const { return last_exact_; }
  /// Whether the last evaluateBounded() returned a deferred (wider) bound.
  bool lastDeferred() const { return last_deferred_; }
  std::int64_t exactEvaluations() const { return exact_count_; }
  /// Bounds within the tolerance (deferred ones not included).
  std::int64_t boundedEvaluations() const { return bounded_count_; }
  /// Deferred bounds (wider than the tolerance) since construction.
  std::int64_t deferredEvaluations() const { return deferred_count_; }
  /// The longest run of deferred bounds in a row since construction (a run
  /// ends at an exact or in-tolerance evaluation).
  int longestDeferral() const { return longest_deferral_; }
  /// Continue the counts above from `old` (an envelope this one replaces:
  /// the twin adopted another model; the counters stay monotonic).  The
  /// bounded evaluations restart from an exact one.
  void carryCountsFrom(const GuideRopeEnvelope& old) {
    exact_count_ = old.exact_count_;
    bounded_count_ = old.bounded_count_;
    deferred_count_ = old.deferred_count_;
    longest_deferral_ = old.longest_deferral_;
    have_ref_ = false;
  }
  const VectorXd& depths() const { return x_; }
  /// The shapes of the last EXACT evaluation.
  const VectorXd& y1() const { return y1_; }
  const VectorXd& y2() const { return y2_; }

 private:
  double exact(const Solver& s, const SleeveLoads& loads);
  VectorXd x_;
  MatrixXd table_;  // samples x n
  VectorXd umax_;   // max over the grid of |U_i|
  VectorXd S1_, S2_;  // S_r(x) on the grid (Green's function of the sleeve loads)
  double SL1_ = 0.0, SL2_ = 0.0;
  double lip1_ = 0.0, lip2_ = 0.0;  // 1 / min_x T_r(x): bound of |dG_r(x, a)/da|
  VectorXd q1_, q2_, y1_, y2_;
  // reference of evaluateBounded(): the last exact evaluation
  bool have_ref_ = false, last_exact_ = true, last_deferred_ = false;
  VectorXd q1r_, q2r_;
  SleeveLoads ref_loads_;
  double e1r_ = 0.0, e2r_ = 0.0;
  std::int64_t exact_count_ = 0, bounded_count_ = 0, deferred_count_ = 0;
  int deferred_run_ = 0, longest_deferral_ = 0;
};

}  // namespace hoist
