// The shaft of a daemon configuration: see hoist/io/daemon_shaft.hpp.
#include "hoist/io/daemon_shaft.hpp"

#include "hoist/io/config.hpp"
#include "hoist/io/estimator_config.hpp"

namespace hoist::io {

std::vector<std::string> daemonOnlySectionsIn(const toml::table& tbl) {
  std::vector<std::string> out;
  for (const auto& [k, node] : tbl) {
    (void)node;
    for (const auto& s : daemonSections())
      if (k.str() == s) out.push_back(s);
  }
  return out;
}

std::string ignoredSectionsNote(const std::string& tool, const std::string& path,
                                const std::vector<std::string>& ignored) {
  if (ignored.empty()) return {};
  std::string s = tool + ": --config " + path + ": using its shaft only; ignoring ";
  for (std::size_t i = 0; i < ignored.size(); ++i) s += (i ? ", [" : "[") + ignored[i] + "]";
  return s;
}

ShaftParams loadDaemonShaft(const std::string& path, const std::string& tool, std::string* note) {
  const toml::table tbl = loadTomlFile(path);
  ShaftParams p = shaftParamsFromToml(tbl, path, daemonSections());
  if (note) *note = ignoredSectionsNote(tool, path, daemonOnlySectionsIn(tbl));
  return p;
}

}  // namespace hoist::io
