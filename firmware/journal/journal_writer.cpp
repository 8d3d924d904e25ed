// The journal writer: records into a buffer, the buffer to the file, the file to the disk.
#include "firmware/journal/journal_writer.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include "firmware/journal/journal_bytes.hpp"

namespace stencil::journal {
namespace {

constexpr std::int64_t kSyncEveryNs = 1'000'000'000;
constexpr std::size_t kWriteOutBytes = 64 * 1024;  // a buffer this full is written out at once

}  // namespace

JournalWriter::~JournalWriter() { static_cast<void>(close()); }

bool JournalWriter::fail(const std::string& what, int error_number) {
  failed_ = true;
  error_ = path_ + ": " + what + (error_number != 0 ? std::string(": ") + std::strerror(error_number) : std::string());
  return false;
}

bool JournalWriter::open(const std::string& path, const JournalStart& start) {
  path_ = path;
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    return fail("cannot be created", errno);
  }
  ByteWriter header;
  header.bytes(reinterpret_cast<const std::uint8_t*>(kMagic), sizeof kMagic);
  header.u32(kVersion);
  buffer_.insert(buffer_.end(), header.data(), header.data() + header.size());
  ByteWriter payload;
  payload.u32(start.tables_crc32);
  payload.u32(start.triangle_count);
  payload.i64(start.unix_time_ns);
  const std::size_t name_length = std::min<std::size_t>(start.program.size(), 256);
  payload.u16(static_cast<std::uint16_t>(name_length));
  payload.bytes(reinterpret_cast<const std::uint8_t*>(start.program.data()), name_length);
  add_record(RecordType::Start, payload.data(), static_cast<std::uint32_t>(payload.size()));
  return sync();
}

void JournalWriter::add_record(RecordType type, const std::uint8_t* payload, std::uint32_t length) {
  ByteWriter head;
  head.u32(length);
  head.u8(static_cast<std::uint8_t>(type));
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, head.data(), static_cast<uInt>(head.size()));
  crc = crc32(crc, payload, length);
  ByteWriter tail;
  tail.u32(static_cast<std::uint32_t>(crc));
  buffer_.insert(buffer_.end(), head.data(), head.data() + head.size());
  buffer_.insert(buffer_.end(), payload, payload + length);
  buffer_.insert(buffer_.end(), tail.data(), tail.data() + tail.size());
}

bool JournalWriter::append(const control::JournalRecord& r) {
  if (fd_ < 0 || failed_) {
    return false;
  }
  ByteWriter payload;
  encode_cycle(r, payload);
  add_record(RecordType::Cycle, payload.data(), static_cast<std::uint32_t>(payload.size()));
  ++cycle_records_;
  if (r.safe_reason != control::SafeReason::None && !in_safe_state_) {
    in_safe_state_ = true;
    ByteWriter event;
    event.u64(r.cycle);
    event.u8(static_cast<std::uint8_t>(r.safe_reason));
    add_record(RecordType::SafeState, event.data(), static_cast<std::uint32_t>(event.size()));
    return sync();  // the event and everything before it are on the disk before anything else
  }
  if (r.safe_reason == control::SafeReason::None) {
    in_safe_state_ = false;  // reset: the next safe state is a new event
  }
  return buffer_.size() < kWriteOutBytes || write_out();
}

bool JournalWriter::write_out() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0) {
      if (errno == EINTR) {
        continue;
      }
      return fail("write failed", errno);
    }
    done += static_cast<std::size_t>(n);
    bytes_written_ += static_cast<std::uint64_t>(n);
  }
  buffer_.clear();
  return true;
}

bool JournalWriter::sync() {
  if (fd_ < 0 || failed_) {
    return false;
  }
  if (!write_out()) {
    return false;
  }
  if (::fsync(fd_) != 0) {
    return fail("fsync failed", errno);
  }
  ++syncs_;
  return true;
}

bool JournalWriter::sync_if_due(std::int64_t now_ns) {
  if (fd_ < 0 || failed_) {
    return false;
  }
  if (synced_once_ && now_ns - last_sync_ns_ < kSyncEveryNs) {
    return true;
  }
  synced_once_ = true;
  last_sync_ns_ = now_ns;
  return sync();
}

bool JournalWriter::close() {
  if (fd_ < 0) {
    return !failed_;
  }
  const bool synced = failed_ ? false : sync();
  const bool closed = ::close(fd_) == 0;
  fd_ = -1;
  if (!closed && synced) {
    return fail("close failed", errno);
  }
  return synced && closed;
}

}  // namespace stencil::journal
