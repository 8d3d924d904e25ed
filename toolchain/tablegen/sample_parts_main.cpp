// stencil-sample-parts: writes the project's sample parts (and the benchmark surface) as STL files.
#include <cstdlib>
#include <iostream>
#include <string>

#include "firmware/services/report/build_version.hpp"
#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/sample_parts.hpp"

int main(int argc, char** argv) {
  using namespace stencil::tablegen;
  const std::string usage =
      "usage: stencil-sample-parts DIR            write hex_prism.stl, slotted_block.stl, thin_fin.stl into DIR\n"
      "       stencil-sample-parts --dome N FILE  write a finely tessellated dome of about N facets (binary; open at the bottom)\n"
      "       stencil-sample-parts --version      what built it\n";
  if (argc == 2 && std::string(argv[1]) == "--version") {
    std::cout << stencil::report::version_text("stencil-sample-parts") << "\n";
    return 0;
  }
  try {
    if (argc == 2 && std::string(argv[1]) != "--help" && std::string(argv[1]) != "-h") {
      const std::string directory = argv[1];
      // The embedded default job: circumradius 8 mm, height 6 mm, centred in the 50 x 25 mm floor.
      write_stl(directory + "/hex_prism.stl", hexagonal_prism(8.0, 6.0, 25.0, 12.5), false, "hex_prism");
      // Slot 2 mm wide (narrower than a 3 mm tool), 3 mm deep, through a 30 x 12 x 6 mm block.
      write_stl(directory + "/slotted_block.stl", slotted_block(30.0, 12.0, 6.0, 2.0, 3.0, 10.0, 6.5), false,
                "slotted_block");
      // A fin 20 mm long, 0.6 mm thick, 8 mm tall.
      write_stl(directory + "/thin_fin.stl", thin_fin(20.0, 0.6, 8.0, 15.0, 12.2), true, "thin_fin");
      return 0;
    }
    if (argc == 4 && std::string(argv[1]) == "--dome") {
      char* end = nullptr;
      const unsigned long long facets = std::strtoull(argv[2], &end, 10);
      if (end == argv[2] || *end != '\0' || facets < 8 || facets > 50'000'000ULL) {
        std::cerr << "stencil-sample-parts: --dome " << argv[2] << ": expected a facet count from 8 to 50000000\n";
        return 2;
      }
      write_stl(argv[3], tessellated_dome(static_cast<std::size_t>(facets), 5.0, 2.5, 40.0, 20.0, 2.0, 6.0), true,
                "dome");
      return 0;
    }
    std::cout << usage;
    return argc == 2 ? 0 : 2;
  } catch (const InputError& error) {
    std::cerr << "stencil-sample-parts: " << error.what() << "\n";
    return 2;
  }
}
