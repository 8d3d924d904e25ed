// STL parsing: binary by size, ASCII by grammar, every number checked.
#include "toolchain/tablegen/stl_reader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

#include "toolchain/tablegen/file_io.hpp"
#include "toolchain/tablegen/input_error.hpp"

namespace stencil::tablegen {
namespace {

constexpr std::size_t kBinaryHeaderBytes = 84;
constexpr std::size_t kBinaryFacetBytes = 50;

std::string describe(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

float read_float(const std::byte* at) {
  float value;
  std::memcpy(&value, at, sizeof(value));
  return value;
}

StlMesh parse_binary(std::span<const std::byte> bytes, std::uint32_t count, const std::string& file_name) {
  StlMesh mesh{StlFormat::Binary, {}, 1};
  mesh.triangles.reserve(count);
  for (std::uint32_t facet = 0; facet < count; ++facet) {
    const std::size_t offset = kBinaryHeaderBytes + std::size_t{facet} * kBinaryFacetBytes;
    const std::byte* at = bytes.data() + offset;
    StlTriangle triangle;
    triangle.file_normal = {read_float(at), read_float(at + 4), read_float(at + 8)};
    for (int vertex = 0; vertex < 3; ++vertex) {
      for (int axis = 0; axis < 3; ++axis) {
        const float value = read_float(at + 12 + 12 * vertex + 4 * axis);
        if (!std::isfinite(value)) {
          throw InputError(file_name + ": facet " + std::to_string(facet) + " (byte " +
                           std::to_string(offset + 12 + 12 * static_cast<std::size_t>(vertex)) + "): vertex " +
                           std::to_string(vertex) + " has a non-finite coordinate (" + describe(value) +
                           "); expected a finite number");
        }
        triangle.vertices[vertex][axis] = value;
      }
    }
    if (!triangle.file_normal.allFinite()) {
      triangle.file_normal.setZero();  // the normal is recomputed anyway; a bad one is no reason to refuse
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

// A tokenizer over ASCII STL that knows its line number.
class AsciiTokens {
 public:
  AsciiTokens(std::string_view text, const std::string& file_name) : text_(text), file_name_(file_name) {}

  bool at_end() {
    skip_space();
    return position_ >= text_.size();
  }

  std::string_view next() {
    skip_space();
    const std::size_t start = position_;
    while (position_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[position_]))) {
      ++position_;
    }
    return text_.substr(start, position_ - start);
  }

  // The rest of the current line (a solid's name), consumed.
  void skip_line() {
    while (position_ < text_.size() && text_[position_] != '\n') {
      ++position_;
    }
  }

  void expect(std::string_view keyword) {
    const std::size_t line = line_after_space();
    const std::string_view word = next();
    if (word != keyword) {
      fail(line, "expected '" + std::string(keyword) + "', found " + quoted(word));
    }
  }

  double number(const char* what) {
    const std::size_t line = line_after_space();
    const std::string_view word = next();
    double value = 0.0;
    const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
    if (word.empty() || error != std::errc() || end != word.data() + word.size()) {
      fail(line, std::string("expected a number for ") + what + ", found " + quoted(word));
    }
    if (!std::isfinite(value)) {
      fail(line, std::string(what) + " is not finite (" + std::string(word) + "); expected a finite number");
    }
    return value;
  }

  std::size_t line_after_space() {
    skip_space();
    return line_;
  }

  [[noreturn]] void fail(std::size_t line, const std::string& message) const {
    throw InputError(file_name_ + ": line " + std::to_string(line) + ": " + message);
  }

 private:
  static std::string quoted(std::string_view word) {
    if (word.empty()) {
      return "the end of the file";
    }
    return "'" + std::string(word.substr(0, 40)) + "'";
  }

  void skip_space() {
    while (position_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[position_]))) {
      if (text_[position_] == '\n') {
        ++line_;
      }
      ++position_;
    }
  }

  std::string_view text_;
  const std::string& file_name_;
  std::size_t position_ = 0;
  std::size_t line_ = 1;
};

StlMesh parse_ascii(std::span<const std::byte> bytes, const std::string& file_name) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  AsciiTokens tokens(text, file_name);
  StlMesh mesh{StlFormat::Ascii, {}, 0};
  while (!tokens.at_end()) {
    tokens.expect("solid");
    tokens.skip_line();
    ++mesh.solid_count;
    for (;;) {
      const std::size_t line = tokens.line_after_space();
      const std::string_view word = tokens.next();
      if (word == "endsolid") {
        tokens.skip_line();
        break;
      }
      if (word != "facet") {
        tokens.fail(line, word.empty() ? "the file ends inside a solid; expected 'facet' or 'endsolid'"
                                       : "expected 'facet' or 'endsolid', found '" + std::string(word.substr(0, 40)) + "'");
      }
      StlTriangle triangle;
      tokens.expect("normal");
      for (int axis = 0; axis < 3; ++axis) {
        triangle.file_normal[axis] = tokens.number("a normal component");
      }
      tokens.expect("outer");
      tokens.expect("loop");
      for (int vertex = 0; vertex < 3; ++vertex) {
        tokens.expect("vertex");
        for (int axis = 0; axis < 3; ++axis) {
          triangle.vertices[vertex][axis] = tokens.number("a vertex coordinate");
        }
      }
      tokens.expect("endloop");
      tokens.expect("endfacet");
      mesh.triangles.push_back(triangle);
    }
  }
  if (mesh.solid_count == 0) {
    throw InputError(file_name + ": line 1: expected 'solid'; the file is empty");
  }
  if (mesh.triangles.empty()) {
    throw InputError(file_name + ": the ASCII STL has no facets; expected at least one");
  }
  return mesh;
}

// ASCII STL is printable text; a NUL or another control byte in the first kilobyte after the
// 80-byte header means a binary file whose header happens to begin with "solid".
bool looks_binary(std::span<const std::byte> bytes) {
  const std::size_t end = std::min<std::size_t>(bytes.size(), kBinaryHeaderBytes + 1024);
  for (std::size_t i = 80; i < end; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c < 0x20 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v') {
      return true;
    }
  }
  return false;
}

