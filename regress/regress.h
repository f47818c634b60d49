// Runs a regression suite (regress/suite.h): each selected case in OUT/cases/NAME, the cases in parallel, then every
// check against its bound; writes OUT/results.json, OUT/junit.xml, OUT/timings.json and OUT/report.html
// (regress/report.h), each atomically. A finished case leaves its record, OUT/cases/NAME/case_result.json. The reports
// of an earlier run and the directories of cases not selected are removed first. OUT/INCOMPLETE (common/interrupt.h)
// lists the finished cases while the run goes on; after SIGINT or SIGTERM no further case starts, a case the signal
// stopped is removed, the marker stays and the outcome is a failure naming the interruption; `resume` continues.
#pragma once

#include <functional>
#include <string>

#include "experiment/steps.h"
#include "regress/report.h"

namespace roamlab::regress {

struct RunOptions {
  std::string suite;
  std::string out;
  std::string baseline;          // baseline directory; "" = the suite's `baseline`
  bool update_baseline = false;  // write the values as the new baseline (one CASE.json per case that ran)
  int jobs = 0;                  // cases (and montecarlo runs) in parallel; 0 = one per core
  std::string filter;            // glob on case names (fnmatch); "" = all
  bool quick = false;            // only the cases marked `quick: true`
  // Continue an interrupted run in `out`: a case whose record (cases/NAME/case_result.json) matches its definition is
  // taken from it, the others run. The reports are the same bytes as an uninterrupted run's.
  bool resume = false;
  // Optional: one line per finished case ("regress [3/9] NAME (MODE): ran in 12.5 s").
  std::function<void(const std::string& line)> progress;
};

// Paths of the reports a run wrote.
struct RunReports {
  std::string baseline_dir;  // where the baseline was read (and, with update_baseline, written)
  std::string results_json;
  std::string junit_xml;
  std::string report_html;
};

// Runs the suite; `result` receives the results (also when the reports cannot be written). Bad input (a suite or
// baseline file, with one line naming the file, the case and the problem; no case selected) is reported before any
// case runs; a report that cannot be written is a failure. A run whose checks fail is ok here: result->Passed().
experiment::Outcome RunSuite(const RunOptions& options, SuiteResult* result, RunReports* reports);

}  // namespace roamlab::regress
