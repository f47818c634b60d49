#include "experiment/external.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include "common/interrupt.h"
#include "common/time.h"
#include "eval/nees.h"

extern char** environ;

namespace roamlab::experiment {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr double kMaxTimeoutS = 1e6;
// How long a command has between SIGTERM and SIGKILL [s].
constexpr double kTerminateGraceS = 2.0;
// How often the wait loop looks at the child, the clock and the interrupt flag.
constexpr std::chrono::milliseconds kPollPeriod{20};

// `text` as one word for /bin/sh: in single quotes, each ' written as '\''.
std::string ShellQuote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string Absolute(const std::string& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  return (ec ? fs::path(path) : absolute).lexically_normal().string();
}

// Replaces every occurrence of `key` in `text`; whether there was one.
bool ReplaceAll(std::string* text, const std::string& key, const std::string& value) {
  bool found = false;
  for (std::size_t at = text->find(key); at != std::string::npos; at = text->find(key, at + value.size())) {
    text->replace(at, key.size(), value);
    found = true;
  }
  return found;
}

// The last non-empty line of the log, "" when there is none (or it cannot be read).
std::string LastLine(const std::string& log_file) {
  std::ifstream in(log_file);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  constexpr std::size_t kMaxQuoted = 200;
  return last.size() > kMaxQuoted ? last.substr(0, kMaxQuoted) + "..." : last;
}

// Starts /bin/sh -c LINE in its own process group, in `working_dir`, with its output in `log_file`.
Result<pid_t> Spawn(const std::string& line, const std::string& working_dir, const std::string& log_file) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  if (!working_dir.empty()) posix_spawn_file_actions_addchdir_np(&actions, working_dir.c_str());
  // Its own process group (so that a time-out ends everything it started), default signal handling and mask.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  posix_spawnattr_setpgroup(&attributes, 0);
  sigset_t defaults, empty;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigaddset(&defaults, SIGPIPE);
  sigemptyset(&empty);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setsigmask(&attributes, &empty);
  std::string sh = "/bin/sh", dash_c = "-c", command = line;
  char* argv[] = {sh.data(), dash_c.data(), command.data(), nullptr};
  pid_t pid = 0;
  const int spawned = ::posix_spawn(&pid, sh.c_str(), &actions, &attributes, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) return Status::Error(std::string("cannot start /bin/sh: ") + std::strerror(spawned));
  return pid;
}

// Waits until the child has ended (without reaping it, so that its pid, the process group's id, cannot be reused
// before the group is killed) or `deadline` passed; true when it ended.
bool WaitUntil(pid_t pid, Clock::time_point deadline, bool stop_on_interrupt) {
  for (;;) {
    siginfo_t info{};
    const int waited = ::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT);
    if ((waited == 0 && info.si_pid == pid) || (waited < 0 && errno != EINTR)) return true;
    if (Clock::now() >= deadline || (stop_on_interrupt && InterruptRequested())) return false;
    std::this_thread::sleep_for(kPollPeriod);
  }
}

// Kills what is left of the child's process group (what the command started and left running) and reaps the
// child; its wait status.
int KillGroupAndReap(pid_t pid) {
  ::kill(-pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

// Ends the child's process group: SIGTERM, then SIGKILL after the grace period; reaps the child.
void TerminateGroup(pid_t pid) {
  ::kill(-pid, SIGTERM);
  const auto grace =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kTerminateGraceS));
  WaitUntil(pid, grace, false);
  KillGroupAndReap(pid);
}

// Why the wait status is a failure ("exited with status 3", "was killed by signal 11"), "" for exit status 0.
std::string Failure(int status) {
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    if (code == 0) return "";
    if (code == 127) return "exited with status 127 (command not found)";
    if (code == 126) return "exited with status 126 (not executable)";
    return "exited with status " + std::to_string(code);
  }
  if (WIFSIGNALED(status)) return "was killed by signal " + std::to_string(WTERMSIG(status));
  return "ended abnormally";
}

// Checks that the covariance rows and the poses pair one to one by stamp.
Status MatchCovarianceRows(const std::string& path, const std::vector<eval::StampedCovariance>& rows,
                           const Trajectory& trajectory) {
  if (rows.size() != trajectory.size())
    return Status::Error(path + ": " + std::to_string(rows.size()) + " rows for " + std::to_string(trajectory.size()) +
                         " poses in trajectory.tum (one row per pose, at the pose's stamp)");
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k].t != trajectory[k].t)
      return Status::Error(path + ":" + std::to_string(k + 2) + ": stamp " + FormatSeconds(rows[k].t) +
                           " is not the stamp of pose " + std::to_string(k + 1) + " in trajectory.tum (" +
                           FormatSeconds(trajectory[k].t) + ")");
  return Status::Ok();
}

}  // namespace

