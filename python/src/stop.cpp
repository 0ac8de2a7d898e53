// Stopping the module's computations at interpreter exit and on signals (stop.hpp).
#include "stop.hpp"

#include <pythread.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

namespace proxseg::python {
namespace {

// How often the main thread's computation checks for signals (takes the GIL for a moment).
constexpr std::chrono::milliseconds kSignalCheck{50};

// The calls running. Never destroyed: daemon threads may still use it while the process exits.
struct Calls {
  std::mutex mutex;
  std::condition_variable done;
  std::set<StopToken*> running;
  bool exiting = false;  // the exit handler ran: calls are refused, and those running stopped
  bool gave_up = false;  // it stopped waiting: a call that ends now must not take the GIL
  unsigned long main_thread = 0;
};
Calls& calls() {
  static Calls* c = new Calls;
  return *c;
}

[[noreturn]] void raise_exiting(const char* what) {
  PyErr_SetString(PyExc_SystemExit, what);
  throw py::error_already_set();
}

// The atexit handler: stops the calls still running (daemon threads': the other threads have
// been joined by now) and waits for them, at most `timeout` seconds.
int stop_calls(double timeout) {
  Calls& c = calls();
  std::unique_lock<std::mutex> lock(c.mutex);
  c.exiting = true;
  for (StopToken* t : c.running) t->request_stop();
  PyThreadState* saved = PyEval_SaveThread();  // the calls take the GIL back to return
  const bool all = c.done.wait_for(lock, std::chrono::duration<double>(timeout),
                                   [&] { return c.running.empty(); });
  if (!all) c.gave_up = true;
  const int left = static_cast<int>(c.running.size());
  lock.unlock();
  PyEval_RestoreThread(saved);
  return left;
}

}  // namespace

Call::Call() {
  Calls& c = calls();
  bool exiting = false;
  {
    const std::lock_guard<std::mutex> lock(c.mutex);
    exiting = c.exiting;
    if (!exiting) c.running.insert(&token_);
  }
  if (exiting) raise_exiting("proxseg: not started: the interpreter is exiting");
  // Signals reach the main thread only; there the computation checks for them.
  if (PyThread_get_thread_ident() == c.main_thread)
    token_.poll_with([this] { return poll_signals(); }, kSignalCheck);
}

Call::~Call() {
  Calls& c = calls();
  {
    const std::lock_guard<std::mutex> lock(c.mutex);
    c.running.erase(&token_);
  }
  c.done.notify_all();
  for (PyObject*& e : error_) Py_XDECREF(e);  // only set when the GIL is held: it is now
}

void Call::release_gil() {
  saved_ = PyEval_SaveThread();
}

void Call::restore_gil() {
  Calls& c = calls();
  bool park = false;
  {
    const std::lock_guard<std::mutex> lock(c.mutex);
    park = c.gave_up;
    if (park) c.running.erase(&token_);
  }
  if (park)
    for (;;) std::this_thread::sleep_for(std::chrono::hours(1));  // until the process ends
  PyEval_RestoreThread(saved_);
}

bool Call::poll_signals() {
  const PyGILState_STATE gil = PyGILState_Ensure();
  const bool raised = PyErr_CheckSignals() != 0;
  if (raised) PyErr_Fetch(&error_[0], &error_[1], &error_[2]);
  PyGILState_Release(gil);
  return raised;
}

void Call::raise_if_stopped() {
  if (error_[0] != nullptr) {
    PyErr_Restore(error_[0], error_[1], error_[2]);
    error_[0] = error_[1] = error_[2] = nullptr;
    throw py::error_already_set();
  }
  if (token_.stop_requested()) raise_exiting("proxseg: stopped: the interpreter is exiting");
}

void bind_stop(py::module_& m) {
  calls().main_thread =
      py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  m.def("_stop_calls", &stop_calls, py::arg("timeout"),
        "At exit: stops the computations still running and waits for them, at most `timeout` "
        "seconds; the number left running.");
}

}  // namespace proxseg::python
