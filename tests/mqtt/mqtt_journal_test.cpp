// hoist-mqtt's store-and-forward journal (hoist/mqtt/journal.hpp) on real
// files: restart recovery, a corrupt record in the middle, a truncated tail,
// a full journal dropping the oldest samples before any alarm transition,
// length fields validated before anything is allocated, and the checked
// writer's rules for the directory and the file.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "hoist/io/error.hpp"
#include "hoist/mqtt/config.hpp"
#include "hoist/mqtt/journal.hpp"

using namespace hoist::mqtt;
namespace fs = std::filesystem;

// The address-space-limit test cannot run under a sanitizer (its shadow memory).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define HOIST_JOURNAL_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define HOIST_JOURNAL_SANITIZED 1
#endif
#endif
using Clock = std::chrono::steady_clock;

namespace {

class MqttJournal : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("hoist_journal_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, ec);
    fs::remove_all(dir_, ec);
  }
  std::string file() const { return (dir_ / "journal.bin").string(); }
  fs::path dir_;
};

OutMsg msg(int i, MsgClass cls = MsgClass::Cage, std::size_t pad = 0) {
  OutMsg m;
  m.topic = cls == MsgClass::Alarm ? "hoist/s/alarm/K" : "hoist/s/cage";
  m.payload = "{\"i\":" + std::to_string(i) + ",\"pad\":\"" + std::string(pad, 'x') + "\"}";
  m.qos = cls == MsgClass::Alarm ? 1 : 0;
  m.retain = cls == MsgClass::Alarm;
  m.cls = cls;
  return m;
}

/// The "i" of a payload made by msg().
int idOf(const OutMsg& m) { return std::stoi(m.payload.substr(5)); }

std::vector<OutMsg> drain(Journal& j) {
  std::vector<OutMsg> out;
  while (!j.empty()) {
    auto m = j.peek();
    EXPECT_TRUE(m.has_value()) << j.lastError();
    if (m) out.push_back(*m);
    j.pop();
  }
  return out;
}

std::string readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
void writeAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace

TEST_F(MqttJournal, RestartRecoversEveryFieldInOrder) {
  {
    Journal j;
    const auto rep = j.open(dir_.string(), {});
    EXPECT_TRUE(rep.created);
    EXPECT_EQ(rep.recovered, 0u);
    OutMsg a = msg(1);
    a.queued = Clock::now() - std::chrono::seconds(30);
    OutMsg b = msg(2, MsgClass::Alarm);
    OutMsg c = msg(3, MsgClass::Health);
    c.sparkplug = true;
    c.qos = 2;
    c.payload += std::string("\0\x01\xff", 3);  // binary payloads (Sparkplug protobuf) survive
    for (const auto& m : {a, b, c}) ASSERT_TRUE(j.append(m)) << j.lastError();
    EXPECT_EQ(j.size(), 3u);
  }  // destructor: synced and closed, as at a bridge's shutdown
  Journal j;
  const auto rep = j.open(dir_.string(), {});
  EXPECT_FALSE(rep.created);
  EXPECT_EQ(rep.recovered, 3u);
  EXPECT_EQ(rep.problem, "");
  const auto got = drain(j);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(idOf(got[0]), 1);
  EXPECT_EQ(got[0].cls, MsgClass::Cage);
  EXPECT_EQ(got[0].qos, 0);
  EXPECT_FALSE(got[0].retain);
  EXPECT_FALSE(got[0].sparkplug);
  const double age = std::chrono::duration<double>(Clock::now() - got[0].queued).count();
  EXPECT_GT(age, 29.0);  // the queued time crossed the restart
  EXPECT_LT(age, 300.0);
  EXPECT_EQ(got[1].topic, "hoist/s/alarm/K");
  EXPECT_EQ(got[1].cls, MsgClass::Alarm);
  EXPECT_EQ(got[1].qos, 1);
  EXPECT_TRUE(got[1].retain);
  EXPECT_EQ(got[2].cls, MsgClass::Health);
  EXPECT_EQ(got[2].qos, 2);
  EXPECT_TRUE(got[2].sparkplug);
  EXPECT_EQ(got[2].payload, msg(3, MsgClass::Health).payload + std::string("\0\x01\xff", 3));
  // Emptied: back to the bare header.
  EXPECT_EQ(fs::file_size(file()), Journal::kHeaderBytes);
}

