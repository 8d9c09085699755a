// The hub's trends (Hub's members; docs/dashboard.md): the min/max
// decimation of the cage and estimate streams (MinMaxDecimator) and the
// per-shaft history of the decimated samples that a page loads when it
// opens (historyOf).  Called on the hub's thread (flushDecimated, the
// history endpoint); the rest of the hub is hub.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "hub.hpp"

namespace hoist::dash {

// ---- MinMaxDecimator -----------------------------------------------------------

void MinMaxDecimator::foldMin(Json& acc, const Json& v) {
  if (acc.is_object() && v.is_object()) {
    for (auto it = acc.begin(); it != acc.end(); ++it) {
      const auto f = v.find(it.key());
      if (f != v.end()) foldMin(it.value(), *f);
    }
  } else if (acc.is_array() && v.is_array() && acc.size() == v.size()) {
    for (std::size_t i = 0; i < acc.size(); ++i) foldMin(acc[i], v[i]);
  } else if (acc.is_number() && v.is_number()) {
    if (v.get<double>() < acc.get<double>()) acc = v;
  } else if (acc.is_boolean() && v.is_boolean()) {
    acc = acc.get<bool>() && v.get<bool>();
  }
}

void MinMaxDecimator::foldMax(Json& acc, const Json& v) {
  if (acc.is_object() && v.is_object()) {
    for (auto it = acc.begin(); it != acc.end(); ++it) {
      const auto f = v.find(it.key());
      if (f != v.end()) foldMax(it.value(), *f);
    }
  } else if (acc.is_array() && v.is_array() && acc.size() == v.size()) {
    for (std::size_t i = 0; i < acc.size(); ++i) foldMax(acc[i], v[i]);
  } else if (acc.is_number() && v.is_number()) {
    if (v.get<double>() > acc.get<double>()) acc = v;
  } else if (acc.is_boolean() && v.is_boolean()) {
    acc = acc.get<bool>() || v.get<bool>();
  }
}

void MinMaxDecimator::add(const Json& sample) {
  if (count_ == 0) {
    // Only numbers and booleans are folded; strings are dropped from min/max.
    Json keep = Json::object();
    if (sample.is_object())
      for (auto it = sample.begin(); it != sample.end(); ++it)
        if (it->is_number() || it->is_boolean() || it->is_array()) keep[it.key()] = *it;
    min_ = max_ = keep;
    first_ = Json{{"t", sample.value("t", 0.0)}, {"utime", sample.value("utime", std::int64_t{0})}};
  } else {
    foldMin(min_, sample);
    foldMax(max_, sample);
  }
  last_ = sample;
  ++count_;
}

Json MinMaxDecimator::take() {
  Json out{{"count", count_}, {"first", first_}, {"last", last_}, {"min", min_}, {"max", max_}};
  count_ = 0;
  first_ = last_ = min_ = max_ = Json();
  return out;
}

const std::vector<std::string>& Hub::historyFields() {
  static const std::vector<std::string> f{"y_c",       "theta",     "lambdas.0",     "lambdas.1",
                                          "lambdas.2", "lambdas.3", "lambdas.4",     "min_clearance",
                                          "v",         "l",         "rope_slack_threshold", "rope_overload_threshold"};
  return f;
}

namespace {
double fieldOf(const Json& m, const std::string& f) {
  const Json* v = nullptr;
  if (f.rfind("lambdas.", 0) == 0) {
    const auto k = static_cast<std::size_t>(f[8] - '0');
    const auto it = m.find("lambdas");
    if (it != m.end() && it->is_array() && k < it->size()) v = &(*it)[k];
  } else if (const auto it = m.find(f); it != m.end()) {
    v = &*it;
  }
  return v != nullptr && v->is_number() ? v->get<double>() : std::nan("");
}
}  // namespace

void Hub::addHistory(const std::string& prefix, const Json& d) {
  if (!d.is_object() || !d.contains("last") || !d["last"].is_object()) return;
  const std::int64_t t0 = d.value("first", Json::object()).value("utime", std::int64_t{0});
  const std::int64_t t1 = d["last"].value("utime", std::int64_t{0});
  if (t1 <= 0) return;
  auto& h = history_[prefix];
  if (!h.empty() && t1 < h.back().last_utime) h.clear();  // a restarted daemon: time went back
  const Json& mn = d.value("count", 0) > 1 ? d["min"] : d["last"];
  const Json& mx = d.value("count", 0) > 1 ? d["max"] : d["last"];
  const auto& fields = historyFields();
  const auto bucket_us = static_cast<std::int64_t>(opt_.history_bucket_s * 1e6);
  if (h.empty() || t1 - h.back().first_utime >= bucket_us) {
    HistBucket b;
    b.first_utime = t0 > 0 ? t0 : t1;
    b.last_utime = t1;
    b.min.resize(fields.size());
    b.max.resize(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      b.min[i] = fieldOf(mn, fields[i]);
      b.max[i] = fieldOf(mx, fields[i]);
    }
    h.push_back(std::move(b));
  } else {
    HistBucket& b = h.back();
    b.last_utime = t1;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const double lo = fieldOf(mn, fields[i]), hi = fieldOf(mx, fields[i]);
      if (std::isnan(b.min[i]) || lo < b.min[i]) b.min[i] = lo;
      if (std::isnan(b.max[i]) || hi > b.max[i]) b.max[i] = hi;
    }
  }
  const auto keep_us = static_cast<std::int64_t>(opt_.history_s * 1e6);
  const std::size_t cap = static_cast<std::size_t>(opt_.history_s / std::max(1e-3, opt_.history_bucket_s)) + 16;
  while (!h.empty() && (h.front().last_utime < t1 - keep_us || h.size() > cap)) h.pop_front();
}

std::string Hub::historyOf(const std::string& prefix) const {
  Json out{{"fields", historyFields()}, {"first_utime", Json::array()}, {"last_utime", Json::array()},
           {"min", Json::array()}, {"max", Json::array()}};
  const auto it = history_.find(prefix);
  if (it != history_.end()) {
    auto row = [](const std::vector<double>& v) {
      Json r = Json::array();
      // 6 significant digits (a trend's resolution): half the JSON.
      char buf[32];
      for (double x : v) {
        if (!std::isfinite(x)) {
          r.push_back(nullptr);
          continue;
        }
        std::snprintf(buf, sizeof buf, "%.6g", x);
        r.push_back(std::strtod(buf, nullptr));
      }
      return r;
    };
    for (const auto& b : it->second) {
      out["first_utime"].push_back(b.first_utime);
      out["last_utime"].push_back(b.last_utime);
      out["min"].push_back(row(b.min));
      out["max"].push_back(row(b.max));
    }
  }
  return out.dump();
}

}  // namespace hoist::dash
