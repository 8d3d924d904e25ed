// The bitrate check made when the CAN link is opened: the verdict for a bitrate, the parsing of the
// kernel's RTM_GETLINK answer (built here by hand: no CAN or vcan interface can be created on this
// machine), and the real netlink query against interfaces that exist here but are not CAN.
#include "hal/socketcan/can_interface_bitrate.hpp"

#include <linux/can/netlink.h>
#include <linux/if_link.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include <CppUTest/TestHarness.h>

using namespace stencil::hal::socketcan;

namespace {

// An rtnetlink message under construction: attributes appended, nests closed by hand.
class LinkMessage {
 public:
  explicit LinkMessage(std::uint16_t type = RTM_NEWLINK) {
    bytes_.resize(NLMSG_LENGTH(sizeof(ifinfomsg)));
    header().nlmsg_type = type;
  }
  std::size_t attribute(std::uint16_t type, const void* payload, std::size_t length) {
    const std::size_t at = bytes_.size();
    bytes_.resize(at + RTA_SPACE(length));
    rtattr attr{static_cast<unsigned short>(RTA_LENGTH(length)), type};
    std::memcpy(&bytes_[at], &attr, sizeof attr);
    if (length > 0) std::memcpy(&bytes_[at + RTA_LENGTH(0)], payload, length);
    return at;
  }
  std::size_t string(std::uint16_t type, const char* text) { return attribute(type, text, std::strlen(text) + 1); }
  std::size_t open_nest(std::uint16_t type) { return attribute(type, nullptr, 0); }
  void close_nest(std::size_t at) {
    rtattr attr;
    std::memcpy(&attr, &bytes_[at], sizeof attr);
    attr.rta_len = static_cast<unsigned short>(bytes_.size() - at);
    std::memcpy(&bytes_[at], &attr, sizeof attr);
  }
  const std::vector<unsigned char>& finish() {
    header().nlmsg_len = static_cast<std::uint32_t>(bytes_.size());
    return bytes_;
  }
  nlmsghdr& header() { return *reinterpret_cast<nlmsghdr*>(bytes_.data()); }

 private:
  std::vector<unsigned char> bytes_;
};

std::vector<unsigned char> can_link(std::uint32_t bitrate_bps) {
  LinkMessage message;
  message.string(IFLA_IFNAME, "can0");
  const std::size_t info = message.open_nest(IFLA_LINKINFO);
  message.string(IFLA_INFO_KIND, "can");
  const std::size_t data = message.open_nest(IFLA_INFO_DATA);
  can_bittiming timing{};
  timing.bitrate = bitrate_bps;
  timing.sample_point = 875;
  message.attribute(IFLA_CAN_BITTIMING, &timing, sizeof timing);
  message.close_nest(data);
  message.close_nest(info);
  return message.finish();
}

}  // namespace

TEST_GROUP(CanInterfaceBitrate) {};