TEST_F(MqttJournal, SentMessagesAreNotReplayedAfterARestart) {
  {
    Journal j;
    j.open(dir_.string(), {});
    for (int i = 1; i <= 5; ++i) ASSERT_TRUE(j.append(msg(i)));
    j.pop();
    j.pop();
    j.sync(true);
  }
  Journal j;
  const auto rep = j.open(dir_.string(), {});
  EXPECT_EQ(rep.recovered, 3u);
  EXPECT_EQ(rep.already_sent, 2u);
  const auto got = drain(j);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(idOf(got.front()), 3);
  EXPECT_EQ(idOf(got.back()), 5);
}

TEST_F(MqttJournal, CorruptRecordInTheMiddleIsReportedAndSkippedFromThere) {
  std::vector<std::uint64_t> ends;
  {
    Journal j;
    j.open(dir_.string(), {});
    for (int i = 1; i <= 5; ++i) {
      ASSERT_TRUE(j.append(msg(i)));
      ends.push_back(j.fileBytes());
    }
  }
  std::string bytes = readAll(file());
  bytes[ends[1] + 20] ^= 0x40;  // inside the third record's body
  writeAll(file(), bytes);
  {
    Journal j;
    const auto rep = j.open(dir_.string(), {});
    EXPECT_EQ(rep.recovered, 2u);
    EXPECT_NE(rep.problem.find("CRC"), std::string::npos) << rep.problem;
    EXPECT_NE(rep.problem.find("byte " + std::to_string(ends[1])), std::string::npos) << rep.problem;
    EXPECT_EQ(rep.skipped_bytes, ends[4] - ends[1]);
    EXPECT_EQ(fs::file_size(file()), ends[1]);  // cut at the bad record
    ASSERT_TRUE(j.append(msg(6)));              // and usable
  }
  Journal j;
  const auto rep = j.open(dir_.string(), {});
  EXPECT_EQ(rep.problem, "");
  const auto got = drain(j);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(idOf(got[0]), 1);
  EXPECT_EQ(idOf(got[1]), 2);
  EXPECT_EQ(idOf(got[2]), 6);
}

TEST_F(MqttJournal, TruncatedTailIsReportedAndTheRestRecovered) {
  {
    Journal j;
    j.open(dir_.string(), {});
    for (int i = 1; i <= 3; ++i) ASSERT_TRUE(j.append(msg(i, MsgClass::Cage, 100)));
  }
  for (std::uintmax_t cut : {5u, 130u}) {  // inside the last body; inside the last prefix + body
    SCOPED_TRACE(cut);
    const auto size = fs::file_size(file());
    fs::resize_file(file(), size - cut);
    Journal j;
    const auto rep = j.open(dir_.string(), {});
    EXPECT_NE(rep.problem.find("truncated"), std::string::npos) << rep.problem;
    EXPECT_GT(rep.skipped_bytes, 0u);
    EXPECT_EQ(j.size(), 2u);
    j.close();
    // Next round: the cut file has 2 good records; append one to cut again.
    Journal k;
    k.open(dir_.string(), {});
    ASSERT_TRUE(k.append(msg(9, MsgClass::Cage, 100)));
  }
}

TEST_F(MqttJournal, BadHeaderSkipsTheWholeFile) {
  const std::string text = "this is not a journal at all, but a long enough text file";
  writeAll(file(), text);
  Journal j;
  const auto rep = j.open(dir_.string(), {});
  EXPECT_NE(rep.problem.find("bad magic"), std::string::npos) << rep.problem;
  EXPECT_EQ(rep.recovered, 0u);
  EXPECT_EQ(rep.skipped_bytes, text.size());
  ASSERT_TRUE(j.append(msg(1)));
  j.close();
  Journal k;
  EXPECT_EQ(k.open(dir_.string(), {}).recovered, 1u);
}

