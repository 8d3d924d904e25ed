// The Flexible Collision Library as the benchmark's yardstick: the part's triangles as an OBBRSS
// model against the tool as an FCL shape. Kept apart from the core's headers (FCL is not built for
// EIGEN_NO_MALLOC), behind plain data.
#pragma once

#include <cstddef>
#include <memory>

namespace stencil::bench {

class FclReference {
 public:
  // triangles_mm: 9 floats per triangle (three vertices).
  FclReference(const float* triangles_mm, std::size_t triangle_count);
  ~FclReference();
  FclReference(const FclReference&) = delete;
  FclReference& operator=(const FclReference&) = delete;

  struct Contacts {
    std::size_t count;
    double max_depth_mm;
  };
  // The tool upright with its tip at tip_mm: a capsule (ball end mill: radius R, from tip + R to
  // the top of the flutes) or a cylinder (flat end mill), contacts and penetration depth requested.
  Contacts query(const double tip_mm[3], bool ball, double radius_mm, double flute_length_mm) const;

 private:
  struct Model;
  std::unique_ptr<Model> model_;
};

}  // namespace stencil::bench
