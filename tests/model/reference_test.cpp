// Agreement with the independent reference solutions of the paper's baseline
// (tests/data/c1-paper*, copied from shared/cases): normalized RMS error
// (RMS of the difference / RMS of the reference) and normalized peak error.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "hoist/simulator.hpp"
#include "test_util.hpp"

using namespace hoist;
using namespace hoist::test;

namespace {

HoistProfile loadProfile(const std::string& cs) {
  const Table t = readCsv(dataDir() + "/" + cs + "/profile.csv");
  std::vector<ProfileSample> s;
  for (const auto& r : t.rows) s.push_back({r[0], {r[1], r[2], r[3]}});
  return HoistProfile(std::move(s));
}

struct Errors {
  double nrms[8], npeak[8];
};
const char* kCols[8] = {"x_c", "y_c", "theta", "lambda_0", "lambda_1", "lambda_2", "lambda_3", "lambda_4"};

Errors compare(const std::string& cs, InitialState init, double dt, double max_step, Method m = Method::Fast,
               double t_end = -1) {
  const Table ref = readCsv(dataDir() + "/" + cs + "/reference.csv");
  // The reference is the paper baseline (shaft.toml = defaults) with the
  // paper's truncation: static correction off.
  ShaftParams p;
  p.static_correction = false;
  auto solver = makeSolver(m, std::make_shared<const ShaftModel>(p));
  SimulationOptions o;
  o.dt = dt;
  o.max_step = max_step;
  o.initial = init;
  o.t_end = t_end;
  std::vector<CageResponse> out;
  simulate(*solver, loadProfile(cs), o, [&](const CageResponse& r) { out.push_back(r); });
  const int stride = static_cast<int>(std::lround(0.01 / dt));
  Errors e{};
  for (int c = 0; c < 8; ++c) {
    std::vector<double> a, b;
    for (size_t k = 0; k < ref.rows.size() && k * stride < out.size(); ++k) {
      const auto& r = out[k * stride];
      EXPECT_NEAR(r.t, ref.rows[k][0], 1e-9);
      const double v[8] = {r.x_c, r.y_c, r.theta, r.lambda[0], r.lambda[1], r.lambda[2], r.lambda[3], r.lambda[4]};
      a.push_back(v[c]);
      b.push_back(ref.rows[k][ref.col(kCols[c])]);
    }
    e.nrms[c] = nrms(a, b);
    double pe = 0, pr = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      pe = std::max(pe, std::abs(a[i] - b[i]));
      pr = std::max(pr, std::abs(b[i]));
    }
    e.npeak[c] = pe / pr;
  }
  std::cout << cs << " dt=" << dt << " max_step=" << max_step << " method=" << toString(m) << "\n";
  for (int c = 0; c < 8; ++c) std::printf("  %-9s nrms %.2e  npeak %.2e\n", kCols[c], e.nrms[c], e.npeak[c]);
  return e;
}

TEST(Reference, PaperBaselineStaticStartAtPaperStep) {
  // dt = 0.01 s, the paper's step, no substeps.
  const Errors e = compare("c1-paper", InitialState::Static, 0.01, 0.0);
  for (int c = 0; c < 8; ++c) {
    EXPECT_LT(e.nrms[c], 0.02) << kCols[c];
    EXPECT_LT(e.npeak[c], 0.02) << kCols[c];
  }
}

TEST(Reference, PaperBaselineStaticStartFine) {
  const Errors e = compare("c1-paper", InitialState::Static, 0.001, 0.0);
  for (int c = 0; c < 8; ++c) {
    EXPECT_LT(e.nrms[c], 0.002) << kCols[c];
    EXPECT_LT(e.npeak[c], 0.002) << kCols[c];
  }
}

TEST(Reference, PaperBaselineRestStart) {
  // Free vibration: phase error accumulates, so integrate with 2.5 ms substeps
  // (hoist-sim's default --max-step) and report every 10 ms.
  const Errors e = compare("c1-paper-rest", InitialState::Rest, 0.01, 0.0025);
  for (int c = 0; c < 8; ++c) {
    EXPECT_LT(e.nrms[c], 0.02) << kCols[c];
    EXPECT_LT(e.npeak[c], 0.03) << kCols[c];
  }
}

TEST(Reference, PaperMethodFirstSeconds) {
  // The paper's literal method against the reference (first 3 s; ~10 ms/step).
  // Lateral columns only: over the first seconds x_c and lambda_0 are dominated
  // by the kHz hoisting-rope transient that a 10 ms step cannot resolve (both
  // paths alike; over the whole run x_c is within 0.6 %, see above, and the
  // paths agree with each other, dynamics_test).
  const Errors e = compare("c1-paper", InitialState::Static, 0.01, 0.0, Method::Paper, 3.0);
  for (int c = 1; c < 8; ++c)
    if (c != 3) { EXPECT_LT(e.nrms[c], 0.02) << kCols[c]; }
}

TEST(Reference, GuideRopeShapes) {
  const Table shape = readCsv(dataDir() + "/c1-paper/shape.csv");
  ShaftParams p;
  p.static_correction = false;
  auto model = std::make_shared<const ShaftModel>(p);
  auto solver = makeSolver(Method::Fast, model);
  const HoistProfile prof = loadProfile("c1-paper");
  VectorXd x(static_cast<Eigen::Index>(shape.rows.size()));
  for (size_t i = 0; i < shape.rows.size(); ++i) x(static_cast<Eigen::Index>(i)) = shape.rows[i][0];
  for (int T : {18, 36, 60}) {
    SimulationOptions o;
    o.t_end = T;
    simulate(*solver, prof, o, {});
    VectorXd y1, y2;
    solver->guideRopeShapes(x, y1, y2);
    const auto r1 = shape.column("y1_t" + std::to_string(T));
    const auto r2 = shape.column("y2_t" + std::to_string(T));
    const double e1 = nrms(std::vector<double>(y1.data(), y1.data() + y1.size()), r1);
    const double e2 = nrms(std::vector<double>(y2.data(), y2.data() + y2.size()), r2);
    std::printf("shape t=%d s: nrms y1 %.2e y2 %.2e\n", T, e1, e2);
    EXPECT_LT(e1, 0.02) << "t = " << T;
    EXPECT_LT(e2, 0.02) << "t = " << T;
  }
}

}  // namespace
