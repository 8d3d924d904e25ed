// stencil-same-behaviour: is what a newer stencil-sim wrote the same as what an older one wrote for
// the same job? `report OLD NEW` (JSON reports) or `journal OLD NEW`. Prints "same" or what
// differs, one line each. Exit 0 the same (a report may add fields), 1 different, 2 a file that
// cannot be read or parsed. toolchain/same-behaviour.sh runs both programs and calls this per file.
#include <cstdio>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "toolchain/same_behaviour/journal_comparison.hpp"
#include "toolchain/same_behaviour/report_comparison.hpp"

namespace {

using namespace stencil::same_behaviour;

constexpr int kSame = 0;
constexpr int kDifferent = 1;
constexpr int kUnreadable = 2;

bool parse(const std::string& path, nlohmann::json& out) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "%s: cannot be read\n", path.c_str());
    return false;
  }
  try {
    out = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    std::fprintf(stderr, "%s: not a JSON report: %s\n", path.c_str(), e.what());
    return false;
  }
  return true;
}

int reports(const std::string& older_path, const std::string& newer_path) {
  nlohmann::json older;
  nlohmann::json newer;
  if (!parse(older_path, older) || !parse(newer_path, newer)) {
    return kUnreadable;
  }
  const ReportComparison result = compare_reports(older, newer);
  for (const std::string& line : result.changed) {
    std::printf("changed: %s\n", line.c_str());
  }
  for (const std::string& line : result.added) {
    std::printf("added: %s\n", line.c_str());
  }
  if (result.changed.empty()) {
    std::printf("same\n");
  }
  return result.changed.empty() ? kSame : kDifferent;
}

int journals(const std::string& older_path, const std::string& newer_path) {
  const JournalComparison result = compare_journals(older_path, newer_path);
  if (!result.error.empty()) {
    std::fprintf(stderr, "%s\n", result.error.c_str());
    return kUnreadable;
  }
  for (const std::string& line : result.differences) {
    std::printf("differs: %s\n", line.c_str());
  }
  if (result.differences.empty()) {
    std::printf("same (%llu records; the start time of %llu start/resume record(s) and %llu provenance record(s) left out)\n",
                static_cast<unsigned long long>(result.records), static_cast<unsigned long long>(result.start_times),
                static_cast<unsigned long long>(result.provenance));
  }
  return result.differences.empty() ? kSame : kDifferent;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Compares what two builds of stencil-sim wrote for the same job, apart from the wall clock"};
  app.require_subcommand(1);
  std::string older_path;
  std::string newer_path;
  CLI::App* report = app.add_subcommand("report", "two JSON reports: equal apart from provenance, wall_s, compute_us, memory_kb and "
                                                  "latencies; fields only the newer has are listed as added");
  CLI::App* journal = app.add_subcommand("journal", "two journals: equal byte for byte apart from the start times in "
                                                    "the Start and Resume records and those records' CRC-32s, and the Provenance records");
  for (CLI::App* command : {report, journal}) {
    command->add_option("older", older_path, "what the older build wrote")->required();
    command->add_option("newer", newer_path, "what the newer build wrote")->required();
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : kUnreadable;
  }
  return report->parsed() ? reports(older_path, newer_path) : journals(older_path, newer_path);
}
