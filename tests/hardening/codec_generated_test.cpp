// What lcm_codec_gen.py generates besides the decoders and JSON, for every
// type in msgs/: allFinite() (a NaN or an infinity in ANY float/double --
// scalar, fixed or variable array element, nested value -- is caught), the
// CSV writers (header and row agree; hoist-sim's columns first for
// cage_state_t) and the name tables of the `@enum` members (they match the
// .lcm constants as lcm-gen and the JSON Schema give them); the `@channel`
// names equal hoist/bus/channels.hpp's.
//
// The messages are built from each type's JSON Schema, not by hand: every
// number 1.5, every string a comma and a quote, every variable array two
// elements; a test therefore covers a member added to a .lcm file without
// being edited.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "hoist/bus/channels.hpp"
#include "hoist/msg/codec.hpp"

using namespace hoist;
using namespace hoist::msg;
using nlohmann::json;
using Bytes = std::vector<std::uint8_t>;

namespace {

constexpr int kVarElements = 2;


/// The variable array's count member, from the schema's "(length: COUNT)".
std::string lengthOf(const json& s) {
  const std::string d = s.value("description", "");
  const auto p = d.rfind("(length: ");
  return p == std::string::npos ? "" : d.substr(p + 9, d.find(')', p) - p - 9);
}

/// A valid JSON value of schema `s`; every real `fill`, except the real at
/// leaf number `target` (counted in document order) which is `special`.
json sample(const json& s, int& leaf, int target, double fill, double special) {
  const std::string type = s.at("type").is_string() ? s.at("type").get<std::string>() : "number";
  if (type == "object") {
    json o = json::object();
    std::set<std::string> counts;
    for (auto it = s.at("properties").begin(); it != s.at("properties").end(); ++it)
      if (!lengthOf(it.value()).empty()) counts.insert(lengthOf(it.value()));
    for (auto it = s.at("properties").begin(); it != s.at("properties").end(); ++it)
      o[it.key()] = counts.count(it.key()) ? json(kVarElements) : sample(it.value(), leaf, target, fill, special);
    return o;
  }
  if (type == "array") {
    const int n = s.contains("minItems") ? s.at("minItems").get<int>() : kVarElements;
    json a = json::array();
    for (int i = 0; i < n; ++i) a.push_back(sample(s.at("items"), leaf, target, fill, special));
    return a;
  }
  if (type == "string") return "a,\"b\"";
  if (type == "boolean") return true;
  if (type == "integer") return 1;
  return leaf++ == target ? special : fill;  // a real
}

template <class M>
Bytes encode(const M& m) {
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

/// Builds the sample of M with the leaf-th real equal to `marker`, encodes
/// it, and overwrites the marker's 8 bytes with `bad` (JSON cannot carry a
/// NaN): a message with exactly one non-finite double, at any depth.
template <class M>
bool withOneBadReal(int target, double bad, M& out, int& leaves) {
  const double marker = 12345.6789 + target;
  int leaf = 0;
  M m{};
  std::string err;
  const json j = sample(json::parse(jsonSchema<M>()), leaf, target, 1.5, marker);
  leaves = leaf;
  if (target >= leaf) return false;
  EXPECT_TRUE(fromJson(j, m, err)) << err;
  Bytes b = encode(m);
  std::uint64_t u = 0;
  std::memcpy(&u, &marker, 8);
  std::uint8_t be[8], nb[8];
  std::uint64_t v = 0;
  std::memcpy(&v, &bad, 8);
  for (int i = 0; i < 8; ++i) {
    be[i] = static_cast<std::uint8_t>(u >> (56 - 8 * i));
    nb[i] = static_cast<std::uint8_t>(v >> (56 - 8 * i));
  }
  int found = 0;
  for (std::size_t i = 0; i + 8 <= b.size(); ++i)
    if (std::memcmp(b.data() + i, be, 8) == 0) {
      std::memcpy(b.data() + i, nb, 8);
      ++found;
    }
  EXPECT_EQ(found, 1) << "real #" << target << " (a float member? extend this test)";
  EXPECT_EQ(checkedDecode(b.data(), b.size(), out), DecodeStatus::ok);
  return true;
}

template <class M>
void expectAllFiniteCatchesEveryReal(const char* name) {
  SCOPED_TRACE(name);
  int leaves = 0, leaf = 0;
  M good{};
  std::string err;
  ASSERT_TRUE(fromJson(sample(json::parse(jsonSchema<M>()), leaf, -1, 1.5, 0.0), good, err)) << err;
  EXPECT_TRUE(allFinite(good));
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()}) {
    for (int target = 0;; ++target) {
      M m{};
      if (!withOneBadReal(target, bad, m, leaves)) break;
      EXPECT_FALSE(allFinite(m)) << "real #" << target << " = " << bad << " not caught";
    }
  }
  EXPECT_EQ(leaves, leaf);
  EXPECT_GT(leaf, 0);  // every type of msgs/ has a double
}

