// Tables made from facets by the real generator and loaded, kept together: the part's views point
// into the bytes, so the pair is neither copied nor moved.
#pragma once

#include <vector>

#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/sample_tables.hpp"

namespace stencil::test {

struct LoadedPart {
  tablegen::TableBytes bytes;
  tables::PartTables part{};
  bool loaded = false;  // the loader took the bytes (a test checks it)

  explicit LoadedPart(const std::vector<tablegen::Facet>& facets, unsigned threads = 2)
      : bytes(make_table(facets, default_job_options(threads))),
        loaded(tables::load_tables({bytes.data(), bytes.size()}, part).ok) {}
  LoadedPart(const LoadedPart&) = delete;
  LoadedPart& operator=(const LoadedPart&) = delete;
};

}  // namespace stencil::test
