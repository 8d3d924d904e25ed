// Reading a CAN interface's bitrate over rtnetlink, and refusing one too slow for the haptic frames.
#include "hal/socketcan/can_interface_bitrate.hpp"

#include <linux/can/netlink.h>
#include <linux/if_link.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "hal/socketcan/can_bus_load.hpp"

namespace stencil::hal::socketcan {

namespace {

InterfaceBitrate unreadable(const std::string& detail) { return {BitrateReading::Unreadable, 0, detail}; }
InterfaceBitrate no_bit_timing(const std::string& detail) { return {BitrateReading::NoBitTiming, 0, detail}; }

// Walking a run of attributes by the kernel's alignment rules (the RTA_* macros, without their
// signed-unsigned mixing).
constexpr std::size_t aligned(std::size_t bytes) { return (bytes + RTA_ALIGNTO - 1U) & ~std::size_t{RTA_ALIGNTO - 1U}; }
bool attribute_fits(const rtattr* attribute, std::size_t length) {
  return length >= sizeof(rtattr) && attribute->rta_len >= sizeof(rtattr) && attribute->rta_len <= length;
}
const rtattr* next_attribute(const rtattr* attribute, std::size_t& length) {
  const std::size_t step = aligned(attribute->rta_len);
  length = step >= length ? 0 : length - step;
  return reinterpret_cast<const rtattr*>(reinterpret_cast<const char*>(attribute) + step);
}
const void* payload_of(const rtattr* attribute) { return reinterpret_cast<const char*>(attribute) + aligned(sizeof(rtattr)); }
std::size_t payload_length(const rtattr* attribute) { return attribute->rta_len - aligned(sizeof(rtattr)); }
int attribute_type(const rtattr* attribute) { return attribute->rta_type & NLA_TYPE_MASK; }

// The link's IFLA_LINKINFO: its kind and, for "can", the bitrate in IFLA_INFO_DATA.
InterfaceBitrate from_link_info(const rtattr* link_info) {
  std::string kind;
  const rtattr* data = nullptr;
  std::size_t length = payload_length(link_info);
  for (const auto* attribute = static_cast<const rtattr*>(payload_of(link_info)); attribute_fits(attribute, length);
       attribute = next_attribute(attribute, length)) {
    if (attribute_type(attribute) == IFLA_INFO_KIND) {
      const auto* text = static_cast<const char*>(payload_of(attribute));
      kind.assign(text, strnlen(text, payload_length(attribute)));
    } else if (attribute_type(attribute) == IFLA_INFO_DATA) {
      data = attribute;
    }
  }
  if (kind != "can") {
    return no_bit_timing("a link of kind " + (kind.empty() ? std::string("(none)") : kind) + " has no bit timing");
  }
  if (data != nullptr) {
    length = payload_length(data);
    for (const auto* attribute = static_cast<const rtattr*>(payload_of(data)); attribute_fits(attribute, length);
         attribute = next_attribute(attribute, length)) {
      if (attribute_type(attribute) != IFLA_CAN_BITTIMING) continue;
      if (payload_length(attribute) < sizeof(can_bittiming)) return unreadable("IFLA_CAN_BITTIMING is cut short");
      can_bittiming timing;
      std::memcpy(&timing, payload_of(attribute), sizeof timing);
      if (timing.bitrate == 0) break;
      return {BitrateReading::Known, timing.bitrate, ""};
    }
  }
  return no_bit_timing("a CAN interface with no bitrate set");
}

}  // namespace

InterfaceBitrate parse_link_bitrate(const void* answer, std::size_t length) {
  auto remaining = static_cast<unsigned int>(length);
  for (const nlmsghdr* header = static_cast<const nlmsghdr*>(answer); NLMSG_OK(header, remaining);
       header = NLMSG_NEXT(header, remaining)) {
    if (header->nlmsg_type == NLMSG_DONE) break;
    if (header->nlmsg_type == NLMSG_ERROR) {
      if (header->nlmsg_len < NLMSG_LENGTH(sizeof(nlmsgerr))) return unreadable("RTM_GETLINK: a cut error answer");
      nlmsgerr refusal;
      std::memcpy(&refusal, NLMSG_DATA(header), sizeof refusal);
      if (refusal.error == 0) continue;  // an acknowledgement, not an error
      return unreadable(std::string("RTM_GETLINK: ") + std::strerror(-refusal.error));
    }
    if (header->nlmsg_type != RTM_NEWLINK) continue;
    if (header->nlmsg_len < NLMSG_LENGTH(sizeof(ifinfomsg))) return unreadable("RTM_NEWLINK: cut short");
    const std::size_t attributes_at = NLMSG_LENGTH(aligned(sizeof(ifinfomsg)));
    std::size_t attributes_length = header->nlmsg_len > attributes_at ? header->nlmsg_len - attributes_at : 0;
    for (const auto* attribute = reinterpret_cast<const rtattr*>(reinterpret_cast<const char*>(header) + attributes_at);
         attribute_fits(attribute, attributes_length); attribute = next_attribute(attribute, attributes_length)) {
      if (attribute_type(attribute) == IFLA_LINKINFO) return from_link_info(attribute);
    }
    return no_bit_timing("not a CAN interface: it has no link kind");
  }
  return unreadable("RTM_GETLINK: the answer held no link");
}

InterfaceBitrate read_can_bitrate(const std::string& interface) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) return unreadable("not an interface name");
  const unsigned int index = if_nametoindex(interface.c_str());
  if (index == 0) return unreadable(std::string("no such interface (") + std::strerror(errno) + ")");
  const int fd = ::socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
  if (fd < 0) return unreadable(std::string("socket(AF_NETLINK, NETLINK_ROUTE): ") + std::strerror(errno));
  const timeval timeout{1, 0};
  static_cast<void>(::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout));

  struct {
    nlmsghdr header;
    ifinfomsg link;
  } request{};
  request.header.nlmsg_len = NLMSG_LENGTH(sizeof(ifinfomsg));
  request.header.nlmsg_type = RTM_GETLINK;
  request.header.nlmsg_flags = NLM_F_REQUEST;
  request.header.nlmsg_seq = 1;
  request.link.ifi_family = AF_UNSPEC;
  request.link.ifi_index = static_cast<int>(index);
  sockaddr_nl kernel{};
  kernel.nl_family = AF_NETLINK;
  if (::sendto(fd, &request, request.header.nlmsg_len, 0, reinterpret_cast<const sockaddr*>(&kernel), sizeof kernel) < 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    return unreadable("RTM_GETLINK: send: " + why);
  }
  std::vector<nlmsghdr> answer(65536 / sizeof(nlmsghdr));  // nlmsghdr-aligned room for one link's answer
  const std::size_t room = answer.size() * sizeof(nlmsghdr);
  const ssize_t received = ::recv(fd, answer.data(), room, MSG_TRUNC);
  const std::string why = received < 0 ? std::strerror(errno) : "";
  ::close(fd);
  if (received < 0) return unreadable("RTM_GETLINK: receive: " + why);
  if (static_cast<std::size_t>(received) > room) return unreadable("RTM_GETLINK: the answer is larger than 64 KiB");
  return parse_link_bitrate(answer.data(), static_cast<std::size_t>(received));
}

