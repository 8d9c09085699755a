// hoist/study/studies.hpp -- the catalogue of studies: the paper's Section 3
// studies (Figs. 2-13) and a sweep of any key.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "hoist/params.hpp"
#include "hoist/study/runner.hpp"

namespace hoist::study {

/// A set of runs that differ in one parameter.
struct Study {
  std::string name;     ///< "preload", "sweep", ...
  std::string title;    ///< human-readable
  std::string figures;  ///< the paper's figures it reproduces, e.g. "6-7"
  std::string key;      ///< swept key ("" for the single baseline run)
  std::vector<RunSpec> runs;
};

/// The paper's studies, in paper order.
const std::vector<std::string>& paperStudyNames();  // response, preload, tension-difference, eccentric-load, mass
/// The named paper study on top of `base` (nullopt for an unknown name).
/// The tension-difference study sets the total preload to 6e4 N first.
std::optional<Study> paperStudy(const std::string& name, const ShaftParams& base);
/// A sweep of `key` over `values` on top of `base`; throws ParamError for a bad
/// key or a value that makes the parameters invalid (naming the key).
Study sweepStudy(const std::string& key, const std::vector<double>& values,
                 const ShaftParams& base);

}  // namespace hoist::study
