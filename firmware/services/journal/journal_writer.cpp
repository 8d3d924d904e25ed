// The journal writer: records into a buffer, the buffer to the file, the file to the disk.
#include "firmware/services/journal/journal_writer.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include "firmware/services/journal/journal_bytes.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"

namespace stencil::journal {
namespace {

constexpr std::int64_t kSyncEveryNs = 1'000'000'000;
constexpr std::size_t kWriteOutBytes = 64 * 1024;  // a buffer this full is written out at once

class PosixJournalStorage final : public JournalStorage {
 public:
  ssize_t write(int fd, const std::uint8_t* data, std::size_t size) override { return ::write(fd, data, size); }
  int fsync(int fd) override { return ::fsync(fd); }
};

}  // namespace

JournalStorage& posix_journal_storage() {
  static PosixJournalStorage storage;
  return storage;
}

JournalWriter::JournalWriter(JournalStorage& storage) : storage_(storage) {
  // A process-private semaphore: sem_post is a futex wake (no lock, no allocation), safe from the
  // machine thread; the records thread waits on it with a timeout.
  static_cast<void>(sem_init(&machine_queued_signal_, 0, 0));
}

JournalWriter::~JournalWriter() {
  static_cast<void>(close());
  sem_destroy(&machine_queued_signal_);
}

bool JournalWriter::fail(const std::string& what, int error_number) {
  failed_ = true;
  accepting_.store(false);
  error_ = path_ + ": " + what + (error_number != 0 ? std::string(": ") + std::strerror(error_number) : std::string());
  return false;
}

bool JournalWriter::open(const std::string& path, const JournalStart& start) {
  std::unique_lock<std::mutex> lock(mutex_);
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
  const std::size_t job_length = std::min<std::size_t>(start.job.size(), 1024);
  payload.u16(static_cast<std::uint16_t>(job_length));
  payload.bytes(reinterpret_cast<const std::uint8_t*>(start.job.data()), job_length);
  add_record(RecordType::Start, payload.data(), static_cast<std::uint32_t>(payload.size()));
  encoder_.restart();
  cycles_.clear();
  cycles_in_record_ = 0;
  add_provenance(start.provenance);
  const bool synced = sync_locked(lock);
  accepting_.store(synced);
  return synced;
}

bool JournalWriter::open_to_resume(const std::string& path, std::size_t good_bytes, const JournalResume& resume) {
  std::unique_lock<std::mutex> lock(mutex_);
  path_ = path;
  fd_ = ::open(path.c_str(), O_RDWR | O_CLOEXEC);  // read: its version
  if (fd_ < 0) {
    return fail("cannot be opened to carry on with it", errno);
  }
  // Its records would be this version's: a journal an older program began is not carried on.
  std::uint8_t header[kFileHeaderBytes] = {};
  if (::pread(fd_, header, sizeof header, 0) != static_cast<ssize_t>(sizeof header)) {
    return fail("cannot read its header", errno);
  }
  ByteReader version_bytes(header + sizeof kMagic, 4);
  // Version 3's and 4's records are all version 5's (4 adds the Provenance record, 5 the Cycles
  // record; the reader takes a Cycle record in any version): such a journal is carried on as
  // version 5, its header's version rewritten first. Anything older is not.
  constexpr std::uint32_t kOldestCarriedOn = 3;
  const std::uint32_t version = version_bytes.u32();
  if (version < kOldestCarriedOn || version > kVersion) {
    return fail("is a version " + std::to_string(version) + " journal; this program carries on versions " +
                    std::to_string(kOldestCarriedOn) + " to " + std::to_string(kVersion) + " only (start the job afresh)",
                0);
  }
  if (version != kVersion) {
    ByteWriter now;
    now.u32(kVersion);
    if (::pwrite(fd_, now.data(), now.size(), sizeof kMagic) != static_cast<ssize_t>(now.size())) {
      return fail("cannot have its header's version brought to " + std::to_string(kVersion), errno);
    }
  }
  if (::ftruncate(fd_, static_cast<off_t>(good_bytes)) != 0) {
    return fail("cannot be cut to its " + std::to_string(good_bytes) + " whole bytes", errno);
  }
  if (::lseek(fd_, 0, SEEK_END) < 0) {
    return fail("seek to its end failed", errno);
  }
  ByteWriter payload;
  payload.u32(resume.segment);
  payload.i64(resume.unix_time_ns);
  payload.f64(resume.script_s);
  payload.f64(resume.approach_s);
  const std::size_t name_length = std::min<std::size_t>(resume.program.size(), 256);
  payload.u16(static_cast<std::uint16_t>(name_length));
  payload.bytes(reinterpret_cast<const std::uint8_t*>(resume.program.data()), name_length);
  add_record(RecordType::Resume, payload.data(), static_cast<std::uint32_t>(payload.size()));
  encoder_.restart();
  cycles_.clear();
  cycles_in_record_ = 0;
  add_provenance(resume.provenance);
  const bool synced = sync_locked(lock);
  accepting_.store(synced);
  return synced;
}

void JournalWriter::add_provenance(const std::string& text) {
  if (text.empty()) {
    return;
  }
  const std::size_t length = std::min(text.size(), kMaxProvenanceBytes);
  ByteWriter payload;
  payload.u16(static_cast<std::uint16_t>(length));
  payload.bytes(reinterpret_cast<const std::uint8_t*>(text.data()), length);
  add_record(RecordType::Provenance, payload.data(), static_cast<std::uint32_t>(payload.size()));
}

bool JournalWriter::append_homed(std::int64_t time_ns) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (fd_ < 0 || failed_ || !write_machine_commands_locked()) {
    return false;
  }
  ByteWriter payload;
  payload.i64(time_ns);
  add_record(RecordType::Homed, payload.data(), static_cast<std::uint32_t>(payload.size()));
  return write_out();
}