bool check_can_bitrate(const std::string& interface, const InterfaceBitrate& bitrate, std::string& note,
                       std::string& error) {
  const BusLoad load = haptic_bus_load(bitrate.bitrate_bps);
  const std::string needed = std::to_string(load.bitrate_needed_bps) + " bit/s";
  if (bitrate.reading != BitrateReading::Known) {
    note = "CAN interface " + interface + ": its bitrate could not be checked (" + bitrate.detail +
           "); the haptic frames need " + needed;
    return true;
  }
  char percent[32];
  std::snprintf(percent, sizeof percent, "%.1f %%", 100.0 * load.worst_case_load);
  if (!load.fits) {
    char period[32];
    std::snprintf(period, sizeof period, "%g ms", static_cast<double>(kFramePeriodNs) / 1e6);
    error = "CAN interface " + interface + ": bitrate " + std::to_string(bitrate.bitrate_bps) +
            " bit/s is too slow for the haptic frames, which need " + needed + " (" +
            std::to_string(kHapticFramesPerPeriod) + " frames of up to " +
            std::to_string(classic_frame_bits_worst_case(kFrameBytes)) + " bits every " + period +
            " would load it to " + percent + "); run the bus at 1000000 bit/s (ip link set " + interface +
            " type can bitrate 1000000, and the device's controller at the same)";
    return false;
  }
  note = "CAN interface " + interface + ": " + std::to_string(bitrate.bitrate_bps) +
         " bit/s; the haptic frames load it to " + percent + " at most";
  return true;
}

bool check_can_bitrate(const std::string& interface, std::string& note, std::string& error) {
  return check_can_bitrate(interface, read_can_bitrate(interface), note, error);
}

}  // namespace stencil::hal::socketcan
