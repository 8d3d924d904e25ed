// The rig's configuration file (board/sherline_suzuki/rig_config.hpp): the shipped example equals the
// compiled-in defaults, and a bad file is refused with its line, its key and what was expected.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "board/sherline_suzuki/rig_config.hpp"

#include <CppUTest/TestHarness.h>

namespace {

using stencil::board::sherline_suzuki::kRig;
using stencil::board::sherline_suzuki::RigConfig;

std::string example_text() {
  std::ifstream file(STENCIL_RIG_TOML);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The example with the line starting `key =` replaced by `line` ("" removes it).
std::string example_with(const std::string& key, const std::string& line) {
  std::istringstream in(example_text());
  std::string out, current;
  bool found = false;
  while (std::getline(in, current)) {
    if (!found && current.rfind(key + " =", 0) == 0) {
      found = true;
      if (!line.empty()) out += line + "\n";
      continue;
    }
    out += current + "\n";
  }
  CHECK_TEXT(found, key.c_str());
  return out;
}

// "rig.toml:N: " for the example's line starting `key =` (plus `after` lines).
std::string at_line_of(const std::string& key, int after = 0) {
  std::istringstream in(example_text());
  std::string current;
  for (int line = 1; std::getline(in, current); ++line) {
    if (current.rfind(key + " =", 0) == 0) return "rig.toml:" + std::to_string(line + after) + ": ";
  }
  FAIL(("no key " + key + " in the example").c_str());
  return "";
}

std::string refusal(const std::string& text) {
  RigConfig config;
  std::string error;
  CHECK_FALSE(stencil::board::sherline_suzuki::parse_rig_config(text, "rig.toml", config, error));
  CHECK(config.facts == kRig);  // nothing of a refused file is taken
  return error;
}

void contains(const std::string& text, const std::string& part) {
  CHECK_TEXT(text.find(part) != std::string::npos, (text + "\n  does not contain: " + part).c_str());
}

}  // namespace

TEST_GROUP(RigConfig){};

TEST(RigConfig, the_shipped_example_equals_the_compiled_in_defaults) {
  RigConfig config;
  config.facts.force_limit_n = 1.0;  // read over other values: every fact comes from the file
  config.facts.machine_sign = {1, 1, 1};
  std::string error;
  CHECK_TEXT(stencil::board::sherline_suzuki::read_rig_config(STENCIL_RIG_TOML, config, error), error.c_str());
  CHECK(config.facts == kRig);
  STRCMP_EQUAL("/dev/ttyS0", config.serial_port.c_str());
  STRCMP_EQUAL("pio:/dev/uio0", config.haptic_link.c_str());
  CHECK(config.work_offset_mm == stencil::board::sherline_suzuki::kHomeWorldMm);
  CHECK_EQUAL(80, config.cycle_priority);
  CHECK_EQUAL(70, config.machine_priority);
  CHECK_EQUAL(-1, config.cycle_cpu);
  CHECK_EQUAL(50U, config.keep_jobs);
  CHECK_EQUAL(0U, config.keep_mb);
}

TEST(RigConfig, the_retention_of_job_folders_is_taken_and_its_range_held) {
  RigConfig config;
  std::string error;
  std::string text = example_with("keep_jobs", "keep_jobs = 3");
  text.replace(text.find("keep_mb = 0 "), 12, "keep_mb = 2000 ");
  CHECK_TEXT(stencil::board::sherline_suzuki::parse_rig_config(text, "rig.toml", config, error), error.c_str());
  CHECK_EQUAL(3U, config.keep_jobs);
  CHECK_EQUAL(2000U, config.keep_mb);
  contains(refusal(example_with("keep_jobs", "keep_jobs = -1")), at_line_of("keep_jobs") + "job.keep_jobs");
}

TEST(RigConfig, a_changed_fact_is_taken) {
  RigConfig config;
  std::string error;
  CHECK_TEXT(stencil::board::sherline_suzuki::parse_rig_config(
                 example_with("axis_sign", "axis_sign = [1, -1, -1]"), "rig.toml", config, error),
             error.c_str());
  CHECK_EQUAL(1, config.facts.machine_sign[0]);
  CHECK_EQUAL(-1, config.facts.machine_sign[1]);
  CHECK_TRUE(config.facts != kRig);
}

TEST(RigConfig, an_unknown_key_is_refused_with_its_line) {
  const std::string error = refusal(example_with("serial_baud", "serial_baud = 57600\nsteps_per_inch = 16000"));
  contains(error, at_line_of("serial_baud", 1) + "unknown key 'machine.steps_per_inch'");
}

TEST(RigConfig, a_missing_required_key_is_refused) {
  contains(refusal(example_with("serial_port", "")), "missing the key 'machine.serial_port'");
  // The line of its section's header.
  contains(refusal(example_with("serial_port", "")), at_line_of("controller", -1) + "[machine]: missing the key");
}

TEST(RigConfig, a_wrong_type_is_refused_with_what_was_expected) {
  contains(refusal(example_with("steps_per_mm", "steps_per_mm = \"640\"")),
           at_line_of("steps_per_mm") + "machine.steps_per_mm: expected an array of 3 numbers from 1 to 100000");
  contains(refusal(example_with("overrun_limit", "overrun_limit = 3.5")),
           "controller.overrun_limit: expected an integer from 1 to 100");
  contains(refusal(example_with("start_held", "start_held = 1")), "controller.start_held: expected true or false");
}

TEST(RigConfig, a_value_out_of_range_names_the_range) {
  contains(refusal(example_with("update_hz", "update_hz = 0.5")),
           "machine.update_hz: 0.5 is out of range: expected a number from 1 to 200");
  contains(refusal(example_with("steps_per_mm", "steps_per_mm = [640.0, nan, 640.0]")),
           "machine.steps_per_mm: nan is out of range");
}

TEST(RigConfig, the_force_ceiling_cannot_be_raised) {
  contains(refusal(example_with("force_limit_n", "force_limit_n = 50.0")),
           "haptic.force_limit_n: 50 is out of range: expected a number from 0.5 to 5 (N, at most the board's 5 N");
}

TEST(RigConfig, the_speed_is_held_to_what_the_steps_allow) {
  contains(refusal(example_with("max_speed_mm_per_s", "max_speed_mm_per_s = 2.0")),
           "machine.max_speed_mm_per_s 2 needs 1280 steps/s at 640 steps/mm, above machine.step_rate_steps_per_s 1000");
  contains(refusal(example_with("virtual_tool_speed_mm_per_s", "virtual_tool_speed_mm_per_s = 1.5")),
           "controller.virtual_tool_speed_mm_per_s 1.5 is above machine.max_speed_mm_per_s 1.4");
}

TEST(RigConfig, facts_that_contradict_each_other_are_refused) {
  contains(refusal(example_with("steps_per_mm", "steps_per_mm = [640.0, 640.0, 646.4]")),
           "expected the same steps per mm on every axis");
  contains(refusal(example_with("axis_sign", "axis_sign = [-1, 0, -1]")), "expected 1 or -1 per axis");
  contains(refusal(example_with("backlash_mm", "backlash_mm = [0.125, 0.051, 0.125]")),
           "machine.backlash_mm 0.051 on y is 32.64 steps: expected a whole number of steps");
  contains(refusal(example_with("order", "order = \"xyz\"")), "Z first");
  contains(refusal(example_with("standoff_mm", "standoff_mm = 0.005")), "controller.standoff_mm 0.005 is under the");
  contains(refusal(example_with("machine_priority", "machine_priority = 85")),
           "threads.machine_priority 85: expected below threads.cycle_priority 80");
  contains(refusal(example_with("link", "link = \"/dev/uio0\"")), "haptic.link: expected pio:/dev/uioN or can:IFACE");
}

TEST(RigConfig, a_syntax_error_names_its_line) {
  contains(refusal(example_with("serial_baud", "serial_baud = = 57600")), at_line_of("serial_baud"));
}

TEST(RigConfig, a_file_others_can_write_is_refused) {
  char path[] = "/tmp/rig_config_testXXXXXX";
  const int fd = mkstemp(path);
  CHECK(fd >= 0);
  const std::string text = example_text();
  CHECK_EQUAL(static_cast<ssize_t>(text.size()), write(fd, text.data(), text.size()));
  close(fd);
  RigConfig config;
  std::string error;
  CHECK_EQUAL(0, chmod(path, 0644));
  CHECK_TEXT(stencil::board::sherline_suzuki::read_rig_config(path, config, error), error.c_str());
  CHECK_EQUAL(0, chmod(path, 0666));
  CHECK_FALSE(stencil::board::sherline_suzuki::read_rig_config(path, config, error));
  contains(error, std::string(path) + ": writable by other users (mode 0666)");
  CHECK_EQUAL(0, chmod(path, 0620));
  CHECK_FALSE(stencil::board::sherline_suzuki::read_rig_config(path, config, error));
  contains(error, "(mode 0620)");
  unlink(path);
  CHECK_FALSE(stencil::board::sherline_suzuki::read_rig_config(path, config, error));
  contains(error, "no such configuration file");
}

// toml++ 3.3.0 reaches __builtin_unreachable() on U+02B6 (fuzz_rig_config found it): the file is
// refused as not ASCII before the parser sees it.
TEST(RigConfig, a_byte_that_is_not_ascii_is_refused_before_the_parser_sees_it) {
  contains(refusal("[machine]\nr = [\xca\xb6]\n"), "rig.toml:2: byte 0xCA at offset 15: expected ASCII text");
}

TEST(RigConfig, what_the_hardware_cannot_do_is_refused) {
  contains(refusal(example_with("serial_baud", "serial_baud = 14400")),
           "machine.serial_baud: expected 9600, 19200, 38400 or 57600");
  contains(refusal(example_with("heartbeat_period_ms", "heartbeat_period_ms = 1800.0")),
           "machine.watchdog_relay_timeout_ms 1000: expected at least twice the heartbeat's longest gap");
  contains(refusal(example_with("step_rate_steps_per_s", "step_rate_steps_per_s = 1000.5")),
           "machine.step_rate_steps_per_s: expected an integer");
}

TEST(RigConfig, a_number_past_what_a_double_holds_exactly_is_a_wrong_type_not_zero) {
  contains(refusal(example_with("home_overtravel_mm", "home_overtravel_mm = 9007199254740993")),
           "machine.home_overtravel_mm: expected a number");
}

TEST(RigConfig, a_section_written_as_a_value_is_named) {
  contains(refusal("[machine]\nhoming = 5\n"), "rig.toml:2: machine.homing: expected the table [machine.homing], not a value");
}

TEST(RigConfig, a_symbolic_link_a_folder_others_can_write_and_a_missing_output_folder_are_refused) {
  char folder[] = "/tmp/rig_config_dirXXXXXX";
  CHECK(mkdtemp(folder) != nullptr);
  const std::string file = std::string(folder) + "/rig.toml", link = std::string(folder) + "/link.toml";
  {
    std::ofstream out(file);
    out << example_with("output_folder", "output_folder = \"" + std::string(folder) + "\"");
  }
  CHECK_EQUAL(0, chmod(file.c_str(), 0600));
  RigConfig config;
  std::string error;
  CHECK_TEXT(stencil::board::sherline_suzuki::read_rig_config(file, config, error), error.c_str());
  STRCMP_EQUAL(folder, config.output_folder.c_str());
  CHECK(config.file_crc32 != 0);
  CHECK_EQUAL(0, symlink(file.c_str(), link.c_str()));
  CHECK_FALSE(stencil::board::sherline_suzuki::read_rig_config(link, config, error));
  contains(error, "link.toml: a symbolic link: expected the file itself");
  CHECK_EQUAL(0, chmod(folder, 0777));
  CHECK_FALSE(stencil::board::sherline_suzuki::read_rig_config(file, config, error));
  contains(error, "its folder " + std::string(folder) + " is writable by other users");
  CHECK_EQUAL(0, chmod(folder, 0700));
  {
    std::ofstream out(file);
    out << example_with("output_folder", "output_folder = \"/nonexistent/jobs\"");
  }
  CHECK_FALSE(stencil::board::sherline_suzuki::read_rig_config(file, config, error));
  contains(error, "job.output_folder /nonexistent/jobs: expected a folder this program may write in");
  unlink(link.c_str());
  unlink(file.c_str());
  rmdir(folder);
}

// ---- The CY545's file, unchanged: the controller key is optional and says the CY545.

TEST(RigConfig, the_controller_is_the_cy545_when_the_file_says_so_or_says_nothing) {
  RigConfig config;
  config.facts.controller = stencil::board::sherline_suzuki::MachineController::Linuxcnc;  // read over: the file's
  config.facts.linuxcnc.max_velocity_mm_per_s = {5.0, 5.0, 5.0};
  std::string error;
  CHECK_TEXT(stencil::board::sherline_suzuki::parse_rig_config(example_with("controller", ""), "rig.toml", config, error),
             error.c_str());
  CHECK(config.facts == kRig);
  CHECK(config.linuxcnc_ini.source.empty());
  contains(refusal(example_with("controller", "controller = \"grbl\"")),
           at_line_of("controller") + "machine.controller: expected \"cy545\" or \"linuxcnc\"");
}

TEST(RigConfig, a_linuxcnc_section_in_a_cy545_file_is_refused_at_its_header) {
  const std::string text = example_text() + "\n[machine.linuxcnc]\nconnect_password = \"SimMillHello\"\n";
  int header = 1;
  for (const char c : example_text()) header += c == '\n' ? 1 : 0;
  contains(refusal(text), "rig.toml:" + std::to_string(header + 1) + ": [machine.linuxcnc]: machine.controller is \"cy545\": " +
                              "expected no [machine.linuxcnc] section");
  contains(refusal(example_with("controller", "") + "\n[machine.linuxcnc]\n"),
           "[machine.linuxcnc]: machine.controller is \"cy545\" (absent: the CY545): expected no [machine.linuxcnc] section");
}

// ---- A LinuxCNC mill (rig-linuxcnc.toml): its INI read with the file.

namespace {

std::string linuxcnc_example_text() {
  std::ifstream file(STENCIL_RIG_LINUXCNC_TOML);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

std::string fixture_ini_text() {
  std::ifstream file(STENCIL_LINUXCNC_TEST_INI);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// `text` with the first line starting `key =` replaced by `line` ("" removes it), and its number.
std::string with_line(const std::string& text, const std::string& key, const std::string& line, int* number = nullptr) {
  std::istringstream in(text);
  std::string out, current;
  bool found = false;
  for (int n = 1; std::getline(in, current); ++n) {
    if (!found && current.rfind(key + " =", 0) == 0) {
      found = true;
      if (number != nullptr) *number = n;
      if (!line.empty()) out += line + "\n";
      continue;
    }
    out += current + "\n";
  }
  CHECK_TEXT(found, key.c_str());
  return out;
}

}  // namespace

// A folder holding the test INI as mill.ini, and the example pointing at it: ini = "mill.ini",
// relative to the configuration's folder.
TEST_GROUP(LinuxcncRigConfig) {
  char folder[64] = "/tmp/rig_config_linuxcncXXXXXX";
  std::string toml, ini;

  void setup() override {
    CHECK(mkdtemp(folder) != nullptr);
    toml = std::string(folder) + "/rig.toml";
    ini = std::string(folder) + "/mill.ini";
    write_ini(fixture_ini_text());
  }
  void teardown() override {
    unlink(ini.c_str());
    unlink(toml.c_str());
    rmdir(folder);
  }
  void write_ini(const std::string& text) const {
    std::ofstream out(ini);
    out << text;
  }
  static std::string example(const std::string& key = "", const std::string& line = "") {
    const std::string text = with_line(linuxcnc_example_text(), "ini", "ini = \"mill.ini\"");
    return key.empty() ? text : with_line(text, key, line);
  }
  // "FOLDER/rig.toml:N: " for the example's line starting `key =`.
  std::string at_key(const std::string& key) const {
    int number = 0;
    static_cast<void>(with_line(example(), key, "", &number));
    return toml + ":" + std::to_string(number) + ": ";
  }
  std::string at_ini(const std::string& text, const std::string& section = "") const {
    std::istringstream in(fixture_ini_text());
    std::string current, in_section;
    for (int line = 1; std::getline(in, current); ++line) {
      if (!current.empty() && current[0] == '[') in_section = current;
      if ((section.empty() || in_section == "[" + section + "]") && current.rfind(text, 0) == 0) {
        return ini + ":" + std::to_string(line) + ": ";
      }
    }
    FAIL(("no line " + text + " in the test INI").c_str());
    return "";
  }
  bool parse(const std::string& text, RigConfig& config, std::string& error) const {
    return stencil::board::sherline_suzuki::parse_rig_config(text, toml, config, error);
  }
  std::string refused(const std::string& text) const {
    RigConfig config;
    std::string error;
    CHECK_FALSE(parse(text, config, error));
    CHECK(config.facts == kRig);
    return error;
  }
};

TEST(LinuxcncRigConfig, a_good_file_loads_with_the_inis_numbers) {
  RigConfig config;
  std::string error;
  CHECK_TEXT(parse(example(), config, error), error.c_str());
  const stencil::board::sherline_suzuki::RigFacts& f = config.facts;
  CHECK(f.controller == stencil::board::sherline_suzuki::MachineController::Linuxcnc);
  STRCMP_EQUAL("127.0.0.1", f.linuxcnc.address.data());
  CHECK_EQUAL(5007, f.linuxcnc.port);
  STRCMP_EQUAL("SimMillHello", f.linuxcnc.connect_password.data());
  STRCMP_EQUAL("SimMillEnable", f.linuxcnc.enable_password.data());
  for (std::size_t axis = 0; axis < 3; ++axis) {
    DOUBLES_EQUAL(5.0, f.linuxcnc.max_velocity_mm_per_s[axis], 0.0);
    DOUBLES_EQUAL(200.0, f.linuxcnc.max_acceleration_mm_per_s2[axis], 0.0);
  }
  DOUBLES_EQUAL(0.0, f.linuxcnc.max_linear_velocity_mm_per_s, 0.0);
  DOUBLES_EQUAL(8.0, f.machine_update_hz, 0.0);
  CHECK(f.workspace_mm == kRig.workspace_mm);
  STRCMP_EQUAL(ini.c_str(), config.linuxcnc_ini.source.c_str());  // from the configuration's folder
  DOUBLES_EQUAL(4.0, stencil::board::sherline_suzuki::planner_limits(f).speed.max_axis_speed_mm_per_s, 1e-12);
  // The link takes what the file gave (it checks again as it starts).
  STRCMP_EQUAL("", std::string(stencil::hal::linuxcnc::check_linuxcnc_config(
                                   stencil::board::sherline_suzuki::linuxcnc_config(f)))
                       .c_str());
  // The CY545's facts it leaves out stay the compiled-in ones; nothing on LinuxCNC's path reads them.
  STRCMP_EQUAL("", config.serial_port.c_str());
  DOUBLES_EQUAL(kRig.step_rate_steps_per_s, f.step_rate_steps_per_s, 0.0);
}

TEST(LinuxcncRigConfig, the_address_and_port_are_taken_and_an_absolute_ini_is_used_as_given) {
  std::string text = with_line(example(), "address", "address = \"192.168.1.20\"");
  text = with_line(text, "port", "port = 5008");
  text = with_line(text, "ini", "ini = \"" + ini + "\"");
  write_ini(with_line(fixture_ini_text(), "DISPLAY", "DISPLAY = linuxcncrsh -p 5008 -w SimMillHello -e SimMillEnable"));
  RigConfig config;
  std::string error;
  CHECK_TEXT(stencil::board::sherline_suzuki::parse_rig_config(text, "elsewhere/rig.toml", config, error), error.c_str());
  STRCMP_EQUAL("192.168.1.20", config.facts.linuxcnc.address.data());
  CHECK_EQUAL(5008, config.facts.linuxcnc.port);
  STRCMP_EQUAL(ini.c_str(), config.linuxcnc_ini.source.c_str());
  contains(refused(with_line(example(), "address", "address = \"mill.local\"")),
           at_key("address") + "machine.linuxcnc.address: expected IPv4 digits");
}

TEST(LinuxcncRigConfig, the_file_and_its_ini_make_the_crc_a_job_records) {
  {
    std::ofstream out(toml);
    out << example();
  }
  CHECK_EQUAL(0, chmod(toml.c_str(), 0600));
  RigConfig config;
  std::string error;
  CHECK_TEXT(stencil::board::sherline_suzuki::read_rig_config(toml, config, error), error.c_str());
  const std::uint32_t both = config.file_crc32;
  write_ini(with_line(fixture_ini_text(), "CYCLE_TIME", "CYCLE_TIME = 0.050"));
  CHECK_TEXT(stencil::board::sherline_suzuki::read_rig_config(toml, config, error), error.c_str());
  CHECK(config.file_crc32 != both);  // the INI changed, the file did not
}

TEST(LinuxcncRigConfig, linuxcncrshs_default_passwords_are_refused) {
  contains(refused(example("connect_password", "connect_password = \"EMC\"")),
           at_key("connect_password") + "machine.linuxcnc.connect_password: expected a password of the rig's own: EMC and "
                                        "EMCTOO are linuxcncrsh's defaults");
  contains(refused(example("enable_password", "enable_password = \"EMCTOO\"")),
           at_key("enable_password") + "machine.linuxcnc.enable_password: expected a password of the rig's own");
  contains(refused(example("enable_password", "enable_password = \"Sim Mill\"")),
           "machine.linuxcnc.enable_password: expected one word of 1 to 15 printable ASCII characters, no spaces");
  contains(refused(example("enable_password", "enable_password = \"SixteenCharsLong\"")),
           "machine.linuxcnc.enable_password: expected one word of 1 to 15");
  contains(refused(example("connect_password", "")),
           "[machine.linuxcnc]: missing the key 'machine.linuxcnc.connect_password'");
}

TEST(LinuxcncRigConfig, a_missing_ini_is_refused_naming_the_key_or_the_file) {
  contains(refused(example("ini", "")),
           "[machine.linuxcnc]: missing the key 'machine.linuxcnc.ini': expected a quoted string (LinuxCNC's INI file");
  contains(refused(example("ini", "ini = \"nope.ini\"")),
           at_key("ini") + "machine.linuxcnc.ini: " + std::string(folder) +
               "/nope.ini: cannot be opened (No such file or directory): expected LinuxCNC's INI file");
  // No [machine.linuxcnc] at all.
  std::string text = example();
  const std::size_t section = text.find("\n[machine.linuxcnc]") + 1;
  text.erase(section, text.find("\n[haptic]") + 1 - section);
  contains(refused(text), toml + ": no [machine.linuxcnc] section: missing the key 'machine.linuxcnc.connect_password'");
}

TEST(LinuxcncRigConfig, an_ini_without_z_max_velocity_is_refused_naming_the_ini_and_its_section) {
  std::string text = fixture_ini_text();
  const std::size_t z = text.find("[AXIS_Z]");
  text.erase(text.find("MAX_VELOCITY = 5\n", z), 17);
  write_ini(text);
  contains(refused(example()), at_key("ini") + "machine.linuxcnc.ini: " + at_ini("[AXIS_Z]") +
                                   "[AXIS_Z]: missing MAX_VELOCITY: expected mm/s, the axis's top speed");
}

TEST(LinuxcncRigConfig, an_ini_in_inches_is_refused) {
  write_ini(with_line(fixture_ini_text(), "LINEAR_UNITS", "LINEAR_UNITS = inch"));
  contains(refused(example()), at_ini("LINEAR_UNITS") + "[TRAJ] LINEAR_UNITS: 'inch': expected mm or metric");
}

TEST(LinuxcncRigConfig, a_travel_beyond_an_axiss_max_limit_is_refused_naming_both_files) {
  contains(refused(example("travel_mm", "travel_mm = [60.0, 25.0, 25.0]")),
           at_key("travel_mm") + "machine.travel_mm: " + at_ini("MAX_LIMIT", "AXIS_X") +
               "[AXIS_X] MAX_LIMIT 50 cuts into machine.travel_mm's x [0, 60] (machine mm, 0 at home): expected at least 60");
}

TEST(LinuxcncRigConfig, more_than_nine_updates_a_second_are_refused) {
  contains(refused(example("update_hz", "update_hz = 30.0")),
           at_key("update_hz") + "machine.update_hz 30: expected at most 9 with machine.controller = \"linuxcnc\": each update "
                                 "is one G1 over linuxcncrsh, which answers a set after about 100 ms");
  RigConfig config;
  std::string error;
  CHECK_TEXT(parse(example("update_hz", "update_hz = 9.0"), config, error), error.c_str());
}

TEST(LinuxcncRigConfig, passwords_or_a_port_other_than_the_displays_are_refused) {
  const std::string display = at_key("ini") + "machine.linuxcnc.ini: " + at_ini("DISPLAY =") + "[DISPLAY] DISPLAY: ";
  contains(refused(example("connect_password", "connect_password = \"OtherHello\"")),
           display + "--connectpw differs from machine.linuxcnc.connect_password: expected the same password");
  contains(refused(example("enable_password", "enable_password = \"OtherEnable\"")),
           display + "--enablepw differs from machine.linuxcnc.enable_password");
  contains(refused(example("port", "port = 5010")), display + "linuxcncrsh listens on port 5007, machine.linuxcnc.port is 5010");
  write_ini(with_line(fixture_ini_text(), "DISPLAY", "DISPLAY = linuxcncrsh --port 5007"));
  contains(refused(example()), "[DISPLAY] DISPLAY: no --connectpw: linuxcncrsh would take its default password EMC");
}

TEST(LinuxcncRigConfig, the_cy545s_keys_and_sections_are_refused_in_a_linuxcnc_file) {
  contains(refused(example("controller", "controller = \"linuxcnc\"\nserial_port = \"/dev/ttyS0\"")),
           "machine.serial_port: machine.controller is \"linuxcnc\": expected no machine.serial_port (the CY545's");
  contains(refused(example("controller", "controller = \"linuxcnc\"\nbacklash_mm = [0.125, 0.05, 0.125]")),
           "machine.backlash_mm: machine.controller is \"linuxcnc\": expected no machine.backlash_mm");
  contains(refused(example() + "\n[machine.board]\nspindle_output = 4\n"),
           "[machine.board]: machine.controller is \"linuxcnc\": expected no [machine.board] section");
}

TEST(LinuxcncRigConfig, a_virtual_tool_faster_than_the_mill_makes_good_is_refused) {
  std::string text = fixture_ini_text();
  for (std::size_t at = text.find("MAX_VELOCITY = 5\n"); at != std::string::npos; at = text.find("MAX_VELOCITY = 5\n", at)) {
    text.replace(at, 17, "MAX_VELOCITY = 0.5\n");
  }
  write_ini(text);
  // 0.5 * (0.125 - 0.5 / 200) = 0.06125 mm an update: 0.49 mm/s.
  contains(refused(example()), at_key("virtual_tool_speed_mm_per_s") + "controller.virtual_tool_speed_mm_per_s 1 is above the "
                                   "0.49 mm/s the LinuxCNC mill makes good (0.06125 mm from rest to rest in one update");
}

TEST(LinuxcncRigConfig, the_shipped_example_names_the_simulated_mills_template_which_is_refused_until_filled_in) {
  RigConfig config;
  std::string error;
  CHECK_FALSE(stencil::board::sherline_suzuki::parse_rig_config(linuxcnc_example_text(), STENCIL_RIG_LINUXCNC_TOML, config,
                                                                error));
  contains(error, "board/sherline_suzuki/../../sim/linuxcnc_mill/mill.ini:");
  contains(error, "[DISPLAY] DISPLAY: '@PORT@' is a template's placeholder");
  // Filled in as linuxcnc-sim.sh does, it loads: the simulated mill's 5 mm/s and 50 mm/s^2, a
  // triangle of 0.1953125 mm in 1/8 s.
  std::ifstream file(STENCIL_SIM_MILL_INI);
  std::stringstream read;
  read << file.rdbuf();
  std::string filled = read.str();
  filled.replace(filled.find("@PORT@"), 6, "5007");
  filled.replace(filled.find("@NAME@"), 6, "SIMMILL");
  filled.replace(filled.find("@CONNECTPW@"), 11, "SimMillHello");
  filled.replace(filled.find("@ENABLEPW@"), 10, "SimMillEnable");
  filled.replace(filled.find("@SESSIONS@"), 10, "-1");
  write_ini(filled);
  CHECK_TEXT(parse(example(), config, error), error.c_str());
  DOUBLES_EQUAL(50.0, config.facts.linuxcnc.max_acceleration_mm_per_s2[2], 0.0);
  DOUBLES_EQUAL(5.0, config.facts.linuxcnc.max_linear_velocity_mm_per_s, 0.0);
  DOUBLES_EQUAL(0.1953125 / 0.125, stencil::board::sherline_suzuki::planner_limits(config.facts).speed.max_axis_speed_mm_per_s,
                1e-12);
}

TEST(LinuxcncRigConfig, the_keys_say_which_controller_they_belong_to) {
  const std::string keys = stencil::board::sherline_suzuki::describe_rig_config_keys();
  contains(keys, "machine.controller (optional): a quoted string");
  contains(keys, "machine.serial_port (cy545 only): a quoted string");
  contains(keys, "machine.linuxcnc.ini (linuxcnc only): a quoted string");
  contains(keys, "machine.linuxcnc.port (optional, linuxcnc only): an integer from 1 to 65535");
  contains(keys, "threads.cycle_cpu (optional): an integer");
  contains(keys, "\nmachine.steps_per_mm: an array of 3 numbers");
}
