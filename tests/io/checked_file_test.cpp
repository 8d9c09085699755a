// hoist::io::CheckedFile, the one writer of every file the project writes:
// files that are not ours (a FIFO, a character device, a symlink, a planted
// temporary-file symlink) are never opened, followed or replaced, a failed
// write leaves no trace, and a bad output path is found by the start-up check.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "hoist/io/checked_file.hpp"

namespace fs = std::filesystem;
using hoist::io::CheckedFile;
using hoist::io::WriteError;

namespace {

fs::path freshDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hoist_checked_file_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The WriteError message of writing "x" to `path`, or "" if it was written.
std::string openError(const fs::path& path) {
  try {
    CheckedFile f(path.string(), "--report");
    f.write("x");
    f.close();
  } catch (const WriteError& e) {
    return e.what();
  }
  return "";
}

/// Only `keep` is left in `dir` (no temporary file behind).
std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace

TEST(CheckedFile, WritesAndReplacesARegularFileAtomically) {
  const fs::path d = freshDir("regular");
  const fs::path p = d / "out.csv";
  { std::ofstream(p) << "old\n"; }
  CheckedFile f(p.string());
  f.write("new ");
  f.printf("%d\n", 42);
  // Until close() the target keeps its old content: the data is elsewhere.
  EXPECT_EQ(slurp(p), "old\n");
  EXPECT_NE(f.tempPath(), p.string());
  EXPECT_EQ(fs::path(f.tempPath()).parent_path(), d);
  f.close();
  EXPECT_EQ(slurp(p), "new 42\n");
  EXPECT_EQ(entries(d), std::vector<std::string>{"out.csv"});
}

// close(true) (hoist-mqtt's journal compactions): the same replacement, the
// data and the rename fsynced; the null device stays a sink.
TEST(CheckedFile, DurableCloseReplacesTheFileAndLeavesNoTemporary) {
  const fs::path d = freshDir("durable");
  const fs::path p = d / "journal.bin";
  { std::ofstream(p) << "old"; }
  CheckedFile f(p.string());
  f.write("new");
  f.close(/*durable=*/true);
  EXPECT_EQ(slurp(p), "new");
  EXPECT_EQ(entries(d), std::vector<std::string>{"journal.bin"});
  CheckedFile null("/dev/null");
  null.write("discarded");
  EXPECT_NO_THROW(null.close(/*durable=*/true));
}

TEST(CheckedFile, AnAbandonedWriteLeavesNoFileBehind) {
  const fs::path d = freshDir("abandoned");
  {
    CheckedFile f((d / "out.csv").string());
    f.write("partial");
  }  // no close(): an error path
  EXPECT_TRUE(entries(d).empty());
}

TEST(CheckedFile, RefusesAFifoAndLeavesItAFifo) {
  const fs::path d = freshDir("fifo");
  const fs::path p = d / "report.json";
  ASSERT_EQ(::mkfifo(p.c_str(), 0600), 0);
  const std::string e = openError(p);
  EXPECT_NE(e.find("--report " + p.string()), std::string::npos) << e;
  EXPECT_NE(e.find("a FIFO"), std::string::npos) << e;
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(p)));
  EXPECT_EQ(entries(d), std::vector<std::string>{"report.json"});
  EXPECT_NE(hoist::io::outputPathError(p.string(), "--report").find("a FIFO"), std::string::npos);
}

TEST(CheckedFile, RefusesASymlinkAndLeavesItsTargetAlone) {
  // --report /dev/null as root replaced the device node: here a symlink to
  // a character device (/dev/null itself is only read, never written).
  const fs::path d = freshDir("symlink");
  const fs::path victim = d / "victim.txt";
  { std::ofstream(victim) << "precious\n"; }
  for (const fs::path& target : {victim, fs::path("/dev/null")}) {
    const fs::path p = d / "out.json";
    fs::remove(p);
    fs::create_symlink(target, p);
    const std::string e = openError(p);
    EXPECT_NE(e.find("a symbolic link"), std::string::npos) << e;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(p)));
    EXPECT_EQ(fs::read_symlink(p), target);
  }
  EXPECT_EQ(slurp(victim), "precious\n");
}