/// RFC 4180 fields of one line.
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') out.back() += c, ++i;
      else if (c == '"') quoted = false;
      else out.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

template <class M>
void expectCsvHeaderMatchesRow(const char* name) {
  SCOPED_TRACE(name);
  int leaf = 0;
  M m{};
  std::string err;
  ASSERT_TRUE(fromJson(sample(json::parse(jsonSchema<M>()), leaf, -1, 1.5, 0.0), m, err)) << err;
  std::string header, row;
  csvHeader<M>(header);
  csvRow(row, m);
  EXPECT_EQ(header.find('\n'), std::string::npos);
  EXPECT_EQ(row.find('\n'), std::string::npos);
  const auto h = splitCsv(header), r = splitCsv(row);
  EXPECT_EQ(h.size(), csvColumns<M>().size());
  EXPECT_EQ(h.size(), r.size()) << header << "\n" << row;
  std::set<std::string> unique(h.begin(), h.end());
  EXPECT_EQ(unique.size(), h.size()) << "a column name twice: " << header;
  for (std::size_t i = 0; i < h.size() && i < r.size(); ++i) {
    EXPECT_FALSE(h[i].empty());
    EXPECT_FALSE(r[i].empty()) << h[i];
  }
}

}  // namespace

#define HOIST_ALL_FINITE(T) expectAllFiniteCatchesEveryReal<T>(#T);
#define HOIST_CSV(T) expectCsvHeaderMatchesRow<T>(#T);

TEST(CodecGenerated, AllFiniteCatchesANonFiniteRealAnywhere) { HOIST_MSG_FOR_EACH_TYPE(HOIST_ALL_FINITE) }

TEST(CodecGenerated, AllFiniteCoversNestedVariableArrays) {
  // forecast_t: a NaN in the last series point of the second scenario.
  forecast_t f{};
  f.num_scenarios = 2;
  f.scenarios.resize(2);
  for (auto& s : f.scenarios) {
    s.num_points = 3;
    s.series_t = s.series_min_clearance = s.series_lambda0_min = s.series_lambda0_max = {1, 2, 3};
  }
  EXPECT_TRUE(allFinite(f));
  f.scenarios[1].series_lambda0_max[2] = std::nan("");
  EXPECT_FALSE(allFinite(f));
  f.scenarios[1].series_lambda0_max[2] = 0;
  f.scenarios[0].peak_lambdas[3] = -std::numeric_limits<double>::infinity();
  EXPECT_FALSE(allFinite(f));
}

TEST(CodecGenerated, CsvHeaderAndRowHaveTheSameColumns) { HOIST_MSG_FOR_EACH_TYPE(HOIST_CSV) }

TEST(CodecGenerated, CsvCageColumnsStartWithHoistSims) {
  std::string h;
  csvHeader<cage_state_t>(h);
  EXPECT_EQ(h.rfind("t,l,v,a,x_c,y_c,theta,lambda_0,lambda_1,lambda_2,lambda_3,lambda_4,utime,seq,", 0), 0u) << h;
  cage_state_t m{};
  m.t = 0.1;
  m.lambdas[4] = -2.5;
  m.alarm_level = alarm_t::LEVEL_CRITICAL;
  std::string r;
  csvRow(r, m);
  const auto cols = splitCsv(h), vals = splitCsv(r);
  ASSERT_EQ(cols.size(), vals.size());
  std::map<std::string, std::string> row;
  for (std::size_t i = 0; i < cols.size(); ++i) row[cols[i]] = vals[i];
  EXPECT_EQ(row["t"], "0.10000000000000001");  // 17 significant digits: round-trip exact
  EXPECT_EQ(std::stod(row["t"]), 0.1);
  EXPECT_EQ(row["lambda_4"], "-2.5");
  EXPECT_EQ(row["alarm_level"], "2");  // a plain integer: not an @enum member of cage_state_t
  for (const char* c : {"instance_id", "input_seq", "min_clearance", "degraded", "rope_overload_threshold"})
    EXPECT_TRUE(row.count(c)) << c;
}

