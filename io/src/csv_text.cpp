// The CSV text helpers of hoist_io: see csv_text.hpp.
#include "csv_text.hpp"

#include <charconv>

namespace hoist::io::csv {

std::string trim(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return std::string(s.substr(b, e - b));
}

std::vector<std::string> splitComma(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t c = line.find(',', start);
    out.push_back(trim(std::string_view(line).substr(start, c == std::string::npos ? std::string::npos : c - start)));
    if (c == std::string::npos) break;
    start = c + 1;
  }
  return out;
}

bool parseDouble(const std::string& f, double& out) {
  if (f.empty()) return false;
  const char* b = f.data();
  const char* e = b + f.size();
  if (*b == '+') ++b;  // from_chars does not take a leading '+'
  const auto r = std::from_chars(b, e, out);
  return r.ec == std::errc() && r.ptr == e;
}

std::string shortened(const std::string& s) {
  std::string o;
  for (char c : s.substr(0, 40)) o += (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) ? '?' : c;
  return s.size() > 40 ? o + "..." : o;
}

std::string checkLine(std::string& line, int lineno, const char* kind) {
  if (lineno == 1 && line.size() >= 3 && static_cast<unsigned char>(line[0]) == 0xEF &&
      static_cast<unsigned char>(line[1]) == 0xBB && static_cast<unsigned char>(line[2]) == 0xBF)
    line.erase(0, 3);  // UTF-8 byte-order mark
  if (line.size() > 4096) return std::string("line longer than 4096 characters: not a ") + kind;
  for (unsigned char c : line)
    if (c == 0 || (c < 32 && c != '\t' && c != '\r')) return "binary data (control character) in a text CSV";
  return {};
}

}  // namespace hoist::io::csv
