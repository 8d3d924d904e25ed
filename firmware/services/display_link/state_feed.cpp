#include "firmware/services/display_link/state_feed.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <new>

namespace stencil::display_link {
namespace {

constexpr std::uint64_t align(std::uint64_t offset) { return (offset + 63) & ~std::uint64_t{63}; }

}  // namespace

FeedLayout feed_layout(std::uint32_t triangle_count) {
  FeedLayout layout{};
  std::uint64_t at = align(sizeof(FeedHeader));
  layout.mesh_offset = at;
  at = align(at + std::uint64_t{triangle_count} * 9 * sizeof(float));
  layout.flags_offset = at;
  at = align(at + triangle_count);
  layout.touched_offset = at;
  at = align(at + (std::uint64_t{triangle_count} + 7) / 8);
  layout.force_ring_offset = at;
  at = align(at + sizeof(ForceRing));
  layout.figures_offset = at;
  at = align(at + sizeof(FiguresCell));
  layout.stock_offset = at;
  at = align(at + sizeof(StockCell));
  layout.machine_offset = at;
  at = align(at + sizeof(MachineCell));
  layout.total_bytes = (at + 4095) & ~std::uint64_t{4095};
  return layout;
}

FeedWriter::~FeedWriter() {
  if (base_ != nullptr) {
    munmap(base_, size_);
  }
  if (fd_ >= 0) {
    ::close(fd_);
  }
}

bool FeedWriter::create(const tables::PartTables& part, const FeedFacts& facts, std::string& error) {
  const std::uint32_t triangles = part.triangle_count();
  const FeedLayout layout = feed_layout(triangles);
  fd_ = memfd_create("stencil-display-feed", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  if (fd_ < 0) {
    error = std::string("the display feed: memfd_create: ") + std::strerror(errno);
    return false;
  }
  size_ = layout.total_bytes;
  if (ftruncate(fd_, static_cast<off_t>(size_)) != 0) {
    error = std::string("the display feed: ftruncate: ") + std::strerror(errno);
    return false;
  }
  void* mapped = mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (mapped == MAP_FAILED) {
    error = std::string("the display feed: mmap: ") + std::strerror(errno);
    return false;
  }
  base_ = static_cast<unsigned char*>(mapped);
  std::memset(base_, 0, size_);  // every page in now, none faulted in while the job runs
  header_ = new (base_) FeedHeader{};
  FeedHeader& h = *header_;
  h.magic = kFeedMagic;
  h.version = kProtocolVersion;
  h.total_bytes = size_;
  h.header_bytes = sizeof(FeedHeader);
  h.figures_bytes = sizeof(Figures);
  h.stock_bytes = sizeof(FeedStock);
  h.telemetry_bytes = sizeof(control::Telemetry);
  h.machine_bytes = sizeof(FeedMachine);
  h.job_id = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
  h.controller_pid = static_cast<std::uint32_t>(getpid());
  std::memcpy(h.program, facts.program.data(), std::min(facts.program.size(), sizeof h.program - 1));
  h.virtual_clock = facts.virtual_clock ? 1 : 0;
  h.limits = facts.limits;
  h.reset_rule = facts.reset_rule;
  h.triangle_count = triangles;
  h.reachable_triangle_count = part.header.reachable_triangle_count;
  h.tool_diameter_mm = part.tool.spec.diameter_mm;
  std::copy(std::begin(part.header.workspace_mm), std::end(part.header.workspace_mm), h.workspace_mm);
  h.mesh_offset = layout.mesh_offset;
  h.flags_offset = layout.flags_offset;
  h.touched_offset = layout.touched_offset;
  h.force_ring_offset = layout.force_ring_offset;
  h.figures_offset = layout.figures_offset;
  h.stock_offset = layout.stock_offset;
  h.machine_offset = layout.machine_offset;
  auto* mesh = reinterpret_cast<float*>(base_ + layout.mesh_offset);
  for (std::uint32_t t = 0; t < triangles; ++t) {
    for (int v = 0; v < 3; ++v) {
      const tables::PackedPoint& p = part.triangles[t].vertices[v];
      mesh[t * 9 + static_cast<std::uint32_t>(v) * 3 + 0] = p.x_mm;
      mesh[t * 9 + static_cast<std::uint32_t>(v) * 3 + 1] = p.y_mm;
      mesh[t * 9 + static_cast<std::uint32_t>(v) * 3 + 2] = p.z_mm;
    }
  }
  std::memcpy(base_ + layout.flags_offset, part.triangle_flags, triangles);
  touched_ = base_ + layout.touched_offset;
  forces_ = new (base_ + layout.force_ring_offset) ForceRing{};
  figures_ = new (base_ + layout.figures_offset) FiguresCell{};
  stock_ = new (base_ + layout.stock_offset) StockCell{};
  machine_ = new (base_ + layout.machine_offset) MachineCell{};
  // No display may write it or change its size: only new writable mappings are refused (ours stays);
  // F_SEAL_FUTURE_WRITE needs Linux 5.1, without it the display's read-only mapping is the guard.
  if (fcntl(fd_, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_FUTURE_WRITE) != 0 &&
      fcntl(fd_, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW) != 0) {
    error = std::string("the display feed: sealing it: ") + std::strerror(errno);
    return false;
  }
  return true;
}

void FeedWriter::mark_touched(std::uint32_t id) {
  if (touched_ == nullptr || id >= header_->triangle_count) {
    return;
  }
  std::atomic_ref<unsigned char> byte(touched_[id / 8]);
  byte.store(static_cast<unsigned char>(byte.load(std::memory_order_relaxed) | (1U << (id % 8))), std::memory_order_relaxed);
}

void FeedWriter::record_force(std::uint64_t cycle, float force_n) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &force_n, sizeof bits);
  std::atomic_ref<std::uint32_t>(forces_->force_bits[cycle % kForceRing]).store(bits, std::memory_order_relaxed);
  std::atomic_ref<std::uint64_t>(forces_->newest_cycle).store(cycle, std::memory_order_release);
}