// The machine thread: never the lock (the records thread may be inside a long write() with it).
bool JournalWriter::append_machine_command(const control::MachineCommandRecord& record) {
  if (!accepting_.load(std::memory_order_acquire)) {
    return false;
  }
  if (!machine_ring_.push(record)) {
    machine_refused_.fetch_add(1);  // not queued, so not sent: the machine side stops on a journal fault
    return false;
  }
  ++machine_queued_;
  static_cast<void>(sem_post(&machine_queued_signal_));
  return true;
}

bool JournalWriter::machine_commands_written() const {
  return machine_written_.load(std::memory_order_acquire) >= machine_queued_;
}

bool JournalWriter::write_machine_commands() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (fd_ < 0 || failed_) {
    return false;
  }
  return write_machine_commands_locked();
}

// Under mutex_: every queued target into the buffer, the buffer to the file, then the targets are
// published as written (a crash of the program from here on cannot lose them: the kernel has them).
bool JournalWriter::write_machine_commands_locked() {
  control::MachineCommandRecord record{};
  std::uint64_t taken = 0;
  while (machine_ring_.pop(record)) {
    ByteWriter payload;
    encode_machine_command(record, payload);
    add_record(RecordType::MachineCommand, payload.data(), static_cast<std::uint32_t>(payload.size()));
    ++taken;
  }
  if (taken == 0) {
    return true;
  }
  if (!write_out()) {
    return false;  // not published: the machine side holds the target, and the cycle is told
  }
  machine_taken_ += taken;
  machine_records_ += taken;
  machine_written_.store(machine_taken_, std::memory_order_release);
  return true;
}

void JournalWriter::wait_for_machine_commands(std::chrono::nanoseconds most) {
  const timespec until = hal::posix_clock::monotonic_timespec(hal::posix_clock::monotonic_now_ns() + most.count());
  while (sem_clockwait(&machine_queued_signal_, CLOCK_MONOTONIC, &until) != 0 && errno == EINTR) {
  }
  while (sem_trywait(&machine_queued_signal_) == 0) {
    // the posts of targets this look takes together: one look for all of them
  }
}

void JournalWriter::end_cycles() {
  if (cycles_.size() > 0) {
    add_record(RecordType::Cycles, cycles_.data(), static_cast<std::uint32_t>(cycles_.size()));
    cycles_.clear();
  }
  cycles_in_record_ = 0;
}

