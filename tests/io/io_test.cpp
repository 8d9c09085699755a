// hoist_io: every rule of the file formats (docs/model.md, README), accepted and rejected.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "hoist/io/config.hpp"
#include "hoist/io/profile.hpp"
#include "hoist/io/results.hpp"
#include "test_util.hpp"

using namespace hoist;
using namespace hoist::io;

namespace {

ShaftParams parse(const std::string& text, std::vector<std::string> other = {}) {
  return shaftParamsFromToml(parseToml(text, "shaft.toml"), "shaft.toml", other);
}

/// The ConfigError for `text`; fails the test if none is thrown.
ConfigError configError(const std::string& text) {
  try {
    parse(text);
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return ConfigError("", 0, "", "");
}

HoistProfile csv(const std::string& text, double l0 = 50.0) {
  std::istringstream in(text);
  return readProfileCsv(in, "p.csv", l0);
}

ProfileError csvError(const std::string& text) {
  try {
    csv(text);
  } catch (const ProfileError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return ProfileError("", 0, "", "");
}

}  // namespace

// ---------------------------------------------------------------- config --

TEST(Config, EmptyFileGivesThePaperBaseline) {
  const ShaftParams p = parse("");
  const ShaftParams d;
  EXPECT_EQ(p.rho1, d.rho1);
  EXPECT_EQ(p.Tb1, 3.0e4);
  EXPECT_EQ(p.n, 50);
  EXPECT_EQ(p.initial, InitialState::Static);
}

TEST(Config, EveryKeyReachesItsParameter) {
  const ShaftParams p = parse(R"(
[hoisting_rope]
mass_per_length = 3.5
axial_stiffness = 4e7
damping = 20
initial_length = 60.0
[guide_ropes]
length = 500.0
mass_per_length = 2.5
damping = 0.4
preload = [40000, 35000.5]
[cage]
mass = 1200.0
inertia = 1305.0
half_height = 7.5
[load]
eccentric_force = 2000.0
offset = -0.5
[model]
modes = 20
gravity = 9.8
initial = "rest"
rho_inf = 0.8
static_correction = false
)");
  EXPECT_EQ(p.rho1, 3.5);
  EXPECT_EQ(p.EA, 4e7);
  EXPECT_EQ(p.u1, 20.0);
  EXPECT_EQ(p.l0, 60.0);
  EXPECT_EQ(p.L, 500.0);
  EXPECT_EQ(p.rho2, 2.5);
  EXPECT_EQ(p.u2, 0.4);
  EXPECT_EQ(p.Tb1, 40000.0);
  EXPECT_EQ(p.Tb2, 35000.5);
  EXPECT_EQ(p.m, 1200.0);
  EXPECT_EQ(p.J, 1305.0);
  EXPECT_EQ(p.h, 7.5);
  EXPECT_EQ(p.Fa, 2000.0);
  EXPECT_EQ(p.b, -0.5);
  EXPECT_EQ(p.n, 20);
  EXPECT_EQ(p.g, 9.8);
  EXPECT_EQ(p.initial, InitialState::Rest);
  EXPECT_EQ(p.rho_inf, 0.8);
  EXPECT_FALSE(p.static_correction);
}

TEST(Config, ReferenceCaseFileLoads) {
  const ShaftParams p = loadShaftConfig(test::dataDir() + "/c1-paper-rest/shaft.toml");
  EXPECT_EQ(p.initial, InitialState::Rest);
  EXPECT_EQ(p.EA, 3.2e7);
}

TEST(Config, UnknownKeyIsNamedWithLineAndSuggestion) {
  const ConfigError e = configError("[cage]\nmass = 800.0\nmas = 3\n");
  EXPECT_EQ(e.key(), "cage.mas");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("did you mean 'mass'"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("shaft.toml:3"), std::string::npos) << e.what();
}

TEST(Config, UnknownSectionIsRejectedUnlessSomeoneElseOwnsIt) {
  EXPECT_EQ(configError("[cagee]\nmass = 1.0\n").key(), "cagee");
  EXPECT_NE(std::string(configError("[cagee]\n").what()).find("did you mean 'cage'"), std::string::npos);
  EXPECT_NO_THROW(parse("[service]\nrate = 100\n", {"service"}));
  EXPECT_THROW(parse("[service]\nrate = 100\n"), ConfigError);
}

TEST(Config, KeyOutsideItsSectionSaysWhere) {
  const ConfigError e = configError("modes = 20\n");
  EXPECT_NE(std::string(e.what()).find("[model]"), std::string::npos) << e.what();
}

TEST(Config, WrongTypesAreRejected) {
  EXPECT_EQ(configError("[cage]\nmass = \"800\"\n").key(), "cage.mass");
  EXPECT_EQ(configError("[model]\nmodes = 50.5\n").key(), "model.modes");
  EXPECT_EQ(configError("[model]\nmodes = \"50\"\n").key(), "model.modes");
  EXPECT_EQ(configError("[model]\ninitial = 1\n").key(), "model.initial");
  EXPECT_EQ(configError("[model]\ninitial = \"moving\"\n").key(), "model.initial");
  EXPECT_EQ(configError("[guide_ropes]\npreload = 30000\n").key(), "guide_ropes.preload");
  EXPECT_EQ(configError("[guide_ropes]\npreload = [1.0, 2.0, 3.0]\n").key(), "guide_ropes.preload");
  EXPECT_EQ(configError("[guide_ropes]\npreload = [30000, \"x\"]\n").key(), "guide_ropes.preload[1]");
  EXPECT_EQ(configError("cage = 3\n").key(), "cage");
  EXPECT_EQ(configError("[cage]\nmass = true\n").key(), "cage.mass");
}

TEST(Config, ImpossibleValuesNameKeyAndLine) {
  ConfigError e = configError("[cage]\nmass = nan\n");
  EXPECT_EQ(e.key(), "cage.mass");
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(configError("[cage]\nmass = -800.0\n").key(), "cage.mass");
  EXPECT_EQ(configError("[cage]\nmass = 0\n").key(), "cage.mass");
  EXPECT_EQ(configError("[hoisting_rope]\naxial_stiffness = inf\n").key(), "hoisting_rope.axial_stiffness");
  EXPECT_EQ(configError("[model]\nmodes = 0\n").key(), "model.modes");
  EXPECT_EQ(configError("[model]\nmodes = 1000000\n").key(), "model.modes");
  EXPECT_EQ(configError("[guide_ropes]\npreload = [30000, -1]\n").key(), "guide_ropes.preload");
  e = configError("[guide_ropes]\nlength = 400.0\n[cage]\nhalf_height = 250.0\n");
  EXPECT_EQ(e.key(), "cage.half_height");
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(configError("[hoisting_rope]\ninitial_length = 390.0\n").key(), "hoisting_rope.initial_length");
  EXPECT_EQ(configError("[model]\nrho_inf = 1.5\n").key(), "model.rho_inf");
  // static_correction is a boolean: 1, "on", "true" are errors naming the key.
  for (const char* v : {"1", "\"on\"", "\"true\"", "0.0"}) {
    const ConfigError b = configError(std::string("[model]\nstatic_correction = ") + v + "\n");
    EXPECT_EQ(b.key(), "model.static_correction") << v;
    EXPECT_EQ(b.line(), 2) << v;
    EXPECT_NE(std::string(b.what()).find("true or false"), std::string::npos) << b.what();
  }
  EXPECT_TRUE(parse("[model]\nmodes = 10\n").static_correction) << "default on";
  EXPECT_FALSE(parse("[model]\nstatic_correction = false\n").static_correction);
}

TEST(Config, SyntaxErrorsGiveTheLine) {
  const ConfigError e = configError("[cage]\nmass = 800.0\nmass = = 3\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("syntax"), std::string::npos);
  EXPECT_THROW(loadTomlFile("/nonexistent/shaft.toml"), ConfigError);
}

TEST(Config, ToTomlReadsBackExactly) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    ShaftParams p;
    p.rho1 *= u(rng);
    p.EA *= u(rng);
    p.u1 *= u(rng);
    p.l0 *= u(rng);
    p.rho2 *= u(rng);
    p.u2 *= u(rng);
    p.Tb1 *= u(rng);
    p.Tb2 *= u(rng);
    p.m *= u(rng);
    p.J *= u(rng);
    p.h *= u(rng);
    p.Fa *= u(rng);
    p.b = u(rng) - 1.25;
    p.n = 10 + trial;
    p.rho_inf = u(rng) / 2.0;
    p.initial = trial % 2 ? InitialState::Rest : InitialState::Static;
    p.static_correction = trial % 3 != 0;
    const ShaftParams q = parse(toToml(p));
    EXPECT_EQ(q.rho1, p.rho1);
    EXPECT_EQ(q.EA, p.EA);
    EXPECT_EQ(q.u1, p.u1);
    EXPECT_EQ(q.l0, p.l0);
    EXPECT_EQ(q.rho2, p.rho2);
    EXPECT_EQ(q.u2, p.u2);
    EXPECT_EQ(q.Tb1, p.Tb1);
    EXPECT_EQ(q.Tb2, p.Tb2);
    EXPECT_EQ(q.m, p.m);
    EXPECT_EQ(q.J, p.J);
    EXPECT_EQ(q.h, p.h);
    EXPECT_EQ(q.Fa, p.Fa);
    EXPECT_EQ(q.b, p.b);
    EXPECT_EQ(q.n, p.n);
    EXPECT_EQ(q.rho_inf, p.rho_inf);
    EXPECT_EQ(q.initial, p.initial);
    EXPECT_EQ(q.static_correction, p.static_correction);
  }
}

// ------------------------------------------------------------------- CSV --

TEST(ProfileCsv, WithLengthColumnKeepsTheSamples) {
  const HoistProfile p = csv("t,l,v,a\n0,50,0,1\n0.5,50.125,0.5,1\n1,50.5,1,1\n");
  ASSERT_EQ(p.samples().size(), 3u);
  EXPECT_EQ(p.samples()[1].k.l, 50.125);
  EXPECT_DOUBLE_EQ(p.at(0.25).v, 0.25);
}

TEST(ProfileCsv, WithoutLengthIntegratesVelocityFromInitialLength) {
  // Constant acceleration 1 m/s^2 from rest: l = l0 + t^2/2, exactly.
  const HoistProfile p = csv("t,v,a\n0,0,1\n1,1,1\n2,2,1\n", 100.0);
  EXPECT_NEAR(p.samples()[2].k.l, 102.0, 1e-12);
  EXPECT_NEAR(p.at(1.5).l, 101.125, 1e-12);
}

TEST(ProfileCsv, ColumnOrderCommentsBomCrlfAndExtraColumnsAreAccepted) {
  const HoistProfile p = csv("\xEF\xBB\xBF# a comment\r\n a , extra, t ,v\r\n\r\n1, 9, 0, 0\r\n# mid\r\n1,9,1,1\r\n", 10.0);
  ASSERT_EQ(p.samples().size(), 2u);
  EXPECT_EQ(p.samples()[1].t, 1.0);
  EXPECT_EQ(p.samples()[1].k.v, 1.0);
  EXPECT_NEAR(p.samples()[1].k.l, 10.5, 1e-12);
}

TEST(ProfileCsv, TheReferenceProfileAndAResultFileRead) {
  const HoistProfile p = readProfileCsvFile(test::dataDir() + "/c1-paper/profile.csv", 50.0);
  EXPECT_EQ(p.samples().size(), 6001u);
  const HoistProfile r = readProfileCsvFile(test::dataDir() + "/c1-paper/reference.csv", 50.0);
  EXPECT_EQ(r.samples().size(), 6001u);
  EXPECT_EQ(r.samples()[3000].k.l, p.samples()[3000].k.l);
}

TEST(ProfileCsv, BadFilesAreRejectedWithLineAndColumn) {
  ProfileError e = csvError("t,l,v\n0,50,0\n1,50,0\n");
  EXPECT_EQ(e.key(), "a");
  EXPECT_EQ(e.line(), 1);
  e = csvError("0,50,0,1\n1,50,0,1\n");  // no header
  EXPECT_NE(std::string(e.what()).find("header"), std::string::npos) << e.what();
  e = csvError("t,v,a\n0,0,1\n1,x,1\n");
  EXPECT_EQ(e.key(), "v");
  EXPECT_EQ(e.line(), 3);
  e = csvError("t,v,a\n0,0,1\n1,nan,1\n");
  EXPECT_EQ(e.key(), "v");
  EXPECT_EQ(csvError("t,v,a\n0,0,1\n1,inf,1\n").key(), "v");
  e = csvError("t,v,a\n0,0,1\n1,1,1\n1,1,1\n");
  EXPECT_EQ(e.key(), "t");
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(csvError("t,v,a\n0,0,1\n-1,1,1\n").key(), "t");
  EXPECT_EQ(csvError("t,v,a\n0,0,1\n1000,1,1\n").key(), "t");  // gap
  EXPECT_EQ(csvError("t,v,a\n0,0,1\n1,1\n").line(), 3);          // field count
  EXPECT_EQ(csvError("t,v,a\n0,0,1\n1,1,1,1\n").line(), 3);
  EXPECT_EQ(csvError("t,v,a\n0,0,1\n1,1e6,1\n").key(), "v");    // |v| limit
  EXPECT_EQ(csvError("t,v,a\n0,0,1\n1,1,1e6\n").key(), "a");    // |a| limit
  EXPECT_EQ(csvError("t,l,v,a\n0,50,0,1\n1,-3,0,1\n").key(), "l");
  EXPECT_EQ(csvError("t,t,v,a\n").key(), "t");                 // duplicate column
  csvError("");                                                 // empty
  csvError("# only a comment\n");
  csvError("t,v,a\n");                                          // no rows
  csvError("t,v,a\n0,0,0\n");                                   // one row
  csvError(std::string("t,v,a\n0,0,0\n\x01\x02\x00\xff", 16));  // binary
  csvError("t,v,a\n0,,0\n1,0,0\n");                             // empty field
  csvError("t,v,a\n0,0x1p3,0\n1,0,0\n");                        // hex float
  csvError("t,v,a\n0,1 2,0\n1,0,0\n");                          // junk inside a field
}

TEST(ProfileCsv, WriteThenReadIsExact) {
  const HoistProfile a = HoistProfile::sCurve(60.0, 4.0, 0.8, 0.4, -40.0, 30.0, 0.01);
  std::stringstream ss;
  writeProfileCsv(ss, a);
  const HoistProfile b = readProfileCsv(ss, "s", 0.0);
  ASSERT_EQ(a.samples().size(), b.samples().size());
  for (std::size_t i = 0; i < a.samples().size(); ++i) {
    EXPECT_EQ(a.samples()[i].t, b.samples()[i].t);
    EXPECT_EQ(a.samples()[i].k.l, b.samples()[i].k.l);
    EXPECT_EQ(a.samples()[i].k.v, b.samples()[i].k.v);
    EXPECT_EQ(a.samples()[i].k.a, b.samples()[i].k.a);
  }
}

// ------------------------------------------------------------------ SPEC --

TEST(ProfileSpec, PaperIsTheFigure2TrapezoidOfTheReferenceData) {
  const HoistProfile p = profileFromSpec("paper", 50.0);
  const HoistProfile ref = readProfileCsvFile(test::dataDir() + "/c1-paper/profile.csv", 50.0);
  ASSERT_EQ(p.samples().size(), ref.samples().size());
  for (std::size_t i = 0; i < p.samples().size(); i += 37) {
    EXPECT_NEAR(p.samples()[i].t, ref.samples()[i].t, 1e-9);
    EXPECT_NEAR(p.samples()[i].k.l, ref.samples()[i].k.l, 1e-9) << i;
    EXPECT_NEAR(p.samples()[i].k.v, ref.samples()[i].k.v, 1e-9) << i;
    EXPECT_NEAR(p.samples()[i].k.a, ref.samples()[i].k.a, 1e-9) << i;
  }
}

TEST(ProfileSpec, ParametersAreApplied) {
  const HoistProfile up = profileFromSpec("trapezoid:vmax=4,amax=0.5,travel=-100,t_end=40,dt=0.02,l0=200", 50.0);
  EXPECT_EQ(up.samples().front().k.l, 200.0);
  EXPECT_NEAR(up.samples().back().k.l, 100.0, 1e-9);
  EXPECT_NEAR(up.endTime(), 40.0, 1e-9);
  EXPECT_EQ(up.samples().size(), 2001u);
  double vmin = 0;
  for (const auto& s : up.samples()) vmin = std::min(vmin, s.k.v);
  EXPECT_NEAR(vmin, -4.0, 1e-9);

  const HoistProfile e = profileFromSpec("estop:vmax=3,t_stop=5,decel=2,t_end=10", 80.0);
  EXPECT_NEAR(e.at(4.0).v, 3.0, 1e-9);
  EXPECT_NEAR(e.at(9.9).v, 0.0, 1e-9);
  const HoistProfile r = profileFromSpec("rest:t_end=5", 70.0);
  EXPECT_EQ(r.at(3.0).l, 70.0);
  EXPECT_EQ(r.at(3.0).v, 0.0);
  const HoistProfile s = profileFromSpec("scurve", 50.0);
  EXPECT_NEAR(s.samples().back().k.l, 300.0, 1e-6);
}

TEST(ProfileSpec, MistakesAreExplained) {
  auto err = [](const std::string& spec) -> std::string {
    try {
      profileFromSpec(spec, 50.0);
    } catch (const ProfileError& e) {
      return e.what();
    }
    ADD_FAILURE() << spec << " accepted";
    return "";
  };
  EXPECT_NE(err("trapezoid:vmx=3").find("did you mean 'vmax'"), std::string::npos);
  EXPECT_NE(err("trapezod").find("did you mean 'trapezoid'"), std::string::npos);
  EXPECT_NE(err("trapezoid:vmax=fast").find("trapezoid.vmax"), std::string::npos);
  EXPECT_NE(err("trapezoid:vmax").find("key=value"), std::string::npos);
  EXPECT_NE(err("trapezoid:vmax=1,vmax=2").find("twice"), std::string::npos);
  EXPECT_NE(err("trapezoid:dt=0").find("trapezoid.dt"), std::string::npos);
  EXPECT_NE(err("trapezoid:vmax=-1").find("trapezoid"), std::string::npos);
  EXPECT_NE(err("trapezoid:travel=nan").find("trapezoid.travel"), std::string::npos);
}

TEST(ProfileSpec, LoadProfilePrefersExistingFiles) {
  EXPECT_EQ(loadProfile(test::dataDir() + "/c1-paper/profile.csv", 50.0).samples().size(), 6001u);
  EXPECT_EQ(loadProfile("paper", 50.0).samples().size(), 6001u);
  EXPECT_THROW(loadProfile("/no/such/file.csv", 50.0), ProfileError);
  EXPECT_THROW(loadProfile("nonsense", 50.0), ProfileError);
  EXPECT_THROW(loadProfile(test::dataDir(), 50.0), ProfileError);  // a directory
}

TEST(ProfileSpec, ProfilesLeavingTheShaftAreRejected) {
  ShaftParams p;
  EXPECT_NO_THROW(checkProfileInShaft(profileFromSpec("paper", 50.0), p, "paper"));
  EXPECT_THROW(checkProfileInShaft(profileFromSpec("trapezoid:travel=340,t_end=100", 50.0), p, "x"), ProfileError);
  EXPECT_THROW(checkProfileInShaft(profileFromSpec("trapezoid:travel=-60", 50.0), p, "x"), ProfileError);
}

// ---------------------------------------------------------------- result --

TEST(ResultCsv, HeaderAndRowsRoundTripExactly) {
  CageResponse r;
  r.t = 0.1 + 0.2;
  r.kin = {50.000001, -4.999999999, 1.0 / 3.0};
  r.x_c = 1.556167637079e-03;
  r.y_c = -4.944342092860e-03;
  r.theta = 7.241816331936e-04;
  r.lambda = {8847.990516327, -31.25572257162, -31.25572257162, 31.24427445640, 1e-300};
  std::stringstream ss;
  writeResultHeader(ss);
  writeResultRow(ss, r);
  std::string header, row;
  std::getline(ss, header);
  std::getline(ss, row);
  EXPECT_EQ(header, "t,l,v,a,x_c,y_c,theta,lambda_0,lambda_1,lambda_2,lambda_3,lambda_4");
  std::vector<double> v;
  std::stringstream rs(row);
  std::string f;
  while (std::getline(rs, f, ',')) v.push_back(std::strtod(f.c_str(), nullptr));
  ASSERT_EQ(v.size(), 12u);
  const double want[12] = {r.t, r.kin.l, r.kin.v, r.kin.a, r.x_c, r.y_c, r.theta,
                           r.lambda[0], r.lambda[1], r.lambda[2], r.lambda[3], r.lambda[4]};
  for (int i = 0; i < 12; ++i) EXPECT_EQ(v[i], want[i]) << i;
}
