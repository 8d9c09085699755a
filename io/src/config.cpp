// The shaft TOML of INTERFACES.md -> ShaftParams.  See hoist/io/config.hpp.
#include "hoist/io/config.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include "hoist/io/results.hpp"

namespace hoist::io {

namespace {

int lineOf(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

const char* typeName(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "nothing";
  }
}

/// One key of the file: where it goes and how it is read.
struct Field {
  const char* section;
  const char* key;
  std::function<void(const toml::node&, ShaftParams&, const std::string& source, const std::string& full)> read;
};

double readNumber(const toml::node& n, const std::string& source, const std::string& key) {
  if (const auto* f = n.as_floating_point()) return f->get();
  if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
  throw ConfigError(source, lineOf(n), key, std::string("expected a number, got ") + typeName(n));
}

auto number(double ShaftParams::*member) {
  return [member](const toml::node& n, ShaftParams& p, const std::string& src, const std::string& key) {
    p.*member = readNumber(n, src, key);
  };
}

const std::vector<Field>& fields() {
  static const std::vector<Field> f = {
      {"hoisting_rope", "mass_per_length", number(&ShaftParams::rho1)},
      {"hoisting_rope", "axial_stiffness", number(&ShaftParams::EA)},
      {"hoisting_rope", "damping", number(&ShaftParams::u1)},
      {"hoisting_rope", "initial_length", number(&ShaftParams::l0)},
      {"guide_ropes", "length", number(&ShaftParams::L)},
      {"guide_ropes", "mass_per_length", number(&ShaftParams::rho2)},
      {"guide_ropes", "damping", number(&ShaftParams::u2)},
      {"guide_ropes", "preload",
       [](const toml::node& n, ShaftParams& p, const std::string& src, const std::string& key) {
         const auto* arr = n.as_array();
         if (!arr)
           throw ConfigError(src, lineOf(n), key,
                             std::string("expected an array of two numbers [Tb1, Tb2], got ") + typeName(n));
         if (arr->size() != 2)
           throw ConfigError(src, lineOf(n), key,
                             "expected exactly two preloads [Tb1, Tb2], got " + std::to_string(arr->size()));
         p.Tb1 = readNumber(*arr->get(0), src, key + "[0]");
         p.Tb2 = readNumber(*arr->get(1), src, key + "[1]");
       }},
      {"cage", "mass", number(&ShaftParams::m)},
      {"cage", "inertia", number(&ShaftParams::J)},
      {"cage", "half_height", number(&ShaftParams::h)},
      {"load", "eccentric_force", number(&ShaftParams::Fa)},
      {"load", "offset", number(&ShaftParams::b)},
      {"model", "modes",
       [](const toml::node& n, ShaftParams& p, const std::string& src, const std::string& key) {
         const auto* i = n.as_integer();
         if (!i) throw ConfigError(src, lineOf(n), key, std::string("expected an integer, got ") + typeName(n));
         const auto v = i->get();
         if (v < 1 || v > kMaxModes)
           throw ConfigError(src, lineOf(n), key,
                             "must be between 1 and " + std::to_string(kMaxModes) + " (got " + std::to_string(v) + ")");
         p.n = static_cast<int>(v);
       }},
      {"model", "gravity", number(&ShaftParams::g)},
      {"model", "initial",
       [](const toml::node& n, ShaftParams& p, const std::string& src, const std::string& key) {
         const auto* s = n.as_string();
         if (!s)
           throw ConfigError(src, lineOf(n), key,
                             std::string("expected \"static\" or \"rest\", got ") + typeName(n));
         if (s->get() == "static") p.initial = InitialState::Static;
         else if (s->get() == "rest") p.initial = InitialState::Rest;
         else throw ConfigError(src, lineOf(n), key, "expected \"static\" or \"rest\", got \"" + s->get() + "\"");
       }},
      {"model", "rho_inf", number(&ShaftParams::rho_inf)},
  };
  return f;
}

const std::vector<std::string> kSections = {"hoisting_rope", "guide_ropes", "cage", "load", "model"};

std::string didYouMean(const std::string& word, const std::vector<std::string>& cands) {
  const std::string m = closestMatch(word, cands);
  return m.empty() ? std::string() : " (did you mean '" + m + "'?)";
}

std::string keysOf(const char* section) {
  std::string s;
  for (const auto& f : fields())
    if (std::string(f.section) == section) s += (s.empty() ? "" : ", ") + std::string(f.key);
  return s;
}

}  // namespace

toml::table parseToml(std::string_view text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw ConfigError(source, static_cast<int>(e.source().begin.line), "",
                      "TOML syntax error: " + std::string(e.description()));
  }
}

