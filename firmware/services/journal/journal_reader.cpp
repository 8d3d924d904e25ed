// The journal reader: the header, then record by record until the bytes or the whole records end.
#include "firmware/services/journal/journal_reader.hpp"

#include <cmath>
#include <cstring>
#include <algorithm>
#include <vector>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/journal/journal_bytes.hpp"

namespace stencil::journal {
namespace {

std::string at(std::size_t offset) { return "journal offset " + std::to_string(offset) + ": "; }

}  // namespace

JournalReadResult read_journal(const std::uint8_t* data, std::size_t size, const JournalVisitor& visit) {
  JournalReadResult result;
  ByteReader header(data, size);
  if (size < kFileHeaderBytes || std::memcmp(data, kMagic, sizeof kMagic) != 0) {
    result.error = at(0) + "not a journal (expected the magic STENCILJ and a version: " + std::to_string(kFileHeaderBytes) +
                   " bytes)";
    return result;
  }
  header.skip(sizeof kMagic);
  const std::uint32_t version = header.u32();
  if (version < kOldestVersion || version > kVersion) {
    result.error = at(8) + "version " + std::to_string(version) + "; this program reads versions " +
                   std::to_string(kOldestVersion) + " to " + std::to_string(kVersion);
    return result;
  }
  std::size_t offset = kFileHeaderBytes;
  RecordType previous = RecordType::End;  // none yet
  CycleDecoder decoder;
  // A run's cycles are all in one form: Cycle records (a version 2 to 4 writer's run) or Cycles.
  enum class RunForm { None, Whole, Compact } form = RunForm::None;
  while (offset < size) {
    const std::size_t left = size - offset;
    ByteReader head(data + offset, left);
    const std::uint32_t length = head.u32();
    const auto type = static_cast<RecordType>(head.u8());
    if (head.overrun() || length > kMaxPayloadBytes || left < kRecordOverheadBytes + length) {
      result.tail = at(offset) + (head.overrun() || length <= kMaxPayloadBytes
                                      ? "a record cut short"
                                      : "a record length of " + std::to_string(length) + " (at most " +
                                            std::to_string(kMaxPayloadBytes) + ")");
      break;
    }
    const std::uint8_t* payload = data + offset + 5;
    uLong crc = crc32(0L, Z_NULL, 0);
    crc = crc32(crc, data + offset, static_cast<uInt>(5 + length));
    ByteReader tail(payload + length, 4);
    if (tail.u32() != static_cast<std::uint32_t>(crc)) {
      const std::size_t after = left - (kRecordOverheadBytes + length);
      if (after > 0) {
        // A crash tears only the end: a bad record with more after it is damage, not a torn tail.
        result.error = at(offset) + "a record whose CRC-32 does not match, with " + std::to_string(after) +
                       " bytes after it (the journal is damaged, not cut short by a crash)";
        result.good_bytes = offset;
        return result;
      }
      result.tail = at(offset) + "a last record whose CRC-32 does not match";
      break;
    }
    ByteReader body(payload, length);
    if (visit.offset) {
      visit.offset(offset);
    }
    switch (type) {
      case RecordType::Start: {
        JournalStart start;
        start.tables_crc32 = body.u32();
        start.triangle_count = body.u32();
        start.unix_time_ns = body.i64();
        const std::uint16_t name = body.u16();
        if (body.overrun() || body.left() < name + 2U || name > 256) {
          result.error = at(offset) + "a start record of " + std::to_string(length) + " bytes that does not hold its program name";
          return result;
        }
        start.program.assign(reinterpret_cast<const char*>(body.here()), name);
        body.skip(name);
        const std::uint16_t job = body.u16();
        if (body.overrun() || body.left() != job || job > 1024) {
          result.error = at(offset) + "a start record of " + std::to_string(length) + " bytes that does not hold its job";
          return result;
        }
        start.job.assign(reinterpret_cast<const char*>(body.here()), job);
        decoder.restart();
        form = RunForm::None;
        if (visit.start) {
          visit.start(start);
        }
        break;
      }
      case RecordType::Cycle: {
        if (length != kCyclePayloadBytes || form == RunForm::Compact) {
          result.error = at(offset) + "a cycle record of " + std::to_string(length) + " bytes" +
                         (form == RunForm::Compact ? " in a run of compact cycles (expected a Cycles record: a run's cycles are "
                                                     "all in one form)"
                                                   : " (expected " + std::to_string(kCyclePayloadBytes) + ")");
          return result;
        }
        form = RunForm::Whole;
        control::JournalRecord r{};
        r.cycle = body.u64();
        r.time_ns = body.i64();
        for (double& v : r.device_mm) {
          v = body.f64();
        }
        for (double& v : r.angles_rad) {
          v = body.f64();
        }
        r.sample_counter = body.u32();
        const std::uint8_t fresh = body.u8();
        for (double& v : r.virtual_tip_mm) {
          v = body.f64();
        }
        const std::uint8_t reason = body.u8();
        if (fresh > 1 || !control::is_safe_reason_byte(reason)) {
          result.error = at(offset) + (fresh > 1 ? "a cycle record's fresh flag is " + std::to_string(fresh) + " (expected 0 or 1)"
                                                 : "a cycle record's safe reason is " + std::to_string(reason) + " (no such reason)");
          return result;
        }
        r.fresh = fresh == 1;
        r.safe_reason = static_cast<control::SafeReason>(reason);
        r.touched_triangles = body.u32();
        for (float& v : r.force_n) {
          v = body.f32();
        }
        r.status_bits = body.u16();
        const std::uint8_t read_status = body.u8();
        const std::uint8_t read_reason = body.u8();
        if (read_status > static_cast<std::uint8_t>(hal::ReadStatus::Fault) ||
            read_reason > static_cast<std::uint8_t>(hal::HapticFault::HostWatchdogTripped)) {
          result.error = at(offset) + "a cycle record's read status " + std::to_string(read_status) + " or reason " +
                         std::to_string(read_reason) + " is out of range";
          return result;
        }
        r.read_status = static_cast<hal::ReadStatus>(read_status);
        r.read_reason = static_cast<hal::HapticFault>(read_reason);
        decoder.whole_record_read();
        if (visit.cycle) {
          RecordedCycle recorded;
          recorded.record = r;
          recorded.tip_check = tip_check(r.virtual_tip_mm);
          visit.cycle(recorded);
        }
        break;
      }
      case RecordType::Cycles: {
        if (version < kCompactVersion || form == RunForm::Whole || length == 0) {
          result.error = at(offset) + (version < kCompactVersion
                                           ? "a cycles record in a version " + std::to_string(version) + " journal (version 5 has them)"
                                       : length == 0 ? std::string("an empty cycles record (expected at least one cycle)")
                                                     : std::string("a cycles record in a run of cycle records (expected a Cycle "
                                                                   "record: a run's cycles are all in one form)"));
          return result;
        }
        form = RunForm::Compact;
        RecordedCycle recorded;
        std::string why;
        while (body.left() > 0) {
          const std::size_t cycle_at = offset + 5 + body.at();
          if (!decoder.decode(body, recorded, why)) {
            result.error = at(cycle_at) + why;
            return result;
          }
          if (visit.cycle) {
            visit.cycle(recorded);
          }
        }
        break;
      }
      case RecordType::SafeState: {
        const std::uint32_t expected = version == kOldestVersion ? kSafeStateV2PayloadBytes : kSafeStatePayloadBytes;
        if (length != expected) {
          result.error = at(offset) + "a safe-state record of " + std::to_string(length) + " bytes (expected " +
                         std::to_string(expected) + ")";
          return result;
        }
        const std::uint64_t cycle = body.u64();
        const std::uint8_t reason = body.u8();
        if (!control::is_safe_reason_byte(reason) || reason == 0) {
          result.error = at(offset) + "a safe-state record's reason is " + std::to_string(reason) + " (no such reason)";
          return result;
        }
        const std::uint8_t source = version == kOldestVersion ? 0 : body.u8();
        if (source >= control::kCommandSourceCount) {
          result.error = at(offset) + "a safe-state record's source is " + std::to_string(source) + " (no such source)";
          return result;
        }
        if (visit.safe_state) {
          visit.safe_state(cycle, static_cast<control::SafeReason>(reason));
        }
        if (visit.safe_source) {
          visit.safe_source(cycle, static_cast<control::SafeReason>(reason), static_cast<control::CommandSource>(source));
        }
        break;
      }
      case RecordType::Command: {
        if (version == kOldestVersion || length != kCommandPayloadBytes) {
          result.error = at(offset) + "a command record of " + std::to_string(length) + " bytes in a version " +
                         std::to_string(version) + " journal (expected " + std::to_string(kCommandPayloadBytes) +
                         " bytes, version 3)";
          return result;
        }
        control::CommandEvent e{};
        e.cycle = body.u64();
        e.time_ns = body.i64();
        e.queued_after_cycle = body.u64();
        const std::uint8_t kind = body.u8();
        const std::uint8_t source = body.u8();
        const std::uint8_t outcome = body.u8();
        e.asked = body.f64();
        e.applied = body.f64();
        // Each field named, at its byte in the file (the payload starts after the 5-byte head).
        const std::size_t payload_at = offset + 5;
        const struct {
          std::uint8_t value, count;
          std::size_t at;
          const char* name;
        } fields[] = {{kind, control::kCommandKindCount, 24, "kind"},
                      {source, control::kCommandSourceCount, 25, "source"},
                      {outcome, control::kCommandOutcomeCount, 26, "outcome"}};
        bool bad = false;
        for (const auto& field : fields) {
          if (field.value >= field.count) {
            result.error = at(payload_at + field.at) + "a command record's " + field.name + " is " +
                           std::to_string(field.value) + " (expected below " + std::to_string(field.count) + ")";
            bad = true;
            break;
          }
        }
        if (!bad && (std::isnan(e.asked) || std::isnan(e.applied))) {
          result.error = at(payload_at + (std::isnan(e.asked) ? 27 : 35)) + "a command record's " +
                         (std::isnan(e.asked) ? "value asked" : "value applied") + " is not a number";
          bad = true;
        }
        if (bad) {
          return result;
        }
        e.kind = static_cast<control::CommandKind>(kind);
        e.source = static_cast<control::CommandSource>(source);
        e.outcome = static_cast<control::CommandOutcome>(outcome);
        if (visit.command) {
          visit.command(e);
        }
        break;
      }
      case RecordType::Homed: {
        if (length != kHomedPayloadBytes) {
          result.error = at(offset) + "a homed record of " + std::to_string(length) + " bytes (expected " +
                         std::to_string(kHomedPayloadBytes) + ")";
          return result;
        }
        const std::int64_t time_ns = body.i64();
        if (visit.homed) {
          visit.homed(time_ns);
        }
        break;
      }
      case RecordType::MachineCommand: {
        if (length != kMachineCommandPayloadBytes) {
          result.error = at(offset) + "a machine command record of " + std::to_string(length) + " bytes (expected " +
                         std::to_string(kMachineCommandPayloadBytes) + ")";
          return result;
        }
        control::MachineCommandRecord r{};
        r.update = body.u64();
        r.time_ns = body.i64();
        for (std::int32_t& v : r.motor_target) {
          v = body.i32();
        }
        for (std::uint8_t& v : r.order) {
          v = body.u8();
        }
        bool finite = true;
        for (double& v : r.target_tip_mm) {
          v = body.f64();
          finite = finite && std::isfinite(v);
        }
        if (r.order[0] > 3 || r.order[1] > 3 || r.order[2] > 3 || !finite) {
          result.error = at(offset) + (finite ? "a machine command's leg order names an axis over 3"
                                              : "a machine command's target is not a finite number");
          return result;
        }
        if (visit.machine_command) {
          visit.machine_command(r);
        }
        break;
      }
      case RecordType::Resume: {
        JournalResume resume;
        resume.segment = body.u32();
        resume.unix_time_ns = body.i64();
        resume.script_s = body.f64();
        resume.approach_s = body.f64();
        const std::uint16_t name = body.u16();
        if (body.overrun() || body.left() != name || name > 256 || !std::isfinite(resume.script_s) ||
            !std::isfinite(resume.approach_s) || resume.script_s < 0.0 || resume.approach_s < 0.0) {
          result.error = at(offset) + "a resume record of " + std::to_string(length) +
                         " bytes that does not hold its program name, or whose script times are not finite and >= 0";
          return result;
        }
        resume.program.assign(reinterpret_cast<const char*>(body.here()), name);
        decoder.restart();
        form = RunForm::None;
        if (visit.resume) {
          visit.resume(resume);
        }
        break;
      }
      case RecordType::End: {
        if (length != kEndPayloadBytes) {
          result.error = at(offset) + "an end record of " + std::to_string(length) + " bytes (expected " +
                         std::to_string(kEndPayloadBytes) + ")";
          return result;
        }
        const std::uint64_t cycles = body.u64();
        const std::uint8_t reason = body.u8();
        if (!control::is_safe_reason_byte(reason)) {
          result.error = at(offset) + "an end record's reason is " + std::to_string(reason) + " (no such reason)";
          return result;
        }
        if (visit.end) {
          visit.end(cycles, static_cast<control::SafeReason>(reason));
        }
        break;
      }
      case RecordType::Provenance: {
        if (previous != RecordType::Start && previous != RecordType::Resume) {
          result.error = at(offset) + "a provenance record not right after a start or resume record (it says what "
                                      "made that run, once)";
          return result;
        }
        const std::uint16_t text = body.u16();
        if (version < kProvenanceVersion || body.overrun() || body.left() != text || text > kMaxProvenanceBytes) {
          result.error = at(offset) + "a provenance record of " + std::to_string(length) + " bytes" +
                         (version < kProvenanceVersion ? " in a version " + std::to_string(version) + " journal (version 4 has them)"
                                                       : " that does not hold its text (a u16 length and at most 4000 bytes)");
          return result;
        }
        if (visit.provenance) {
          visit.provenance(std::string(reinterpret_cast<const char*>(body.here()), text));
        }
        break;
      }
      default:
        result.error = at(offset) + "a record of type " + std::to_string(static_cast<int>(type)) +
                       " (expected 1 start, 2 cycle, 3 safe state, 4 homed, 5 machine command, 6 resume, 7 end, "
                       "8 command, 9 provenance or 10 cycles)";
        return result;
    }
    ++result.records;
    previous = type;
    offset += kRecordOverheadBytes + length;
  }
  result.good_bytes = offset;
  result.tail_bytes = size - offset;
  result.ok = true;
  return result;
}

JournalReadResult read_journal_file(const std::string& path, const JournalVisitor& visit, std::size_t limit_bytes) {
  JournalReadResult result;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat info {};
  if (fd < 0 || ::fstat(fd, &info) != 0) {
    result.error = path + ": cannot be read";
  } else if (!S_ISREG(info.st_mode)) {
    result.error = path + ": not a regular file (a journal is one)";
  }
  if (!result.error.empty()) {
    if (fd >= 0) {
      ::close(fd);
    }
    return result;
  }
  // Mapped, not read in: an hours-long job's journal is gigabytes, and the page cache holds it.
  const std::size_t size = std::min(static_cast<std::size_t>(info.st_size), limit_bytes);
  void* mapped = size > 0 ? ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0) : nullptr;
  ::close(fd);
  if (mapped == MAP_FAILED) {
    result.error = path + ": cannot be mapped to be read";
    return result;
  }
  static const std::uint8_t kNothing = 0;
  // Pages already read are given back as the reader goes, so reading gigabytes keeps memory flat.
  JournalVisitor dropping = visit;
  std::size_t dropped = 0;
  constexpr std::size_t kDropEvery = 8U << 20;
  dropping.offset = [&](std::size_t at_offset) {
    if (at_offset - dropped >= 2 * kDropEvery) {
      const std::size_t upto = (at_offset - kDropEvery) & ~(kDropEvery - 1);
      ::madvise(static_cast<std::uint8_t*>(mapped) + dropped, upto - dropped, MADV_DONTNEED);
      dropped = upto;
    }
    if (visit.offset) {
      visit.offset(at_offset);
    }
  };
  result = read_journal(mapped != nullptr ? static_cast<const std::uint8_t*>(mapped) : &kNothing, size, dropping);
  if (mapped != nullptr) {
    ::munmap(mapped, size);
  }
  if (!result.error.empty()) {
    result.error = path + ": " + result.error;
  }
  return result;
}

}  // namespace stencil::journal
