// hoist._hoist._trips, _trip, _record_trips (python/src/trips_py.hpp).
//
// _trips: the columns of `hoist-trips list --format csv` (tools/trips/report.cpp,
// listCsvRow), one numpy array each: numbers as float64 (a sigma not observed,
// empty in the CSV, is nan; so is the preload scale of a trip without an
// identification), trip as int64, mismatch/informative as bool, wall_start/
// wall_end as datetime64[us] (UTC), direction/alarms/shaft as str.
// _trip / _record_trips: a record as a dict of every stored column by the
// schema's names (hoist/history/schema.hpp, as `hoist-trips show` prints
// them), plus shaft, trip and bins (the depth bins' columns as arrays).
#include "trips_py.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "config_py.hpp"
#include "errors.hpp"
#include "estimate_py.hpp"
#include "hoist/history/condition_config.hpp"
#include "hoist/history/config.hpp"
#include "hoist/history/schema.hpp"
#include "hoist/history/store.hpp"
#include "hoist/trip_pipeline.hpp"
#include "tasks.hpp"

namespace py = pybind11;

namespace hoist::python {

namespace {

using history::Kind;

/// The database `url` names, opened read-only (SQLite: never created or
/// migrated; a missing file is an error).  ValueError naming db_url for a bad
/// URL; history::StoreError (hoist.HistoryError) for a database we cannot read.
std::unique_ptr<history::Store> openReadOnly(const std::string& url) {
  history::StoreOptions so;
  try {
    history::HistoryConfig cfg;
    const auto u = history::parseDatabaseUrl(url, "db_url");
    cfg.url = u.backend == history::Backend::Sqlite ? std::filesystem::absolute(u.target).string() : url;
    so = history::resolveStoreOptions(cfg, "", "db_url");
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  so.read_only = true;
  return history::openStore(so);
}

double nanIfNegative(double sigma) { return sigma < 0.0 ? std::nan("") : sigma; }

py::object numpyOf(const py::list& values, const char* dtype) {
  return py::module_::import("numpy").attr("array")(values, py::arg("dtype") = dtype);
}

py::array_t<std::int64_t> int64Array(const std::vector<std::int64_t>& v) {
  py::array_t<std::int64_t> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::object valueObject(const history::Value& v) {
  switch (v.kind) {
    case Kind::Real: return py::float_(v.real);
    case Kind::Integer: return py::int_(v.integer);
    case Kind::Boolean: return py::bool_(v.integer != 0);
    case Kind::Text: return py::str(v.text);
  }
  return py::none();
}

/// One record as a dict (see the file's head).
py::dict recordDict(const TripRecord& r) {
  py::dict d;
  d["shaft"] = r.shaft;
  d["trip"] = r.trip;
  for (const auto& f : history::tripFields()) d[py::str(std::string(f.column))] = valueObject(f.get(r));
  py::dict bins;
  for (const auto& f : history::binFields()) {
    const std::string name(f.column);
    if (f.kind == Kind::Real) {
      std::vector<double> col;
      col.reserve(r.bins.size());
      for (const auto& b : r.bins) col.push_back(f.get(b).real);
      bins[py::str(name)] = toNumpy(std::move(col));
    } else {
      std::vector<std::int64_t> col;
      col.reserve(r.bins.size());
      for (const auto& b : r.bins) col.push_back(f.get(b).integer);
      bins[py::str(name)] = int64Array(col);
    }
  }
  d["bins"] = bins;
  return d;
}

py::dict tripsTable(const std::string& url, const std::optional<std::string>& shaft) {
  std::vector<TripRecord> recs;
  {
    py::gil_scoped_release nogil;
    auto db = openReadOnly(url);
    history::ListFilter f;
    f.shaft = shaft;
    recs = db->list(f);
  }
  const std::size_t n = recs.size();
  std::vector<std::int64_t> trip, wall_start, wall_end;
  py::list direction, alarms, shafts, mismatch, informative;
  // The float columns, in the CSV's order among the others (assembled below).
  const char* real_names[] = {"t_start", "t_end", "Fa", "sigma_Fa", "moment", "sigma_moment", "preload_scale",
                              "sigma_preload_scale", "depth_start", "depth_end", "peak_speed", "imbalance",
                              "sigma_imbalance", "nis_peak", "min_clearance"};
  constexpr std::size_t kReals = sizeof real_names / sizeof real_names[0];
  std::vector<std::vector<double>> real(kReals);
  for (auto& c : real) c.reserve(n);
  const double nan = std::nan("");
  for (const auto& r : recs) {
    trip.push_back(r.trip);
    wall_start.push_back(r.wall_start_us);
    wall_end.push_back(r.wall_end_us);
    direction.append(r.direction == TripDirection::Down ? "down" : "up");
    alarms.append(history::joinAlarms(r.alarms));
    shafts.append(r.shaft);
    mismatch.append(r.mismatch);
    informative.append(r.id.informative);
    const double row[kReals] = {r.t_start, r.t_end, r.Fa_end, nanIfNegative(r.sigma_Fa_end), r.moment_end,
                                nanIfNegative(r.sigma_moment_end), r.id.attempted ? r.id.scale : nan,
                                r.id.attempted ? nanIfNegative(r.id.sigma_scale) : nan, r.depth_start, r.depth_end,
                                r.peak_speed, r.id.imbalance, nanIfNegative(r.id.sigma_imbalance), r.nis_peak,
                                r.min_clearance};
    for (std::size_t k = 0; k < kReals; ++k) real[k].push_back(row[k]);
  }
  std::vector<py::object> reals;
  for (auto& c : real) reals.push_back(toNumpy(std::move(c)));
  const auto when = [](const std::vector<std::int64_t>& us) { return int64Array(us).attr("view")("datetime64[us]"); };
  py::dict d;  // hoist-trips list --format csv's columns, in its order
  d["trip"] = int64Array(trip);
  d["direction"] = numpyOf(direction, "str");
  for (std::size_t k = 0; k < 8; ++k) d[real_names[k]] = reals[k];  // t_start .. sigma_preload_scale
  d["mismatch"] = numpyOf(mismatch, "bool");
  d["alarms"] = numpyOf(alarms, "str");
  d["shaft"] = numpyOf(shafts, "str");
  d["wall_start"] = when(wall_start);
  d["wall_end"] = when(wall_end);
  for (std::size_t k = 8; k < 11; ++k) d[real_names[k]] = reals[k];  // depth_start, depth_end, peak_speed
  d["informative"] = numpyOf(informative, "bool");
  for (std::size_t k = 11; k < kReals; ++k) d[real_names[k]] = reals[k];
  return d;
}

py::dict oneTrip(const std::string& url, std::int64_t n, const std::string& shaft) {
  std::optional<TripRecord> r;
  std::string where;
  {
    py::gil_scoped_release nogil;
    auto db = openReadOnly(url);
    r = db->get(shaft, n);
    where = db->describe();
  }
  if (!r) throw py::key_error("no trip " + std::to_string(n) + " of shaft '" + shaft + "' in " + where);
  return recordDict(*r);
}

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// hoist-trips ingest's run (tools/trips/ingest.cpp) up to the store: the same
/// shaft, settings, NIS-window sizing and substep, so the same records.
py::list recordTripsPy(const Config& cfg, const py::object& measurements, std::optional<int> modes,
                       std::optional<double> max_step_opt, const py::object& progress) {
  ShaftParams p = cfg.params;
  const io::EstimatorConfig ec = cfg.estimator();
  const ConditionSettings cond = history::conditionSettingsFromToml(cfg.tbl, cfg.source);
  const double max_step = recordedRunOptions(cfg, modes, max_step_opt, p);
  std::string source;
  const std::vector<MeasurementSample> samples = measurementSamples(measurements, source);
  EstimatorSettings set = ec.settings;
  double min_dt = samples[1].t - samples[0].t;  // the NIS window is sized for the file's rate
  for (std::size_t i = 2; i < samples.size(); ++i) min_dt = std::min(min_dt, samples[i].t - samples[i - 1].t);
  set.max_rate = std::max(set.max_rate, static_cast<int>(std::min(100000.0, std::ceil(1.0 / min_dt - 1e-9))));
  try {
    for (std::size_t i = 1; i < samples.size(); ++i) substepCount(samples[i].t - samples[i - 1].t, max_step);
  } catch (const std::invalid_argument& e) {
    throw py::value_error("max_step " + fmt(max_step) + ": " + e.what());
  }

  std::vector<TripRecord> recs;
  std::atomic<double> fraction{0.0};
  struct Stop {};
  const TaskOutcome out = runTasks(
      1, 1,
      [&](std::size_t, const std::atomic<bool>& cancel) {
        try {
          recs = recordTrips(p, set, cond, max_step, samples, [&](double f) {
            fraction.store(f);
            if (cancel.load(std::memory_order_relaxed)) throw Stop{};
          });
        } catch (const std::domain_error& e) {
          throw RunError(std::string("the model left its domain: ") + e.what());
        } catch (const Stop&) {
        }
      },
      [&](std::size_t) {
        if (!progress.is_none()) progress(fraction.load());
      });
  if (out.errors[0]) raise(out.errors[0], source + ": ");
  py::list l;
  for (const auto& r : recs) l.append(recordDict(r));
  return l;
}

}  // namespace

void bindTrips(py::module_& m) {
  py::register_exception<history::StoreError>(m, "HistoryError", PyExc_RuntimeError);
  m.def("_trips", &tripsTable, py::arg("db_url"), py::arg("shaft"));
  m.def("_trip", &oneTrip, py::arg("db_url"), py::arg("n"), py::arg("shaft"));
  m.def("_record_trips", &recordTripsPy, py::arg("cfg"), py::arg("measurements"), py::arg("modes"),
        py::arg("max_step"), py::arg("progress"));
}

}  // namespace hoist::python
