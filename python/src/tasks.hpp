// python/src/tasks.hpp -- run N independent tasks on C++ threads while the
// calling Python thread waits with the GIL released.
//
// The waiting thread wakes every 50 ms (or when a task ends), takes the GIL,
// checks for signals (Ctrl-C: PyErr_CheckSignals -> KeyboardInterrupt) and
// calls `report(done)` (progress, on every wake; it may raise).  An interrupt, an exception from
// `report` or the first failing task sets the cancel flag, which every task
// polls; all threads are joined before runTasks returns or throws, so nothing
// runs on after it.  Called with the GIL held; `task` runs without it and
// must not touch Python objects.
#pragma once

#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <vector>

namespace hoist::python {

struct TaskOutcome {
  std::vector<std::exception_ptr> errors;  ///< per task; null when it succeeded (or never ran)
  std::size_t done = 0;                    ///< tasks that finished (either way)
};

/// `threads` <= 0: one per hardware thread.  Throws pybind11::error_already_set
/// on an interrupt or when `report` raised (after joining every thread).
TaskOutcome runTasks(std::size_t n, int threads,
                     const std::function<void(std::size_t, const std::atomic<bool>& cancel)>& task,
                     const std::function<void(std::size_t done)>& report);

}  // namespace hoist::python
