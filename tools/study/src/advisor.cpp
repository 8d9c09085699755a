#include "hoist/study/advisor.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "hoist/shaft_model.hpp"
#include "hoist/solver.hpp"
#include "hoist/study/sweep.hpp"

namespace hoist::study {
namespace {

std::string fmt(const char* f, double v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

PeakEvaluator simulationEvaluator(const ShaftParams& base, const HoistProfile& profile,
                                  const SimulationOptions& sim) {
  return [base, profile, sim](double Tb1, double Tb2) {
    ShaftParams p = base;
    p.Tb1 = Tb1;
    p.Tb2 = Tb2;
    auto model = std::make_shared<const ShaftModel>(p);
    auto solver = makeSolver(sim.method, model);
    TripPeaks pk;
    simulate(*solver, profile, sim, [&](const CageResponse& r) {
      const double top = std::abs(r.y_c - p.h * r.theta);
      const double bot = std::abs(r.y_c + p.h * r.theta);
      pk.excursion = std::max({pk.excursion, top, bot});
      for (int k = 1; k <= 4; ++k) pk.sleeve_force = std::max(pk.sleeve_force, std::abs(r.lambda[k]));
      pk.y_c = std::max(pk.y_c, std::abs(r.y_c));
      pk.theta = std::max(pk.theta, std::abs(r.theta));
    });
    if (!solver->finite() || !std::isfinite(pk.excursion))
      throw std::runtime_error("advisor: non-finite solution at Tb1 = " + fmt("%g", Tb1) +
                               " N, Tb2 = " + fmt("%g", Tb2) + " N");
    return pk;
  };
}

void AdvisorOptions::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  if (!(clearance > 0.0) || !std::isfinite(clearance)) bad("--clearance must be a finite value > 0 [m]");
  if (!(max_sleeve_force > 0.0)) bad("--max-sleeve-force must be > 0 [N]");
  if (!(total_min > 0.0) || !(total_max > total_min) || !std::isfinite(total_max))
    bad("--total-range must satisfy 0 < min < max");
  if (!(split_min > 0.0) || !(split_max < 1.0) || !(split_min <= split_max))
    bad("--split-range must satisfy 0 < min <= max < 1");
  if (samples < 2) bad("samples must be >= 2");
  if (!(rel_tol > 0.0 && rel_tol < 0.5)) bad("rel_tol must be in (0, 0.5)");
  if (!(split_tol > 0.0)) bad("split_tol must be > 0");
}

bool feasible(const TripPeaks& p, const AdvisorOptions& opt) {
  return p.excursion <= opt.clearance && p.sleeve_force <= opt.max_sleeve_force;
}

AdvisorResult advisePreload(const PeakEvaluator& eval, const AdvisorOptions& opt) {
  opt.validate();
  AdvisorResult res;
  std::atomic<int> count{0};
  auto at = [&](double total, double split) {
    AdvisorPoint p;
    p.total = total;
    p.split = split;
    p.peaks = eval(split * total, (1.0 - split) * total);
    p.feasible = feasible(p.peaks, opt);
    ++count;
    return p;
  };
  // Normalized violation: <= 1 means feasible; the split search minimizes it.
  auto objective = [&](const TripPeaks& p) {
    double o = p.excursion / opt.clearance;
    if (std::isfinite(opt.max_sleeve_force)) o = std::max(o, p.sleeve_force / opt.max_sleeve_force);
    return o;
  };

  // (1) log-spaced samples at the initial split.
  const double s0 = std::clamp(0.5, opt.split_min, opt.split_max);
  res.curve.resize(static_cast<std::size_t>(opt.samples));
  parallelFor(opt.samples, opt.jobs, [&](int i) {
    const double f = static_cast<double>(i) / (opt.samples - 1);
    const double T = opt.total_min * std::pow(opt.total_max / opt.total_min, f);
    res.curve[static_cast<std::size_t>(i)] = at(T, s0);
  });
  for (std::size_t i = 1; i < res.curve.size(); ++i)
    if (res.curve[i].peaks.excursion > 1.01 * res.curve[i - 1].peaks.excursion + 1e-12)
      res.monotone = false;

  // Golden-section search of the split at `total` (objective unimodal assumed).
  auto bestSplit = [&](double total, std::vector<AdvisorPoint>& pts) {
    const double gr = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = opt.split_min, b = opt.split_max;
    if (b - a <= opt.split_tol) {
      pts.push_back(at(total, 0.5 * (a + b)));
      return pts.back();
    }
    AdvisorPoint c = at(total, b - gr * (b - a)), d = at(total, a + gr * (b - a));
    pts.push_back(c);
    pts.push_back(d);
    while (b - a > opt.split_tol) {
      if (objective(c.peaks) <= objective(d.peaks)) {
        b = d.split;
        d = c;
        c = at(total, b - gr * (b - a));
        pts.push_back(c);
      } else {
        a = c.split;
        c = d;
        d = at(total, a + gr * (b - a));
        pts.push_back(d);
      }
    }
    // The ends of the range too (the optimum of a monotone objective is there).
    pts.push_back(at(total, opt.split_min));
    pts.push_back(at(total, opt.split_max));
    AdvisorPoint best = pts.front();
    for (const auto& p : pts)
      if (objective(p.peaks) < objective(best.peaks)) best = p;
    return best;
  };

  // Bisection (geometric) of the total between an infeasible lo and a feasible hi.
  auto bisect = [&](AdvisorPoint lo, AdvisorPoint hi) {
    while ((hi.total - lo.total) > opt.rel_tol * hi.total) {
      AdvisorPoint mid = at(std::sqrt(lo.total * hi.total), hi.split);
      (mid.feasible ? hi : lo) = mid;
    }
    return std::make_pair(lo, hi);
  };

  // (2) bracket from the samples.
  std::size_t k = 0;
  while (k < res.curve.size() && !res.curve[k].feasible) ++k;
  double split = s0;
  AdvisorPoint lo, hi;
  bool haveLo = false;
  if (k == res.curve.size()) {
    // Infeasible at the initial split everywhere: try the best split at the top.
    AdvisorPoint top = bestSplit(opt.total_max, res.split_scan);
    if (!top.feasible) {
      res.feasible = false;
      res.evaluations = count;
      const TripPeaks& p = top.peaks;
      std::string why;
      if (p.excursion > opt.clearance)
        why = "a peak excursion of " + fmt("%.4g", p.excursion * 1e3) + " mm, above the clearance of " +
              fmt("%.4g", opt.clearance * 1e3) + " mm";
      if (p.sleeve_force > opt.max_sleeve_force)
        why += std::string(why.empty() ? "" : " and ") + "a peak sleeve force of " +
               fmt("%.4g", p.sleeve_force) + " N, above the limit of " + fmt("%.4g", opt.max_sleeve_force) + " N";
      res.message = "INFEASIBLE: even the largest total preload in the range, " +
                    fmt("%.4g", opt.total_max) + " N (best split " + fmt("%.3f", top.split) + "), gives " +
                    why + "; widen --total-range, relax the target, or reduce the eccentric load";
      res.achieved = p;
      res.split = top.split;
      res.total = opt.total_max;
      return res;
    }
    split = top.split;
    hi = top;
    lo = res.curve.back();  // infeasible at s0; re-checked at the new split below
    haveLo = false;
  } else if (k == 0) {
    hi = res.curve[0];
  } else {
    lo = res.curve[k - 1];
    hi = res.curve[k];
    haveLo = true;
    std::tie(lo, hi) = bisect(lo, hi);
  }

  // (3) best split at the found total.
  if (k < res.curve.size()) {
    AdvisorPoint best = bestSplit(hi.total, res.split_scan);
    if (objective(best.peaks) < objective(hi.peaks) * (1.0 - 1e-6)) {
      split = best.split;
      hi = best;
      haveLo = false;
    }
  }

  // (4) re-bracket and bisect at the (new) split: walk down until infeasible.
  if (!haveLo) {
    double T = hi.total;
    for (;;) {
      if (T <= opt.total_min * (1.0 + 1e-12)) break;
      T = std::max(opt.total_min, T / 1.5);
      AdvisorPoint p = at(T, split);
      if (!p.feasible) {
        lo = p;
        haveLo = true;
        break;
      }
      hi = p;
    }
    if (haveLo) std::tie(lo, hi) = bisect(lo, hi);
  }

  res.feasible = true;
  res.total = hi.total;
  res.split = hi.split;
  res.Tb1 = hi.split * hi.total;
  res.Tb2 = (1.0 - hi.split) * hi.total;
  res.achieved = hi.peaks;
  res.infeasible_below = haveLo ? lo.total : 0.0;
  res.evaluations = count;
  if (!haveLo) {
    res.message = "the target is met already at the bottom of the range (Tb1 + Tb2 = " +
                  fmt("%.4g", opt.total_min) + " N); the smallest sufficient preload may be lower";
  } else {
    res.message = "smallest total preload meeting the target: " + fmt("%.5g", res.total) +
                  " N (infeasible at " + fmt("%.5g", res.infeasible_below) + " N), split Tb1/(Tb1+Tb2) = " +
                  fmt("%.3f", res.split);
  }
  // Monotonicity of the samples above the recommendation (non-monotone curves
  // can have infeasible islands above the first feasible total).
  for (const auto& p : res.curve)
    if (p.total > res.total && !p.feasible && std::abs(p.split - res.split) < 1e-12) {
      res.message += "; WARNING: the sampled total " + fmt("%.4g", p.total) +
                     " N is infeasible although larger (excursion not monotone in the preload)";
      break;
    }
  if (!res.monotone) res.message += "; note: sampled peak excursion is not monotone in the total preload";
  return res;
}

}  // namespace hoist::study
