// Running simulations on threads: see hoist/study/runner.hpp.
#include "hoist/study/runner.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "hoist/shaft_model.hpp"
#include "hoist/solver.hpp"

namespace hoist::study {

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

}  // namespace hoist::study
