// linuxcncrsh's replies as LinuxCNC 2.9's linuxcncrsh sends them (the lines below are copied from
// sessions with sim/linuxcnc_mill), and lines that must not parse.
#include <array>
#include <string_view>

#include "hal/linuxcnc/linuxcncrsh_replies.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::hal::linuxcnc;

TEST_GROUP(LinuxcncrshReplies){};

TEST(LinuxcncrshReplies, ASetIsAckedOrNakedUnderItsOwnName) {
  CHECK(set_reply("SET MDI ACK", "MDI") == SetReply::Ack);
  CHECK(set_reply("SET MDI NAK", "MDI") == SetReply::Nak);
  CHECK(set_reply("SET MODE ACK", "MDI") == SetReply::Other);  // another command's answer
  CHECK(set_reply("SET MDI ACK trailing", "MDI") == SetReply::Other);
  CHECK(set_reply("set echo off", "ECHO") == SetReply::Other);   // echo, not an answer
  CHECK(set_reply("", "MDI") == SetReply::Other);
  CHECK(set_reply("SET MDI", "MDI") == SetReply::Other);
}

TEST(LinuxcncrshReplies, HelloIsAcceptedOnlyWithAck) {
  CHECK(hello_accepted("HELLO ACK SIMMILL 1.1"));
  CHECK_FALSE(hello_accepted("HELLO NAK"));
  CHECK_FALSE(hello_accepted("HELLO"));
  CHECK_FALSE(hello_accepted("ACK HELLO"));
}

TEST(LinuxcncrshReplies, AOneWordValueBelongsToItsKey) {
  CHECK(value_of("ESTOP ON", "ESTOP") == "ON");
  CHECK(value_of("MACHINE OFF", "MACHINE") == "OFF");
  CHECK(value_of("PROGRAM_STATUS IDLE", "PROGRAM_STATUS") == "IDLE");
  CHECK(value_of("ESTOP ON", "MACHINE").empty());
  CHECK(value_of("ESTOP ON OFF", "ESTOP").empty());
  CHECK(value_of("ESTOP", "ESTOP").empty());
}

TEST(LinuxcncrshReplies, APositionIsItsFirstThreeNumbers) {
  std::array<double, 3> xyz{};
  CHECK(parse_xyz("ABS_ACT_POS 3.319200 1.659600 0.663840 0.000000 0.000000 0.000000", "ABS_ACT_POS", xyz));
  DOUBLES_EQUAL(3.3192, xyz[0], 0.0);
  DOUBLES_EQUAL(1.6596, xyz[1], 0.0);
  DOUBLES_EQUAL(0.66384, xyz[2], 0.0);
  CHECK(parse_xyz("ABS_CMD_POS -1.5 +2 0", "ABS_CMD_POS", xyz));
  DOUBLES_EQUAL(-1.5, xyz[0], 0.0);
  DOUBLES_EQUAL(2.0, xyz[1], 0.0);
}

TEST(LinuxcncrshReplies, APositionThatIsNotThreePlainNumbersIsRefusedAndLeavesTheOldOne) {
  std::array<double, 3> xyz{7.0, 8.0, 9.0};
  CHECK_FALSE(parse_xyz("ABS_ACT_POS 1.0 2.0", "ABS_ACT_POS", xyz));
  CHECK_FALSE(parse_xyz("ABS_ACT_POS 1.0 nan 2.0", "ABS_ACT_POS", xyz));
  CHECK_FALSE(parse_xyz("ABS_ACT_POS 1.0 inf 2.0", "ABS_ACT_POS", xyz));
  CHECK_FALSE(parse_xyz("ABS_ACT_POS 1e3 2.0 3.0", "ABS_ACT_POS", xyz));
  CHECK_FALSE(parse_xyz("ABS_ACT_POS 1.0 2.0x 3.0", "ABS_ACT_POS", xyz));
  CHECK_FALSE(parse_xyz("ABS_ACT_POS 1.0 - 3.0", "ABS_ACT_POS", xyz));
  CHECK_FALSE(parse_xyz("ABS_CMD_POS 1.0 2.0 3.0", "ABS_ACT_POS", xyz));
  CHECK_FALSE(parse_xyz("ABS_ACT_POS 1.0 2.0 999999999999999999999999999999999999999999", "ABS_ACT_POS", xyz));
  DOUBLES_EQUAL(7.0, xyz[0], 0.0);
  DOUBLES_EQUAL(9.0, xyz[2], 0.0);
}

TEST(LinuxcncrshReplies, JointsHomedAreYesOrNo) {
  std::array<bool, 3> homed{};
  CHECK(parse_joints_homed("JOINT_HOMED YES YES YES NO NO NO", homed));
  CHECK(homed[0] && homed[1] && homed[2]);
  CHECK(parse_joints_homed("JOINT_HOMED NO YES NO NO NO NO", homed));
  CHECK(!homed[0] && homed[1] && !homed[2]);
  CHECK_FALSE(parse_joints_homed("JOINT_HOMED YES MAYBE YES", homed));
  CHECK_FALSE(parse_joints_homed("JOINT_HOMED YES YES", homed));
  CHECK_FALSE(parse_joints_homed("HOMED YES YES YES", homed));
}

TEST(LinuxcncrshReplies, AnErrorCarriesLinuxcncsOwnWords) {
  std::string_view words;
  CHECK(parse_error("ERROR OK", words) == ErrorReply::None);
  CHECK(parse_error("ERROR joint 0 following error", words) == ErrorReply::Error);
  CHECK(words == "joint 0 following error");
  CHECK(parse_error("ERROR Linear move on line 0 would exceed X's positive limit", words) == ErrorReply::Error);
  CHECK(words == "Linear move on line 0 would exceed X's positive limit");
  CHECK(parse_error("ERROR ", words) == ErrorReply::Other);
  CHECK(parse_error("ERRORS OK", words) == ErrorReply::Other);
  CHECK(parse_error("ESTOP ON", words) == ErrorReply::Other);
}
