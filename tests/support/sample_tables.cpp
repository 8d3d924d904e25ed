// Tables for tests, made by the real generator from the project's sample parts.
#include "tests/support/sample_tables.hpp"

#include "board/sherline_suzuki/rig_facts.hpp"
#include "toolchain/tablegen/tool_option.hpp"

namespace stencil::test {

tablegen::PlacementOptions rig_placement() {
  namespace rig = board::sherline_suzuki;
  tablegen::PlacementOptions placement;
  placement.workspace_mm = {rig::kRig.workspace_mm[0], rig::kRig.workspace_mm[1], rig::kRig.workspace_mm[2]};
  return placement;
}

tablegen::GeneratorOptions default_job_options(unsigned threads) {
  tablegen::GeneratorOptions options;
  options.placement = rig_placement();
  options.rig_largest_backlash_mm = board::sherline_suzuki::largest_backlash_mm();
  options.tool = tablegen::parse_tool("ball:d=3", "");
  options.threads = threads;
  return options;
}

tablegen::TableBytes make_table(const std::vector<tablegen::Facet>& facets, const tablegen::GeneratorOptions& options,
                                bool binary_stl) {
  const std::vector<std::byte> stl = tablegen::encode_stl(facets, binary_stl, "test_part");
  tablegen::GeneratorReport report;
  tablegen::TableContents contents =
      tablegen::generate_tables(stl, "test_part.stl", options, report, [](const char*, double) {});
  return tablegen::assemble_table(contents);
}

std::vector<tablegen::Facet> default_part() { return tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5); }

}  // namespace stencil::test
