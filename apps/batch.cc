#include "apps/batch.h"

#include <iostream>

#include "apps/cli.h"

namespace roamlab::apps {

int SubmitBatch(batch::Work& work, const BackendArgs& backend, bool resume, bool quiet, std::ostream* err,
                const std::string& command) {
  std::string headline;
  const experiment::Outcome outcome = batch::SubmitToSlurm(work, backend.slurm, resume, std::cerr, &headline);
  if (!outcome.ok()) return Exit(err, command, outcome);
  if (!quiet && !headline.empty()) std::cout << headline << "\n";
  return 0;
}

int RunBatchStatus(const BatchArgs& args) {
  auto status = batch::ReadBatchStatus(args.out);
  if (!status.ok()) return BadInput(args.err, "batch status", status.status().message());
  const batch::BatchStatus& s = status.value();
  std::cout << s.kind << " (" << s.backend << " backend), " << s.runs << " runs: " << s.done << " done, " << s.queued
            << " pending or running, " << s.failed.size() << " failed; state " << s.state << "\n";
  // While the batch is submitted, the aggregation job submits such runs again as long as retries remain.
  const std::string label =
      s.backend == "slurm" && s.state == "submitted" ? "failed (retried while retries remain): " : "failed: ";
  for (const std::string& line : s.failed) std::cout << label << line << "\n";
  if (!s.message.empty()) std::cout << s.message << "\n";
  return s.failed.empty() && s.state != "failed" ? 0 : 1;
}

int RunBatchTask(const BatchArgs& args) {
  return batch::RunSlurmTask(args.out, args.index, args.err ? *args.err : std::cerr);
}

int RunBatchAggregate(const BatchArgs& args) {
  return batch::AggregateSlurm(args.out, std::cout, args.err ? *args.err : std::cerr);
}

}  // namespace roamlab::apps
