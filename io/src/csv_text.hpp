// io/src/csv_text.hpp -- the small text helpers of hoist_io's CSV readers
// (the profile CSV of profile_io.cpp and the measurement CSV of
// measurements.cpp), so that both accept and reject the same text.
// Internal to hoist_io: not installed, not included from outside io/src.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace hoist::io::csv {

/// `s` without leading/trailing blanks, tabs and CRs.
std::string trim(std::string_view s);
/// The comma-separated fields of `line`, each trimmed.
std::vector<std::string> splitComma(const std::string& line);
/// Parses the whole field as a double (accepts what strtod accepts except
/// hex floats, no trailing junk).  Returns false if it is not a number.
bool parseDouble(const std::string& f, double& out);
/// At most 40 printable characters of `s` for a message.
std::string shortened(const std::string& s);
/// Line limits shared by the CSV readers: strips a UTF-8 byte-order mark from
/// line 1, then returns "" or what is wrong with the line (longer than 4096
/// characters: "not a <kind>", binary data).
std::string checkLine(std::string& line, int lineno, const char* kind);

}  // namespace hoist::io::csv