TEST_F(MqttJournal, FullJournalDropsTheOldestSamplesFirstAndNeverAnAlarmForASample) {
  JournalLimits lim;
  lim.max_bytes = 65536;
  Journal j;
  j.open(dir_.string(), lim);
  // 600 messages of ~540 bytes (5x the journal): every 10th an alarm transition.
  int alarms = 0;
  for (int i = 0; i < 600; ++i) {
    const bool alarm = i % 10 == 0;
    alarms += alarm;
    ASSERT_TRUE(j.append(msg(i, alarm ? MsgClass::Alarm : MsgClass::Cage, 500))) << j.lastError();
    ASSERT_LE(j.fileBytes(), lim.max_bytes);
  }
  EXPECT_GT(j.droppedCage(), 400u);
  EXPECT_EQ(j.droppedAlarm(), 0u);
  EXPECT_GT(j.compactions(), 0u);
  EXPECT_EQ(static_cast<int>(j.queuedAlarms()), alarms);
  j.close();
  Journal k;
  const auto rep = k.open(dir_.string(), lim);  // the compacted file reads back
  EXPECT_EQ(rep.problem, "");
  const auto got = drain(k);
  int prev = -1, n_alarm = 0, first_cage = -1;
  for (const auto& m : got) {
    EXPECT_GT(idOf(m), prev) << "order";
    prev = idOf(m);
    if (m.cls == MsgClass::Alarm) ++n_alarm;
    else if (first_cage < 0) first_cage = idOf(m);
  }
  EXPECT_EQ(n_alarm, alarms);  // every alarm transition kept
  // The samples kept are the newest: contiguous up to the last one.
  int cages = 0;
  for (const auto& m : got) cages += m.cls == MsgClass::Cage;
  EXPECT_EQ(prev, 599);
  int expected = 0;
  for (int i = first_cage; i < 600; ++i) expected += i % 10 != 0;
  EXPECT_EQ(cages, expected);
}

TEST_F(MqttJournal, AlarmsOnlyJournalDropsItsOldestAlarms) {
  JournalLimits lim;
  lim.max_bytes = 65536;
  Journal j;
  j.open(dir_.string(), lim);
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(j.append(msg(i, MsgClass::Alarm, 500)));
  EXPECT_GT(j.droppedAlarm(), 0u);
  const auto got = drain(j);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(idOf(got.back()), 299);
  EXPECT_EQ(static_cast<std::uint64_t>(got.size()) + j.droppedAlarm(), 300u);
}

TEST_F(MqttJournal, PrependPutsMessagesBeforeTheJournal) {
  Journal j;
  j.open(dir_.string(), {});
  ASSERT_TRUE(j.append(msg(3)));
  ASSERT_TRUE(j.prepend({msg(1), msg(2)}));
  j.close();
  Journal k;
  k.open(dir_.string(), {});
  const auto got = drain(k);
  ASSERT_EQ(got.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(idOf(got[i]), i + 1);
}

namespace {
/// A journal with one good record followed by a record prefix whose length is `len`.
void writeWithLength(const std::string& dir, std::uint32_t len) {
  {
    Journal j;
    j.open(dir, {});
    j.append(msg(1));
  }
  std::string bytes = readAll(dir + "/journal.bin");
  for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<char>((len >> (8 * i)) & 0xff));
  bytes += std::string(4 + 40, 'z');
  writeAll(dir + "/journal.bin", bytes);
}
}  // namespace

TEST_F(MqttJournal, OversizedLengthFieldIsRejectedBeforeAllocating) {
  writeWithLength(dir_.string(), 0xFFFFFFF0u);
  Journal j;
  const auto rep = j.open(dir_.string(), {});
  EXPECT_EQ(rep.recovered, 1u);
  EXPECT_NE(rep.problem.find("exceeds the record limit"), std::string::npos) << rep.problem;
  // Under the record limit but past the end of the file: truncated, not read.
  j.close();
  fs::remove(file());
  writeWithLength(dir_.string(), Journal::kMaxRecordBytes - 1);
  const auto rep2 = j.open(dir_.string(), {});
  EXPECT_EQ(rep2.recovered, 1u);
  EXPECT_NE(rep2.problem.find("truncated"), std::string::npos) << rep2.problem;
}

