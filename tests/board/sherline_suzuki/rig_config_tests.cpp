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
  contains(refusal(example_with("serial_port", "")), at_line_of("serial_port", -1) + "[machine]: missing the key");
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
