#include "interrupt.hpp"

#include <csignal>
#include <map>
#include <mutex>
#include <pthread.h>
#include <thread>
#include <unistd.h>

namespace skinmesh::app {

namespace {

struct Registry {
  std::mutex mutex;
  long next_id = 0;
  std::map<long, std::string> paths;  // by registration order
};

Registry& registry() {
  static Registry r;
  return r;
}

sigset_t interrupt_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  return set;
}

[[noreturn]] void remove_all_and_end(int signal) {
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);  // held to the end: nothing registers after this
    for (auto it = r.paths.rbegin(); it != r.paths.rend(); ++it)
      if (::unlink(it->second.c_str()) != 0) ::rmdir(it->second.c_str());
    // Default action, delivered to this thread: the process ends by the signal.
    std::signal(signal, SIG_DFL);
    const sigset_t set = interrupt_signals();
    pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
    std::raise(signal);
  }
  std::_Exit(128 + signal);  // not reached
}

}  // namespace

void watch_interrupts() {
  const sigset_t set = interrupt_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);  // inherited by every thread started from here
  std::thread([set] {
    int signal = 0;
    if (sigwait(&set, &signal) == 0) remove_all_and_end(signal);
  }).detach();
}

RemovedOnInterrupt::RemovedOnInterrupt(std::string path) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  id_ = r.next_id++;
  r.paths.emplace(id_, std::move(path));
}

RemovedOnInterrupt::RemovedOnInterrupt(RemovedOnInterrupt&& other) noexcept : id_(other.id_) { other.id_ = -1; }

RemovedOnInterrupt& RemovedOnInterrupt::operator=(RemovedOnInterrupt&& other) noexcept {
  if (this != &other) {
    release();
    id_ = other.id_;
    other.id_ = -1;
  }
  return *this;
}

RemovedOnInterrupt::~RemovedOnInterrupt() { release(); }

void RemovedOnInterrupt::release() {
  if (id_ < 0) return;
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.paths.erase(id_);
  id_ = -1;
}

}  // namespace skinmesh::app