void JournalWriter::add_record(RecordType type, const std::uint8_t* payload, std::uint32_t length) {
  if (type != RecordType::Cycles) {
    end_cycles();
  }
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
  std::unique_lock<std::mutex> lock(mutex_);
  if (fd_ < 0 || failed_ || !write_machine_commands_locked()) {
    return false;
  }
  encoder_.encode(r, cycles_);
  // Ended by the records alone (never by when the disk is written), so the same job gives the same
  // bytes; the open one is at most 100 ms of cycles that a write-out leaves for the next.
  if (++cycles_in_record_ >= kCyclesPerRecord || cycles_.size() >= kCyclesRecordBytes) {
    end_cycles();
  }
  ++cycle_records_;
  if (r.safe_reason != control::SafeReason::None && !in_safe_state_) {
    in_safe_state_ = true;
    ByteWriter event;
    event.u64(r.cycle);
    event.u8(static_cast<std::uint8_t>(r.safe_reason));
    event.u8(static_cast<std::uint8_t>(r.safe_source));
    add_record(RecordType::SafeState, event.data(), static_cast<std::uint32_t>(event.size()));
    return sync_locked(lock);  // the event and everything before it are on the disk before anything else
  }
  if (r.safe_reason == control::SafeReason::None) {
    in_safe_state_ = false;  // reset: the next safe state is a new event
  }
  return buffer_.size() < kWriteOutBytes || write_out();
}

bool JournalWriter::append_command(const control::CommandEvent& event) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (fd_ < 0 || failed_ || !write_machine_commands_locked()) {
    return false;
  }
  ByteWriter payload;
  encode_command(event, payload);
  add_record(RecordType::Command, payload.data(), static_cast<std::uint32_t>(payload.size()));
  ++command_records_;
  return buffer_.size() < kWriteOutBytes || write_out();
}

bool JournalWriter::append_end(std::uint64_t cycles, control::SafeReason reason) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (fd_ < 0 || failed_ || !write_machine_commands_locked()) {
    return false;
  }
  ByteWriter payload;
  payload.u64(cycles);
  payload.u8(static_cast<std::uint8_t>(reason));
  add_record(RecordType::End, payload.data(), static_cast<std::uint32_t>(payload.size()));
  return sync_locked(lock);
}

bool JournalWriter::write_out() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = storage_.write(fd_, buffer_.data() + done, buffer_.size() - done);
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
  std::unique_lock<std::mutex> lock(mutex_);
  return sync_locked(lock);
}

// Writes out under the lock (the machine's targets first), then fsyncs without it, so that a
// fsync's seconds on slow storage never hold up whoever locks next (fd_ stays open until close(),
// after the threads that feed the writer are done).
bool JournalWriter::sync_locked(std::unique_lock<std::mutex>& lock) {
  if (fd_ < 0 || failed_) {
    return false;
  }
  if (!write_machine_commands_locked() || !write_out()) {
    return false;
  }
  const int fd = fd_;
  lock.unlock();
  const int synced = storage_.fsync(fd);
  const int error_number = errno;
  lock.lock();
  if (synced != 0) {
    return fail("fsync failed", error_number);
  }
  ++syncs_;
  return true;
}

bool JournalWriter::sync_if_due(std::int64_t now_ns) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (fd_ < 0 || failed_) {
    return false;
  }
  if (synced_once_ && now_ns - last_sync_ns_ < kSyncEveryNs) {
    return true;
  }
  synced_once_ = true;
  last_sync_ns_ = now_ns;
  return sync_locked(lock);
}

bool JournalWriter::close() {
  std::unique_lock<std::mutex> lock(mutex_);
  accepting_.store(false);  // the machine thread is done by now; a target queued after this is refused
  if (fd_ < 0) {
    return !failed_;
  }
  if (!failed_) {
    end_cycles();
  }
  const bool synced = failed_ ? false : sync_locked(lock);
  const bool closed = ::close(fd_) == 0;
  fd_ = -1;
  if (!closed && synced) {
    return fail("close failed", errno);
  }
  return synced && closed;
}

}  // namespace stencil::journal
