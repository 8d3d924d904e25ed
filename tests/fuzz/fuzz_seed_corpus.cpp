// Writes the fuzzers' seed corpus: small valid STL files and valid tables, made by the real generator.
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/sample_parts.hpp"
#include "toolchain/tablegen/table_generator.hpp"
#include "toolchain/tablegen/table_writer.hpp"
#include "toolchain/tablegen/tool_option.hpp"

namespace {

using stencil::tablegen::Facet;

// A right tetrahedron with its corner at (x, y, 0) and legs of `size_mm`: the smallest closed part.
std::vector<Facet> tetrahedron(double size_mm, double x_mm, double y_mm) {
  const Eigen::Vector3d o(x_mm, y_mm, 0.0);
  const Eigen::Vector3d a = o + Eigen::Vector3d(size_mm, 0.0, 0.0);
  const Eigen::Vector3d b = o + Eigen::Vector3d(0.0, size_mm, 0.0);
  const Eigen::Vector3d c = o + Eigen::Vector3d(0.0, 0.0, size_mm);
  return {{o, b, a}, {o, a, c}, {o, c, b}, {a, b, c}};
}

std::vector<std::byte> read_file(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  const std::vector<char> text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    bytes[i] = static_cast<std::byte>(text[i]);
  }
  return bytes;
}

// One table from an STL seed, coarsely sampled (spacing in mm, forced past the gouge limit) so that
// it stays a few kilobytes: small inputs keep the fuzzer fast.
void write_table(const std::filesystem::path& stl_path, const std::string& tool, double spacing_mm,
                 const std::filesystem::path& table_path) {
  stencil::tablegen::GeneratorOptions options;
  const auto& workspace = stencil::board::sherline_suzuki::kRig.workspace_mm;  // the rig's, as stencil-tablegen's
  options.placement.workspace_mm = {workspace[0], workspace[1], workspace[2]};
  options.tool = stencil::tablegen::parse_tool(tool, "");
  options.spacing_mm = spacing_mm;
  options.force = true;
  stencil::tablegen::GeneratorReport report;
  const std::vector<std::byte> stl = read_file(stl_path);
  stencil::tablegen::TableContents contents = stencil::tablegen::generate_tables(
      stl, stl_path.filename().string(), options, report, [](const char*, double) {});
  const stencil::tablegen::TableBytes table = stencil::tablegen::assemble_table(contents);
  std::ofstream file(table_path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(table.data()), static_cast<std::streamsize>(table.size()));
  if (!file.flush()) {
    throw stencil::tablegen::InputError(table_path.string() + ": cannot write");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_seed_corpus DIR   writes DIR/stl_reader/*.stl and DIR/table_loader/*.stbl\n";
    return 2;
  }
  namespace fs = std::filesystem;
  using namespace stencil::tablegen;
  const fs::path stl_dir = fs::path(argv[1]) / "stl_reader";
  const fs::path table_dir = fs::path(argv[1]) / "table_loader";
  try {
    fs::create_directories(stl_dir);
    fs::create_directories(table_dir);
    // Parts centred in the rig's 50 x 25 x 25 mm workspace, a few mm across.
    write_stl((stl_dir / "tetrahedron_ascii.stl").string(), tetrahedron(3.0, 24.0, 11.0), false, "tetrahedron");
    write_stl((stl_dir / "tetrahedron_binary.stl").string(), tetrahedron(3.0, 24.0, 11.0), true, "tetrahedron");
    write_stl((stl_dir / "hex_prism_ascii.stl").string(), hexagonal_prism(3.0, 2.0, 25.0, 12.5), false, "hex_prism");
    write_stl((stl_dir / "hex_prism_binary.stl").string(), hexagonal_prism(3.0, 2.0, 25.0, 12.5), true, "hex_prism");
    write_stl((stl_dir / "thin_fin_binary.stl").string(), thin_fin(6.0, 0.6, 3.0, 22.0, 12.2), true, "thin_fin");

    write_table(stl_dir / "tetrahedron_binary.stl", "flat:d=3", 1.5, table_dir / "tetrahedron_flat.stbl");
    write_table(stl_dir / "tetrahedron_ascii.stl", "ball:d=3", 1.0, table_dir / "tetrahedron_ball.stbl");
    write_table(stl_dir / "hex_prism_binary.stl", "bull:d=3,r=0.5", 2.0, table_dir / "hex_prism_bull.stbl");
    write_table(stl_dir / "thin_fin_binary.stl", "ball:d=2", 1.5, table_dir / "thin_fin_ball.stbl");
    // A deeper tree (a few hundred points, four levels) for the loader's tree walk.
    write_table(stl_dir / "hex_prism_ascii.stl", "ball:d=3", 0.6, table_dir / "hex_prism_ball_deep.stbl");
  } catch (const InputError& error) {
    std::cerr << "fuzz_seed_corpus: " << error.what() << "\n";
    return 1;
  } catch (const fs::filesystem_error& error) {
    std::cerr << "fuzz_seed_corpus: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
