// section.hpp (history/src, private) -- runs a [section] reader, then the
// settings' validate(); a "section.key: why" from validate() becomes an
// io::ConfigError with the key's line (io::rethrowWithLine).
#pragma once

#include <stdexcept>
#include <string>

#include "hoist/io/toml_section.hpp"

namespace hoist::history::detail {

template <class Validate>
void runValidated(io::SectionReader& r, const std::string& source, Validate&& validate) {
  r.run();
  try {
    validate();
  } catch (const std::invalid_argument& e) {
    io::rethrowWithLine(e.what(), source, {&r}, true);
  }
}

}  // namespace hoist::history::detail
