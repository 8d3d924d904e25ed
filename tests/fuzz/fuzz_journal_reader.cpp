// libFuzzer target: the journal reader takes any bytes. It either refuses them with an error naming
// an offset, or reads whole records and accounts for every byte (read, or the torn tail it ignored);
// every record it hands over keeps the format's promises.
#include <cstddef>
#include <cstdint>
#include <string>

#include "firmware/journal/journal_reader.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint64_t visits = 0;
  const stencil::journal::JournalVisitor visitor{
      [&](const stencil::journal::JournalStart& start) {
        require(start.program.size() <= 256);
        ++visits;
      },
      [&](const stencil::control::JournalRecord& r) {
        require(static_cast<int>(r.safe_reason) <= static_cast<int>(stencil::control::SafeReason::Stopped));
        ++visits;
      },
      [&](std::uint64_t, stencil::control::SafeReason reason) {
        require(reason != stencil::control::SafeReason::None);
        ++visits;
      }};
  const stencil::journal::JournalReadResult read = stencil::journal::read_journal(data, size, visitor);
  require(read.ok == read.error.empty());
  require(visits == read.records);
  if (!read.ok) {
    require(read.error.rfind("journal offset ", 0) == 0);
    return 0;
  }
  require(read.good_bytes + read.tail_bytes == size);
  require((read.tail_bytes == 0) == read.tail.empty());
  return 0;
}
