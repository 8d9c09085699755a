// journal_format.hpp -- the byte format of hoist-mqtt's journal file
// (hoist/mqtt/journal.hpp describes it): framing, the header, the consumed
// marker and the message body's decoder.  Private to tools/mqtt; used by
// journal.cpp (Journal::crc32 and Journal::encodeMessage live in
// journal_format.cpp too).  Pure functions, no state.
#pragma once

#include <cstdint>
#include <string>

#include "hoist/mqtt/journal.hpp"

namespace hoist::mqtt::journal_format {

inline constexpr char kMagic[8] = {'H', 'O', 'I', 'S', 'T', 'J', 'N', 'L'};
inline constexpr std::uint8_t kTypeMessage = 1, kTypeConsumed = 2;
inline constexpr std::size_t kConsumedBody = 12;

std::int64_t wallUtime();
void put16(std::string& s, std::uint16_t v);
void put32(std::string& s, std::uint32_t v);
void put64(std::string& s, std::uint64_t v);
/// Little-endian, `n` bytes.
std::uint64_t get(const unsigned char* p, int n);
/// The file's 16-byte header.
std::string header();
/// Prefix (length, CRC) + body.
std::string frame(const std::string& body);
std::string consumedRecord(std::uint64_t seq);
/// Reads exactly n bytes at offset (false on EOF or error).
bool readAt(int fd, std::uint64_t offset, void* buf, std::size_t n);
/// A message body decoded (fields checked); "" or why not.
std::string decodeMessage(const std::string& body, OutMsg& m, std::uint64_t& seq);

}  // namespace hoist::mqtt::journal_format
