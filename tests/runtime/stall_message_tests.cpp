// What a stall says: the virtual tool's and the mill's positions and what the planner tried, so a
// stall that happens can be found again and explained.
#include <string>

#include "firmware/runtime/stall_message.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

TEST_GROUP(StallMessage){};

TEST(StallMessage, SaysWhereTheVirtualToolAndTheMillWereAndWhatWasTried) {
  control::MachineSide::Stall stall{Eigen::Vector3d(25.0, 12.5, 5.99), Eigen::Vector3d(25.0, 12.5, 6.02), {}};
  stall.search = {15, 8, 0, 0, 0, Eigen::Vector3d(25.0, 12.5, 5.995)};
  const std::string text = runtime::stall_message(stall);
  CHECK(text.find("stalled") != std::string::npos);
  CHECK(text.find("the virtual tool at (25.00000, 12.50000, 5.99000) mm") != std::string::npos);
  CHECK(text.find("the mill at (25.00000, 12.50000, 6.02000) mm") != std::string::npos);
  CHECK(text.find("its next path point (25.00000, 12.50000, 5.99500) mm") != std::string::npos);
  CHECK(text.find("tried 15 path points, 8 grid corners (0 legal), 0 staircases, 0 one-axis legs") != std::string::npos);
}