TEST(CodecGenerated, CsvAlarmWritesNamesAndQuotesText) {
  alarm_t a{};
  a.kind = "CAGE_POS_Y";
  a.level = alarm_t::LEVEL_WARNING;
  a.event_type = alarm_t::EVENT_SHELVE;
  a.message = "two\nlines, \"quoted\"";
  std::string h, r;
  csvHeader<alarm_t>(h);
  csvRow(r, a);
  EXPECT_EQ(h.rfind("utime,id,t,kind,level,event,active,acked,shelved,latched,value,threshold,shelved_for,message", 0),
            0u)
      << h;
  EXPECT_NE(r.find(",\"CAGE_POS_Y\",WARNING,SHELVE,"), std::string::npos) << r;
  EXPECT_NE(r.find(",\"two lines, \"\"quoted\"\"\","), std::string::npos) << r;
  a.level = 7;
  a.event_type = 0;
  r.clear();
  csvRow(r, a);
  EXPECT_NE(r.find(",?,?,"), std::string::npos) << r;  // no name for the value
  // The forecast's scenario columns: peak_lambdas named as the sleeves are.
  std::string s;
  csvHeader<forecast_scenario_t>(s);
  EXPECT_NE(s.find(",peak_lambda_1,peak_lambda_2,peak_lambda_3,peak_lambda_4,"), std::string::npos) << s;
  EXPECT_EQ(s.find("series_"), std::string::npos) << s;  // variable arrays: no columns
}

TEST(CodecGenerated, NameTablesMatchTheLcmConstants) {
  namespace names = enums::alarm_t;
  // Against lcm-gen's constants.
  EXPECT_EQ(names::levelName(alarm_t::LEVEL_NONE), "NONE");
  EXPECT_EQ(names::levelName(alarm_t::LEVEL_WARNING), "WARNING");
  EXPECT_EQ(names::levelName(alarm_t::LEVEL_CRITICAL), "CRITICAL");
  EXPECT_EQ(names::eventName(alarm_t::EVENT_RAISE), "RAISE");
  EXPECT_EQ(names::eventName(alarm_t::EVENT_REANNOUNCE), "REANNOUNCE");
  EXPECT_EQ(names::kindName(alarm_t::KIND_CAGE_POS_Y), "CAGE_POS_Y");
  EXPECT_EQ(names::kindName(alarm_t::KIND_PREDICTED_SLACK), "PREDICTED_SLACK");
  EXPECT_EQ(names::kindName(alarm_t::KIND_MODEL_MISMATCH), "MODEL_MISMATCH");
  EXPECT_EQ(names::kindName(alarm_t::KIND_SENSOR_FAULT), "SENSOR_FAULT");
  EXPECT_EQ(names::kindName(alarm_t::KIND_GUIDE_PRELOAD_LOW), "GUIDE_PRELOAD_LOW");
  EXPECT_EQ(names::kindName(alarm_t::KIND_SHAFT_FINGERPRINT), "SHAFT_FINGERPRINT");
  EXPECT_EQ(names::kKindNames.size(), 15u);
  EXPECT_EQ(names::levelName(3), "?");
  EXPECT_EQ(names::levelName(-1), "?");
  EXPECT_EQ(names::eventName(0), "?");
  EXPECT_EQ(names::parseLevel("CRITICAL"), std::optional<std::int64_t>(+alarm_t::LEVEL_CRITICAL));
  EXPECT_EQ(names::parseLevel("critical"), std::nullopt);
  EXPECT_EQ(names::parseKind("ROPE_OVERLOAD"), std::optional<std::int64_t>(+alarm_t::KIND_ROPE_OVERLOAD));

  // Every table against its type's constants in the JSON Schema: each const
  // PREFIX_<NAME> is in the table at its value, and nothing else is.
  std::set<std::string> seen;
  for (const EnumInfo& e : allEnums()) {
    SCOPED_TRACE(std::string(e.type) + "." + e.member);
    seen.insert(std::string(e.type) + "." + e.member);
    const TypeInfo* t = findByName(e.type);
    ASSERT_NE(t, nullptr);
    const json consts = json::parse(t->schema).at("x-lcm-constants");
    const std::string prefix = e.prefix;
    std::size_t n = 0;
    for (auto it = consts.begin(); it != consts.end(); ++it) {
      if (it.key().rfind(prefix, 0) != 0) continue;
      ++n;
      const auto i = it.value().get<std::int64_t>() - e.first;
      ASSERT_GE(i, 0) << it.key();
      ASSERT_LT(i, static_cast<std::int64_t>(e.names.size())) << it.key();
      EXPECT_EQ(e.names[static_cast<std::size_t>(i)], it.key().substr(prefix.size()));
    }
    EXPECT_EQ(n, e.names.size());
  }
  EXPECT_EQ(seen, (std::set<std::string>{"hoist.alarm_t.level", "hoist.alarm_t.event_type", "hoist.alarm_t.kind"}));
}

