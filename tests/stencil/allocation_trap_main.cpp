// Runs the cycle's engine calls (query, legality, touched marking, remediation, haptic output) with
// every heap entry point wrapped at link time, and fails if any of them is reached while armed.
// A plain program rather than a CppUTest suite: CppUTest's own operator new would clash.
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>

#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/stencil/haptic_force.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/sample_tables.hpp"
#include "tests/support/heap_trap.hpp"

int main() {
  using namespace stencil;
  const tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(1));
  static tables::PartTables part{};
  if (!tables::load_tables({bytes.data(), bytes.size()}, part).ok) {
    std::fprintf(stderr, "allocation_trap: the sample table did not load\n");
    return 1;
  }
  static geometry::ToolBsp contact_tool{};
  static engine::TriangleSet touched;
  if (!engine::build_contact_tool(part.tool.spec, 0.01, contact_tool)) {
    return 1;
  }
  engine::VirtualTool tool(part, {25.0, 12.5, 20.0});
  const engine::ContactParameters parameters{};
  const engine::HapticLimits limits{};
  std::mt19937_64 random(61);
  std::uniform_real_distribution<double> x(5.0, 45.0), y(2.0, 23.0), z(-1.0, 10.0);
  unsigned long cycles = 0;
  stencil::test::arm_heap_trap("allocation_trap");
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d desired(x(random), y(random), z(random));
    const engine::ContactResult contact = engine::query_contacts(part, {desired, Eigen::Vector3d::UnitZ()}, parameters);
    const engine::RemediationResult result = tool.step(desired, contact, parameters);
    static_cast<void>(engine::mark_touched(part, contact_tool, tool.pose(), 0.01, touched));
    static_cast<void>(engine::haptic_output(desired, result.tip_mm, contact, limits));
    ++cycles;
  }
  stencil::test::disarm_heap_trap();
  const unsigned long trapped = stencil::test::trapped_heap_calls();
  std::printf("allocation_trap: %lu cycles, %lu heap calls inside them, %zu triangles touched\n", cycles, trapped,
              touched.count());
  std::printf("%lu passed, %lu failed\n", trapped == 0 ? 1ul : 0ul, trapped == 0 ? 0ul : 1ul);
  return trapped == 0 ? 0 : 1;
}
