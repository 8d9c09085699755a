// hoist/dash log_safe.hpp -- network strings made safe for hoist-dash's log
// lines (request paths, Host and Origin headers): control characters (C0,
// DEL, C1) and invalid UTF-8 as \xHH / \u00HH (msg::terminalSafe), and the
// Unicode bidirectional controls (U+061C, U+200E, U+200F, U+202A..U+202E,
// U+2066..U+2069) as \uHHHH, so that a request cannot reorder or hide what
// an operator reads in the journal ("Trojan Source").  Pure; called by
// server.cpp for every network string it logs.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace hoist::dash {

/// `s` (at most `max_bytes` of it, then "...") safe to print in a log line.
std::string logSafe(std::string_view s, std::size_t max_bytes = 200);

}  // namespace hoist::dash
