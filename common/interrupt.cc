#include "common/interrupt.h"

#include <atomic>
#include <csignal>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"

namespace roamlab {
namespace {

std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free flag");

std::string& CommandLineStorage() {
  static std::string command_line;
  return command_line;
}

// Async-signal-safe: an atomic store, or for a second signal the default action (signal() and raise() are safe).
extern "C" void OnSignal(int signal) {
  int none = 0;
  if (!g_signal.compare_exchange_strong(none, signal)) {
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

const char* SignalName(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "a signal";
}

}  // namespace

void InstallInterruptHandlers() {
  struct sigaction action = {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool InterruptRequested() { return g_signal.load(std::memory_order_relaxed) != 0; }
int InterruptSignal() { return g_signal.load(std::memory_order_relaxed); }
int InterruptExitCode() { return InterruptRequested() ? 128 + InterruptSignal() : 0; }
Status InterruptedError() { return Status::Error(std::string("interrupted by ") + SignalName(InterruptSignal())); }
void RequestInterrupt(int signal) { g_signal.store(signal); }
void ClearInterrupt() { g_signal.store(0); }

void SetCommandLine(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) line += (i ? " " : "") + std::string(argv[i]);
  CommandLineStorage() = line;
}

const std::string& CommandLine() { return CommandLineStorage(); }

IncompleteMarker::IncompleteMarker(std::string directory) : directory_(std::move(directory)) {}

IncompleteMarker::~IncompleteMarker() {
  // Best effort: a destructor cannot report; Start() already wrote a marker that says "running".
  if (started_ && !completed_) (void)Write(InterruptRequested() ? "interrupted" : "failed");
}

Status IncompleteMarker::Start() {
  started_ = true;
  return Write("running");
}

Status IncompleteMarker::AddDone(const std::string& item) {
  done_.push_back(item);
  return started_ ? Write("running") : Status::Ok();
}

Status IncompleteMarker::Complete() {
  completed_ = true;
  return RemoveStaleFile(path());
}

Status IncompleteMarker::Write(const std::string& state) const {
  nlohmann::json marker = {{"command", CommandLine()}, {"state", state}};
  if (state == "interrupted") marker["signal"] = SignalName(InterruptSignal());
  if (state != "running" && !message_.empty()) marker["message"] = message_;
  marker["done"] = done_;
  return WriteFileAtomic(path(), marker.dump(2) + "\n");
}

}  // namespace roamlab