#ifndef HOIST_JOURNAL_SANITIZED
namespace {
/// In a child: limits the address space to what it uses now plus 8 MiB, opens
/// both journals; exit 0 if both opened, reported a problem and recovered
/// their one good record.
[[noreturn]] void openBothUnderAddressSpaceLimit(const std::string& a_dir, const std::string& b_dir) {
  long pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  const rlim_t limit = static_cast<rlim_t>(pages) * static_cast<rlim_t>(::sysconf(_SC_PAGESIZE)) + (8u << 20);
  const rlimit rl{limit, limit};
  if (::setrlimit(RLIMIT_AS, &rl) != 0) std::_Exit(3);
  try {
    Journal a, b;
    const auto ra = a.open(a_dir, {});
    const auto rb = b.open(b_dir, {});
    std::_Exit(ra.recovered == 1 && rb.recovered == 1 && !ra.problem.empty() && !rb.problem.empty() ? 0 : 4);
  } catch (...) {
    std::_Exit(5);
  }
}
}  // namespace

TEST_F(MqttJournal, LengthFieldsNeverReachTheAllocatorUnderAnAddressSpaceLimit) {
  // In a child whose address space can grow by only 8 MiB: a journal whose
  // length fields claim 4 GiB and 16 MiB opens (reports, recovers), which it
  // could not if either length were allocated before being checked.
  writeWithLength(dir_.string(), 0xFFFFFFF0u);
  const std::string dir2 = (dir_ / "second").string();
  fs::create_directories(dir2);
  writeWithLength(dir2, Journal::kMaxRecordBytes - 1);
  EXPECT_EXIT(openBothUnderAddressSpaceLimit(dir_.string(), dir2), ::testing::ExitedWithCode(0), "");
}
#endif

namespace {
/// In a child limited to 8 KiB files (a full disk, as far as the journal can
/// tell): appends fail, are counted and leave a journal whose records all
/// read back; nothing is fatal.  Exit 0 if so.
[[noreturn]] void appendPastAFileSizeLimit(const std::string& dir) {
  std::signal(SIGXFSZ, SIG_IGN);  // write() then fails with EFBIG instead of killing the process
  const rlimit rl{8192, 8192};
  if (::setrlimit(RLIMIT_FSIZE, &rl) != 0) std::_Exit(3);
  Journal j;
  JournalLimits lim;
  lim.max_bytes = 1 << 20;
  j.open(dir, lim);
  int stored = 0, refused = 0;
  for (int i = 0; i < 40; ++i) (j.append(msg(i, MsgClass::Cage, 500)) ? stored : refused)++;
  if (refused == 0 || stored == 0 || j.writeErrors() != static_cast<std::uint64_t>(refused)) std::_Exit(4);
  if (j.lastError().find("journal.bin") == std::string::npos) std::_Exit(5);
  j.close();
  Journal k;
  const auto rep = k.open(dir, lim);
  if (!rep.problem.empty() || rep.recovered != static_cast<std::uint64_t>(stored)) std::_Exit(6);
  int n = 0;
  while (!k.empty()) {
    auto m = k.peek();
    if (!m || idOf(*m) != n++) std::_Exit(7);
    k.pop();
  }
  std::_Exit(0);
}
}  // namespace

TEST_F(MqttJournal, AFullDiskIsCountedAndLeavesAReadableJournal) {
  EXPECT_EXIT(appendPastAFileSizeLimit(dir_.string()), ::testing::ExitedWithCode(0), "");
}