TEST(CodecGenerated, ChannelsMatchBusChannels) {
  // The channel names are a contract (exact): every name clients have been
  // told is still annotated (`// @channel` in the .lcm files: kChannels) on
  // the same type, and the generated C++ names the programs use
  // (hoist/bus/channels.hpp) spell it.  A renamed or removed channel fails
  // here; a new one is its annotation alone (it joins kChannels and the
  // bus names, which must agree).
  const std::map<std::string_view, std::string_view> contract = {
      {"hoist.winder_t", "HOIST_WINDER"},          {"hoist.cage_state_t", "HOIST_CAGE"},
      {"hoist.guide_shape_t", "HOIST_GUIDE_SHAPE"}, {"hoist.alarm_t", "HOIST_ALARM"},
      {"hoist.alarm_ack_t", "HOIST_ALARM_ACK"},    {"hoist.health_t", "HOIST_HEALTH"},
      {"hoist.forecast_t", "HOIST_FORECAST"},      {"hoist.trip_plan_t", "HOIST_TRIP_PLAN"},
      {"hoist.cage_imu_t", "HOIST_CAGE_IMU"},      {"hoist.rope_load_t", "HOIST_ROPE_LOAD"},
      {"hoist.estimate_t", "HOIST_ESTIMATE"}};
  const std::map<std::string_view, std::string_view> bus = {
      {"hoist.winder_t", bus::kChannelWinder},         {"hoist.cage_state_t", bus::kChannelCage},
      {"hoist.guide_shape_t", bus::kChannelGuideShape}, {"hoist.alarm_t", bus::kChannelAlarm},
      {"hoist.alarm_ack_t", bus::kChannelAlarmAck},    {"hoist.health_t", bus::kChannelHealth},
      {"hoist.forecast_t", bus::kChannelForecast},     {"hoist.trip_plan_t", bus::kChannelTripPlan},
      {"hoist.cage_imu_t", bus::kChannelCageImu},      {"hoist.rope_load_t", bus::kChannelRopeLoad},
      {"hoist.estimate_t", bus::kChannelEstimate}};
  std::map<std::string_view, std::string_view> gen;
  for (const ChannelInfo& c : kChannels) {
    EXPECT_NE(findByName(c.type), nullptr) << c.type;
    EXPECT_TRUE(gen.emplace(c.type, c.channel).second) << c.type << ": two channels";
  }
  for (const auto& [type, name] : contract) {
    const auto it = gen.find(type);
    EXPECT_TRUE(it != gen.end() && it->second == name) << type << " is no longer on " << name;
  }
  EXPECT_EQ(bus, contract);
  // bus::Channels holds one prefixed name per annotated channel (and nothing else).
  EXPECT_EQ(sizeof(bus::Channels), kChannels.size() * sizeof(std::string));
  EXPECT_EQ(bus::Channels("P/").estimate, "P/HOIST_ESTIMATE");
}