toml::table loadTomlFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path, 0, "", "cannot open the configuration file");
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  if (text.size() > (1u << 20)) throw ConfigError(path, 0, "", "file larger than 1 MiB: not a shaft configuration");
  return parseToml(text, path);
}

ShaftParams shaftParamsFromToml(const toml::table& tbl, const std::string& source,
                                const std::vector<std::string>& other_sections) {
  ShaftParams p;
  // Where each key was, to give validate()'s errors a line number.
  std::vector<std::pair<std::string, int>> lines;
  for (const auto& [k, node] : tbl) {
    const std::string sec(k.str());
    bool other = false;
    for (const auto& o : other_sections) other = other || o == sec;
    if (other) continue;
    bool known = false;
    for (const auto& s : kSections) known = known || sec == s;
    if (!known) {
      if (!node.is_table()) {
        // A key outside any section: say where it belongs if we know it.
        for (const auto& f : fields())
          if (sec == f.key)
            throw ConfigError(source, lineOf(node), sec,
                              std::string("key outside its section: put it under [") + f.section + "]");
      }
      std::string msg = "unknown section" + didYouMean(sec, kSections) + "; known: hoisting_rope, guide_ropes, cage, load, model";
      for (const auto& o : other_sections) msg += ", " + o;
      throw ConfigError(source, lineOf(node), sec, msg);
    }
    const auto* section = node.as_table();
    if (!section) throw ConfigError(source, lineOf(node), sec, std::string("expected a table [") + sec + "], got " + typeName(node));
    for (const auto& [kk, value] : *section) {
      const std::string key(kk.str());
      const std::string full = sec + "." + key;
      const Field* field = nullptr;
      for (const auto& f : fields())
        if (sec == f.section && key == f.key) field = &f;
      if (!field) {
        std::vector<std::string> cands;
        for (const auto& f : fields())
          if (sec == f.section) cands.emplace_back(f.key);
        const std::string hint = didYouMean(key, cands);
        throw ConfigError(source, lineOf(value), full,
                          "unknown key" + hint + "; [" + sec + "] takes " + keysOf(sec.c_str()));
      }
      field->read(value, p, source, full);
      lines.emplace_back(full, lineOf(value));
    }
  }
  try {
    p.validate();
  } catch (const ParamError& e) {
    int line = 0;
    for (const auto& [k, l] : lines)
      if (k == e.key()) line = l;
    // validate() says "key: message"; keep only the message.
    std::string msg = e.what();
    const std::string prefix = e.key() + ": ";
    if (msg.rfind(prefix, 0) == 0) msg = msg.substr(prefix.size());
    throw ConfigError(source, line, e.key(), msg);
  }
  return p;
}

ShaftParams loadShaftConfig(const std::string& path, const std::vector<std::string>& other_sections) {
  return shaftParamsFromToml(loadTomlFile(path), path, other_sections);
}

namespace {
std::string num(double v) {
  std::string s;
  appendNumber(s, v);
  if (s.find_first_of(".eni") == std::string::npos) s += ".0";
  if (s == "inf") s = "inf";
  return s;
}
}  // namespace

std::string toToml(const ShaftParams& p) {
  std::ostringstream os;
  os << "[hoisting_rope]\n"
     << "mass_per_length = " << num(p.rho1) << "   # rho1, kg/m\n"
     << "axial_stiffness = " << num(p.EA) << "   # EA, N\n"
     << "damping = " << num(p.u1) << "   # u1, kg/(m s)\n"
     << "initial_length = " << num(p.l0) << "   # l(0), m\n\n"
     << "[guide_ropes]\n"
     << "length = " << num(p.L) << "   # L, m\n"
     << "mass_per_length = " << num(p.rho2) << "   # rho2, kg/m\n"
     << "damping = " << num(p.u2) << "   # u2, kg/(m s)\n"
     << "preload = [" << num(p.Tb1) << ", " << num(p.Tb2) << "]   # Tb1, Tb2, N\n\n"
     << "[cage]\n"
     << "mass = " << num(p.m) << "   # m, kg\n"
     << "inertia = " << num(p.J) << "   # J, kg m^2\n"
     << "half_height = " << num(p.h) << "   # h, m\n\n"
     << "[load]\n"
     << "eccentric_force = " << num(p.Fa) << "   # Fa, N\n"
     << "offset = " << num(p.b) << "   # b, m\n\n"
     << "[model]\n"
     << "modes = " << p.n << "\n"
     << "gravity = " << num(p.g) << "\n"
     << "initial = \"" << toString(p.initial) << "\"\n"
     << "rho_inf = " << num(p.rho_inf) << "   # generalized-alpha high-frequency damping\n";
  return os.str();
}

}  // namespace hoist::io
