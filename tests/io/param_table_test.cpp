// The one parameter table (hoist::kParamFields) drives validation, the TOML
// reader and writer and the README's key list: every key round-trips through
// the file, every bound rejects (in validate() and from a file, naming the
// key and line), and README.md lists exactly the table's keys.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "hoist/io/config.hpp"
#include "hoist/params.hpp"

using namespace hoist;

namespace {

ShaftParams parse(const std::string& text) {
  return io::shaftParamsFromToml(io::parseToml(text, "shaft.toml"), "shaft.toml");
}

/// A valid value different from the default.
void perturb(const ParamField& f, ShaftParams& p) {
  switch (f.type) {
    case ParamType::Real: p.*f.real = p.*f.real * 1.1 + 1e-7; break;
    case ParamType::Integer: p.*f.integer = 17; break;
    case ParamType::Boolean: p.*f.boolean = !(p.*f.boolean); break;
    case ParamType::Initial:
      p.*f.initial = p.*f.initial == InitialState::Static ? InitialState::Rest : InitialState::Static;
      break;
  }
}

/// Values that break the field's own bound.
std::vector<double> outOfBound(const ParamField& f) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  switch (f.bound) {
    case ParamBound::None: return {};
    case ParamBound::Finite: return {nan, inf, -inf};
    case ParamBound::Positive: return {0.0, -1.0, nan, inf};
    case ParamBound::NonNegative: return {-1e-3, nan, -inf};
    case ParamBound::Closed:
      if (f.type == ParamType::Integer) return {f.lo - 1.0, f.hi + 1.0};
      return {f.lo - 0.5, f.hi + 0.5, nan};
  }
  return {};
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(ParamTable, KeysAreUniqueAndInTheirSections) {
  std::set<std::string> seen;
  for (const auto& f : kParamFields) {
    EXPECT_TRUE(seen.insert(f.element()).second) << f.element();
    bool known = false;
    for (auto s : kParamSections) known = known || s == f.section;
    EXPECT_TRUE(known) << f.key();
    EXPECT_FALSE(f.doc.empty()) << f.key();
    EXPECT_EQ(findParam(f.element()), &f);
    // Exactly one member pointer, of the declared type.
    const int set = (f.real != nullptr) + (f.integer != nullptr) + (f.boolean != nullptr) + (f.initial != nullptr);
    EXPECT_EQ(set, 1) << f.key();
  }
  EXPECT_EQ(findParam("cage.colour"), nullptr);
  EXPECT_EQ(findParam("guide_ropes.preload"), nullptr);  // an array: only its elements are fields
  EXPECT_EQ(paramFieldsOf("guide_ropes", "preload").size(), 2u);
}

TEST(ParamTable, EveryKeyRoundTripsThroughTheFile) {
  for (const auto& f : kParamFields) {
    ShaftParams p;
    perturb(f, p);
    ASSERT_NO_THROW(p.validate()) << f.element();
    ASSERT_NE(f.get(p), f.get(ShaftParams{})) << f.element();
    const std::string text = io::toToml(p);
    const ShaftParams q = parse(text);
    EXPECT_EQ(f.get(q), f.get(p)) << f.element() << "\n" << text;
    EXPECT_TRUE(q == p) << f.element() << "\n" << text;
  }
}

TEST(ParamTable, EachBoundRejectsInValidateAndFromAFile) {
  int checked = 0;
  for (const auto& f : kParamFields) {
    for (double bad : outOfBound(f)) {
      ShaftParams p;
      f.set(p, bad);
      try {
        p.validate();
        ADD_FAILURE() << f.element() << " = " << bad << " accepted";
      } catch (const ParamError& e) {
        EXPECT_EQ(e.key(), f.key()) << e.what();
        EXPECT_EQ(e.what(), f.key() + ": " + f.check(bad));
      }
      // The same value written to a file is refused with the key and its line.
      const std::string text = io::toToml(p);
      try {
        (void)parse(text);
        ADD_FAILURE() << f.element() << " = " << bad << " accepted from\n" << text;
      } catch (const io::ConfigError& e) {
        EXPECT_EQ(e.key(), f.key()) << e.what();
        EXPECT_GT(e.line(), 0) << e.what();
        EXPECT_NE(e.message().find(f.check(bad)), std::string::npos) << e.what();
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 40);
}

TEST(ParamTable, ReadmeListsExactlyTheTablesKeys) {
  const std::string readme = readFile(std::string(HOIST_SOURCE_DIR) + "/README.md");
  const auto at = readme.find("**Shaft configuration**");
  ASSERT_NE(at, std::string::npos);
  const auto begin = readme.find("```toml\n", at);
  ASSERT_NE(begin, std::string::npos);
  const auto end = readme.find("```", begin + 8);
  const std::string block = readme.substr(begin + 8, end - begin - 8);
  // The README's values are the defaults...
  EXPECT_TRUE(parse(block) == ShaftParams{}) << block;
  // ...and its keys are the table's, in the table's order.
  std::vector<std::string> listed, expected;
  std::istringstream in(block);
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.rfind('[', 0) == 0) section = line.substr(1, line.find(']') - 1);
    else if (const auto eq = line.find(" = "); eq != std::string::npos) listed.push_back(section + "." + line.substr(0, eq));
  }
  for (const auto& f : kParamFields)
    if (f.index <= 0) expected.push_back(f.key());
  EXPECT_EQ(listed, expected);
}
