#include "hoist/study/sweep.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "hoist/shaft_model.hpp"
#include "hoist/solver.hpp"

namespace hoist::study {
namespace {

struct KeyInfo {
  const char* key;
  const char* help;
};

const std::vector<KeyInfo>& keyTable() {
  static const std::vector<KeyInfo> k = {
      {"hoisting_rope.mass_per_length", "rho1 [kg/m]"},
      {"hoisting_rope.axial_stiffness", "EA [N]"},
      {"hoisting_rope.damping", "u1 [kg/(m s)]"},
      {"guide_ropes.length", "L [m]"},
      {"guide_ropes.mass_per_length", "rho2 [kg/m]"},
      {"guide_ropes.damping", "u2 [kg/(m s)]"},
      {"guide_ropes.preload", "total preload Tb1 + Tb2 [N], split equally"},
      {"guide_ropes.preload[0]", "Tb1 [N] alone"},
      {"guide_ropes.preload[1]", "Tb2 [N] alone"},
      {"guide_ropes.preload_difference", "Tb2 - Tb1 [N] at the current total"},
      {"guide_ropes.preload_split", "Tb1 / (Tb1 + Tb2) at the current total"},
      {"cage.mass", "m [kg] alone"},
      {"cage.mass_and_inertia", "m [kg] with J scaled in proportion (the paper's mass study)"},
      {"cage.inertia", "J [kg m^2]"},
      {"cage.half_height", "h [m]"},
      {"load.eccentric_force", "Fa [N]"},
      {"load.offset", "b [m]"},
      {"model.modes", "n, assumed modes per rope (integer)"},
      {"model.gravity", "g [m/s^2]"},
      {"model.rho_inf", "integrator spectral radius in [0, 1)"},
      {"model.static_correction", "residual flexibility of the guide ropes: 1 on, 0 off"},
  };
  return k;
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

const std::vector<std::string>& sweepableKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> v;
    for (const auto& k : keyTable()) v.emplace_back(k.key);
    return v;
  }();
  return keys;
}

std::string parameterHelp() {
  std::string s;
  for (const auto& k : keyTable()) {
    std::string key = k.key;
    key.resize(std::max<std::size_t>(key.size() + 2, 34), ' ');
    s += "  " + key + k.help + "\n";
  }
  return s;
}

void applyParameter(ShaftParams& p, const std::string& key, double value) {
  if (!std::isfinite(value)) throw ParamError(key, "value must be finite, got " + fmt(value));
  const double total = p.Tb1 + p.Tb2;
  if (key == "hoisting_rope.mass_per_length") p.rho1 = value;
  else if (key == "hoisting_rope.axial_stiffness") p.EA = value;
  else if (key == "hoisting_rope.damping") p.u1 = value;
  else if (key == "hoisting_rope.initial_length")
    throw ParamError(key, "not sweepable here: the profile fixes l(t) (use --profile)");
  else if (key == "guide_ropes.length") p.L = value;
  else if (key == "guide_ropes.mass_per_length") p.rho2 = value;
  else if (key == "guide_ropes.damping") p.u2 = value;
  else if (key == "guide_ropes.preload") p.Tb1 = p.Tb2 = 0.5 * value;
  else if (key == "guide_ropes.preload[0]") p.Tb1 = value;
  else if (key == "guide_ropes.preload[1]") p.Tb2 = value;
  else if (key == "guide_ropes.preload_difference") {
    p.Tb1 = 0.5 * (total - value);
    p.Tb2 = 0.5 * (total + value);
  } else if (key == "guide_ropes.preload_split") {
    if (!(value > 0.0 && value < 1.0)) throw ParamError(key, "split must be in (0, 1), got " + fmt(value));
    p.Tb1 = value * total;
    p.Tb2 = (1.0 - value) * total;
  } else if (key == "cage.mass") p.m = value;
  else if (key == "cage.mass_and_inertia") {
    if (!(value > 0.0)) throw ParamError(key, "mass must be > 0, got " + fmt(value));
    p.J *= value / p.m;
    p.m = value;
  } else if (key == "cage.inertia") p.J = value;
  else if (key == "cage.half_height") p.h = value;
  else if (key == "load.eccentric_force") p.Fa = value;
  else if (key == "load.offset") p.b = value;
  else if (key == "model.modes") {
    if (value != std::floor(value) || value < 1 || value > kMaxModes)
      throw ParamError(key, "must be an integer in [1, " + std::to_string(kMaxModes) + "], got " + fmt(value));
    p.n = static_cast<int>(value);
  } else if (key == "model.gravity") p.g = value;
  else if (key == "model.rho_inf") p.rho_inf = value;
  else if (key == "model.static_correction") {
    if (value != 0.0 && value != 1.0) throw ParamError(key, "must be 1 (on) or 0 (off), got " + fmt(value));
    p.static_correction = value == 1.0;
  } else {
    std::string list;
    for (const auto& k : sweepableKeys()) list += (list.empty() ? "" : ", ") + k;
    throw ParamError(key, "unknown or unsweepable key; valid keys: " + list);
  }
}

double parameterValue(const ShaftParams& p, const std::string& key) {
  if (key == "hoisting_rope.mass_per_length") return p.rho1;
  if (key == "hoisting_rope.axial_stiffness") return p.EA;
  if (key == "hoisting_rope.damping") return p.u1;
  if (key == "guide_ropes.length") return p.L;
  if (key == "guide_ropes.mass_per_length") return p.rho2;
  if (key == "guide_ropes.damping") return p.u2;
  if (key == "guide_ropes.preload") return p.Tb1 + p.Tb2;
  if (key == "guide_ropes.preload[0]") return p.Tb1;
  if (key == "guide_ropes.preload[1]") return p.Tb2;
  if (key == "guide_ropes.preload_difference") return p.Tb2 - p.Tb1;
  if (key == "guide_ropes.preload_split") return p.Tb1 / (p.Tb1 + p.Tb2);
  if (key == "cage.mass" || key == "cage.mass_and_inertia") return p.m;
  if (key == "cage.inertia") return p.J;
  if (key == "cage.half_height") return p.h;
  if (key == "load.eccentric_force") return p.Fa;
  if (key == "load.offset") return p.b;
  if (key == "model.modes") return p.n;
  if (key == "model.gravity") return p.g;
  if (key == "model.rho_inf") return p.rho_inf;
  if (key == "model.static_correction") return p.static_correction ? 1.0 : 0.0;
  throw ParamError(key, "unknown key");
}

// ---- Trace ----------------------------------------------------------------

void Trace::append(const CageResponse& r) {
  t.push_back(r.t);
  l.push_back(r.kin.l);
  v.push_back(r.kin.v);
  a.push_back(r.kin.a);
  x_c.push_back(r.x_c);
  y_c.push_back(r.y_c);
  theta.push_back(r.theta);
  for (int k = 0; k < 5; ++k) lambda[k].push_back(r.lambda[k]);
}

void Trace::reserve(std::size_t n) {
  for (auto* vec : {&t, &l, &v, &a, &x_c, &y_c, &theta}) vec->reserve(n);
  for (auto& vec : lambda) vec.reserve(n);
}

std::vector<double> Trace::excursion(double h) const {
  std::vector<double> e(size());
  for (std::size_t i = 0; i < size(); ++i)
    e[i] = std::max(std::abs(y_c[i] - h * theta[i]), std::abs(y_c[i] + h * theta[i]));
  return e;
}

// ---- running ----------------------------------------------------------------

RunResult runOne(const RunSpec& spec, const HoistProfile& profile, const RunOptions& opt,
                 const std::function<void(double)>& progress) {
  RunResult res;
  res.spec = spec;
  const auto start = std::chrono::steady_clock::now();
  try {
    auto model = std::make_shared<const ShaftModel>(spec.params);
    auto solver = makeSolver(opt.sim.method, model);
    const double t_end = opt.sim.t_end < 0 ? profile.endTime() : opt.sim.t_end;
    res.trace.reserve(static_cast<std::size_t>((t_end - profile.startTime()) / opt.sim.dt) + 2);
    std::vector<double> pending = opt.shape_times;
    std::sort(pending.begin(), pending.end());
    VectorXd x = VectorXd::LinSpaced(std::max(2, opt.shape_points), 0.0, spec.params.L);
    VectorXd y1(x.size()), y2(x.size());
    std::size_t next = 0;
    const double half = 0.5 * opt.sim.dt;
    // Shapes at times beyond the end are taken at the last step.
    auto sink = [&](const CageResponse& r) {
      res.trace.append(r);
      const bool last = r.t >= t_end - half;
      while (next < pending.size() && (r.t >= pending[next] - half || last)) {
        solver->guideRopeShapes(x, y1, y2);
        Shape s;
        s.t = pending[next];
        s.l = r.kin.l;
        s.x.assign(x.data(), x.data() + x.size());
        s.y1.assign(y1.data(), y1.data() + y1.size());
        s.y2.assign(y2.data(), y2.data() + y2.size());
        res.shapes.push_back(std::move(s));
        ++next;
      }
    };
    simulate(*solver, profile, opt.sim, sink, progress);
    if (!solver->finite()) res.error = "the solution became non-finite";
  } catch (const std::exception& e) {
    res.error = e.what();
  }
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return res;
}

void parallelFor(int count, int jobs, const std::function<void(int)>& f) {
  if (count <= 0) return;
  if (jobs <= 0) jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  jobs = std::min(jobs, count);
  std::atomic<int> next{0};
  std::exception_ptr err;
  std::mutex m;
  auto worker = [&] {
    for (;;) {
      const int i = next.fetch_add(1);
      if (i >= count) return;
      {
        std::lock_guard<std::mutex> lk(m);
        if (err) return;
      }
      try {
        f(i);
      } catch (...) {
        std::lock_guard<std::mutex> lk(m);
        if (!err) err = std::current_exception();
      }
    }
  };
  if (jobs == 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(jobs));
    for (int j = 0; j < jobs; ++j) pool.emplace_back(worker);
    for (auto& th : pool) th.join();
  }
  if (err) std::rethrow_exception(err);
}

