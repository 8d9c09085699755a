// Tasks on C++ threads, the GIL released (python/src/tasks.hpp).
#include "tasks.hpp"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#include <pybind11/pybind11.h>

namespace py = pybind11;

namespace hoist::python {

TaskOutcome runTasks(std::size_t n, int threads,
                     const std::function<void(std::size_t, const std::atomic<bool>&)>& task,
                     const std::function<void(std::size_t)>& report) {
  TaskOutcome out;
  out.errors.resize(n);
  if (n == 0) return out;
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(threads), n));

  std::atomic<bool> cancel{false};
  std::atomic<std::size_t> next{0};
  std::mutex mu;
  std::condition_variable cv;
  std::size_t done = 0;
  int running = 0;
  auto worker = [&] {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= n || cancel.load()) break;
      try {
        task(i, cancel);
      } catch (...) {
        out.errors[i] = std::current_exception();
        cancel.store(true);
      }
      {
        std::lock_guard<std::mutex> lk(mu);
        ++done;
      }
      cv.notify_all();
    }
    {
      std::lock_guard<std::mutex> lk(mu);
      --running;
    }
    cv.notify_all();
  };

  std::vector<std::thread> pool;
  std::optional<py::error_already_set> py_error;
  std::exception_ptr start_error;
  {
    py::gil_scoped_release nogil;
    try {
      for (int k = 0; k < threads; ++k) {
        {
          std::lock_guard<std::mutex> lk(mu);
          ++running;
        }
        try {
          pool.emplace_back(worker);
        } catch (...) {
          std::lock_guard<std::mutex> lk(mu);
          --running;
          throw;
        }
      }
    } catch (...) {
      start_error = std::current_exception();
      cancel.store(true);
    }
  }
  std::size_t reported = static_cast<std::size_t>(-1);
  for (;;) {
    std::size_t d = 0;
    bool finished = false;
    {
      py::gil_scoped_release nogil;
      std::unique_lock<std::mutex> lk(mu);
      cv.wait_for(lk, std::chrono::milliseconds(50), [&] { return running == 0 || done != reported; });
      d = done;
      finished = running == 0;
    }
    if (!py_error && PyErr_CheckSignals() != 0) {
      py_error.emplace();  // KeyboardInterrupt (or what the handler raised)
      cancel.store(true);
    }
    if (!py_error && report) {
      try {
        report(d);
      } catch (py::error_already_set& e) {
        py_error.emplace(std::move(e));
        cancel.store(true);
      }
    }
    reported = d;
    if (finished) break;
  }
  {
    py::gil_scoped_release nogil;
    for (auto& t : pool) t.join();
  }
  if (py_error) throw std::move(*py_error);
  if (start_error) std::rethrow_exception(start_error);
  out.done = done;
  return out;
}

}  // namespace hoist::python
