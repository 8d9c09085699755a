// hoist/study/advisor.hpp -- the preload advisor: the smallest total guide-rope
// preload Tb1 + Tb2, and the best split Tb1 / (Tb1 + Tb2), that keep the cage's
// peak lateral excursion max_t max(|y_c - h theta|, |y_c + h theta|) within a
// clearance and (optionally) the peak sleeve force |lambda_1..4| within a limit
// (the paper's conclusion: the model should "determine the suitable preload in
// the guiding cable").  Pure numerics: no I/O.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "hoist/params.hpp"
#include "hoist/profile.hpp"
#include "hoist/simulator.hpp"

namespace hoist::study {

/// Peaks of one trip at one preload pair.
struct TripPeaks {
  double excursion = 0.0;     ///< max over t of max(|y_c - h theta|, |y_c + h theta|) [m]
  double sleeve_force = 0.0;  ///< max over t, k = 1..4 of |lambda_k| [N]
  double y_c = 0.0;           ///< max |y_c| [m]
  double theta = 0.0;         ///< max |theta| [rad]
};

/// Peaks of a trip for preloads (Tb1, Tb2).  Must be thread-safe.
using PeakEvaluator = std::function<TripPeaks(double Tb1, double Tb2)>;

/// The evaluator that simulates `profile` with `base` (Tb1, Tb2 replaced).
PeakEvaluator simulationEvaluator(const ShaftParams& base, const HoistProfile& profile,
                                  const SimulationOptions& sim);

struct AdvisorOptions {
  double clearance = 0.0;                                          ///< [m], > 0
  double max_sleeve_force = std::numeric_limits<double>::infinity();  ///< [N]
  double total_min = 1e4;   ///< search range of Tb1 + Tb2 [N]
  double total_max = 5e5;
  double split_min = 0.3;   ///< search range of Tb1 / (Tb1 + Tb2)
  double split_max = 0.7;
  int samples = 12;         ///< log-spaced totals sampled first (curve + monotonicity check)
  double rel_tol = 1e-3;    ///< relative bracket width at which bisection stops
  double split_tol = 0.005; ///< golden-section tolerance on the split
  int jobs = 0;             ///< threads for the sampling (<= 0: hardware concurrency)
  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

/// One evaluated point.
struct AdvisorPoint {
  double total = 0.0;
  double split = 0.5;
  TripPeaks peaks;
  bool feasible = false;
};

struct AdvisorResult {
  bool feasible = false;
  std::string message;     ///< one readable sentence (why infeasible, or what was found)
  double total = 0.0;      ///< recommended Tb1 + Tb2 [N] (feasible only)
  double split = 0.5;      ///< recommended Tb1 / (Tb1 + Tb2)
  double Tb1 = 0.0, Tb2 = 0.0;
  TripPeaks achieved;      ///< peaks at the recommendation
  double infeasible_below = 0.0;  ///< largest total found infeasible at the recommended split (bracket)
  bool monotone = true;    ///< sampled excursion non-increasing in the total (within 1 %)
  std::vector<AdvisorPoint> curve;  ///< the log-spaced samples at the initial split (sorted by total)
  std::vector<AdvisorPoint> split_scan;  ///< points of the split search at the found total
  int evaluations = 0;
};

/// Feasibility of one point under `opt`.
bool feasible(const TripPeaks& p, const AdvisorOptions& opt);

/// Search: (1) sample `samples` log-spaced totals in [total_min, total_max] at
/// the split nearest 0.5 in range and check monotonicity; (2) bisect the total
/// between the largest infeasible and the smallest feasible sample; (3)
/// golden-section search of the split at that total, minimizing the larger of
/// excursion / clearance and sleeve force / limit; (4) if the split moved,
/// bisect the total again at the new split.  Reports infeasible when even
/// total_max at the best split violates the target.
AdvisorResult advisePreload(const PeakEvaluator& eval, const AdvisorOptions& opt);

}  // namespace hoist::study
