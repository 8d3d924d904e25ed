// A core file that breaks each of the core's include rules once (never compiled: include-rules.sh's test input).
#include "firmware/core/control/controller.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "hal/cy545/cy545_link.hpp"
#include <nlohmann/json.hpp>
#include <vector>
