// A part's table file read whole and checked by the firmware's loader (firmware/programs/table_file):
// a good table loads with the part pointing into the bytes read; a missing file, a directory and a
// file that is not a table are refused naming the file (and, for a bad table, the field, what was
// expected and what was found); a table of the older format is to be regenerated, in those words.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "firmware/programs/table_file.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

struct TempFile {
  std::string path = "/tmp/table_file_tests_" + std::to_string(getpid()) + ".stbl";
  ~TempFile() { std::remove(path.c_str()); }
  void write(const void* data, std::size_t size) const {
    std::ofstream out(path, std::ios::binary);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
};

}  // namespace

TEST_GROUP(TableFile){};

TEST(TableFile, AGoodTableLoadsFromTheBytesRead) {
  const tablegen::TableBytes table = test::make_table(test::default_part(), test::default_job_options(1));
  const TempFile file;
  file.write(table.data(), table.size());
  std::vector<unsigned char> bytes;
  tables::PartTables part{};
  std::string error;
  CHECK_TEXT(app::load_table_file(file.path, bytes, part, error), error.c_str());
  CHECK_EQUAL(table.size(), bytes.size());
  CHECK(part.triangle_count() > 0U);
  // The part's views point into the bytes read, which the caller keeps.
  const auto* first = reinterpret_cast<const unsigned char*>(part.points);
  CHECK(first >= bytes.data() && first < bytes.data() + bytes.size());
}

TEST(TableFile, AMissingFileOrADirectoryCannotBeRead) {
  std::vector<unsigned char> bytes;
  tables::PartTables part{};
  std::string error;
  CHECK_FALSE(app::load_table_file("/nonexistent/part.stbl", bytes, part, error));
  STRCMP_EQUAL("/nonexistent/part.stbl: cannot be read", error.c_str());
  CHECK_FALSE(app::load_table_file("/tmp", bytes, part, error));
  STRCMP_EQUAL("/tmp: cannot be read", error.c_str());
}

TEST(TableFile, AFileThatIsNotATableNamesTheField) {
  const TempFile file;
  const std::string text = "solid not a table\n";
  file.write(text.data(), text.size());
  std::vector<unsigned char> bytes;
  tables::PartTables part{};
  std::string error;
  CHECK_FALSE(app::load_table_file(file.path, bytes, part, error));
  STRCMP_CONTAINS((file.path + ": not a valid table: ").c_str(), error.c_str());
  CHECK(error.size() > file.path.size() + std::string(": not a valid table: ").size());
}

TEST(TableFile, ATableOfTheOlderFormatIsToBeRegenerated) {
  tablegen::TableBytes table = test::make_table(test::default_part(), test::default_job_options(1));
  tables::TableHeader header;
  std::memcpy(&header, table.data(), sizeof header);
  header.format_version = 1;  // before the packed leaves
  std::memcpy(table.data(), &header, sizeof header);
  header.crc32 = tables::table_crc32({table.data(), table.size()});
  std::memcpy(table.data(), &header, sizeof header);
  const TempFile file;
  file.write(table.data(), table.size());
  std::vector<unsigned char> bytes;
  tables::PartTables part{};
  std::string error;
  CHECK_FALSE(app::load_table_file(file.path, bytes, part, error));
  STRCMP_EQUAL((file.path + ": format version 1: regenerate with stencil-tablegen (this build reads format version 5)").c_str(),
               error.c_str());
}

TEST(TableFile, ABadTableSaysWhatWasExpectedAndFound) {
  tablegen::TableBytes table = test::make_table(test::default_part(), test::default_job_options(1));
  tables::TableHeader header;
  std::memcpy(&header, table.data(), sizeof header);
  header.flags = 7;
  std::memcpy(table.data(), &header, sizeof header);
  header.crc32 = tables::table_crc32({table.data(), table.size()});
  std::memcpy(table.data(), &header, sizeof header);
  const TempFile file;
  file.write(table.data(), table.size());
  std::vector<unsigned char> bytes;
  tables::PartTables part{};
  std::string error;
  CHECK_FALSE(app::load_table_file(file.path, bytes, part, error));
  STRCMP_EQUAL((file.path + ": not a valid table: header.flags (at 20): expected 0, found 7").c_str(), error.c_str());
}