TEST(CheckedFile, RefusesADirectoryAndACharacterDevice) {
  const fs::path d = freshDir("dir");
  EXPECT_NE(openError(d).find("a directory"), std::string::npos);
  // A character device other than the null device is only stat()ed, never
  // opened for writing: refused (/dev/full: never written, so no ENOSPC).
  if (fs::exists("/dev/full") && fs::is_character_file("/dev/full")) {
    EXPECT_NE(hoist::io::outputPathError("/dev/full", "--report").find("a character device"), std::string::npos);
    EXPECT_NE(openError("/dev/full").find("a character device"), std::string::npos);
  }
  // The null device is a discard sink: written to, left a character device.
  if (fs::exists("/dev/null") && fs::is_character_file("/dev/null")) {
    EXPECT_EQ(hoist::io::outputPathError("/dev/null", "--out"), "");
    EXPECT_EQ(openError("/dev/null"), "");
    EXPECT_TRUE(fs::is_character_file(fs::symlink_status("/dev/null")));
  }
}

TEST(CheckedFile, APlantedTemporaryFileSymlinkIsNotFollowed) {
  const fs::path d = freshDir("planted");
  const fs::path victim = d / "victim.txt";
  { std::ofstream(victim) << "precious\n"; }
  const fs::path p = d / "report.json";
  // The old writer's fixed name, and the new one's prefix with guesses.
  fs::create_symlink(victim, d / "report.json.tmp");
  fs::create_symlink(victim, d / ".report.json.tmp");
  CheckedFile f(p.string(), "--report");
  f.write("{}\n");
  f.close();
  EXPECT_EQ(slurp(p), "{}\n");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(p)));
  EXPECT_EQ(slurp(victim), "precious\n");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d / "report.json.tmp")));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d / ".report.json.tmp")));
}

TEST(CheckedFile, ATargetReplacedBeforeCloseIsNotOverwritten) {
  const fs::path d = freshDir("swapped");
  const fs::path p = d / "out.csv";
  CheckedFile f(p.string());
  f.write("data\n");
  ASSERT_EQ(::mkfifo(p.c_str(), 0600), 0);  // appears while we write
  try {
    f.close();
    ADD_FAILURE() << "renamed over a FIFO";
  } catch (const WriteError& e) {
    EXPECT_NE(std::string(e.what()).find("a FIFO"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(p)));
  EXPECT_EQ(entries(d), std::vector<std::string>{"out.csv"});
}

TEST(CheckedFile, StartUpCheckReportsAMissingOrUnwritableDirectory) {
  const fs::path d = freshDir("startup");
  EXPECT_EQ(hoist::io::outputPathError((d / "ok.json").string(), "--report"), "");
  const std::string missing = hoist::io::outputPathError((d / "no" / "such" / "r.json").string(), "--report");
  EXPECT_NE(missing.find("--report"), std::string::npos) << missing;
  EXPECT_NE(missing.find((d / "no" / "such").string()), std::string::npos) << missing;
  EXPECT_NE(missing.find("No such file or directory"), std::string::npos) << missing;
  { std::ofstream(d / "file") << "x"; }
  EXPECT_NE(hoist::io::outputPathError((d / "file" / "r.json").string()).find("not a directory"),
            std::string::npos);
  EXPECT_NE(hoist::io::outputPathError("").find("empty"), std::string::npos);
  if (::geteuid() != 0) {  // root writes anywhere
    const fs::path ro = d / "ro";
    fs::create_directories(ro);
    ::chmod(ro.c_str(), 0500);
    EXPECT_NE(hoist::io::outputPathError((ro / "r.json").string()).find("not writable"), std::string::npos);
    ::chmod(ro.c_str(), 0700);
  }
  EXPECT_THROW(hoist::io::checkOutputPath((d / "no" / "r.json").string()), WriteError);
}

TEST(CheckedFile, KeepsTheUsualPermissions) {
  const fs::path d = freshDir("mode");
  const mode_t old = ::umask(022);
  hoist::io::writeFileChecked((d / "f.csv").string(), "x\n");
  ::umask(old);
  struct stat st{};
  ASSERT_EQ(::stat((d / "f.csv").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);
}
