// --inspect (toolchain/tablegen/inspect): a valid table described for people and as JSON (exit 0),
// and a damaged or missing one refused on one error line naming the file, the field and the value
// (exit 2). The program's own exit codes: e2e inspect_refuses_corrupted_table and the rest.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "tests/support/sample_tables.hpp"
#include "toolchain/tablegen/inspect.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

struct TableFile {
  std::string path = "/tmp/inspect_tests_" + std::to_string(getpid()) + ".stbl";
  tablegen::TableBytes table = test::make_table(test::default_part(), test::default_job_options(1));
  TableFile() { write(); }
  ~TableFile() { std::remove(path.c_str()); }
  void write() const {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(table.data()), static_cast<std::streamsize>(table.size()));
  }
};

}  // namespace

TEST_GROUP(Inspect){};

TEST(Inspect, AValidTableIsDescribedForPeople) {
  const TableFile file;
  std::ostringstream out, err;
  CHECK_EQUAL(0, tablegen::inspect_table(file.path, false, out, err));
  STRCMP_EQUAL("", err.str().c_str());
  STRCMP_CONTAINS((file.path + ": valid stencil table, format ").c_str(), out.str().c_str());
  STRCMP_CONTAINS("  tool       ball d=3", out.str().c_str());
  STRCMP_CONTAINS("(3-axis, tool vertical)", out.str().c_str());
}

TEST(Inspect, AValidTableIsDescribedAsJsonWithItsCounts) {
  const TableFile file;
  std::ostringstream out, err;
  CHECK_EQUAL(0, tablegen::inspect_table(file.path, true, out, err));
  const nlohmann::json summary = nlohmann::json::parse(out.str());
  STRCMP_EQUAL(file.path.c_str(), summary["file"].get<std::string>().c_str());
  CHECK_EQUAL(file.table.size(), summary["bytes"].get<std::size_t>());
  STRCMP_EQUAL("ball", summary["tool"]["kind"].get<std::string>().c_str());
  CHECK(summary["reachable_triangles"].get<std::uint32_t>() > 0U);
  CHECK_EQUAL(64U, summary["source"]["sha256"].get<std::string>().size());
}

TEST(Inspect, ADamagedTableIsRefusedNamingTheField) {
  TableFile file;
  // One byte of the last section flipped: the CRC no longer matches.
  file.table.data()[file.table.size() - 1] ^= std::byte{0x5a};
  file.write();
  std::ostringstream out, err;
  CHECK_EQUAL(2, tablegen::inspect_table(file.path, false, out, err));
  STRCMP_EQUAL("", out.str().c_str());
  STRCMP_CONTAINS(("stencil-tablegen: " + file.path + ": ").c_str(), err.str().c_str());
  STRCMP_CONTAINS("expected", err.str().c_str());
  STRCMP_CONTAINS("; found ", err.str().c_str());
}

TEST(Inspect, AMissingTableIsRefused) {
  std::ostringstream out, err;
  CHECK_EQUAL(2, tablegen::inspect_table("/nonexistent/part.stbl", true, out, err));
  STRCMP_CONTAINS("stencil-tablegen: /nonexistent/part.stbl: cannot open", err.str().c_str());
}
