// figures.hpp -- the catalogue of figures of each study (which columns of
// which files go in which panel, after the paper's Figs. 2-13).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hoist/study/studies.hpp"
#include "output.hpp"

namespace hoist::study::cli {

/// The trace file of run i, relative to the study's directory.
std::string runFile(std::size_t i);
/// The figures of study `s` (by its name; a sweep gets the generic set).
std::vector<out::Figure> figuresFor(const Study& s);

}  // namespace hoist::study::cli