std::string ExternalCommand::Validate() const {
  if (command.find_first_not_of(" \t") == std::string::npos) return "the estimator command is empty";
  if (!(timeout_s > 0.0 && timeout_s <= kMaxTimeoutS)) return "timeout_s must be positive and at most 1e6 s";
  if (!working_dir.empty() && !fs::is_directory(working_dir))
    return working_dir + ": not a directory (the estimator command's working directory)";
  return "";
}

std::string ExpandCommand(const std::string& command, const std::string& recording_dir, const std::string& out_dir) {
  std::string line = command;
  const bool recording = ReplaceAll(&line, "{recording}", ShellQuote(Absolute(recording_dir)));
  const bool out = ReplaceAll(&line, "{out}", ShellQuote(Absolute(out_dir)));
  if (!recording && !out) line += " " + ShellQuote(Absolute(recording_dir)) + " " + ShellQuote(Absolute(out_dir));
  return line;
}

Status MakeEstimatorInput(const std::string& recording_dir, const std::string& input_dir) {
  std::error_code ec;
  fs::remove_all(input_dir, ec);
  fs::create_directories(input_dir, ec);
  if (ec) return Status::Error(input_dir + ": cannot create the estimator's input directory: " + ec.message());
  const fs::path source = Absolute(recording_dir);
  for (const fs::directory_entry& entry : fs::directory_iterator(source, ec)) {
    const std::string name = entry.path().filename().string();
    if (name == "ground_truth.tum" || name == "truth.yaml") continue;
    fs::create_symlink(entry.path(), fs::path(input_dir) / name, ec);
    if (ec) return Status::Error(input_dir + "/" + name + ": cannot link the recording's file: " + ec.message());
  }
  if (ec) return Status::Error(recording_dir + ": cannot list the recording: " + ec.message());
  return Status::Ok();
}

Status RunExternalCommand(const ExternalCommand& command, const std::string& recording_dir, const std::string& out_dir,
                          const std::string& log_file) {
  const std::string name = "estimator command '" + command.command + "'";
  if (const std::string problem = command.Validate(); !problem.empty()) return Status::Error(name + ": " + problem);
  std::error_code ec;
  fs::remove_all(out_dir, ec);
  fs::create_directories(out_dir, ec);
  if (ec) return Status::Error(out_dir + ": cannot create the output directory: " + ec.message());
  const Result<pid_t> pid =
      Spawn(ExpandCommand(command.command, recording_dir, out_dir), command.working_dir, Absolute(log_file));
  if (!pid.ok()) return Status::Error(name + ": " + pid.status().message());
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(command.timeout_s));
  if (!WaitUntil(pid.value(), deadline, true)) {
    TerminateGroup(pid.value());
    if (InterruptRequested()) return Status::Error(name + ": stopped, " + InterruptedError().message());
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", command.timeout_s);
    return Status::Error(name + ": killed after the time-out of " + std::string(limit) + " s (output in " + log_file +
                         ")");
  }
  const std::string failure = Failure(KillGroupAndReap(pid.value()));
  if (failure.empty()) return Status::Ok();
  const std::string last = LastLine(log_file);
  return Status::Error(name + ": " + failure + " (" + log_file + (last.empty() ? ")" : ": " + last + ")"));
}

Result<ExternalEstimate> ReadExternalEstimate(const std::string& out_dir) {
  ExternalEstimate estimate;
  const std::string trajectory = (fs::path(out_dir) / "trajectory.tum").string();
  if (!fs::is_regular_file(trajectory))
    return Status::Error(trajectory + ": missing: the estimator wrote no trajectory");
  Result<Trajectory> poses = ReadTum(trajectory);
  if (!poses.ok()) return poses.status();
  if (poses.value().empty()) return Status::Error(trajectory + ": no poses");
  estimate.trajectory = std::move(poses).value();
  const std::string covariance = (fs::path(out_dir) / "covariance.csv").string();
  if (!fs::exists(covariance)) return estimate;
  Result<std::vector<eval::StampedCovariance>> rows = eval::ReadPositionCovariances(covariance);
  if (!rows.ok()) return rows.status();
  if (Status matched = MatchCovarianceRows(covariance, rows.value(), estimate.trajectory); !matched.ok())
    return matched;
  std::vector<Eigen::Matrix3d> matrices;
  for (const eval::StampedCovariance& row : rows.value()) matrices.push_back(row.covariance_world);
  estimate.position_covariance_world = std::move(matrices);
  return estimate;
}

}  // namespace roamlab::experiment