bool begins_with_solid(std::span<const std::byte> bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) {
    ++i;
  }
  return bytes.size() - i >= 5 && std::memcmp(bytes.data() + i, "solid", 5) == 0;
}

}  // namespace

StlMesh parse_stl(std::span<const std::byte> bytes, const std::string& file_name) {
  if (bytes.empty()) {
    throw InputError(file_name + ": the file is empty; expected an ASCII or binary STL");
  }
  if (bytes.size() >= kBinaryHeaderBytes) {
    std::uint32_t count;
    std::memcpy(&count, bytes.data() + 80, sizeof(count));
    if (bytes.size() == kBinaryHeaderBytes + std::size_t{count} * kBinaryFacetBytes) {
      if (count == 0) {
        throw InputError(file_name + ": binary STL with 0 triangles; expected at least one");
      }
      return parse_binary(bytes, count, file_name);
    }
    if (!begins_with_solid(bytes) || looks_binary(bytes)) {
      throw InputError(file_name + ": binary STL header says " + std::to_string(count) + " triangles, which needs " +
                       std::to_string(kBinaryHeaderBytes + std::size_t{count} * kBinaryFacetBytes) +
                       " bytes, but the file has " + std::to_string(bytes.size()) +
                       " (truncated, or not an STL file)");
    }
  } else if (!begins_with_solid(bytes)) {
    throw InputError(file_name + ": " + std::to_string(bytes.size()) +
                     " bytes is too short for a binary STL (84-byte header) and the file does not begin with 'solid'");
  }
  return parse_ascii(bytes, file_name);
}

std::vector<std::byte> read_file_bytes(const std::string& path) {
  static_cast<void>(regular_file_size(path));  // refuses directories and missing files by name
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError(path + ": cannot open (" + std::strerror(errno) + ")");
  }
  file.seekg(0, std::ios::end);
  const std::streamoff size = file.tellg();
  if (size < 0) {
    throw InputError(path + ": cannot read (not a regular file?)");
  }
  file.seekg(0, std::ios::beg);
  std::vector<std::byte> contents(static_cast<std::size_t>(size));
  if (size > 0 && !file.read(reinterpret_cast<char*>(contents.data()), size)) {
    throw InputError(path + ": cannot read (" + std::strerror(errno) + ")");
  }
  return contents;
}

}  // namespace stencil::tablegen
