// Valid tables made in memory with the real generator, for tests that need one to start from.
#pragma once

#include <string>
#include <vector>

#include "toolchain/tablegen/sample_parts.hpp"
#include "toolchain/tablegen/table_generator.hpp"
#include "toolchain/tablegen/table_writer.hpp"

namespace stencil::test {

// The rig's placement: its workspace (board/sherline_suzuki/rig_facts.hpp), the part as it is.
tablegen::PlacementOptions rig_placement();

// Generator options for the default job: a 3 mm ball end mill under the default holder, for the rig
// (its workspace, its backlash), as stencil-tablegen's defaults are.
tablegen::GeneratorOptions default_job_options(unsigned threads = 1);

// The table bytes for the facets with the given options (the STL passes through encode_stl).
tablegen::TableBytes make_table(const std::vector<tablegen::Facet>& facets, const tablegen::GeneratorOptions& options,
                                bool binary_stl = false);

// The embedded default job's part: a hexagonal prism, circumradius 8 mm, height 6 mm, centred.
std::vector<tablegen::Facet> default_part();

}  // namespace stencil::test
