// The runtime reaching into a board and a program (never compiled: include-rules.sh's test input).
#include "board/sim/sim_job.hpp"
#include "firmware/programs/sim_options.hpp"
