// The calling thread's stop token (core/stop.hpp): one thread-local slot, read at the stop points.
#include <proxseg/core/stop.hpp>

namespace proxseg {
namespace {

struct Current {
  StopToken* token = nullptr;
  bool polls = false;
};
thread_local Current current;

}  // namespace

StopScope::StopScope(StopToken* token, bool polls)
    : previous_(current.token), previous_polls_(current.polls) {
  // A thread of the token's own scope (the master thread of an OpenMP team) keeps polling.
  if (token != current.token) current = {token, polls};
}

StopScope::~StopScope() {
  current = {previous_, previous_polls_};
}

StopToken* current_stop_token() noexcept {
  return current.token;
}

void stop_point() {
  StopToken* token = current.token;
  if (token == nullptr) return;
  if (current.polls && token->poll_) {
    const auto now = std::chrono::steady_clock::now();
    if (now - token->polled_ >= token->every_) {
      token->polled_ = now;
      if (token->poll_()) token->request_stop();
    }
  }
  if (token->stop_requested()) throw Stopped();
}

}  // namespace proxseg
