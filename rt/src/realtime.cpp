// Optional real-time settings: see realtime.hpp.
#include "hoist/rt/realtime.hpp"

#include <cerrno>
#include <cstring>
#include <pthread.h>
#include <sched.h>
#include <sstream>
#include <stdexcept>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

namespace hoist::rt {

namespace {
std::string errnoText(int e) {
  std::string s = std::strerror(e);
  if (e == EPERM)
    s += "; needs root or the capability (CAP_IPC_LOCK / CAP_SYS_NICE) or a raised ulimit";
  return s;
}

std::string cpuSetText(const cpu_set_t& set) {
  std::ostringstream os;
  bool first = true;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) {
      os << (first ? "" : ",") << c;
      first = false;
    }
  return os.str();
}
}  // namespace

std::vector<int> parseCpuList(const std::string& text, const std::string& what) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string item;
  const long ncpu = sysconf(_SC_NPROCESSORS_CONF);
  auto num = [&](const std::string& s) {
    std::size_t pos = 0;
    int v = -1;
    try {
      v = std::stoi(s, &pos);
    } catch (const std::exception&) {
      pos = 0;
    }
    if (pos != s.size() || s.empty() || v < 0)
      throw std::invalid_argument(what + ": '" + text + "' is not a CPU list (e.g. 1 or 0,2 or 2-3)");
    if (v >= ncpu || v >= CPU_SETSIZE)
      throw std::invalid_argument(what + ": CPU " + std::to_string(v) + " does not exist (this machine has " +
                                  std::to_string(ncpu) + ")");
    return v;
  };
  while (std::getline(ss, item, ',')) {
    const auto dash = item.find('-');
    if (dash == std::string::npos) {
      out.push_back(num(item));
    } else {
      const int a = num(item.substr(0, dash)), b = num(item.substr(dash + 1));
      if (b < a) throw std::invalid_argument(what + ": empty range '" + item + "'");
      for (int c = a; c <= b; ++c) out.push_back(c);
    }
  }
  if (out.empty()) throw std::invalid_argument(what + ": empty CPU list");
  return out;
}

RealtimeOutcome applyRealtime(const RealtimeRequest& req) {
  RealtimeOutcome o;
  if (req.mlockall) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      o.mlockall = "on";
    } else {
      o.mlockall = "FAILED (" + errnoText(errno) + ")";
      o.all_granted = false;
    }
  } else {
    o.mlockall = "not requested";
  }

  if (req.fifo_priority > 0) {
    sched_param sp{};
    sp.sched_priority = req.fifo_priority;
    const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (e == 0) {
      o.scheduling = "SCHED_FIFO " + std::to_string(req.fifo_priority);
    } else {
      o.scheduling = "FAILED (SCHED_FIFO " + std::to_string(req.fifo_priority) + ": " + errnoText(e) + ")";
      o.all_granted = false;
    }
  } else {
    o.scheduling = "SCHED_OTHER (not requested)";
  }

  cpu_set_t set;
  CPU_ZERO(&set);
  if (!req.cpus.empty()) {
    for (int c : req.cpus) CPU_SET(c, &set);
    const int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    if (e == 0) {
      o.affinity = "CPU " + cpuSetText(set);
    } else {
      o.affinity = "FAILED (CPU " + cpuSetText(set) + ": " + errnoText(e) + ")";
      o.all_granted = false;
    }
  } else {
    if (pthread_getaffinity_np(pthread_self(), sizeof set, &set) == 0)
      o.affinity = "not set (CPUs " + cpuSetText(set) + ")";
    else
      o.affinity = "not set";
  }
  return o;
}

bool yieldToRealtimeLoop(int nice, std::string* why) {
  sched_param sp{};
  sp.sched_priority = 0;
  if (const int e = pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp); e != 0) {
    if (why) *why = "SCHED_OTHER: " + errnoText(e);
    return false;
  }
  // setpriority(PRIO_PROCESS, tid) sets the nice value of one thread on Linux.
  const int value = nice < 0 ? 0 : (nice > 19 ? 19 : nice);
  if (::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), value) != 0) {
    if (why) *why = "nice " + std::to_string(value) + ": " + errnoText(errno);
    return false;
  }
  return true;
}

std::string RealtimeOutcome::summary() const {
  return "memory lock: " + mlockall + "; scheduling: " + scheduling + "; affinity: " + affinity;
}

}  // namespace hoist::rt