std::vector<RunResult> runAll(const std::vector<RunSpec>& specs, const HoistProfile& profile,
                              const RunOptions& opt, int jobs,
                              const std::function<void(double)>& progress) {
  std::vector<RunResult> out(specs.size());
  std::vector<double> frac(specs.size(), 0.0);
  std::mutex m;
  auto report = [&](std::size_t i, double f) {
    if (!progress) return;
    std::lock_guard<std::mutex> lk(m);
    frac[i] = f;
    double s = 0.0;
    for (double x : frac) s += x;
    progress(s / static_cast<double>(frac.size()));
  };
  parallelFor(static_cast<int>(specs.size()), jobs, [&](int i) {
    const auto k = static_cast<std::size_t>(i);
    out[k] = runOne(specs[k], profile, opt, [&, k](double f) { report(k, f); });
    report(k, 1.0);
  });
  return out;
}

// ---- studies -----------------------------------------------------------------

const std::vector<std::string>& paperStudyNames() {
  static const std::vector<std::string> names = {"response", "preload", "tension-difference",
                                                 "eccentric-load", "mass"};
  return names;
}

Study sweepStudy(const std::string& key, const std::vector<double>& values, const ShaftParams& base) {
  if (values.empty()) throw ParamError(key, "no values to sweep");
  Study s;
  s.name = "sweep";
  s.key = key;
  s.title = "sweep of " + key;
  for (double v : values) {
    RunSpec r;
    r.value = v;
    r.params = base;
    applyParameter(r.params, key, v);
    try {
      r.params.validate();
    } catch (const ParamError& e) {
      throw ParamError(key, "value " + fmt(v) + " gives invalid parameters (" + e.what() + ")");
    }
    r.label = key + "=" + fmt(v);
    s.runs.push_back(std::move(r));
  }
  return s;
}

