#pragma once
// A benchmark's last accepted figures, kept as JSON beside it (perf/NAME/baseline.json), so that a run says how
// today's figures compare without anyone reading RESULTS.md. The figures kept are ratios against a peer measured
// in the same run: the machine is shared and noisy, so absolute times from another day compare nothing.
//   {"benchmark": ..., "written": "YYYY-MM-DD", "machine": ..., "command": ...,
//    "figures": [{"name": ..., "value": ..., "target": ...}, ...]}
// A run prints each figure against the file's (and against its target), and `--write-baseline` replaces the file
// with the run's figures. A missing file is said and is not an error; a malformed one names the file and the problem.
#include <string>
#include <vector>

#include "engine/common.hpp"

namespace fire::perf {

struct Figure {
  std::string name;   // unique within the benchmark: the row and the column it comes from
  double value = 0;   // higher is better (a ratio peer / ours)
  double target = 0;  // the value the figure must reach; 0 when it has none
};

struct Baseline {
  std::string written, machine, command;
  std::vector<Figure> figures;
};

// The baseline at `path`; an empty Baseline when there is no file.
Result<Baseline> read_baseline(const std::string& path);

// A Markdown table: each of `now` beside the baseline's figure of the same name, the change in percent and
// whether its target is met; the baseline's date and machine above it.
std::string compare_with_baseline(const Baseline& baseline, const std::vector<Figure>& now, const std::string& path);

// Writes `now` as the new baseline at `path` (atomically), with today's date (UTC) and this machine's CPU model.
Status write_baseline(const std::string& path, const std::string& benchmark, const std::string& command,
                      const std::vector<Figure>& now);

// A benchmark's run against its baseline: the file read at the start (a malformed one stops the run before any
// timing), then at the end the comparison printed and, with --write-baseline, the file replaced.
struct BaselineRun {
  std::string benchmark, path;
  Baseline baseline;
  bool write = false;
};
// For a benchmark whose only argument is an optional --write-baseline.
Result<BaselineRun> start_baseline_run(const std::string& benchmark, const std::string& path, int argc, char** argv);
Status finish_baseline_run(const BaselineRun& run, const std::string& command, const std::vector<Figure>& now);

}  // namespace fire::perf
