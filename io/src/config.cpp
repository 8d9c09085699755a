// The shaft TOML of docs/model.md -> ShaftParams, driven by hoist::kParamFields.
// See hoist/io/config.hpp.
#include "hoist/io/config.hpp"

#include <fstream>
#include <sstream>

#include "hoist/io/results.hpp"
#include "hoist/io/toml_section.hpp"

namespace hoist::io {

namespace {

std::vector<std::string> sectionNames() {
  return {kParamSections.begin(), kParamSections.end()};
}

double readNumber(const SectionReader& r, const toml::node& n, const std::string& key) {
  if (const auto* f = n.as_floating_point()) return f->get();
  if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
  r.fail(n, key, std::string("must be a number, got ") + typeName(n));
}

/// Read one value of `f` from `n` into `p`; `key` names it in errors.
void readField(const SectionReader& r, const ParamField& f, const toml::node& n, const std::string& key,
               ShaftParams& p) {
  switch (f.type) {
    case ParamType::Real: p.*f.real = readNumber(r, n, key); return;
    case ParamType::Integer: {
      const auto* i = n.as_integer();
      if (!i) r.fail(n, key, std::string("must be an integer, got ") + typeName(n));
      const double v = static_cast<double>(i->get());
      if (std::string why = f.check(v); !why.empty()) r.fail(n, key, why);
      p.*f.integer = static_cast<int>(i->get());
      return;
    }
    case ParamType::Boolean: {
      const auto* b = n.as_boolean();
      if (!b) r.fail(n, key, std::string("must be true or false, got ") + typeName(n));
      p.*f.boolean = b->get();
      return;
    }
    case ParamType::Initial: {
      const auto* s = n.as_string();
      if (!s) r.fail(n, key, std::string("must be \"static\" or \"rest\", got ") + typeName(n));
      if (s->get() == "static") p.*f.initial = InitialState::Static;
      else if (s->get() == "rest") p.*f.initial = InitialState::Rest;
      else r.fail(n, key, "must be \"static\" or \"rest\", got \"" + s->get() + "\"");
      return;
    }
  }
}

/// Register the keys of one section of the table with `r`.
void registerSection(SectionReader& r, ShaftParams& p) {
  for (const auto& f : kParamFields) {
    if (f.section != r.section() || f.index > 0) continue;
    const std::string name(f.name);
    const auto elems = paramFieldsOf(f.section, f.name);
    if (f.index < 0) {
      r.on(name, [&r, &p, fp = &f, name](const toml::node& n) { readField(r, *fp, n, name, p); });
      continue;
    }
    // An array of elems.size() numbers, e.g. preload = [Tb1, Tb2].
    std::string symbols;
    for (const auto* e : elems) symbols += (symbols.empty() ? "" : ", ") + std::string(e->symbol);
    r.on(name, [&r, &p, elems, name, symbols](const toml::node& n) {
      const auto* arr = n.as_array();
      const std::string count = std::to_string(elems.size());
      if (!arr)
        r.fail(n, name, "must be an array of " + count + " numbers [" + symbols + "], got " + typeName(n));
      if (arr->size() != elems.size())
        r.fail(n, name, "must have exactly " + count + " elements [" + symbols + "], got " +
                            std::to_string(arr->size()));
      for (std::size_t i = 0; i < elems.size(); ++i)
        readField(r, *elems[i], *arr->get(i), name + "[" + std::to_string(i) + "]", p);
    });
  }
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
  // Top level: only the table's sections and those someone else owns.
  const std::vector<std::string> sections = sectionNames();
  for (const auto& [k, node] : tbl) {
    const std::string sec(k.str());
    bool known = false;
    for (const auto& s : sections) known = known || sec == s;
    for (const auto& o : other_sections) known = known || sec == o;
    if (known) continue;
    if (!node.is_table()) {
      // A key outside any section: say where it belongs if we know it.
      for (const auto& f : kParamFields)
        if (sec == f.name)
          throw ConfigError(source, lineOf(node), sec,
                            "key outside its section: put it under [" + std::string(f.section) + "]");
    }
    std::string msg = "unknown section" + didYouMean(sec, sections) + "; known: ";
    for (std::size_t i = 0; i < sections.size(); ++i) msg += (i ? ", " : "") + sections[i];
    for (const auto& o : other_sections) msg += ", " + o;
    throw ConfigError(source, lineOf(node), sec, msg);
  }
  ShaftParams p;
  std::vector<SectionReader> readers;
  readers.reserve(sections.size());
  for (const auto& s : sections) {
    readers.emplace_back(tbl, s, source);
    registerSection(readers.back(), p);
  }
  for (auto& r : readers) r.run();
  try {
    p.validate();
  } catch (const ParamError& e) {
    std::vector<const SectionReader*> rs;
    for (const auto& r : readers) rs.push_back(&r);
    rethrowWithLine(e.what(), source, rs, false);
  }
  return p;
}

ShaftParams loadShaftConfig(const std::string& path, const std::vector<std::string>& other_sections) {
  return shaftParamsFromToml(loadTomlFile(path), path, other_sections);
}

namespace {
/// A double as a TOML float: shortest round-trip form, always with '.' or 'e'.
std::string num(double v) {
  std::string s;
  appendNumber(s, v);
  if (s.find_first_of(".eni") == std::string::npos) s += ".0";
  return s;
}

std::string valueOf(const ParamField& f, const ShaftParams& p) {
  switch (f.type) {
    case ParamType::Real: return num(p.*f.real);
    case ParamType::Integer: return std::to_string(p.*f.integer);
    case ParamType::Boolean: return p.*f.boolean ? "true" : "false";
    case ParamType::Initial: return std::string("\"") + toString(p.*f.initial) + "\"";
  }
  return {};
}
}  // namespace

std::string toToml(const ShaftParams& p) {
  std::string out;
  std::string_view section;
  for (const auto& f : kParamFields) {
    if (f.index > 0) continue;  // written with element 0
    if (f.section != section) {
      out += (section.empty() ? "[" : "\n[") + std::string(f.section) + "]\n";
      section = f.section;
    }
    std::string value, symbols;
    if (f.index < 0) {
      value = valueOf(f, p);
      symbols = f.symbol;
    } else {
      for (const auto* e : paramFieldsOf(f.section, f.name)) {
        value += (value.empty() ? "[" : ", ") + valueOf(*e, p);
        symbols += (symbols.empty() ? "" : ", ") + std::string(e->symbol);
      }
      value += "]";
    }
    // "rho1, kg/m"; without a unit, the meaning: "n: assumed modes per rope (integer)".
    std::string comment = symbols;
    if (!f.unit.empty()) comment += (comment.empty() ? "" : ", ") + std::string(f.unit);
    else comment += (comment.empty() ? "" : ": ") + std::string(f.doc);
    out += std::string(f.name) + " = " + value + "   # " + comment + "\n";
  }
  return out;
}

}  // namespace hoist::io
