// The outage queue (hoist/history/queue.hpp).
#include "hoist/history/queue.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "hoist/history/record_json.hpp"
#include "hoist/io/checked_file.hpp"

namespace hoist::history {

namespace fs = std::filesystem;

namespace {

constexpr const char* kMagic = "hoist-trip-queue 1";

void syncDir(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

bool parseSeq(const std::string& name, std::uint64_t& seq) {
  if (name.size() != 2 + 20 + 5 || name.rfind("q-", 0) != 0 || name.substr(22) != ".trip") return false;
  seq = 0;
  for (std::size_t i = 2; i < 22; ++i) {
    if (name[i] < '0' || name[i] > '9') return false;
    seq = seq * 10 + static_cast<std::uint64_t>(name[i] - '0');
  }
  return true;
}

}  // namespace

std::uint32_t crc32(const void* data, std::size_t n) {
  uLong c = ::crc32(0L, Z_NULL, 0);
  const auto* p = static_cast<const Bytef*>(data);
  while (n > 0) {  // zlib takes a uInt length
    const uInt chunk = static_cast<uInt>(std::min<std::size_t>(n, 1u << 30));
    c = ::crc32(c, p, chunk);
    p += chunk;
    n -= chunk;
  }
  return static_cast<std::uint32_t>(c);
}

RecordQueue::RecordQueue(std::string dir) : dir_(std::move(dir)) {}

std::vector<RecordQueue::Entry> RecordQueue::pending() const {
  std::vector<Entry> out;
  std::error_code ec;
  if (!fs::is_directory(dir_, ec)) return out;
  for (const auto& de : fs::directory_iterator(dir_, ec)) {
    Entry e;
    if (de.is_regular_file(ec) && parseSeq(de.path().filename().string(), e.seq)) {
      e.path = de.path().string();
      out.push_back(std::move(e));
    }
  }
  std::sort(out.begin(), out.end(), [](const Entry& a, const Entry& b) { return a.seq < b.seq; });
  return out;
}

void RecordQueue::push(const TripRecord& r) {
  std::error_code ec;
  if (!fs::is_directory(dir_, ec)) {
    fs::create_directories(dir_, ec);
    if (ec) throw io::WriteError(dir_, "cannot create the history queue folder", ec.value());
    ::chmod(dir_.c_str(), 0700);
  }
  const auto all = pending();
  const std::uint64_t seq = all.empty() ? 1 : all.back().seq + 1;
  char name[40];
  std::snprintf(name, sizeof name, "q-%020llu.trip", static_cast<unsigned long long>(seq));
  const std::string body = recordToJson(r).dump();
  char head[80];
  std::snprintf(head, sizeof head, "%s %08x %zu\n", kMagic, crc32(body.data(), body.size()), body.size());
  io::CheckedFile f((fs::path(dir_) / name).string(), "history queue");
  f.write(head);
  f.write(body);
  f.close(true);
}

bool RecordQueue::read(const Entry& e, TripRecord& out, std::string& why) {
  std::ifstream in(e.path, std::ios::binary);
  std::string head;
  std::getline(in, head);
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string body = ss.str();
  unsigned crc = 0;
  std::size_t len = 0;
  char magic[32] = {};
  int ver = 0;
  if (!in.good() && !in.eof()) why = "cannot read it";
  else if (std::sscanf(head.c_str(), "%31s %d %x %zu", magic, &ver, &crc, &len) != 4 ||
           std::string(magic) + " " + std::to_string(ver) != kMagic)
    why = "not a queue file (bad header)";
  else if (len != body.size()) why = "length " + std::to_string(body.size()) + " != " + std::to_string(len);
  else if (crc32(body.data(), body.size()) != crc) why = "CRC mismatch";
  else {
    try {
      out = recordFromJson(nlohmann::json::parse(body));
      return true;
    } catch (const std::exception& ex) {
      why = ex.what();
    }
  }
  ++rejected_;
  std::error_code ec;
  fs::rename(e.path, e.path + ".bad", ec);
  why = e.path + ": " + why + " (moved to .bad)";
  return false;
}

void RecordQueue::remove(const Entry& e) {
  std::error_code ec;
  fs::remove(e.path, ec);
  if (ec) throw io::WriteError(e.path, "cannot remove a flushed queue file", ec.value());
  syncDir(dir_);
}

std::int64_t RecordQueue::maxTrip(const std::string& shaft) {
  std::int64_t m = 0;
  for (const auto& e : pending()) {
    TripRecord r;
    std::string why;
    if (read(e, r, why) && r.shaft == shaft) m = std::max(m, r.trip);
  }
  return m;
}

}  // namespace hoist::history
