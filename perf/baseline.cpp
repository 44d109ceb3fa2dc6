#include "perf/baseline.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "platform/files.hpp"

namespace fire::perf {
namespace {

std::string cpu_model() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown CPU";
}

std::string today_utc() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[16];
  std::strftime(text, sizeof text, "%Y-%m-%d", &utc);
  return text;
}

}  // namespace

Result<Baseline> read_baseline(const std::string& path) {
  if (!std::filesystem::exists(path)) return Baseline{};
  const Result<std::string> text = read_text_file(path);
  if (!text) return Result<Baseline>::failure(text.error());
  try {
    const nlohmann::json j = nlohmann::json::parse(*text);
    Baseline b{j.at("written").get<std::string>(), j.at("machine").get<std::string>(),
               j.at("command").get<std::string>(), {}};
    for (const nlohmann::json& f : j.at("figures")) {
      Figure figure{f.at("name").get<std::string>(), f.at("value").get<double>(), f.value("target", 0.0)};
      if (!std::isfinite(figure.value) || !std::isfinite(figure.target))
        return Result<Baseline>::failure(path + ": figure '" + figure.name + "' is not a finite number");
      b.figures.push_back(std::move(figure));
    }
    return b;
  } catch (const nlohmann::json::exception& e) {
    return Result<Baseline>::failure(path + ": not a baseline file: " + e.what());
  }
}

std::string compare_with_baseline(const Baseline& baseline, const std::vector<Figure>& now, const std::string& path) {
  std::ostringstream out;
  if (baseline.figures.empty()) {
    out << "No baseline at " << path << " yet: run with --write-baseline to keep these figures.\n";
    return out.str();
  }
  out << "Against the baseline " << path << " (" << baseline.written << ", " << baseline.machine << "):\n\n"
      << "| figure | now | baseline | change | target | met |\n|---|---|---|---|---|---|\n";
  char line[512];
  for (const Figure& f : now) {
    const Figure* then = nullptr;
    for (const Figure& b : baseline.figures)
      if (b.name == f.name) then = &b;
    const std::string target = f.target > 0 ? std::to_string(f.target).substr(0, 4) : "-";
    const char* met = f.target > 0 ? (f.value >= f.target ? "yes" : "no") : "-";
    if (then)
      std::snprintf(line, sizeof line, "| %s | %.2f | %.2f | %+.1f %% | %s | %s |\n", f.name.c_str(), f.value,
                    then->value, 100.0 * (f.value / then->value - 1.0), target.c_str(), met);
    else
      std::snprintf(line, sizeof line, "| %s | %.2f | (none) | - | %s | %s |\n", f.name.c_str(), f.value, target.c_str(), met);
    out << line;
  }
  return out.str();
}

Status write_baseline(const std::string& path, const std::string& benchmark, const std::string& command,
                      const std::vector<Figure>& now) {
  nlohmann::json figures = nlohmann::json::array();
  for (const Figure& f : now) figures.push_back({{"name", f.name}, {"value", f.value}, {"target", f.target}});
  const nlohmann::json j = {{"benchmark", benchmark},
                            {"written", today_utc()},
                            {"machine", cpu_model() + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores"},
                            {"command", command},
                            {"figures", figures}};
  return write_file_atomic(path, j.dump(2) + "\n");
}

Result<BaselineRun> start_baseline_run(const std::string& benchmark, const std::string& path, int argc, char** argv) {
  const bool write = argc == 2 && std::string(argv[1]) == "--write-baseline";
  if (argc > 2 || (argc == 2 && !write)) return Result<BaselineRun>::failure("usage: " + benchmark + " [--write-baseline]");
  Result<Baseline> baseline = read_baseline(path);
  if (!baseline) return Result<BaselineRun>::failure(baseline.error());
  return BaselineRun{benchmark, path, std::move(*baseline), write};
}

Status finish_baseline_run(const BaselineRun& run, const std::string& command, const std::vector<Figure>& now) {
  std::printf("\n%s", compare_with_baseline(run.baseline, now, run.path).c_str());
  if (!run.write) return Status::success();
  if (Status written = write_baseline(run.path, run.benchmark, command, now); !written) return written;
  std::printf("\nwrote %s\n", run.path.c_str());
  return Status::success();
}

}  // namespace fire::perf
