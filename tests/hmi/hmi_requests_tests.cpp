// The browser's requests as stencil-display parses them (hmi_requests.hpp): well-formed ones read,
// anything else (not JSON, another shape, an unknown type or parameter, a value that is not a
// number, too long) refused with what was expected, whatever the bytes. The limits they are then
// checked against are display_link's (tests/display_link/request_rules_tests.cpp).
#include <string>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/services/hmi/hmi_requests.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::hmi;

TEST_GROUP(HmiRequests){};

TEST(HmiRequests, WellFormedRequestsAreParsed) {
  Request r;
  std::string error;
  CHECK(parse_request(R"({"type":"set","name":"force_limit","value":2.5})", r, error));
  CHECK(r.kind == RequestKind::Set);
  CHECK(r.parameter == Parameter::ForceLimit);
  DOUBLES_EQUAL(2.5, r.value, 0.0);
  CHECK(command_kind(r.parameter) == control::CommandKind::SetForceLimit);
  CHECK(parse_request(R"({"type":"set","name":"coupling","value":1})", r, error));
  CHECK(r.parameter == Parameter::Coupling);
  CHECK(parse_request(R"({"type":"reset"})", r, error));
  CHECK(r.kind == RequestKind::Reset);
}

TEST(HmiRequests, MalformedMessagesAreRefusedWithWhatWasExpected) {
  Request r;
  std::string error;
  const char* const bad[] = {
      "", "not json", "{", "[]", "42", R"({"type":7})", R"({"kind":"reset"})", R"({"type":"launch"})",
      R"({"type":"set"})", R"({"type":"set","name":"torque","value":1})", R"({"type":"set","name":"coupling"})",
      R"({"type":"set","name":"coupling","value":"1"})", R"({"type":"set","name":"coupling","value":null})",
      "\xff\xfe\x00garbage",
  };
  for (const char* text : bad) {
    error.clear();
    CHECK_FALSE_TEXT(parse_request(text, r, error), text);
    CHECK_TEXT(!error.empty(), text);
  }
  CHECK_FALSE(parse_request(R"({"type":"launch"})", r, error));
  CHECK(error.find("expected \"set\", \"reset\", \"stop\", \"pause\" or \"resume\"") != std::string::npos);
  // Stop, pause and resume are requests of their own.
  CHECK(parse_request(R"({"type":"stop"})", r, error));
  CHECK(r.kind == RequestKind::Stop);
  CHECK(parse_request(R"({"type":"pause"})", r, error));
  CHECK(r.kind == RequestKind::Pause);
  CHECK(parse_request(R"({"type":"resume"})", r, error));
  CHECK(r.kind == RequestKind::Resume);
  const std::string huge = R"({"type":"reset","pad":")" + std::string(2000, 'x') + "\"}";
  CHECK_FALSE(parse_request(huge, r, error));
  CHECK(error.find("at most 1024") != std::string::npos);
}

// The error must tell the browser's author what to send: the parameter's name and its unit.
TEST(HmiRequests, ASetWithoutANumberNamesTheParameterAndItsUnit) {
  Request r;
  std::string error;
  CHECK_FALSE(parse_request(R"({"type":"set","name":"force_limit","value":"5"})", r, error));
  STRCMP_EQUAL("\"set\" force_limit needs a number \"value\" in N", error.c_str());
  CHECK_FALSE(parse_request(R"({"type":"set","name":"speed_limit"})", r, error));
  STRCMP_EQUAL("\"set\" speed_limit needs a number \"value\" in mm/s", error.c_str());
  CHECK_FALSE(parse_request(R"({"type":"set","name":"coupling","value":[1]})", r, error));
  STRCMP_EQUAL("\"set\" coupling needs a number \"value\" in N/mm", error.c_str());
  CHECK_FALSE(parse_request(R"({"type":"set","name":"torque","value":1})", r, error));
  STRCMP_EQUAL("unknown parameter 'torque': expected coupling, force_limit, speed_limit, damping, friction or speed_limiting",
               error.c_str());
  CHECK_FALSE(parse_request(R"({"type":"set","name":"friction"})", r, error));
  STRCMP_EQUAL("\"set\" friction needs a number \"value\"", error.c_str());
  CHECK_FALSE(parse_request(R"({"type":"set","name":"damping","value":"5"})", r, error));
  STRCMP_EQUAL("\"set\" damping needs a number \"value\" in N s/m", error.c_str());
  // A name the size of the message is not echoed whole.
  const std::string long_name = std::string(60, 'n');
  CHECK_FALSE(parse_request(R"({"type":")" + long_name + R"("})", r, error));
  STRCMP_EQUAL(("unknown \"type\" '" + std::string(40, 'n') +
                "': expected \"set\", \"reset\", \"stop\", \"pause\" or \"resume\"").c_str(),
               error.c_str());
  // Exactly the largest message is read; one byte more is not.
  const std::string pad = R"({"type":"reset","pad":")";
  const std::string fits = pad + std::string(kMaxRequestBytes - pad.size() - 2, 'x') + "\"}";
  LONGS_EQUAL(kMaxRequestBytes, fits.size());
  CHECK_TRUE_TEXT(parse_request(fits, r, error), error.c_str());
  CHECK(r.kind == RequestKind::Reset);
  CHECK_FALSE(parse_request(pad + std::string(kMaxRequestBytes - pad.size() - 1, 'x') + "\"}", r, error));
  STRCMP_EQUAL("message of 1025 bytes: at most 1024", error.c_str());
}

// The speed limiting by its name (the page's select) or its number; anything else is named back.
TEST(HmiRequests, TheSpeedLimitingIsSetByNameOrNumber) {
  Request r;
  std::string error;
  CHECK(parse_request(R"({"type":"set","name":"speed_limiting","value":"penalty"})", r, error));
  CHECK(r.kind == RequestKind::Set && r.parameter == Parameter::SpeedLimiting);
  DOUBLES_EQUAL(1.0, r.value, 0.0);
  CHECK(parse_request(R"({"type":"set","name":"speed_limiting","value":"cap"})", r, error));
  DOUBLES_EQUAL(0.0, r.value, 0.0);
  CHECK(parse_request(R"({"type":"set","name":"speed_limiting","value":1})", r, error));
  DOUBLES_EQUAL(1.0, r.value, 0.0);
  CHECK_FALSE(parse_request(R"({"type":"set","name":"speed_limiting","value":"brake"})", r, error));
  STRCMP_EQUAL("speed_limiting 'brake': expected \"cap\" or \"penalty\" (or 0 or 1)", error.c_str());
  CHECK(parse_request(R"({"type":"set","name":"friction","value":0.4})", r, error));
  CHECK(r.parameter == Parameter::Friction);
  DOUBLES_EQUAL(0.4, r.value, 0.0);
}
