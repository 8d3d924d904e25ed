// Error frames: which the host subscribes to, how each is named, and which stop the haptic link.
#include "hal/socketcan/can_error_frames.hpp"

#include <linux/can/error.h>

#include <cstring>

#include "tests/hal/socketcan/can_strings.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil::hal::socketcan;

TEST_GROUP(CanErrorFrames) {};

TEST(CanErrorFrames, TheHostSubscribesToEveryClassThatMeansTheLinkIsDown) {
  for (const can_err_mask_t error_class :
       {CAN_ERR_BUSOFF, CAN_ERR_CRTL, CAN_ERR_RESTARTED, CAN_ERR_ACK, CAN_ERR_TX_TIMEOUT}) {
    CHECK_TRUE((kSubscribedErrorClasses & error_class) != 0U);
  }
  // Single bus errors are retried by the controller and add up into the CRTL warnings above.
  CHECK_EQUAL(0U, kSubscribedErrorClasses & (CAN_ERR_BUSERROR | CAN_ERR_PROT));
}

TEST(CanErrorFrames, EachErrorFrameIsNamedByWhatHappened) {
  CHECK_EQUAL(CanBusError::BusOff, classify_error_frame(make_error_frame(CAN_ERR_BUSOFF)));
  CHECK_EQUAL(CanBusError::Restarted, classify_error_frame(make_error_frame(CAN_ERR_RESTARTED)));
  CHECK_EQUAL(CanBusError::NoAcknowledge, classify_error_frame(make_error_frame(CAN_ERR_ACK | CAN_ERR_BUSERROR)));
  CHECK_EQUAL(CanBusError::TransmitTimeout, classify_error_frame(make_error_frame(CAN_ERR_TX_TIMEOUT)));
  CHECK_EQUAL(CanBusError::ControllerOverflow,
              classify_error_frame(make_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_RX_WARNING)));
  CHECK_EQUAL(CanBusError::ErrorPassive, classify_error_frame(make_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE)));
  CHECK_EQUAL(CanBusError::ErrorWarning, classify_error_frame(make_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING)));
  CHECK_EQUAL(CanBusError::ControllerProblem, classify_error_frame(make_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_UNSPEC)));
  CHECK_EQUAL(CanBusError::BackToErrorActive, classify_error_frame(make_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE)));
  CHECK_EQUAL(CanBusError::Other, classify_error_frame(make_error_frame(CAN_ERR_PROT | CAN_ERR_BUSERROR)));
  // Bus-off outranks what comes with it.
  CHECK_EQUAL(CanBusError::BusOff, classify_error_frame(make_error_frame(CAN_ERR_BUSOFF | CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE)));

  STRCMP_EQUAL("bus-off", can_bus_error_name(CanBusError::BusOff));
  STRCMP_EQUAL("controller problem: frames lost to a full controller buffer",
               can_bus_error_name(CanBusError::ControllerOverflow));
  STRCMP_EQUAL("none", can_bus_error_name(CanBusError::None));
}

TEST(CanErrorFrames, OnlyADataFrameIsNotAnErrorFrame) {
  can_frame data{};
  data.can_id = kPoseAId;
  data.len = 8;
  CHECK_FALSE(is_error_frame(data));
  CHECK_EQUAL(CanBusError::None, classify_error_frame(data));
  const can_frame bus_off = make_error_frame(CAN_ERR_BUSOFF);
  CHECK_TRUE(is_error_frame(bus_off));
  CHECK_EQUAL(CAN_ERR_FLAG | CAN_ERR_BUSOFF, bus_off.can_id);
  CHECK_EQUAL(CAN_ERR_DLC, bus_off.len);
}

TEST(CanErrorFrames, EveryClassButRecoveryAndSingleBusErrorsStopsTheLink) {
  for (const CanBusError error : {CanBusError::BusOff, CanBusError::Restarted, CanBusError::NoAcknowledge,
                                  CanBusError::TransmitTimeout, CanBusError::ControllerOverflow,
                                  CanBusError::ErrorPassive, CanBusError::ErrorWarning, CanBusError::ControllerProblem}) {
    CHECK_TRUE(stops_the_link(error));
  }
  CHECK_FALSE(stops_the_link(CanBusError::None));
  CHECK_FALSE(stops_the_link(CanBusError::BackToErrorActive));
  CHECK_FALSE(stops_the_link(CanBusError::Other));
}