std::optional<Study> paperStudy(const std::string& name, const ShaftParams& base) {
  Study s;
  if (name == "response") {
    s.name = name;
    s.title = "baseline response (Section 3.1)";
    s.figures = "2-5";
    RunSpec r;
    r.label = "baseline";
    r.params = base;
    r.params.validate();
    s.runs.push_back(r);
    return s;
  }
  if (name == "preload") {
    s = sweepStudy("guide_ropes.preload", {4.8e4, 5.4e4, 6e4}, base);
    s.title = "total preload Tb1 + Tb2, Tb1 = Tb2 (Section 3.2, case 1)";
    s.figures = "6-7";
    for (auto& r : s.runs) r.label = "Tb1+Tb2=" + fmt(r.value) + " N";
  } else if (name == "tension-difference") {
    ShaftParams b = base;
    applyParameter(b, "guide_ropes.preload", 6e4);
    s = sweepStudy("guide_ropes.preload_difference", {0.0, 5000.0, 10000.0}, b);
    s.title = "tension difference dT = Tb2 - Tb1 at Tb1 + Tb2 = 6e4 N (Section 3.2, case 2)";
    s.figures = "8-9";
    for (auto& r : s.runs) r.label = "dT=" + fmt(r.value) + " N";
  } else if (name == "eccentric-load") {
    s = sweepStudy("load.eccentric_force", {1000.0, 2000.0, 3000.0}, base);
    s.title = "eccentric load Fa (Section 3.3)";
    s.figures = "10-11";
    for (auto& r : s.runs) r.label = "Fa=" + fmt(r.value) + " N";
  } else if (name == "mass") {
    s = sweepStudy("cage.mass_and_inertia", {800.0, 1200.0, 1600.0}, base);
    s.title = "cage mass m with J in proportion (Section 3.3)";
    s.figures = "12-13";
    for (auto& r : s.runs) r.label = "m=" + fmt(r.params.m) + " kg, J=" + fmt(r.params.J);
  } else {
    return std::nullopt;
  }
  s.name = name;
  return s;
}

