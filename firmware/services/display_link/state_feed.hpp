// The state feed's two ends over one shared region: FeedWriter in the controller (a memfd it
// creates, fills and seals against any other writer) and FeedView in a display (the region mapped
// read-only, every offset checked before it is used).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/services/display_link/display_wire.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::display_link {

struct FeedFacts {
  RequestLimits limits;
  ResetRule reset_rule;
  bool virtual_clock = false;
  std::string program;  // "stencil-sim"
};

class FeedWriter {
 public:
  FeedWriter() = default;
  ~FeedWriter();
  FeedWriter(const FeedWriter&) = delete;
  FeedWriter& operator=(const FeedWriter&) = delete;

  // Creates the region for `part`, writes the header and the mesh and touches every page (so that
  // nothing is faulted in later, and a locked process has it all locked now); false with the reason.
  [[nodiscard]] bool create(const tables::PartTables& part, const FeedFacts& facts, std::string& error);
  [[nodiscard]] int fd() const { return fd_; }  // for SCM_RIGHTS; stays the writer's

  // The one records thread.
  void publish(const Figures& figures) { figures_->write(figures); }
  void mark_touched(std::uint32_t id);
  void record_force(std::uint64_t cycle, float force_n);
  // The one machine thread.
  void publish(const FeedStock& stock) { stock_->write(stock); }
  void publish(const FeedMachine& machine) { machine_->write(machine); }

  [[nodiscard]] const FeedHeader& header() const { return *header_; }

 private:
  int fd_ = -1;
  unsigned char* base_ = nullptr;
  std::size_t size_ = 0;
  FeedHeader* header_ = nullptr;
  FiguresCell* figures_ = nullptr;
  StockCell* stock_ = nullptr;
  MachineCell* machine_ = nullptr;
  ForceRing* forces_ = nullptr;
  unsigned char* touched_ = nullptr;
};

// A display's read-only view of a controller's feed.
class FeedView {
 public:
  FeedView() = default;
  ~FeedView();
  FeedView(const FeedView&) = delete;
  FeedView& operator=(const FeedView&) = delete;

  // Maps `fd` read-only (the descriptor is closed, taken or not) and checks the header: magic,
  // version, the sizes it was built with, every offset inside the region. False with the reason.
  [[nodiscard]] bool open(int fd, std::string& error);
  // The same over memory a test owns (not unmapped).
  [[nodiscard]] bool open_memory(const unsigned char* base, std::size_t size, std::string& error);
  void close();
  [[nodiscard]] bool is_open() const { return base_ != nullptr; }

  [[nodiscard]] const FeedHeader& header() const { return *header_; }
  [[nodiscard]] bool read(Figures& figures) const { return figures_->read(figures); }
  [[nodiscard]] bool read(FeedStock& stock) const { return stock_->read(stock); }
  [[nodiscard]] bool read(FeedMachine& machine) const { return machine_->read(machine); }
  [[nodiscard]] std::uint64_t stock_sequence() const { return stock_->sequence(); }
  // The set as bits, one a triangle (triangle_count bits, rounded up to bytes).
  void touched(std::vector<std::uint8_t>& bits) const;
  // The largest force of the cycles after `after_cycle` up to `newest_cycle` still in the ring.
  [[nodiscard]] float force_peak(std::uint64_t after_cycle, std::uint64_t newest_cycle) const;
  // A triangle's three vertices (9 floats, mm) and its flags.
  [[nodiscard]] const float* vertices(std::uint32_t triangle) const;
  [[nodiscard]] std::uint8_t flags(std::uint32_t triangle) const;

 private:
  const unsigned char* base_ = nullptr;
  std::size_t size_ = 0;
  bool mapped_ = false;
  const FeedHeader* header_ = nullptr;
  const FiguresCell* figures_ = nullptr;
  const StockCell* stock_ = nullptr;
  const MachineCell* machine_ = nullptr;
  const ForceRing* forces_ = nullptr;
  const unsigned char* touched_ = nullptr;
};

}  // namespace stencil::display_link