TEST(CanInterfaceBitrate, ABusTooSlowForAPeriodsFramesIsRefusedNamingInterfaceBitrateAndNeed) {
  std::string note;
  std::string error;
  CHECK_FALSE(check_can_bitrate("can0", {BitrateReading::Known, 500'000, ""}, note, error));
  STRCMP_EQUAL(
      "CAN interface can0: bitrate 500000 bit/s is too slow for the haptic frames, which need 675000 bit/s "
      "(5 frames of up to 135 bits every 1 ms would load it to 135.0 %); run the bus at 1000000 bit/s "
      "(ip link set can0 type can bitrate 1000000, and the device's controller at the same)",
      error.c_str());
  CHECK_TRUE(note.empty());
}

TEST(CanInterfaceBitrate, AFastEnoughBusIsAcceptedWithItsLoadNoted) {
  std::string note;
  std::string error;
  CHECK_TRUE(check_can_bitrate("can0", {BitrateReading::Known, 1'000'000, ""}, note, error));
  CHECK_TRUE(error.empty());
  STRCMP_EQUAL("CAN interface can0: 1000000 bit/s; the haptic frames load it to 67.5 % at most", note.c_str());
}

TEST(CanInterfaceBitrate, AnInterfaceWithoutBitTimingIsAcceptedWithANoteThatItWasNotChecked) {
  std::string note;
  std::string error;
  CHECK_TRUE(check_can_bitrate("vcan0", {BitrateReading::NoBitTiming, 0, "a link of kind vcan has no bit timing"}, note,
                               error));
  CHECK_TRUE(error.empty());
  STRCMP_EQUAL("CAN interface vcan0: its bitrate could not be checked (a link of kind vcan has no bit timing); the "
               "haptic frames need 675000 bit/s",
               note.c_str());
  note.clear();
  CHECK_TRUE(check_can_bitrate("can0", {BitrateReading::Unreadable, 0, "netlink: Operation not permitted"}, note, error));
  STRCMP_EQUAL("CAN interface can0: its bitrate could not be checked (netlink: Operation not permitted); the haptic "
               "frames need 675000 bit/s",
               note.c_str());
}

TEST(CanInterfaceBitrate, ReadsTheBitrateFromTheKernelsLinkAnswer) {
  const std::vector<unsigned char> message = can_link(500'000);
  const InterfaceBitrate read = parse_link_bitrate(message.data(), message.size());
  CHECK_EQUAL(static_cast<int>(BitrateReading::Known), static_cast<int>(read.reading));
  CHECK_EQUAL(500'000U, read.bitrate_bps);
}

TEST(CanInterfaceBitrate, AVirtualOrUnconfiguredInterfaceHasNoBitTiming) {
  LinkMessage vcan;
  vcan.string(IFLA_IFNAME, "vcan0");
  const std::size_t info = vcan.open_nest(IFLA_LINKINFO);
  vcan.string(IFLA_INFO_KIND, "vcan");
  vcan.close_nest(info);
  const std::vector<unsigned char>& bytes = vcan.finish();
  const InterfaceBitrate read = parse_link_bitrate(bytes.data(), bytes.size());
  CHECK_EQUAL(static_cast<int>(BitrateReading::NoBitTiming), static_cast<int>(read.reading));
  STRCMP_EQUAL("a link of kind vcan has no bit timing", read.detail.c_str());

  LinkMessage plain;  // no link kind at all
  plain.string(IFLA_IFNAME, "can9");
  const std::vector<unsigned char>& plain_bytes = plain.finish();
  CHECK_EQUAL(static_cast<int>(BitrateReading::NoBitTiming),
              static_cast<int>(parse_link_bitrate(plain_bytes.data(), plain_bytes.size()).reading));
}

TEST(CanInterfaceBitrate, AnErrorOrACutAnswerIsUnreadableNotABitrate) {
  LinkMessage error_message(NLMSG_ERROR);
  std::vector<unsigned char> bytes(NLMSG_LENGTH(sizeof(nlmsgerr)));
  nlmsghdr header{};
  header.nlmsg_len = static_cast<std::uint32_t>(bytes.size());
  header.nlmsg_type = NLMSG_ERROR;
  nlmsgerr payload{};
  payload.error = -ENODEV;
  std::memcpy(bytes.data(), &header, sizeof header);
  std::memcpy(bytes.data() + NLMSG_HDRLEN, &payload, sizeof payload);
  const InterfaceBitrate refused = parse_link_bitrate(bytes.data(), bytes.size());
  CHECK_EQUAL(static_cast<int>(BitrateReading::Unreadable), static_cast<int>(refused.reading));
  STRCMP_EQUAL("RTM_GETLINK: No such device", refused.detail.c_str());

  const std::vector<unsigned char> whole = can_link(1'000'000);
  const InterfaceBitrate cut = parse_link_bitrate(whole.data(), whole.size() - 8);
  CHECK_EQUAL(static_cast<int>(BitrateReading::Unreadable), static_cast<int>(cut.reading));
}

// The netlink query itself, against this machine's interfaces: none is CAN (no vcan can be made here),
// so this proves the request and the walk through a real answer, not the bitrate of a real bus.
TEST(CanInterfaceBitrate, AskingTheKernelAboutANonCanInterfaceFindsNoBitTiming) {
  const InterfaceBitrate loopback = read_can_bitrate("lo");
  CHECK_EQUAL(static_cast<int>(BitrateReading::NoBitTiming), static_cast<int>(loopback.reading));
  const InterfaceBitrate missing = read_can_bitrate("nosuchcan7");
  CHECK_EQUAL(static_cast<int>(BitrateReading::Unreadable), static_cast<int>(missing.reading));
  STRCMP_CONTAINS("no such interface", missing.detail.c_str());
}
