// A host backend that reaches up into a board (never compiled: include-rules.sh's test input).
#include "board/sherline_suzuki/rig_facts.hpp"