FeedView::~FeedView() { close(); }

void FeedView::close() {
  if (mapped_ && base_ != nullptr) {
    munmap(const_cast<unsigned char*>(base_), size_);
  }
  base_ = nullptr;
  mapped_ = false;
  header_ = nullptr;
}

bool FeedView::open(int fd, std::string& error) {
  close();
  struct stat st {};
  if (fstat(fd, &st) != 0 || st.st_size < static_cast<off_t>(sizeof(FeedHeader))) {
    ::close(fd);
    error = "the controller's state feed is too small to be one";
    return false;
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  void* mapped = mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, 0);
  ::close(fd);
  if (mapped == MAP_FAILED) {
    error = std::string("the controller's state feed: mmap: ") + std::strerror(errno);
    return false;
  }
  if (!open_memory(static_cast<const unsigned char*>(mapped), size, error)) {
    munmap(mapped, size);
    return false;
  }
  mapped_ = true;
  return true;
}

bool FeedView::open_memory(const unsigned char* base, std::size_t size, std::string& error) {
  if (size < sizeof(FeedHeader)) {
    error = "the controller's state feed is too small to be one";
    return false;
  }
  const auto& h = *reinterpret_cast<const FeedHeader*>(base);
  if (h.magic != kFeedMagic) {
    error = "the controller's state feed has a bad magic";
    return false;
  }
  if (h.version != kProtocolVersion) {
    error = "the controller's state feed is protocol version " + std::to_string(h.version) + ", this display speaks version " +
            std::to_string(kProtocolVersion);
    return false;
  }
  if (h.header_bytes != sizeof(FeedHeader) || h.figures_bytes != sizeof(Figures) || h.stock_bytes != sizeof(FeedStock) ||
      h.telemetry_bytes != sizeof(control::Telemetry) || h.machine_bytes != sizeof(FeedMachine)) {
    error = "the controller's state feed was built with another layout of the same version (rebuild both from one tree)";
    return false;
  }
  const FeedLayout layout = feed_layout(h.triangle_count);
  if (h.total_bytes != size || layout.total_bytes != size || h.mesh_offset != layout.mesh_offset ||
      h.flags_offset != layout.flags_offset || h.touched_offset != layout.touched_offset ||
      h.force_ring_offset != layout.force_ring_offset || h.figures_offset != layout.figures_offset ||
      h.stock_offset != layout.stock_offset || h.machine_offset != layout.machine_offset) {
    error = "the controller's state feed's regions do not match its triangle count of " + std::to_string(h.triangle_count);
    return false;
  }
  base_ = base;
  size_ = size;
  header_ = &h;
  figures_ = reinterpret_cast<const FiguresCell*>(base + h.figures_offset);
  stock_ = reinterpret_cast<const StockCell*>(base + h.stock_offset);
  machine_ = reinterpret_cast<const MachineCell*>(base + h.machine_offset);
  forces_ = reinterpret_cast<const ForceRing*>(base + h.force_ring_offset);
  touched_ = base + h.touched_offset;
  return true;
}

void FeedView::touched(std::vector<std::uint8_t>& bits) const {
  const std::size_t bytes = (std::size_t{header_->triangle_count} + 7) / 8;
  bits.resize(bytes);
  for (std::size_t i = 0; i < bytes; ++i) {
    bits[i] = std::atomic_ref<unsigned char>(const_cast<unsigned char&>(touched_[i])).load(std::memory_order_relaxed);
  }
}

float FeedView::force_peak(std::uint64_t after_cycle, std::uint64_t newest_cycle) const {
  const std::uint64_t ring_newest =
      std::atomic_ref<std::uint64_t>(const_cast<std::uint64_t&>(forces_->newest_cycle)).load(std::memory_order_acquire);
  const std::uint64_t last = std::min(newest_cycle, ring_newest);
  // Only the ring's newest kForceRing cycles are still there (older slots hold newer cycles).
  const std::uint64_t first = std::max(after_cycle + 1, ring_newest >= kForceRing ? ring_newest - kForceRing + 1 : 0);
  float peak = 0.0F;
  for (std::uint64_t cycle = first; cycle <= last && last != 0; ++cycle) {
    const std::uint32_t bits = std::atomic_ref<std::uint32_t>(const_cast<std::uint32_t&>(forces_->force_bits[cycle % kForceRing]))
                                   .load(std::memory_order_relaxed);
    float force = 0.0F;
    std::memcpy(&force, &bits, sizeof force);
    if (force > peak) {  // NaN never wins
      peak = force;
    }
  }
  return peak;
}

const float* FeedView::vertices(std::uint32_t triangle) const {
  return reinterpret_cast<const float*>(base_ + header_->mesh_offset) + std::size_t{triangle} * 9;
}

std::uint8_t FeedView::flags(std::uint32_t triangle) const { return base_[header_->flags_offset + triangle]; }

}  // namespace stencil::display_link
