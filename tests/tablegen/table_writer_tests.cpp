// The table's bytes (toolchain/tablegen/table_writer): laid out with the header first and every
// section 64-byte aligned in the loader's order, sealed with the CRC the loader checks; the same
// bytes emitted as a C++ array in its own section; a table file read back whole and aligned.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include <unistd.h>

#include "firmware/core/tables/table_format.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/sample_tables.hpp"
#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/table_writer.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::tablegen;

namespace {

tables::TableHeader header_of(const TableBytes& bytes) {
  tables::TableHeader header{};
  std::memcpy(&header, bytes.data(), sizeof header);
  return header;
}

}  // namespace

TEST_GROUP(TableWriter){};

TEST(TableWriter, TableBytesAreAlignedForTheLoader) {
  for (std::size_t size : {0U, 1U, 100U, 4097U}) {
    const TableBytes bytes(size);
    CHECK_EQUAL(size, bytes.size());
    CHECK_EQUAL(0U, reinterpret_cast<std::uintptr_t>(bytes.data()) % tables::kSectionAlignment);
  }
}

TEST(TableWriter, SectionsFollowTheHeaderAlignedAndInOrderAndTheCrcSealsThem) {
  const TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(1));
  const tables::TableHeader header = header_of(bytes);
  CHECK_EQUAL(0, std::memcmp(header.magic, tables::kTableMagic, sizeof header.magic));
  CHECK_EQUAL(tables::kTableFormatVersion, header.format_version);
  CHECK_EQUAL(bytes.size(), header.file_bytes);
  std::uint64_t end = sizeof(tables::TableHeader);
  for (std::size_t s = 0; s < tables::kSectionCount; ++s) {
    CHECK_EQUAL(0U, header.sections[s].offset % tables::kSectionAlignment);
    CHECK(header.sections[s].offset >= end);
    end = header.sections[s].offset + header.sections[s].bytes;
  }
  CHECK(end <= header.file_bytes);
  CHECK_EQUAL(header.point_count * sizeof(tables::PackedPoint),
              header.sections[static_cast<std::size_t>(tables::TableSection::Points)].bytes);
  CHECK_EQUAL(header.crc32, tables::table_crc32({bytes.data(), bytes.size()}));
  tables::PartTables part{};
  CHECK_TRUE(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
}

TEST(TableWriter, TheCppSourceHoldsTheSameBytesInItsOwnSection) {
  TableBytes bytes(18);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    bytes.data()[i] = static_cast<std::byte>(i * 15);
  }
  const std::string source = table_as_cpp("baked_part", bytes);
  STRCMP_CONTAINS("extern const unsigned char baked_part[];", source.c_str());
  STRCMP_CONTAINS("alignas(64) const unsigned char baked_part[] __attribute__((section(\".stencil_tables\"), used)) = {",
                  source.c_str());
  // Sixteen bytes a line, lower-case hex: bytes 7 and 8 share one.
  STRCMP_CONTAINS("\n    0x00, 0x0f, 0x1e, 0x2d,", source.c_str());
  STRCMP_CONTAINS(" 0x69, 0x78,", source.c_str());
  STRCMP_CONTAINS("0xe1,\n    0xf0, 0xff,\n};", source.c_str());
  STRCMP_CONTAINS("const std::size_t baked_part_size = 18;\n", source.c_str());
}

TEST(TableWriter, ATableFileIsReadBackWholeAndAligned) {
  const TableBytes table = test::make_table(test::default_part(), test::default_job_options(1));
  const std::string path = "/tmp/table_writer_tests_" + std::to_string(getpid()) + ".stbl";
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(table.data()), static_cast<std::streamsize>(table.size()));
  }
  const TableBytes read = read_table_file(path);
  std::remove(path.c_str());
  CHECK_EQUAL(table.size(), read.size());
  CHECK_EQUAL(0, std::memcmp(table.data(), read.data(), table.size()));
  CHECK_EQUAL(0U, reinterpret_cast<std::uintptr_t>(read.data()) % tables::kSectionAlignment);
}

TEST(TableWriter, AMissingTableFileIsRefusedByName) {
  try {
    static_cast<void>(read_table_file("/nonexistent/part.stbl"));
    FAIL("no InputError");
  } catch (const InputError& error) {
    STRCMP_CONTAINS("/nonexistent/part.stbl: cannot open", error.what());
  }
}
