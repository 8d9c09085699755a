// hoist-log2csv's converter: LCM log events -> one CSV file per channel and
// type (the columns, the file names, the summary: main.cpp's header comment).
// The log itself is read by hoist::io::LcmLogReader in main.cpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/lcm_log.hpp"

namespace hoist::log2csv {

using Event = hoist::io::LcmLogEvent;

/// One output file (hoist::io::CheckedFile: every write, the final fflush and
/// fclose checked).  The first failure is kept and the file dropped, so that
/// the other channels are still converted and the summary names every failure.
struct Writer {
  std::optional<hoist::io::CheckedFile> f;
  std::string path;
  std::string type;
  std::string channel;
  long rows = 0;
  std::string error;  ///< the first failure, with the path and errno text ("": none)
  void open() {
    try {
      f.emplace(path);
    } catch (const hoist::io::WriteError& e) {
      error = e.what();
    }
  }
  void write(const std::string& line) {
    if (!f) return;
    try {
      f->write(line);
      f->write("\n");
    } catch (const hoist::io::WriteError& e) {
      error = e.what();
      f.reset();
    }
  }
  /// Flush and close; false (error set) if any byte did not reach the file.
  bool close() {
    if (f) {
      try {
        f->close();
      } catch (const hoist::io::WriteError& e) {
        error = e.what();
      }
      f.reset();
    }
    return error.empty();
  }
};

/// Converts events as they come (handle) and closes the files at the end
/// (finish).  One instance per run; not thread-safe.
class Converter {
 public:
  explicit Converter(std::filesystem::path dir) : dir_(std::move(dir)) {}

  /// Returns false if the event is of no known type or does not decode.
  bool handle(const Event& ev);
  /// Closes every file (checked to the last byte), then prints the summary.
  /// False if any file failed.
  bool finish(std::ostream& os);
  bool failed() const { return failed_; }
  long badCount() const;      ///< events that carry a hoist fingerprint but fail the checked decode
  long unknownCount() const;  ///< events of no known type

 private:
  Writer* writer(const std::string& channel, const char* type, const std::string& header, const char* suffix = "");
  template <class Msg>
  bool decode(const Event& ev, Msg& m);
  template <class Msg, class Extra>
  bool table(const Event& ev, const char* type, Extra extra);
  template <class Msg>
  bool table(const Event& ev, const char* type);
  bool forecast(const Event& ev);
  bool shape(const Event& ev);

  std::filesystem::path dir_;
  struct Owner {
    std::string channel;
  };
  std::map<std::string, std::unique_ptr<Writer>> writers_;  // by channel, suffix and type
  std::map<std::string, Owner> files_;                      // file stem -> the channel written there
  std::vector<std::string> notes_;
  std::map<std::string, long> unknown_;
  std::map<std::pair<std::string, std::string>, long> bad_;  // (channel, status)
  bool failed_ = false;
};

}  // namespace hoist::log2csv
