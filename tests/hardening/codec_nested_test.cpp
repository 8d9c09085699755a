// lcm_codec_gen.py on nested types, with TEST-ONLY types
// (tests/hardening/codec_nested/*.lcm, generated into this test's own
// hoist_msgs_codec copy): a nested value, a fixed array and a variable array
// of another type, two levels deep, maxima from a const by @max and by the
// num_<x> / MAX_<X> convention.  The real types (forecast_t) are covered by
// codec_test; this covers the shapes msgs/ does not use yet.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <set>

#include "hoist/msg/codec.hpp"

using namespace hoist;
using namespace hoist::msg;
using Bytes = std::vector<std::uint8_t>;

namespace {

template <class M>
Bytes encode(const M& m) {
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

codectest_leaf_t leaf(int k, const char* tag, int n) {
  codectest_leaf_t l{};
  l.k = static_cast<std::int8_t>(k);
  l.tag = tag;
  l.n = static_cast<std::int16_t>(n);
  for (int i = 0; i < n; ++i) l.v.push_back(k + 0.25 * i);
  return l;
}

codectest_inner_t inner(int base, int leaves) {
  codectest_inner_t in{};
  in.x = base * 1.5;
  in.one = leaf(base, "one", 1);
  in.pair[0] = leaf(base + 1, "p0", 2);
  in.pair[1] = leaf(base + 2, "p1", 0);
  in.num_leaves = leaves;
  for (int i = 0; i < leaves; ++i) in.leaves.push_back(leaf(base + 10 + i, "lf", i + 1));
  return in;
}

codectest_outer_t outer() {
  codectest_outer_t o{};
  o.utime = 123456789;
  o.inner = inner(1, 2);
  o.two[0] = inner(20, 0);
  o.two[1] = inner(30, 3);
  o.count = 1;
  o.more.push_back(inner(40, 1));
  o.flag = 1;
  return o;
}

// Offsets from lcm-gen's own encoded sizes (its _getEncodedSizeNoHash):
// where o.two[1] starts, and where its num_leaves and its pair[1].n are.
std::size_t twoAt(const codectest_outer_t& o, int i) {
  std::size_t at = 8 + 8 + static_cast<std::size_t>(o.inner._getEncodedSizeNoHash());
  for (int k = 0; k < i; ++k) at += static_cast<std::size_t>(o.two[k]._getEncodedSizeNoHash());
  return at;
}
std::size_t numLeavesAt(const codectest_inner_t& in, std::size_t inner_at) {
  return inner_at + 8 + static_cast<std::size_t>(in.one._getEncodedSizeNoHash()) +
         static_cast<std::size_t>(in.pair[0]._getEncodedSizeNoHash()) +
         static_cast<std::size_t>(in.pair[1]._getEncodedSizeNoHash());
}
std::size_t pairNAt(const codectest_inner_t& in, std::size_t inner_at, int p) {
  std::size_t at = inner_at + 8 + static_cast<std::size_t>(in.one._getEncodedSizeNoHash());
  for (int k = 0; k < p; ++k) at += static_cast<std::size_t>(in.pair[k]._getEncodedSizeNoHash());
  return at + 1 + 4 + in.pair[p].tag.size() + 1;  // k, tag
}
void put(Bytes& b, std::size_t at, std::int64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i)
    b[at + i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * (bytes - 1 - i)));
}

}  // namespace

TEST(CodecGenNested, FingerprintsEqualLcmGen) {
  EXPECT_EQ(allTypes().size(), 3u);
  EXPECT_EQ(findByName("codectest_leaf_t")->fingerprint, codectest_leaf_t::getHash());
  EXPECT_EQ(findByName("codectest_inner_t")->fingerprint, codectest_inner_t::getHash());
  EXPECT_EQ(findByName("codectest_outer_t")->fingerprint, codectest_outer_t::getHash());
}

