// LinuxCNC's INI as the rig reads it (board/sherline_suzuki/linuxcnc_ini.hpp): the test mill's numbers
// and their lines, every bad line refused naming the file, the line and the key, linuxcncrsh's options
// as DISPLAY gives them, and the workspace and the rig's passwords against it.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "board/sherline_suzuki/linuxcnc_ini.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

namespace {

using stencil::board::sherline_suzuki::LinuxcncIni;
using stencil::board::sherline_suzuki::parse_linuxcnc_ini;

std::string fixture_text() {
  std::ifstream file(STENCIL_LINUXCNC_TEST_INI);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The fixture with the line starting `key =` in [section] replaced by `line` ("" removes it).
std::string fixture_with(const std::string& section, const std::string& key, const std::string& line) {
  std::istringstream in(fixture_text());
  std::string out, current, in_section;
  bool found = false;
  while (std::getline(in, current)) {
    if (!current.empty() && current[0] == '[') in_section = current;
    if (!found && in_section == "[" + section + "]" && current.rfind(key + " =", 0) == 0) {
      found = true;
      if (!line.empty()) out += line + "\n";
      continue;
    }
    out += current + "\n";
  }
  CHECK_TEXT(found, (section + " " + key).c_str());
  return out;
}

// "mill.ini:N: " for the fixture's line starting `text` (the first, or the first in [section]).
std::string at_line_of(const std::string& text, const std::string& section = "") {
  std::istringstream in(fixture_text());
  std::string current, in_section;
  for (int line = 1; std::getline(in, current); ++line) {
    if (!current.empty() && current[0] == '[') in_section = current;
    if ((section.empty() || in_section == "[" + section + "]") && current.rfind(text, 0) == 0) {
      return "mill.ini:" + std::to_string(line) + ": ";
    }
  }
  FAIL(("no line " + text + " in the fixture").c_str());
  return "";
}

LinuxcncIni accepted(const std::string& text) {
  LinuxcncIni ini;
  std::string error;
  CHECK_TEXT(parse_linuxcnc_ini(text, "mill.ini", ini, error), error.c_str());
  return ini;
}

std::string refusal(const std::string& text) {
  LinuxcncIni ini;
  std::string error;
  CHECK_FALSE(parse_linuxcnc_ini(text, "mill.ini", ini, error));
  CHECK(ini.source.empty());  // nothing of a refused file is taken
  return error;
}

void contains(const std::string& text, const std::string& part) {
  CHECK_TEXT(text.find(part) != std::string::npos, (text + "\n  does not contain: " + part).c_str());
}

std::string display_with(const std::string& value) {
  return fixture_with("DISPLAY", "DISPLAY", "DISPLAY = " + value);
}

}  // namespace

TEST_GROUP(LinuxcncIni){};

TEST(LinuxcncIni, TheTestMillReadsWithItsNumbersAndTheirLines) {
  const LinuxcncIni ini = accepted(fixture_text());
  STRCMP_EQUAL("mill.ini", ini.source.c_str());
  const double travel[3] = {50.0, 25.0, 25.0};
  const char* sections[3] = {"AXIS_X", "AXIS_Y", "AXIS_Z"};
  for (std::size_t axis = 0; axis < 3; ++axis) {
    DOUBLES_EQUAL(5.0, ini.axes[axis].max_velocity_mm_per_s.value, 0.0);
    DOUBLES_EQUAL(200.0, ini.axes[axis].max_acceleration_mm_per_s2.value, 0.0);
    DOUBLES_EQUAL(0.0, ini.axes[axis].min_limit_mm.value, 0.0);
    DOUBLES_EQUAL(travel[axis], ini.axes[axis].max_limit_mm.value, 0.0);
    STRCMP_EQUAL(at_line_of("MAX_LIMIT", sections[axis]).c_str(),
                 ("mill.ini:" + std::to_string(ini.axes[axis].max_limit_mm.line) + ": ").c_str());
  }
  CHECK_EQUAL(0, ini.max_linear_velocity_mm_per_s.line);  // not given
  CHECK_EQUAL(5007, ini.display.port);
  STRCMP_EQUAL("SimMillHello", ini.display.connect_password.c_str());
  STRCMP_EQUAL("SimMillEnable", ini.display.enable_password.c_str());
  CHECK_EQUAL(fixture_text().size(), ini.size);
  CHECK(ini.crc32 != 0U);
}

TEST(LinuxcncIni, TheFileOnDiskReadsAsItsText) {
  LinuxcncIni ini;
  std::string error;
  CHECK_TEXT(stencil::board::sherline_suzuki::read_linuxcnc_ini(STENCIL_LINUXCNC_TEST_INI, ini, error), error.c_str());
  STRCMP_EQUAL(STENCIL_LINUXCNC_TEST_INI, ini.source.c_str());
  CHECK_EQUAL(accepted(fixture_text()).crc32, ini.crc32);
}

TEST(LinuxcncIni, TheTrajectorysTopSpeedIsTakenWhenGiven) {
  const LinuxcncIni ini = accepted(fixture_with("TRAJ", "LINEAR_UNITS", "LINEAR_UNITS = mm\nMAX_LINEAR_VELOCITY = 4.5"));
  DOUBLES_EQUAL(4.5, ini.max_linear_velocity_mm_per_s.value, 0.0);
  STRCMP_EQUAL(at_line_of("LINEAR_UNITS").c_str(), ("mill.ini:" + std::to_string(ini.max_linear_velocity_mm_per_s.line - 1) + ": ").c_str());
  contains(refusal(fixture_with("TRAJ", "LINEAR_UNITS", "LINEAR_UNITS = mm\nMAX_LINEAR_VELOCITY = 0")),
           "[TRAJ] MAX_LINEAR_VELOCITY: 0 is out of range: expected mm/s, the tool path's top speed, above 0");
}

TEST(LinuxcncIni, AMissingAxisSpeedNamesItsSectionsLine) {
  contains(refusal(fixture_with("AXIS_Z", "MAX_VELOCITY", "")),
           at_line_of("[AXIS_Z]") + "[AXIS_Z]: missing MAX_VELOCITY: expected mm/s, the axis's top speed, above 0");
  std::string no_section = fixture_text();
  no_section.replace(no_section.find("[AXIS_Y]"), 8, "[AXIS_W]");
  contains(refusal(no_section), "mill.ini: no [AXIS_Y] section: missing MAX_VELOCITY");
}

TEST(LinuxcncIni, InchesAreRefusedAndMetricIsMillimetres) {
  contains(refusal(fixture_with("TRAJ", "LINEAR_UNITS", "LINEAR_UNITS = inch")),
           at_line_of("LINEAR_UNITS") + "[TRAJ] LINEAR_UNITS: 'inch': expected mm or metric");
  static_cast<void>(accepted(fixture_with("TRAJ", "LINEAR_UNITS", "LINEAR_UNITS = metric")));
  contains(refusal(fixture_with("TRAJ", "LINEAR_UNITS", "")), "[TRAJ]: missing LINEAR_UNITS: expected mm or metric");
}

TEST(LinuxcncIni, ANumberIsTheWholeValueFiniteAndInItsRange) {
  contains(refusal(fixture_with("AXIS_Y", "MAX_VELOCITY", "MAX_VELOCITY = 5 # mm/s")),
           at_line_of("MAX_VELOCITY", "AXIS_Y") + "[AXIS_Y] MAX_VELOCITY: '5 # mm/s' is not a number");
  contains(refusal(fixture_with("AXIS_Y", "MAX_VELOCITY", "MAX_VELOCITY = nan")), "'nan' is not a number");
  contains(refusal(fixture_with("AXIS_Y", "MAX_VELOCITY", "MAX_VELOCITY = +-5")), "'+-5' is not a number");
  contains(refusal(fixture_with("AXIS_X", "MAX_ACCELERATION", "MAX_ACCELERATION = -200")),
           "[AXIS_X] MAX_ACCELERATION: -200 is out of range: expected mm/s^2, the axis's acceleration, above 0");
  contains(refusal(fixture_with("AXIS_X", "MAX_ACCELERATION", "MAX_ACCELERATION =")), "'' is not a number");
  const LinuxcncIni ini = accepted(fixture_with("AXIS_X", "MAX_VELOCITY", "MAX_VELOCITY = +2.5e0"));
  DOUBLES_EQUAL(2.5, ini.axes[0].max_velocity_mm_per_s.value, 0.0);
}

TEST(LinuxcncIni, TheSoftLimitsMustOpenAnInterval) {
  contains(refusal(fixture_with("AXIS_Y", "MAX_LIMIT", "MAX_LIMIT = 0")),
           at_line_of("MAX_LIMIT", "AXIS_Y") + "[AXIS_Y] MAX_LIMIT 0: expected above MIN_LIMIT 0");
}

TEST(LinuxcncIni, AKeyTheRigReadsGivenTwiceNamesBothLines) {
  const std::string text = fixture_with("AXIS_X", "MAX_VELOCITY", "MAX_VELOCITY = 5\nMAX_VELOCITY = 50");
  const std::string first = at_line_of("MAX_VELOCITY", "AXIS_X");
  const int line = std::atoi(first.c_str() + 9);
  contains(refusal(text), "mill.ini:" + std::to_string(line + 1) + ": [AXIS_X] MAX_VELOCITY: given again (first on line " +
                              std::to_string(line) + "): expected it once");
  // A key it does not read may repeat, as LinuxCNC's HALFILE does.
  static_cast<void>(accepted(fixture_with("EMC", "VERSION", "VERSION = 1.1\nHALFILE = a.hal\nHALFILE = b.hal")));
}

TEST(LinuxcncIni, ALineThatIsNotIniIsRefusedWithItsLine) {
  contains(refusal(fixture_with("AXIS_Z", "MAX_VELOCITY", "MAX_VELOCITY 5")),
           at_line_of("MAX_VELOCITY", "AXIS_Z") + "'MAX_VELOCITY 5': expected KEY = VALUE, a [SECTION] header or a comment");
  contains(refusal("[TRAJ\nLINEAR_UNITS = mm\n"), "mill.ini:1: '[TRAJ': expected a section header, [NAME]");
  contains(refusal("[]\n"), "mill.ini:1: '[]': expected a section header");
  contains(refusal("[ TRAJ ]\nLINEAR_UNITS = mm\n"), "mill.ini:1: '[ TRAJ ]': expected a section header, [NAME] (no blanks");
  contains(refusal("LINEAR_UNITS = mm\n[TRAJ]\n"), "mill.ini:1: 'LINEAR_UNITS': expected a [SECTION] header before the first key");
  contains(refusal("[TRAJ]\n= mm\n"), "mill.ini:2: '= mm': expected a key before '='");
  contains(refusal("[TRAJ]\n#INCLUDE axes.inc\n"), "mill.ini:2: #INCLUDE: expected every value in this file");
  contains(refusal(""), "mill.ini: no [TRAJ] section: missing LINEAR_UNITS");
}

TEST(LinuxcncIni, CarriageReturnsAndBlanksAroundValuesAreNotPartOfThem) {
  std::string text = fixture_text();
  std::string crlf;
  for (const char c : text) {
    if (c == '\n') crlf += " \t\r";
    crlf += c;
  }
  const LinuxcncIni ini = accepted(crlf);
  STRCMP_EQUAL("SimMillEnable", ini.display.enable_password.c_str());
  DOUBLES_EQUAL(25.0, ini.axes[2].max_limit_mm.value, 0.0);
}

TEST(LinuxcncIni, TheDisplayMustBeLinuxcncrshWithPasswordsOfItsOwn) {
  const std::string display = at_line_of("DISPLAY =") + "[DISPLAY] DISPLAY: ";
  contains(refusal(display_with("axis")), display + "runs 'axis': expected linuxcncrsh");
  contains(refusal(fixture_with("DISPLAY", "DISPLAY", "")), "[DISPLAY]: missing DISPLAY: expected linuxcncrsh");
  contains(refusal(display_with("linuxcncrsh --port 5007 --enablepw SimMillEnable")),
           display + "no --connectpw: linuxcncrsh would take its default password EMC");
  contains(refusal(display_with("linuxcncrsh --connectpw SimMillHello")),
           display + "no --enablepw: linuxcncrsh would take its default password EMCTOO");
  contains(refusal(display_with("linuxcncrsh --connectpw EMC --enablepw SimMillEnable")),
           display + "--connectpw EMC is linuxcncrsh's default");
  contains(refusal(display_with("linuxcncrsh --connectpw SimMillHello --enablepw EMCTOO")),
           display + "--enablepw EMCTOO is linuxcncrsh's default");
}

TEST(LinuxcncIni, TheSimulatedMillsTemplateIsRefusedUntilItIsFilledIn) {
  contains(refusal(display_with("linuxcncrsh --port @PORT@ --name @NAME@ --connectpw @CONNECTPW@ --enablepw @ENABLEPW@")),
           "[DISPLAY] DISPLAY: '@PORT@' is a template's placeholder: expected the INI LinuxCNC runs with");
  contains(refusal(display_with("linuxcncrsh --connectpw=@CONNECTPW@ --enablepw x")), "'--connectpw=@CONNECTPW@' is a template's placeholder");
}

TEST(LinuxcncIni, LinuxcncrshsOptionsAreReadInEachOfTheirForms) {
  LinuxcncIni ini = accepted(display_with("/usr/bin/linuxcncrsh --port=6001 -wHello -e Enable --name -efoo --sessions -1"));
  CHECK_EQUAL(6001, ini.display.port);
  STRCMP_EQUAL("Hello", ini.display.connect_password.c_str());
  STRCMP_EQUAL("Enable", ini.display.enable_password.c_str());  // --name's value is not an option
  ini = accepted(display_with("linuxcncrsh -p 6002 --connectpw=Hello --enablepw Enable -- -ini other.ini --port 1"));
  CHECK_EQUAL(6002, ini.display.port);  // after "--", LinuxCNC's arguments, not linuxcncrsh's
  const std::string display = "[DISPLAY] DISPLAY: ";
  contains(refusal(display_with("linuxcncrsh --connectpw Hello --enablepw")), display + "--enablepw has no value");
  contains(refusal(display_with("linuxcncrsh --connectpw Hello --enablepw A -e B")), display + "--enablepw is given twice");
  contains(refusal(display_with("linuxcncrsh --port 70000 --connectpw Hello --enablepw Enable")),
           display + "--port '70000': expected a port from 1 to 65535");
  contains(refusal(display_with("linuxcncrsh --port 50x7 --connectpw Hello --enablepw Enable")), "--port '50x7'");
}

TEST(LinuxcncIni, TheWorkspaceMustLieInsideEveryAxissSoftLimits) {
  const LinuxcncIni ini = accepted(fixture_text());
  STRCMP_EQUAL("", stencil::board::sherline_suzuki::linuxcnc_travel_outside_limits(ini, {50.0, 25.0, 25.0}).c_str());
  STRCMP_EQUAL("", stencil::board::sherline_suzuki::linuxcnc_travel_outside_limits(ini, {40.0, 20.0, 1.0}).c_str());
  contains(stencil::board::sherline_suzuki::linuxcnc_travel_outside_limits(ini, {50.0, 25.0, 26.0}),
           at_line_of("MAX_LIMIT", "AXIS_Z") +
               "[AXIS_Z] MAX_LIMIT 25 cuts into machine.travel_mm's z [0, 26] (machine mm, 0 at home): expected at least 26");
  const LinuxcncIni above_home = accepted(fixture_with("AXIS_Y", "MIN_LIMIT", "MIN_LIMIT = 0.5"));
  contains(stencil::board::sherline_suzuki::linuxcnc_travel_outside_limits(above_home, {50.0, 25.0, 25.0}),
           at_line_of("MIN_LIMIT", "AXIS_Y") + "[AXIS_Y] MIN_LIMIT 0.5 cuts into machine.travel_mm's y [0, 25]");
  const LinuxcncIni below_home = accepted(fixture_with("AXIS_Y", "MIN_LIMIT", "MIN_LIMIT = -3"));
  STRCMP_EQUAL("", stencil::board::sherline_suzuki::linuxcnc_travel_outside_limits(below_home, {50.0, 25.0, 25.0}).c_str());
}

TEST(LinuxcncIni, TheRigsPortAndPasswordsMustBeLinuxcncrshs) {
  using stencil::board::sherline_suzuki::linuxcnc_display_disagreement;
  const LinuxcncIni ini = accepted(fixture_text());
  const std::string display = at_line_of("DISPLAY =") + "[DISPLAY] DISPLAY: ";
  STRCMP_EQUAL("", linuxcnc_display_disagreement(ini, 5007, "SimMillHello", "SimMillEnable").c_str());
  contains(linuxcnc_display_disagreement(ini, 5008, "SimMillHello", "SimMillEnable"),
           display + "linuxcncrsh listens on port 5007, machine.linuxcnc.port is 5008: expected the same port");
  const std::string connect = linuxcnc_display_disagreement(ini, 5007, "SimMillHellO", "SimMillEnable");
  contains(connect, display + "--connectpw differs from machine.linuxcnc.connect_password");
  CHECK(connect.find("SimMill") == std::string::npos);  // no password in a message
  contains(linuxcnc_display_disagreement(ini, 5007, "SimMillHello", "Other"),
           display + "--enablepw differs from machine.linuxcnc.enable_password");
  // Without --port, linuxcncrsh listens on 5007.
  const LinuxcncIni no_port = accepted(display_with("linuxcncrsh --connectpw SimMillHello --enablepw SimMillEnable"));
  STRCMP_EQUAL("", linuxcnc_display_disagreement(no_port, 5007, "SimMillHello", "SimMillEnable").c_str());
}

TEST(LinuxcncIni, OnlyARegularFileIsRead) {
  LinuxcncIni ini;
  std::string error;
  CHECK_FALSE(stencil::board::sherline_suzuki::read_linuxcnc_ini("/nonexistent/mill.ini", ini, error));
  contains(error, "/nonexistent/mill.ini: cannot be opened (No such file or directory): expected LinuxCNC's INI file");
  CHECK_FALSE(stencil::board::sherline_suzuki::read_linuxcnc_ini("/tmp", ini, error));
  contains(error, "/tmp: not a regular file");
  // A FIFO with no writer: refused at once, not waited on.
  char folder[] = "/tmp/linuxcnc_ini_testXXXXXX";
  CHECK(mkdtemp(folder) != nullptr);
  const std::string fifo = std::string(folder) + "/mill.ini";
  CHECK_EQUAL(0, mkfifo(fifo.c_str(), 0600));
  CHECK_FALSE(stencil::board::sherline_suzuki::read_linuxcnc_ini(fifo, ini, error));
  contains(error, fifo + ": not a regular file");
  unlink(fifo.c_str());
  rmdir(folder);
  CHECK(ini.source.empty());
}
