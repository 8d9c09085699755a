// The one TOML section reader: see hoist/io/toml_section.hpp.
#include "hoist/io/toml_section.hpp"

#include <cmath>

namespace hoist::io {

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

std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string m = closestMatch(word, candidates);
  return m.empty() ? std::string() : " (did you mean '" + m + "'?)";
}

SectionReader::SectionReader(const toml::table& root, std::string section, std::string source)
    : section_(std::move(section)), source_(std::move(source)) {
  const toml::node* n = root.get(section_);
  if (!n) return;
  tbl_ = n->as_table();
  if (!tbl_)
    throw ConfigError(source_, lineOf(*n), section_,
                      "must be a table [" + section_ + "], got " + typeName(*n));
}

void SectionReader::on(std::string key, Handler h) { handlers_.emplace_back(std::move(key), std::move(h)); }

void SectionReader::number(std::string key, double& out, bool finite) {
  on(key, [this, key, &out, finite](const toml::node& n) {
    if (const auto* i = n.as_integer()) out = static_cast<double>(i->get());
    else if (const auto* f = n.as_floating_point()) out = f->get();
    else fail(n, key, std::string("must be a number, got ") + typeName(n));
    if (finite && !std::isfinite(out)) fail(n, key, "must be finite");
  });
}

void SectionReader::integer(std::string key, int& out, long long lo, long long hi) {
  on(key, [this, key, &out, lo, hi](const toml::node& n) {
    const auto* i = n.as_integer();
    if (!i) fail(n, key, std::string("must be an integer, got ") + typeName(n));
    if (i->get() < lo || i->get() > hi)
      fail(n, key, "must be between " + std::to_string(lo) + " and " + std::to_string(hi) + " (got " +
                       std::to_string(i->get()) + ")");
    out = static_cast<int>(i->get());
  });
}

void SectionReader::boolean(std::string key, bool& out) {
  on(key, [this, key, &out](const toml::node& n) {
    const auto* b = n.as_boolean();
    if (!b) fail(n, key, std::string("must be true or false, got ") + typeName(n));
    out = b->get();
  });
}

void SectionReader::string(std::string key, std::function<void(const toml::node&, const std::string&)> set) {
  on(key, [this, key, set = std::move(set)](const toml::node& n) {
    const auto* s = n.as_string();
    if (!s) fail(n, key, std::string("must be a string, got ") + typeName(n));
    set(n, s->get());
  });
}

void SectionReader::run() {
  if (!tbl_) return;
  for (auto&& [k, node] : *tbl_) {
    const std::string key(k.str());
    const Handler* h = nullptr;
    for (const auto& [name, handler] : handlers_)
      if (name == key) h = &handler;
    if (!h) {
      std::vector<std::string> known;
      std::string list;
      for (const auto& [name, handler] : handlers_) {
        known.push_back(name);
        list += (list.empty() ? "" : ", ") + name;
      }
      fail(node, key, "unknown key" + didYouMean(key, known) + "; [" + section_ + "] takes " + list);
    }
    (*h)(node);
    lines_.emplace_back(key, lineOf(node));
  }
}

int SectionReader::lineOfKey(const std::string& key) const {
  for (const auto& [k, l] : lines_)
    if (k == key) return l;
  return 0;
}

int SectionReader::line() const { return tbl_ ? lineOf(*tbl_) : 0; }

void SectionReader::fail(const toml::node& n, const std::string& key, const std::string& why) const {
  throw ConfigError(source_, lineOf(n), section_ + "." + key, why);
}

void rethrowWithLine(const std::string& what, const std::string& source,
                     const std::vector<const SectionReader*>& readers, bool section_line_fallback) {
  const auto colon = what.find(": ");
  const std::string key = colon != std::string::npos ? what.substr(0, colon)
                          : readers.empty()        ? std::string()
                                                   : readers.front()->section();
  const std::string why = colon == std::string::npos ? what : what.substr(colon + 2);
  const auto dot = key.find('.');
  const std::string section = key.substr(0, dot);
  int line = 0;
  for (const SectionReader* r : readers) {
    if (r->section() != section) continue;
    line = dot == std::string::npos ? 0 : r->lineOfKey(key.substr(dot + 1));
    if (line == 0 && section_line_fallback) line = r->line();
  }
  throw ConfigError(source, line, key, why);
}

}  // namespace hoist::io