TEST_F(MqttJournal, RefusesWhatTheCheckedWriterRefuses) {
  // journal.bin a symbolic link: refused, the link's target untouched.
  const auto target = dir_ / "elsewhere";
  writeAll(target.string(), "precious");
  fs::create_symlink(target, file());
  Journal j;
  try {
    j.open(dir_.string(), {});
    ADD_FAILURE() << "a symlinked journal.bin was accepted";
  } catch (const JournalError& e) {
    EXPECT_NE(std::string(e.what()).find("journal.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("symbolic link"), std::string::npos) << e.what();
  }
  EXPECT_EQ(readAll(target.string()), "precious");
  fs::remove(file());
  // journal.bin a directory; [buffer] dir a regular file.
  fs::create_directory(file());
  EXPECT_THROW(j.open(dir_.string(), {}), JournalError);
  fs::remove(file());
  EXPECT_THROW(j.open(target.string(), {}), JournalError);
  // A missing directory is created; an unwritable one is refused (not as root).
  EXPECT_NO_THROW(j.open((dir_ / "fresh").string(), {}));
  j.close();
  if (::geteuid() != 0) {
    const auto ro = dir_ / "readonly";
    fs::create_directory(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    try {
      j.open(ro.string(), {});
      ADD_FAILURE() << "an unwritable directory was accepted";
    } catch (const JournalError& e) {
      EXPECT_NE(std::string(e.what()).find("not writable"), std::string::npos) << e.what();
    }
  }
}

// Issue 33: the journal's records are replayed with the bridge's
// credentials, so its directory must be the bridge's own and its file 0600.
TEST_F(MqttJournal, DirectoryMustBeOwnedAndNotGroupOrOtherWritable) {
  auto refused = [&](const fs::path& d, const std::string& want) {
    Journal j;
    try {
      j.open(d.string(), {});
      ADD_FAILURE() << d << " was accepted";
    } catch (const JournalError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(d.string()), std::string::npos) << what;
      EXPECT_NE(what.find(want), std::string::npos) << what;
    }
    EXPECT_FALSE(fs::exists(d / "journal.bin")) << "nothing is created in a refused directory";
  };
  const auto open_dir = dir_ / "world";
  fs::create_directory(open_dir);
  ::chmod(open_dir.c_str(), 0777);
  refused(open_dir, "mode 0777");
  const auto group_dir = dir_ / "group";
  fs::create_directory(group_dir);
  ::chmod(group_dir.c_str(), 0770);
  refused(group_dir, "mode 0770");
  // A symlink to a good directory: refused (its target could be swapped).
  const auto good = dir_ / "good";
  fs::create_directory(good);
  ::chmod(good.c_str(), 0700);
  fs::create_directory_symlink(good, dir_ / "link");
  refused(dir_ / "link", "symbolic link");
  if (::geteuid() == 0) {  // another user's directory (only root can make one here)
    const auto other = dir_ / "other";
    fs::create_directory(other);
    ::chmod(other.c_str(), 0755);
    ASSERT_EQ(::chown(other.c_str(), 65534, 65534), 0);
    refused(other, "owned by uid 65534");
  }
  // The bridge's own directory, 0700 or 0750: accepted.
  Journal j;
  EXPECT_NO_THROW(j.open(good.string(), {}));
  j.close();
  ::chmod(good.c_str(), 0750);
  EXPECT_NO_THROW(j.open(good.string(), {}));
  j.close();
}

TEST_F(MqttJournal, FileIsMode0600AfterCreationReopenAndCompaction) {
  auto mode = [&] {
    struct stat st{};
    EXPECT_EQ(::stat(file().c_str(), &st), 0);
    return st.st_mode & 07777;
  };
  ::chmod(dir_.c_str(), 0700);
  const mode_t old_umask = ::umask(022);
  Journal j;
  j.open(dir_.string(), {});
  EXPECT_EQ(mode(), 0600u);
  j.close();
  ::chmod(file().c_str(), 0644);  // a journal left by an older bridge
  j.open(dir_.string(), {});
  EXPECT_EQ(mode(), 0600u);
  ASSERT_TRUE(j.append(msg(1)));
  ASSERT_TRUE(j.prepend({msg(0)}));  // a compaction: a new file renamed over journal.bin
  EXPECT_EQ(mode(), 0600u);
  j.close();
  ::umask(old_umask);
}

TEST(MqttJournalConfig, BufferKeys) {
  BridgeConfig c;
  applyBridgeToml("[buffer]\ndir = \"/var/lib/hoist-mqtt\"\nmax_bytes = 1048576\nfsync_interval = 0.5\n", "b.toml", c);
  EXPECT_EQ(c.journal_dir, "/var/lib/hoist-mqtt");
  EXPECT_EQ(c.journal_max_bytes, 1048576u);
  EXPECT_DOUBLE_EQ(c.fsync_interval, 0.5);
  for (const char* bad : {"[buffer]\nmax_bytes = 100\n", "[buffer]\nmax_bytes = 100000.5\n",
                          "[buffer]\nfsync_interval = -1\n", "[buffer]\ndir = 3\n"}) {
    BridgeConfig d;
    try {
      applyBridgeToml(bad, "b.toml", d);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const hoist::io::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("buffer."), std::string::npos) << e.what();
    }
  }
}