TEST(CodecGenNested, RoundTripJsonAndEveryTruncation) {
  const codectest_outer_t o = outer();
  const Bytes b = encode(o);
  const TypeInfo* info = findByName("codectest_outer_t");
  ASSERT_NE(info, nullptr);
  EXPECT_LE(b.size(), info->max_size);
  codectest_outer_t d;
  ASSERT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::ok);
  EXPECT_EQ(encode(d), b);
  const auto j = toJson(d);
  EXPECT_EQ(j.at("two")[1].at("leaves")[2].at("v").size(), 3u);
  EXPECT_EQ(j.at("inner").at("pair")[0].at("tag"), "p0");
  EXPECT_EQ(j.at("more")[0].at("one").at("k"), 40);
  EXPECT_EQ(j.at("flag"), true);
  codectest_outer_t back;
  std::string err;
  ASSERT_TRUE(fromJson(nlohmann::json::parse(j.dump()), back, err)) << err;
  EXPECT_EQ(encode(back), b);
  nlohmann::json j2;
  DecodeStatus st{};
  ASSERT_TRUE(info->bytesToJson(b.data(), b.size(), j2, st));
  EXPECT_EQ(j2, j);
  for (std::size_t n = 0; n < b.size(); ++n)
    EXPECT_NE(checkedDecode(b.data(), n, d), DecodeStatus::ok) << n;
  Bytes longer = b;
  longer.push_back(0);
  EXPECT_EQ(checkedDecode(longer.data(), longer.size(), d), DecodeStatus::too_large);
  // The largest valid encoding is exactly max_size.
  codectest_outer_t big{};
  auto full_leaf = leaf(1, "12345678", codectest_leaf_t::MAX_N);
  auto full_inner = [&] {
    codectest_inner_t in{};
    in.one = full_leaf;
    in.pair[0] = in.pair[1] = full_leaf;
    in.num_leaves = codectest_inner_t::MAX_LEAVES;
    in.leaves.assign(codectest_inner_t::MAX_LEAVES, full_leaf);
    return in;
  }();
  big.inner = big.two[0] = big.two[1] = full_inner;
  big.count = 2;
  big.more = {full_inner, full_inner};
  const Bytes bb = encode(big);
  EXPECT_EQ(bb.size(), info->max_size);
  EXPECT_EQ(checkedDecode(bb.data(), bb.size(), d), DecodeStatus::ok);
}

TEST(CodecGenNested, CountsInsideFixedArraysAndTwoLevelsDown) {
  const codectest_outer_t o = outer();
  const Bytes good = encode(o);
  codectest_outer_t d;
  const std::size_t t1 = twoAt(o, 1);
  const std::size_t nl = numLeavesAt(o.two[1], t1);
  {
    Bytes b = good;  // sanity: the offsets point where we think
    ASSERT_EQ(good[nl + 3], 3);
    ASSERT_EQ(good[pairNAt(o.two[1], t1, 0) + 1], 2);
  }
  // num_leaves of two[1]: MAX_LEAVES = 3 by the naming convention.
  for (std::int64_t n : {-1LL, 4LL, static_cast<long long>(INT32_MIN), static_cast<long long>(INT32_MAX)}) {
    Bytes b = good;
    put(b, nl, n, 4);
    EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::bad_count) << n;
  }
  // pair[0].n and pair[1].n inside two[1] (a fixed array of a nested type
  // inside a fixed array): MAX_N = 4 by @max n MAX_N.
  for (int p : {0, 1}) {
    for (std::int64_t n : {-1LL, 5LL, 32767LL, -32768LL}) {
      Bytes b = good;
      put(b, pairNAt(o.two[1], t1, p), n, 2);
      EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::bad_count) << p << " " << n;
    }
  }
  // The outer count (@max count 2) and a lie about it.
  const std::size_t count_at = twoAt(o, 2);
  ASSERT_EQ(good[count_at], 1);
  for (int n : {-1, 3, 127}) {
    Bytes b = good;
    b[count_at] = static_cast<std::uint8_t>(static_cast<std::int8_t>(n));
    EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::bad_count) << n;
  }
  Bytes b = good;
  b[count_at] = 2;  // only one inner present
  EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::truncated);
  // A nested string over its @maxlen (8).
  codectest_outer_t s = o;
  s.two[1].pair[1].tag = "123456789";
  const Bytes bs = encode(s);
  EXPECT_EQ(checkedDecode(bs.data(), bs.size(), d), DecodeStatus::bad_string);
  s.two[1].pair[1].tag = "12345678";
  const Bytes ok = encode(s);
  EXPECT_EQ(checkedDecode(ok.data(), ok.size(), d), DecodeStatus::ok);
}

