// hoist.Config (python/src/config_py.hpp).
#include "config_py.hpp"

#include <sstream>

#include <pybind11/stl.h>

#include "hoist/history/condition_config.hpp"
#include "hoist/history/config.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/error.hpp"
#include "hoist/profile.hpp"

namespace py = pybind11;

namespace hoist::python {

namespace {

/// The source name of values given by Config.set (messages: "Config.set: cage.mass: ...").
const std::string kSetSource = "Config.set";

/// Sections set() may change: the shaft's, the estimator's and [condition] (hoist.record_trips).
bool settableSection(std::string_view s) {
  for (auto k : kParamSections)
    if (s == k) return true;
  return s == "sensors" || s == "estimator" || s == "condition";
}

/// Every shaft key, for "did you mean".
std::vector<std::string> shaftKeys() {
  std::vector<std::string> keys;
  for (const auto& f : kParamFields)
    if (f.index <= 0) keys.push_back(std::string(f.section) + "." + std::string(f.name));
  return keys;
}

/// Split "section.name" or "section.name[i]"; index -1 when there is none.
void splitKey(const std::string& key, std::string& section, std::string& name, int& index) {
  const auto dot = key.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == key.size())
    throw io::ConfigError(kSetSource, 0, key, "expected a dotted key 'section.name', e.g. 'load.eccentric_force'");
  section = key.substr(0, dot);
  name = key.substr(dot + 1);
  index = -1;
  if (const auto br = name.find('['); br != std::string::npos) {
    if (name.back() != ']') throw io::ConfigError(kSetSource, 0, key, "expected 'section.name[index]'");
    try {
      index = std::stoi(name.substr(br + 1, name.size() - br - 2));
    } catch (const std::exception&) {
      throw io::ConfigError(kSetSource, 0, key, "the index must be a non-negative integer");
    }
    if (index < 0) throw io::ConfigError(kSetSource, 0, key, "the index must be a non-negative integer");
    name = name.substr(0, br);
  }
  if (name.find('.') != std::string::npos)
    throw io::ConfigError(kSetSource, 0, key, "keys are 'section.name' (one dot)");
}

/// A Python value as a TOML node; the readers then check its type as they check a file's.
std::unique_ptr<toml::node> toNode(const py::handle& v, const std::string& key) {
  const auto obj = py::reinterpret_borrow<py::object>(v);
  if (py::isinstance<py::bool_>(v) || py::type::of(v).attr("__name__").cast<std::string>() == "bool_")
    return std::make_unique<toml::value<bool>>(v.cast<bool>());
  if (py::isinstance<py::str>(v)) return std::make_unique<toml::value<std::string>>(v.cast<std::string>());
  // numpy scalars count as the Python numbers they stand for (int64 -> integer, float64 -> float).
  const bool is_seq = py::isinstance<py::sequence>(v) || py::hasattr(v, "tolist");
  const bool scalar = !is_seq || (py::hasattr(v, "ndim") && obj.attr("ndim").cast<int>() == 0);
  if (scalar && (py::isinstance<py::int_>(v) || (py::hasattr(v, "__index__") && !py::isinstance<py::float_>(v))))
    return std::make_unique<toml::value<int64_t>>(py::int_(obj).cast<int64_t>());
  if (scalar && (py::isinstance<py::float_>(v) || py::hasattr(v, "__float__")))
    return std::make_unique<toml::value<double>>(py::float_(obj).cast<double>());
  if (is_seq) {
    const py::object items = py::hasattr(v, "tolist") ? obj.attr("tolist")() : obj;
    auto arr = std::make_unique<toml::array>();
    for (const auto& e : items) {
      auto n = toNode(e, key);
      n->visit([&](auto&& x) { arr->push_back(std::move(x)); });
    }
    return arr;
  }
  throw io::ConfigError(kSetSource, 0, key,
                        "cannot be set from a Python " + std::string(py::str(v.get_type().attr("__name__"))) +
                            " (a number, bool, str or list is expected)");
}

/// A TOML node as a Python value.
py::object fromNode(const toml::node& n) {
  if (auto* b = n.as_boolean()) return py::bool_(b->get());
  if (auto* i = n.as_integer()) return py::int_(i->get());
  if (auto* f = n.as_floating_point()) return py::float_(f->get());
  if (auto* s = n.as_string()) return py::str(s->get());
  if (auto* a = n.as_array()) {
    py::list l;
    for (const auto& e : *a) l.append(fromNode(e));
    return l;
  }
  if (auto* t = n.as_table()) {
    py::dict d;
    for (const auto& [k, e] : *t) d[py::str(std::string(k.str()))] = fromNode(e);
    return d;
  }
  return py::none();
}

py::object fieldValue(const ParamField& f, const ShaftParams& p) {
  switch (f.type) {
    case ParamType::Real: return py::float_(p.*f.real);
    case ParamType::Integer: return py::int_(p.*f.integer);
    case ParamType::Boolean: return py::bool_(p.*f.boolean);
    case ParamType::Initial: return py::str(toString(p.*f.initial));
  }
  return py::none();
}

/// Parse and validate a table as hoist-sim and hoist-estimate do.
Config makeConfig(toml::table tbl, std::string source) {
  Config c;
  // hoist-trips' sections too ([history], [condition]): its configuration loads as it stands.
  c.params = io::shaftParamsFromToml(tbl, source, history::configSections());
  io::estimatorConfigFromToml(tbl, source);  // [sensors]/[estimator] errors now, not at estimate()
  history::conditionSettingsFromToml(tbl, source);  // [condition]: now, not at record_trips()
  history::historyConfigFromToml(tbl, source);
  io::serviceMaxStep(tbl, source, kDefaultMaxStep);
  c.tbl = std::move(tbl);
  c.source = std::move(source);
  return c;
}

Config& setValue(Config& c, const std::string& key, const py::handle& value) {
  std::string section, name;
  int index = -1;
  splitKey(key, section, name, index);
  if (!settableSection(section)) {
    std::vector<std::string> sections(kParamSections.begin(), kParamSections.end());
    sections.push_back("sensors");
    sections.push_back("estimator");
    sections.push_back("condition");
    std::string list;
    for (const auto& s : sections) list += (list.empty() ? "" : ", ") + s;
    const std::string near = io::closestMatch(section, sections);
    throw io::ConfigError(kSetSource, 0, key,
                          "unknown section '" + section + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                              "; Config.set takes: " + list);
  }
  toml::table tbl = c.tbl;
  if (!tbl.contains(section)) tbl.insert(section, toml::table{});
  toml::table* sec = tbl[section].as_table();
  if (!sec) throw io::ConfigError(kSetSource, 0, section, "is not a table in this configuration");
  auto node = toNode(value, key);
  if (index < 0) {
    node->visit([&](auto&& x) { sec->insert_or_assign(name, std::move(x)); });
  } else {
    // One element of an array key (guide_ropes.preload[1]): the rest as the configuration has them.
    if (!sec->contains(name)) {
      const auto fields = paramFieldsOf(section, name);
      if (fields.empty()) throw io::ConfigError(kSetSource, 0, key, "not an array key");
      toml::array arr;
      for (const auto* f : fields) arr.push_back(f->get(c.params));
      sec->insert(name, std::move(arr));
    }
    toml::array* arr = (*sec)[name].as_array();
    if (!arr) throw io::ConfigError(kSetSource, 0, key, "not an array key");
    if (static_cast<std::size_t>(index) >= arr->size())
      throw io::ConfigError(kSetSource, 0, key,
                            "index out of range (the array has " + std::to_string(arr->size()) + " elements)");
    node->visit([&](auto&& x) { arr->replace(arr->begin() + index, std::move(x)); });
  }
  Config next = makeConfig(std::move(tbl), kSetSource);
  next.source = c.source;
  c = std::move(next);
  return c;
}

py::object getValue(const Config& c, const std::string& key) {
  if (const ParamField* f = findParam(key)) return fieldValue(*f, c.params);
  if (const auto dot = key.find('.'); dot != std::string::npos) {
    const auto fields = paramFieldsOf(key.substr(0, dot), key.substr(dot + 1));
    if (!fields.empty()) {
      py::list l;
      for (const auto* f : fields) l.append(fieldValue(*f, c.params));
      return l;
    }
    // [sensors], [estimator], [service]...: the value the file gives, if any.
    if (auto n = c.tbl.at_path(key); n) return fromNode(*n.node());
    if (key.substr(0, dot) == "sensors" || key.substr(0, dot) == "estimator") {
      const toml::table defaults = io::parseToml(io::toToml(c.estimator()), "<estimator>");
      if (auto n = defaults.at_path(key); n) return fromNode(*n.node());
    }
  }
  const std::string near = io::closestMatch(key, shaftKeys());
  throw py::key_error("Config.get: " + key + ": unknown key" + (near.empty() ? "" : " (did you mean '" + near + "'?)"));
}

/// The sections of the table that are not the shaft's ([service], [estimator], ...).
toml::table otherSections(const toml::table& tbl) {
  toml::table rest;
  for (const auto& [k, n] : tbl) {
    bool shaft = false;
    for (auto s : kParamSections) shaft = shaft || k.str() == s;
    if (!shaft) rest.insert(k, n);
  }
  return rest;
}

/// The whole configuration as TOML: the shaft (every key) and the file's other sections.
std::string toTomlText(const Config& c) {
  std::string out = io::toToml(c.params);
  const toml::table rest = otherSections(c.tbl);
  if (!rest.empty()) {
    std::ostringstream os;
    os << rest;
    out += "\n" + os.str() + "\n";
  }
  return out;
}

}  // namespace

