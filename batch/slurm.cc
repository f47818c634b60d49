#include "batch/slurm.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include "batch/internal/process.h"
#include "common/atomic_file.h"

namespace roamlab::batch {
namespace {

using experiment::Outcome;
using nlohmann::json;
namespace fs = std::filesystem;

std::string BatchDir(const std::string& out) { return out + "/batch"; }
std::string BatchFile(const std::string& out) { return BatchDir(out) + "/batch.json"; }

Status WriteBatch(const std::string& out, const json& batch) {
  return WriteFileAtomic(BatchFile(out), batch.dump(2) + "\n");
}

// Whether j[key] exists and passes `is`.
template <typename Is>
bool Has(const json& j, const char* key, Is is) {
  const auto it = j.find(key);
  return it != j.end() && is(*it);
}
const auto kString = [](const json& v) { return v.is_string(); };
const auto kInteger = [](const json& v) { return v.is_number_integer(); };

// The options and submissions of a Slurm batch have the types the code reads them as.
bool WellFormedSlurm(const json& batch) {
  const auto strings = [](const json& v) {
    return v.is_array() && std::all_of(v.begin(), v.end(), [](const json& a) { return a.is_string(); });
  };
  const auto options = [&](const json& v) {
    return v.is_object() && Has(v, "partition", kString) && Has(v, "time", kString) &&
           Has(v, "array_parallelism", kInteger) && Has(v, "runs_per_task", kInteger) &&
           v["runs_per_task"].get<std::int64_t>() >= 1 && Has(v, "retries", kInteger) && Has(v, "sbatch_args", strings);
  };
  const auto submission = [](const json& v) {
    return v.is_object() && Has(v, "array_job", kString) && Has(v, "aggregate_job", kString) &&
           (!v.contains("ready") || v["ready"].is_number_integer());
  };
  const auto submissions = [&](const json& v) { return v.is_array() && std::all_of(v.begin(), v.end(), submission); };
  return Has(batch, "slurm", options) && Has(batch, "submissions", submissions);
}

// batch.json has every key the code reads, of its type.
bool WellFormed(const json& batch) {
  if (!batch.is_object() || !Has(batch, "work", [](const json& v) { return v.is_object(); }) ||
      !Has(batch, "backend", kString) || !Has(batch, "cwd", kString) || !Has(batch, "state", kString) ||
      !Has(batch, "message", kString))
    return false;
  return batch["backend"] != "slurm" || WellFormedSlurm(batch);
}

Result<json> ReadBatch(const std::string& out) {
  Result<std::string> text = ReadWholeFile(BatchFile(out));
  if (!text.ok()) return Status::Error(BatchFile(out) + ": cannot read (no batch was started in " + out + ")");
  json batch = json::parse(text.value(), nullptr, false);
  if (!WellFormed(batch)) return Status::Error(BatchFile(out) + ": malformed (not as roamlab writes it)");
  return batch;
}

// The word quoted for sh: '...' with every ' written as '\''.
std::string ShellQuote(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string ExecutablePath() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("roamlab") : self.string();
}

// OUT/batch/task.sh and aggregate.sh: the roamlab commands the array tasks and the aggregation job run.
Status WriteScripts(const std::string& out, const std::string& roamlab) {
  const std::string dir = ShellQuote(fs::absolute(out).string());
  const std::string exe = ShellQuote(roamlab);
  const std::string header = "#!/bin/sh\n# Written by roamlab (batch/slurm.h).\n";
  Status s = WriteFileAtomic(BatchDir(out) + "/task.sh",
                                 header + "exec " + exe + " batch task " + dir + " --index \"$SLURM_ARRAY_TASK_ID\"\n");
  if (!s.ok()) return s;
  return WriteFileAtomic(BatchDir(out) + "/aggregate.sh",
                             header + "exec " + exe + " batch aggregate " + dir + "\n");
}

// "0-3,7,9-10": the sorted indices as Slurm's array ranges.
std::string ArraySpec(const std::vector<int>& indices) {
  std::string spec;
  for (std::size_t k = 0; k < indices.size();) {
    std::size_t end = k;
    while (end + 1 < indices.size() && indices[end + 1] == indices[end] + 1) ++end;
    spec += (spec.empty() ? "" : ",") + std::to_string(indices[k]);
    if (end > k) spec += "-" + std::to_string(indices[end]);
    k = end + 1;
  }
  return spec;
}

// sbatch with the options every job of the batch gets, then `extra` and the script; the job id.
Result<std::string> Sbatch(const json& batch, const std::string& out, std::vector<std::string> extra,
                           const std::string& script) {
  const json& slurm = batch["slurm"];
  std::vector<std::string> argv = {"sbatch", "--parsable", "--chdir=" + batch["cwd"].get<std::string>()};
  if (!slurm["partition"].get<std::string>().empty())
    argv.push_back("--partition=" + slurm["partition"].get<std::string>());
  if (!slurm["time"].get<std::string>().empty()) argv.push_back("--time=" + slurm["time"].get<std::string>());
  for (const json& a : slurm["sbatch_args"]) argv.push_back(a.get<std::string>());
  argv.insert(argv.end(), extra.begin(), extra.end());
  argv.push_back(fs::absolute(BatchDir(out) + "/" + script).string());
  auto ran = internal::RunProcess(argv);
  if (!ran.ok()) return ran.status();
  const std::string id = ran.value().out.substr(0, ran.value().out.find_first_of(";\n"));
  if (ran.value().exit_code != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    std::string why = ran.value().err.empty() ? ran.value().out : ran.value().err;
    while (!why.empty() && why.back() == '\n') why.pop_back();
    return Status::Error("sbatch " + script + " failed: " + why);
  }
  return id;
}

// One submission: the array over the blocks holding `missing` runs and the aggregation job after it. `ready` is the
// work's Ready() the missing runs were chosen under (the retries are counted per value).
Status SubmitAttempt(json* batch, const std::string& out, const std::string& kind, const std::vector<int>& missing,
                     int ready) {
  const int per_task = (*batch)["slurm"]["runs_per_task"].get<int>();
  std::set<int> block_set;
  for (const int run : missing) block_set.insert(run / per_task);
  const std::vector<int> blocks(block_set.begin(), block_set.end());
  std::string array = "--array=" + ArraySpec(blocks);
  if (const int p = (*batch)["slurm"]["array_parallelism"].get<int>(); p > 0) array += "%" + std::to_string(p);
  const std::string logs = fs::absolute(BatchDir(out) + "/logs").string();
  auto array_job =
      Sbatch(*batch, out, {array, "--job-name=roamlab-" + kind, "--output=" + logs + "/task-%A-%a.log"}, "task.sh");
  if (!array_job.ok()) return array_job.status();
  auto aggregate_job = Sbatch(*batch, out,
                              {"--dependency=afterany:" + array_job.value(),
                               "--job-name=roamlab-" + kind + "-aggregate", "--output=" + logs + "/aggregate-%j.log"},
                              "aggregate.sh");
  if (!aggregate_job.ok()) return aggregate_job.status();
  (*batch)["submissions"].push_back({{"array_job", array_job.value()},
                                     {"aggregate_job", aggregate_job.value()},
                                     {"blocks", blocks},
                                     {"ready", ready}});
  (*batch)["state"] = "submitted";
  return WriteBatch(out, *batch);
}

// The runs that can run now and have no result file.
std::vector<int> MissingRuns(const Work& work) {
  std::vector<int> missing;
  for (int i = 0, ready = work.Ready(); i < ready; ++i)
    if (!work.Done(i)) missing.push_back(i);
  return missing;
}

// The tasks Slurm still lists of the batch's submissions (pending or running): their array job and task index.
std::set<std::pair<std::string, int>> QueuedTasks(const json& batch) {
  std::set<std::pair<std::string, int>> queued;
  for (const json& submission : batch["submissions"]) {
    const std::string job = submission["array_job"].get<std::string>();
    auto ran = internal::RunProcess({"squeue", "-h", "-r", "-j", job, "-o", "%F %K"});
    if (!ran.ok() || ran.value().exit_code != 0) continue;  // no longer known: ended
    std::istringstream lines(ran.value().out);
    std::string array_job;
    int index = 0;
    while (lines >> array_job >> index) queued.insert({array_job, index});
  }
  return queued;
}

// Whether Slurm still lists the job as pending or running (a cancelled or completing job does not count).
bool Queued(const std::string& job) {
  auto ran =
      internal::RunProcess({"squeue", "-h", "-j", job, "-t", "PENDING,CONFIGURING,RUNNING,SUSPENDED", "-o", "%i"});
  return ran.ok() && ran.value().exit_code == 0 && !ran.value().out.empty();
}

// The log of the last task that ran run `run`.
std::string TaskLog(const json& batch, const std::string& out, int run) {
  const int block = run / batch["slurm"]["runs_per_task"].get<int>();
  const json& submissions = batch["submissions"];
  for (auto s = submissions.rbegin(); s != submissions.rend(); ++s) {
    const json blocks = s->value("blocks", json::array());
    if (std::find(blocks.begin(), blocks.end(), block) == blocks.end()) continue;
    const std::string job = (*s)["array_job"].get<std::string>();
    return fs::absolute(BatchDir(out) + "/logs/task-" + job + "-" + std::to_string(block) + ".log").string();
  }
  return "(never submitted)";
}

// Polls OUT/batch/batch.json until its state is no longer "submitted"; a failure when the last aggregation job left
// the queue without changing it.
Outcome WaitForBatch(const std::string& out, std::string* headline) {
  int idle_checks = 0;
  while (true) {
    auto batch = ReadBatch(out);
    if (!batch.ok()) return Outcome::Failed(batch.status());
    const std::string state = batch.value().value("state", "");
    if (state == "done") {
      *headline = batch.value().value("message", "");
      return Outcome::Ok();
    }
    if (state == "failed") return Outcome::Failed(Status::Error(batch.value().value("message", "")));
    if (batch.value()["submissions"].empty()) return Outcome::Failed(Status::Error(BatchFile(out) + ": no submission"));
    const std::string aggregate = batch.value()["submissions"].back()["aggregate_job"].get<std::string>();
    if (Queued(aggregate)) {
      idle_checks = 0;
    } else if (++idle_checks > 10) {  // batch.json is written before the job leaves the queue: a few polls apart
      return Outcome::Failed(Status::Error("aggregation job " + aggregate + " ended without a result; see " +
                                           BatchDir(out) + "/logs/aggregate-" + aggregate + ".log"));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
}

json SlurmJson(const SlurmOptions& options) {
  return {{"partition", options.partition},
          {"time", options.time},
          {"array_parallelism", options.array_parallelism},
          {"runs_per_task", options.runs_per_task},
          {"retries", options.retries},
          {"sbatch_args", options.sbatch_args}};
}

// Reads OUT/batch/batch.json of a Slurm batch and rebuilds its work.
Result<std::pair<json, std::unique_ptr<Work>>> LoadSlurmBatch(const std::string& out) {
  auto batch = ReadBatch(out);
  if (!batch.ok()) return batch.status();
  if (batch.value()["backend"] != "slurm" || !batch.value().contains("slurm"))
    return Status::Error(BatchFile(out) + ": not a Slurm batch");
  auto work = WorkFromJson(batch.value()["work"]);
  if (!work.ok()) return Status::Error(BatchFile(out) + ": " + work.status().message());
  return std::make_pair(std::move(batch).value(), std::move(work).value());
}

// failed.json and the batch's state once runs are still missing after the retries.
int ReportFailed(json* batch, const std::string& out, const Work& work, const std::vector<int>& missing,
                 std::ostream& err) {
  json failed = json::array();
  for (const int run : missing)
    failed.push_back({{"run", run}, {"name", work.RunName(run)}, {"log", TaskLog(*batch, out, run)}});
  const std::string message = std::to_string(missing.size()) + " of " + std::to_string(work.runs()) +
                              " runs have no result after " + std::to_string((*batch)["submissions"].size()) +
                              " submissions; first: " + work.RunName(missing.front()) + ", log " +
                              TaskLog(*batch, out, missing.front()) + " (" + BatchDir(out) + "/failed.json)";
  (void)WriteFileAtomic(BatchDir(out) + "/failed.json", json{{"failed", failed}}.dump(2) + "\n");
  (*batch)["state"] = "failed";
  (*batch)["message"] = message;
  (void)WriteBatch(out, *batch);
  err << "roamlab batch aggregate: " << message << "\n";
  return 1;
}

// An error when OUT holds a Slurm batch whose last aggregation job Slurm still lists: a second batch would write the
// same result files.
Status StillRunning(const std::string& out) {
  if (!fs::exists(BatchFile(out))) return Status::Ok();
  auto batch = ReadBatch(out);
  if (!batch.ok() || batch.value()["backend"] != "slurm" || batch.value()["state"] != "submitted" ||
      batch.value()["submissions"].empty())
    return Status::Ok();
  const json& last = batch.value()["submissions"].back();
  const std::string aggregate = last["aggregate_job"].get<std::string>();
  if (!Queued(aggregate)) return Status::Ok();
  return Status::Error(out + ": its batch is still running (array job " + last["array_job"].get<std::string>() +
                       ", aggregation job " + aggregate + "); wait for it or scancel both");
}

}  // namespace

std::string SlurmOptions::Validate() const {
  if (runs_per_task < 1) return "--runs-per-task must be at least 1";
  if (retries < 0) return "--retries must be >= 0";
  if (array_parallelism < 0) return "--array-parallelism must be >= 0";
  for (const std::string& a : sbatch_args)
    if (a.empty() || a[0] != '-') return "--sbatch-arg '" + a + "' is not an sbatch option (it starts with -)";
  return "";
}

Outcome SubmitToSlurm(Work& work, const SlurmOptions& options, bool resume, std::ostream& log, std::string* headline) {
  if (const std::string problem = options.Validate(); !problem.empty())
    return Outcome::BadInput(Status::Error(problem));
  if (Status busy = StillRunning(work.out()); !busy.ok()) return Outcome::BadInput(busy);
  if (Status made = experiment::MakeOutputDirectory(BatchDir(work.out()) + "/logs"); !made.ok())
    return Outcome::BadInput(made);
  if (!resume)
    if (Status cleared = work.Clear(); !cleared.ok()) return Outcome::Failed(cleared);
  if (Outcome prepared = work.Prepare(resume); !prepared.ok()) return prepared;
  const std::string roamlab = ExecutablePath();
  json batch = {{"work", work.ToJson()},
                {"backend", "slurm"},
                {"cwd", fs::current_path().string()},
                {"roamlab", roamlab},
                {"slurm", SlurmJson(options)},
                {"submissions", json::array()},
                {"state", "submitted"},
                {"message", ""}};
  if (Status s = WriteScripts(work.out(), roamlab); !s.ok()) return Outcome::Failed(s);
  const std::vector<int> missing = MissingRuns(work);
  if (missing.empty()) {
    Outcome aggregated = work.Aggregate(headline);
    batch["state"] = aggregated.ok() ? "done" : "failed";
    batch["message"] = aggregated.ok() ? *headline : aggregated.status.message();
    (void)WriteBatch(work.out(), batch);
    return aggregated;
  }
  if (Status s = SubmitAttempt(&batch, work.out(), work.kind(), missing, work.Ready()); !s.ok())
    return Outcome::Failed(s);
  const json& submission = batch["submissions"].back();
  log << "submitted " << missing.size() << " runs as array job " << submission["array_job"].get<std::string>() << " ("
      << submission["blocks"].size() << " tasks), aggregation job " << submission["aggregate_job"].get<std::string>()
      << "; roamlab batch status " << work.out() << "\n";
  if (!options.wait) return Outcome::Ok();
  return WaitForBatch(work.out(), headline);
}

int RunSlurmTask(const std::string& out, int index, std::ostream& err) {
  auto loaded = LoadSlurmBatch(out);
  if (!loaded.ok()) {
    err << "roamlab batch task: " << loaded.status().message() << "\n";
    return 2;
  }
  auto& [batch, work] = loaded.value();
  const int per_task = batch["slurm"]["runs_per_task"].get<int>();
  const int first = index * per_task, last = std::min(work->Ready(), first + per_task);
  if (index < 0 || first >= work->runs()) {
    err << "roamlab batch task: --index " << index << " is outside the batch's " << work->runs() << " runs\n";
    return 2;
  }
  if (first >= last) {
    err << "roamlab batch task: runs " << first << " to " << first + per_task - 1
        << " wait for the earlier runs' results\n";
    return 1;
  }
  if (Outcome prepared = work->PrepareRuns(first, last); !prepared.ok()) {
    err << "roamlab batch task: " << prepared.status.message() << "\n";
    return prepared.bad_input ? 2 : 1;
  }
  int failed = 0;
  for (int i = first; i < last; ++i) {
    if (work->Done(i)) continue;
    const auto start = std::chrono::steady_clock::now();
    const Outcome ran = work->Run(i);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (ran.ok()) {
      err << work->RunName(i) << ": done in " << seconds << " s\n";
    } else {
      ++failed;
      err << work->RunName(i) << ": failed: " << ran.status.message() << "\n";
    }
  }
  return failed ? 1 : 0;
}

int AggregateSlurm(const std::string& out, std::ostream& out_stream, std::ostream& err) {
  auto loaded = LoadSlurmBatch(out);
  if (!loaded.ok()) {
    err << "roamlab batch aggregate: " << loaded.status().message() << "\n";
    return 2;
  }
  auto& [batch, work] = loaded.value();
  const std::vector<int> missing = MissingRuns(*work);
  if (!missing.empty()) {
    // The submissions of the runs ready now: none when earlier runs' results have just made them ready.
    const int ready = work->Ready();
    const int runs = work->runs();  // a structured binding cannot be captured in C++17 (clang refuses it)
    const auto submissions = std::count_if(batch["submissions"].begin(), batch["submissions"].end(),
                                           [&](const json& s) { return s.value("ready", runs) == ready; });
    if (submissions <= batch["slurm"]["retries"].get<int>()) {
      const Status s = SubmitAttempt(&batch, out, work->kind(), missing, ready);
      if (s.ok()) {
        out_stream << missing.size() << " runs without a result: submitted" << (submissions ? " again" : "")
                   << " as array job " << batch["submissions"].back()["array_job"].get<std::string>() << "\n";
        return 0;
      }
      err << "roamlab batch aggregate: " << s.message() << "\n";
    }
    return ReportFailed(&batch, out, *work, missing, err);
  }
  std::string headline;
  const Outcome aggregated = work->Aggregate(&headline);
  batch["state"] = aggregated.ok() ? "done" : "failed";
  batch["message"] = aggregated.ok() ? headline : aggregated.status.message();
  if (Status s = WriteBatch(out, batch); !s.ok()) err << "roamlab batch aggregate: " << s.message() << "\n";
  if (!aggregated.ok()) {
    err << "roamlab batch aggregate: " << aggregated.status.message() << "\n";
    return 1;
  }
  out_stream << headline << "\n";
  return 0;
}

Result<BatchStatus> ReadBatchStatus(const std::string& out) {
  auto batch = ReadBatch(out);
  if (!batch.ok()) return batch.status();
  nlohmann::json described = batch.value()["work"];
  described["out"] = out;  // the directory as named here (it may have been moved or copied)
  auto work = WorkFromJson(described);
  if (!work.ok()) return Status::Error(BatchFile(out) + ": " + work.status().message());
  BatchStatus status;
  status.kind = work.value()->kind();
  status.backend = batch.value()["backend"].get<std::string>();
  status.state = batch.value().value("state", "");
  status.message = batch.value().value("message", "");
  status.runs = work.value()->runs();
  const bool slurm = status.backend == "slurm" && batch.value().contains("slurm");
  const auto queued = slurm ? QueuedTasks(batch.value()) : std::set<std::pair<std::string, int>>();
  const int per_task = slurm ? batch.value()["slurm"].value("runs_per_task", 1) : 1;
  // Runs that wait for earlier runs' results are submitted by the aggregation job once those are done.
  const int ready = work.value()->Ready();
  for (int i = 0; i < status.runs; ++i) {
    if (work.value()->Done(i)) {
      ++status.done;
      continue;
    }
    bool in_queue = slurm && i >= ready && status.state == "submitted";
    for (const auto& [job, index] : queued) in_queue = in_queue || index == i / per_task;
    if (in_queue || (!slurm && status.state == "running")) {
      ++status.queued;
    } else {
      status.failed.push_back(work.value()->RunName(i) +
                              (slurm ? ": log " + TaskLog(batch.value(), out, i) : std::string()));
    }
  }
  return status;
}

Status WriteLocalBatchFile(const Work& work, const std::string& state, const std::string& message) {
  if (Status made = experiment::MakeOutputDirectory(BatchDir(work.out())); !made.ok()) return made;
  return WriteBatch(work.out(), {{"work", work.ToJson()},
                                 {"backend", "local"},
                                 {"cwd", fs::current_path().string()},
                                 {"state", state},
                                 {"message", message}});
}

}  // namespace roamlab::batch