TEST(CodecGenNested, FromJsonPathsAndSchema) {
  const auto j = toJson(outer());
  codectest_outer_t d;
  std::string err;
  auto bad = j;
  bad["two"][1]["pair"][0]["v"][1] = "x";
  EXPECT_FALSE(fromJson(bad, d, err));
  EXPECT_NE(err.find("'two[1]'"), std::string::npos) << err;
  EXPECT_NE(err.find("'pair[0]'"), std::string::npos) << err;
  EXPECT_NE(err.find("'v[1]'"), std::string::npos) << err;
  bad = j;
  bad["two"].erase(1);  // a fixed array of 2 with 1 element
  EXPECT_FALSE(fromJson(bad, d, err));
  EXPECT_NE(err.find("'two'"), std::string::npos) << err;
  bad = j;
  bad["inner"]["one"]["tag"] = "123456789";
  EXPECT_FALSE(fromJson(bad, d, err));
  EXPECT_NE(err.find("'tag'"), std::string::npos) << err;
  bad = j;
  bad["inner"] = nlohmann::json::array();
  EXPECT_FALSE(fromJson(bad, d, err));
  EXPECT_NE(err.find("'inner'"), std::string::npos) << err;

  const auto s = nlohmann::json::parse(jsonSchema<codectest_outer_t>());
  const auto& two = s.at("properties").at("two");
  EXPECT_EQ(two.at("type"), "array");
  EXPECT_EQ(two.at("minItems"), 2);
  EXPECT_EQ(two.at("maxItems"), 2);
  const auto& in = two.at("items");
  EXPECT_EQ(in.at("title"), "hoist.codectest_inner_t");
  EXPECT_FALSE(in.contains("$schema"));
  EXPECT_EQ(in.at("properties").at("num_leaves").at("maximum"), 3);
  EXPECT_EQ(in.at("properties").at("leaves").at("maxItems"), 3);
  EXPECT_EQ(in.at("properties").at("pair").at("items").at("properties").at("n").at("maximum"), 4);
  EXPECT_EQ(in.at("properties").at("one").at("properties").at("tag").at("maxLength"), 8);
  EXPECT_EQ(s.at("properties").at("more").at("maxItems"), 2);
  // Schema keys = toJson keys at every level.
  std::function<void(const nlohmann::json&, const nlohmann::json&)> same = [&](const nlohmann::json& sch,
                                                                             const nlohmann::json& v) {
    if (v.is_object()) {
      std::set<std::string> a, r;
      for (auto it = v.begin(); it != v.end(); ++it) a.insert(it.key());
      for (const auto& k : sch.at("required")) r.insert(k.get<std::string>());
      EXPECT_EQ(a, r) << sch.at("title");
      for (auto it = v.begin(); it != v.end(); ++it) same(sch.at("properties").at(it.key()), it.value());
    } else if (v.is_array()) {
      for (const auto& e : v) same(sch.at("items"), e);
    }
  };
  same(s, j);
}

// allFinite and the CSV columns reach every nesting shape: a nested value,
// a fixed array of them, two levels down, inside a variable array.
TEST(CodecGenNested, AllFiniteAndCsvReachNestedValues) {
  codectest_outer_t o = outer();
  EXPECT_TRUE(allFinite(o));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  using Place = std::function<double&(codectest_outer_t&)>;
  const std::vector<Place> places = {
      [](codectest_outer_t& m) -> double& { return m.inner.x; },
      [](codectest_outer_t& m) -> double& { return m.inner.one.v[0]; },
      [](codectest_outer_t& m) -> double& { return m.two[1].pair[0].v[1]; },
      [](codectest_outer_t& m) -> double& { return m.two[1].leaves[2].v[2]; },
      [](codectest_outer_t& m) -> double& { return m.more[0].leaves[0].v[0]; }};
  for (const Place& at : places) {
    codectest_outer_t bad = outer();
    at(bad) = nan;
    EXPECT_FALSE(allFinite(bad));
    at(bad) = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(allFinite(bad));
  }

  std::string header, row;
  csvHeader<codectest_outer_t>(header);
  csvRow(row, o);
  EXPECT_EQ(header.rfind("utime,inner.x,inner.one.k,inner.one.tag,inner.one.n,inner.pair_0.k,", 0), 0u) << header;
  EXPECT_NE(header.find(",two_1.pair_1.n,two_1.num_leaves,count,flag"), std::string::npos) << header;
  EXPECT_EQ(header.find("leaves_"), std::string::npos) << header;  // variable arrays: no columns
  EXPECT_EQ(header.find("more"), std::string::npos) << header;
  EXPECT_EQ(row.rfind("123456789,1.5,1,\"one\",1,2,\"p0\",2,", 0), 0u) << row;
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
  EXPECT_TRUE(allEnums().empty());  // no @enum in these types
}
