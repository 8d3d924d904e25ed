// What made an output (provenance.hpp): argv as a line a shell takes back, the report's provenance
// section, and the journal's one line, quoted as a shell would need, never two lines, cut after a
// whole argument when too long. Plain functions against hand-written expectations.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/report/build_version.hpp"
#include "firmware/services/report/provenance.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

TEST_GROUP(Provenance){};

TEST(Provenance, AShellLineQuotesOnlyWhatNeedsItAndTakesAQuoteApartAsAShellWould) {
  STRCMP_EQUAL("", report::shell_line({}).c_str());
  STRCMP_EQUAL("stencil-sim --seed=12 --out-dir ./jobs/a_b,c+d@e%f:g",
               report::shell_line({"stencil-sim", "--seed=12", "--out-dir", "./jobs/a_b,c+d@e%f:g"}).c_str());
  STRCMP_EQUAL("a '' 'two words' 'it'\\''s' '$HOME' 'a;b' 'tab?here'",
               report::shell_line({"a", "", "two words", "it's", "$HOME", "a;b", "tab\there"}).c_str());
  STRCMP_EQUAL("'del?'", report::shell_line({std::string("del") + static_cast<char>(0x7f)}).c_str());
}

TEST(Provenance, TheReportsSectionNamesTheBuildTheCommandTheConfigurationAndTheTables) {
  report::Provenance p;
  p.program = "stencil-rig";
  p.command_line = {"stencil-rig", "--config", "/etc/stencil/rig.toml"};
  p.configuration = "/etc/stencil/rig.toml";
  p.configuration_crc32 = 0x0000abcdU;
  p.tables = "part.stbl";
  p.tables_crc32 = 0xdeadbeefU;
  p.triangle_count = 92;
  const nlohmann::json made = report::provenance_json(p);
  STRCMP_EQUAL("stencil-rig", made["program"].get<std::string>().c_str());
  STRCMP_EQUAL(report::source_version(), made["version"].get<std::string>().c_str());
  STRCMP_EQUAL(report::build_compiler(), made["compiler"].get<std::string>().c_str());
  STRCMP_EQUAL(report::build_flags(), made["flags"].get<std::string>().c_str());
  CHECK(made["command_line"] == nlohmann::json(p.command_line));
  STRCMP_EQUAL("/etc/stencil/rig.toml", made["configuration"]["path"].get<std::string>().c_str());
  STRCMP_EQUAL("0000abcd", made["configuration"]["crc32"].get<std::string>().c_str());  // eight digits always
  STRCMP_EQUAL("part.stbl", made["tables"]["path"].get<std::string>().c_str());
  STRCMP_EQUAL("deadbeef", made["tables"]["crc32"].get<std::string>().c_str());
  CHECK_EQUAL(92, made["tables"]["triangles"].get<int>());
  const std::string line = report::provenance_line(p);
  STRCMP_EQUAL((std::string("stencil-rig ") + report::source_version() + " (" + report::build_compiler() +
                "); configuration /etc/stencil/rig.toml crc32=0000abcd; tables part.stbl crc32=deadbeef triangles=92; "
                "command: stencil-rig --config /etc/stencil/rig.toml")
                   .c_str(),
               line.c_str());
}

// Whatever it is given, the line fits a Provenance record.
TEST(Provenance, TheLineNeverOutgrowsItsJournalRecord) {
  report::Provenance p;
  p.program = "stencil-sim";
  p.tables = std::string(5000, 't');  // paths beyond any reason
  p.command_line = {"stencil-sim"};
  const std::string line = report::provenance_line(p);
  LONGS_EQUAL(journal::kMaxProvenanceBytes, line.size());
  // An argument that fits only without the " ..." is not taken: the line says more was.
  p.tables = "part.stbl";
  p.command_line = {"stencil-sim"};
  const std::size_t room = journal::kMaxProvenanceBytes - report::provenance_line(p).size();
  p.command_line.push_back(std::string(room - 1 - 3, 'a'));  // " " + word + " ..." is one too many
  std::string cut = report::provenance_line(p);
  STRCMP_EQUAL(" stencil-sim ...", cut.substr(cut.size() - 16).c_str());
  p.command_line.back() = std::string(room - 1 - 4, 'a');  // exactly fits with room for " ..."
  cut = report::provenance_line(p);
  LONGS_EQUAL(journal::kMaxProvenanceBytes - 4, cut.size());
  CHECK(cut.substr(cut.size() - 4) == "aaaa");
}

TEST(Provenance, AsOneLineForTheJournalItQuotesWhatAShellWouldSplit) {
  report::Provenance p;
  p.program = "stencil-sim";
  p.command_line = {"stencil-sim", "--fast", "--operator", "it's here.csv"};
  p.tables = "(baked-in hex prism)";
  p.tables_crc32 = 0x00c0ffeeU;
  p.triangle_count = 24;
  const std::string line = report::provenance_line(p);
  STRCMP_CONTAINS((std::string("stencil-sim ") + report::source_version() + " (").c_str(), line.c_str());
  STRCMP_CONTAINS("; configuration compiled-in;", line.c_str());
  STRCMP_CONTAINS("tables '(baked-in hex prism)' crc32=00c0ffee triangles=24;", line.c_str());
  STRCMP_CONTAINS("command: stencil-sim --fast --operator 'it'\\''s here.csv'", line.c_str());
  STRCMP_EQUAL("compiled-in", report::provenance_json(p)["configuration"].get<std::string>().c_str());
  // A newline cannot break the line; a command line too long for a record is cut after a whole
  // argument, and says so.
  p.command_line = {"stencil-sim", "--operator", "two\nlines.csv"};
  STRCMP_CONTAINS("command: stencil-sim --operator 'two?lines.csv'", report::provenance_line(p).c_str());
  CHECK(report::provenance_line(p).find('\n') == std::string::npos);
  p.command_line.assign(2000, "--seed=12345");
  const std::string cut = report::provenance_line(p);
  CHECK(cut.size() <= 4000U);
  CHECK(cut.size() > 3980U);
  STRCMP_CONTAINS("--seed=12345 ...", cut.substr(cut.size() - 20).c_str());
}