io::EstimatorConfig Config::estimator() const { return io::estimatorConfigFromToml(tbl, source); }
double Config::serviceMaxStep() const { return io::serviceMaxStep(tbl, source, kDefaultMaxStep); }

void bindConfig(py::module_& m) {
  py::class_<Config>(m, "Config", "A shaft configuration (the TOML of hoist-sim, hoist-estimate and hoist-twind).")
      .def_static("paper", [] { return makeConfig(toml::table{}, "<paper>"); },
                  "The paper's shaft (Wang et al. 2016, Section 3): every key at its default.")
      .def_static("from_file", [](const std::string& path) { return makeConfig(io::loadTomlFile(path), path); },
                  py::arg("path"), "from_file(path) -> Config\n\n"
                  "Read a shaft TOML or hoist-twind's configuration, exactly as hoist-sim and hoist-estimate\n"
                  "do: missing keys take the paper's values; [service], [alarms], [forecast], [sensors],\n"
                  "[estimator] are accepted.  Raises hoist.ConfigError with the programs' message and\n"
                  ".source (file), .line and .key (e.g. 'cage.mass').")
      .def_static("from_toml",
                  [](const std::string& text, const std::string& source) {
                    return makeConfig(io::parseToml(text, source), source);
                  },
                  py::arg("text"), py::arg("source") = "<string>", "Parse TOML text.")
      .def("set", &setValue, py::arg("key"), py::arg("value"), py::return_value_policy::reference_internal,
           "set(key, value) -> self\n\n"
           "Set one value by its dotted TOML key and validate the whole configuration as the file\n"
           "reader does (type, bounds, relations such as 2 h < L):\n\n"
           "    cfg.set(\"load.eccentric_force\", 1500.0)\n"
           "    cfg.set(\"guide_ropes.preload\", [31e3, 29e3]).set(\"guide_ropes.preload[1]\", 30e3)\n"
           "    cfg.set(\"model.modes\", 25).set(\"model.initial\", \"rest\")\n\n"
           "Keys: Config.keys() (the shaft: hoisting_rope, guide_ropes, cage, load, model) and the\n"
           "[sensors]/[estimator] keys of hoist-twind's file.  Values: float, int, bool, str, a list\n"
           "(numpy scalars and arrays too).  Raises hoist.ConfigError naming the key (.key) and\n"
           "leaves the configuration unchanged.  Returns self, so calls chain.")
      .def("get", &getValue, py::arg("key"),
           "get(key) -> value\n\n"
           "The value of a dotted key: float, int (model.modes), bool (model.static_correction),\n"
           "str (model.initial) or a list (guide_ropes.preload); 'guide_ropes.preload[1]' is one\n"
           "element.  Other sections ([service], [sensors], ...) as the file has them, the\n"
           "estimator's defaults when absent.  Raises KeyError for an unknown key.")
      .def("to_toml", &toTomlText,
           "The configuration as TOML text: every shaft key (as hoist-sim --print-config) and the\n"
           "file's other sections; Config.from_toml reads it back equal.")
      .def("__repr__",
           [](const Config& c) {
             return "<hoist.Config from " + c.source + ": n = " + std::to_string(c.params.n) + ", preload = [" +
                    py::str(py::float_(c.params.Tb1)).cast<std::string>() + ", " +
                    py::str(py::float_(c.params.Tb2)).cast<std::string>() + "] N, Fa = " +
                    py::str(py::float_(c.params.Fa)).cast<std::string>() + " N>";
           })
      .def("copy", [](const Config& c) { return c; }, "An independent copy.")
      .def("__copy__", [](const Config& c) { return c; })
      .def("__deepcopy__", [](const Config& c, py::dict) { return c; }, py::arg("memo"))
      .def("__eq__", [](const Config& a, const Config& b) {
             return a.params == b.params && otherSections(a.tbl) == otherSections(b.tbl);
           }, py::is_operator(), "Same shaft and the same other sections (the source is not compared).")
      .def_readonly("source", &Config::source, "Where the configuration came from.")
      .def_static("keys",
                  [] {
                    std::vector<std::string> k;
                    for (const auto& f : kParamFields)
                      if (f.index <= 0) k.push_back(std::string(f.section) + "." + std::string(f.name));
                    return k;
                  },
                  "The shaft's dotted keys.");
}

}  // namespace hoist::python