// ---- metrics -------------------------------------------------------------------

std::vector<Window> stageWindows(const HoistProfile& profile) {
  const auto& smp = profile.samples();
  double best = 0.0, b0 = 0.0, b1 = 0.0;
  std::size_t i = 0;
  while (i < smp.size()) {
    auto cruising = [&](std::size_t k) {
      return std::abs(smp[k].k.a) < 1e-9 && std::abs(smp[k].k.v) > 1e-6;
    };
    if (!cruising(i)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < smp.size() && cruising(j + 1)) ++j;
    if (smp[j].t - smp[i].t > best) {
      best = smp[j].t - smp[i].t;
      b0 = smp[i].t;
      b1 = smp[j].t;
    }
    i = j + 1;
  }
  if (!(best > 0.0) || !(profile.endTime() > b1)) return paperWindows();
  // The sampled profile reaches a = 0 one sample after the corner; round the
  // stage ends to the nearest 0.1 s so the paper's profile gives 5-50 / 50-60 s.
  auto r = [](double t) { return std::round(t * 10.0) / 10.0; };
  return {{"trip", -1e300, 1e300}, {"uniform", r(b0), r(b1)}, {"decel", r(b1), profile.endTime()}};
}

MetricSet runMetrics(const RunResult& r, const std::vector<Window>& windows,
                     const FrequencyOptions& fopt) {
  MetricSet m;
  const Trace& tr = r.trace;
  const std::vector<double> exc = tr.excursion(r.spec.params.h);
  const std::vector<std::pair<std::string, const std::vector<double>*>> sig = {
      {"y_c", &tr.y_c},           {"theta", &tr.theta},       {"excursion", &exc},
      {"lambda_0", &tr.lambda[0]}, {"lambda_1", &tr.lambda[1]}, {"lambda_2", &tr.lambda[2]},
      {"lambda_3", &tr.lambda[3]}, {"lambda_4", &tr.lambda[4]}};
  for (const auto& w : windows) {
    const std::string suf = w.name == "trip" ? "" : "_" + w.name;
    for (const auto& [name, y] : sig) m.set("peak_" + name + suf, peakAbs(tr.t, *y, w.t0, w.t1));
  }
  for (const auto& [name, y] : sig) m.set("rms_" + name, rms(tr.t, *y, -1e300, 1e300));
  for (const auto& w : windows) {
    if (w.name == "trip") continue;
    for (const auto& [name, y] : sig) {
      if (name != "y_c" && name != "theta" && name != "lambda_1") continue;
      m.set("f_" + name + "_" + w.name, dominantFrequencyFFT(tr.t, *y, w.t0, w.t1, fopt));
      m.set("fc_" + name + "_" + w.name, spectralCentroid(tr.t, *y, w.t0, w.t1, fopt));
      m.set("fzc_" + name + "_" + w.name,
            zeroCrossingFrequency(tr.t, *y, w.t0, w.t1, fopt.detrend_degree));
      m.set("osc_" + name + "_" + w.name, oscillationAmplitude(tr.t, *y, w.t0, w.t1, fopt.detrend_degree));
    }
  }
  return m;
}

}  // namespace hoist::study
