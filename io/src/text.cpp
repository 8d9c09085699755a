// Error type and small text helpers of hoist_io.
#include <algorithm>
#include <charconv>
#include <initializer_list>
#include <string>
#include <vector>

#include "hoist/io/error.hpp"
#include "hoist/io/results.hpp"

namespace hoist::io {

namespace {
std::string format(const std::string& source, int line, const std::string& key, const std::string& msg) {
  std::string s;
  s.reserve(source.size() + key.size() + msg.size() + 16);
  s.append(source);
  if (line > 0) s.append(":").append(std::to_string(line));
  s.append(": ");
  if (!key.empty()) s.append(key).append(": ");
  s.append(msg);
  return s;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}
}  // namespace

InputError::InputError(std::string source, int line, std::string key, const std::string& message)
    : std::runtime_error(format(source, line, key, message)),
      source_(std::move(source)),
      line_(line),
      key_(std::move(key)),
      message_(message) {}

std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = 0;
  for (const std::string& c : candidates) {
    const std::size_t d = editDistance(word, c);
    if (best.empty() || d < best_d) {
      best = c;
      best_d = d;
    }
  }
  // A misspelling changes at most about a third of the word.
  if (best.empty() || best_d > std::max<std::size_t>(2, best.size() / 3)) return {};
  return best;
}

void appendNumber(std::string& s, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

}  // namespace hoist::io
