// A program's options parsed as the program parses them (CLI11), from the words of a command line
// written in a test: the program's name is put first.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace stencil::test {

// Throws CLI11's ParseError (a refused value, an unknown option) as app.parse does.
inline void parse_words(CLI::App& app, const std::vector<std::string>& words) {
  std::vector<const char*> argv{"program"};
  for (const std::string& word : words) {
    argv.push_back(word.c_str());
  }
  app.parse(static_cast<int>(argv.size()), argv.data());
}

}  // namespace stencil::test
