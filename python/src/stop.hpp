// The module's computations without the GIL, stoppable: at interpreter exit (the atexit handler
// _stop_calls stops the calls still running, on daemon threads, and waits for them) and, on the
// main thread, when a signal handler raises (Ctrl-C: KeyboardInterrupt within about
// kSignalCheck). Every GIL release of the module goes through without_gil(), so that:
// - a call begun after the exit handler ran is refused (SystemExit, which a thread ends on
//   quietly);
// - a call stopped raises (the handler's KeyboardInterrupt, or SystemExit at exit), never
//   returns a partial result;
// - a call that ends after the exit handler gave up waiting never takes the GIL again (the
//   interpreter would end the thread with pthread_exit, whose unwinding through a noexcept frame,
//   such as pybind11's gil_scoped_release destructor, aborted the process);
// - the GIL is taken back in no noexcept frame.
#pragma once
#include <proxseg/core/stop.hpp>

#include <exception>
#include <optional>
#include <type_traits>
#include <utility>

#include "bindings.hpp"

namespace proxseg::python {

// One computation's registration, from before the GIL is released until after it is taken back.
class Call {
 public:
  Call();  // GIL held; raises SystemExit when the interpreter is exiting
  ~Call();
  Call(const Call&) = delete;
  Call& operator=(const Call&) = delete;

  StopToken& token() { return token_; }
  void release_gil();
  // Takes the GIL back; at exit, when the exit handler no longer waits, blocks the thread
  // forever instead (the process is ending).
  void restore_gil();
  // GIL held: raises the stop's exception if the call was stopped.
  void raise_if_stopped();

 private:
  bool poll_signals();
  StopToken token_;
  PyThreadState* saved_ = nullptr;
  PyObject* error_[3] = {nullptr, nullptr, nullptr};  // what a signal handler raised
};

// f() without the GIL, stoppable (above); its exceptions reach the caller.
template <class F>
auto without_gil(F&& f) -> decltype(f()) {
  using R = decltype(f());
  Call call;
  call.release_gil();
  std::exception_ptr error;
  [[maybe_unused]] std::conditional_t<std::is_void_v<R>, bool, std::optional<R>> result{};
  {
    const StopScope scope(call.token());
    try {
      if constexpr (std::is_void_v<R>)
        f();
      else
        result.emplace(f());
    } catch (...) {
      error = std::current_exception();
    }
  }
  call.restore_gil();  // not in a destructor: see above
  call.raise_if_stopped();
  if (error) std::rethrow_exception(error);
  if constexpr (!std::is_void_v<R>) return std::move(*result);
}

void bind_stop(py::module_& m);

}  // namespace proxseg::python
