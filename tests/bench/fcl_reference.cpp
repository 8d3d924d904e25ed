// FCL model and query for the benchmark.
#include "tests/bench/fcl_reference.hpp"

#include <algorithm>
#include <vector>

#include <fcl/fcl.h>

namespace stencil::bench {

struct FclReference::Model {
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> mesh;
  std::unique_ptr<fcl::CollisionObjectd> part;
};

FclReference::FclReference(const float* triangles_mm, std::size_t triangle_count) : model_(std::make_unique<Model>()) {
  std::vector<fcl::Vector3d> vertices;
  std::vector<fcl::Triangle> triangles;
  vertices.reserve(3 * triangle_count);
  triangles.reserve(triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    for (std::size_t v = 0; v < 3; ++v) {
      const float* p = triangles_mm + 9 * t + 3 * v;
      vertices.emplace_back(p[0], p[1], p[2]);
    }
    triangles.emplace_back(3 * t, 3 * t + 1, 3 * t + 2);
  }
  model_->mesh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  model_->mesh->beginModel();
  model_->mesh->addSubModel(vertices, triangles);
  model_->mesh->endModel();
  model_->part = std::make_unique<fcl::CollisionObjectd>(model_->mesh, fcl::Transform3d::Identity());
}

FclReference::~FclReference() = default;

FclReference::Contacts FclReference::query(const double tip_mm[3], bool ball, double radius_mm,
                                           double flute_length_mm) const {
  std::shared_ptr<fcl::CollisionGeometryd> shape;
  fcl::Transform3d pose = fcl::Transform3d::Identity();
  if (ball) {
    const double length = flute_length_mm - radius_mm;  // between the two hemisphere centres
    shape = std::make_shared<fcl::Capsuled>(radius_mm, length);
    pose.translation() = fcl::Vector3d(tip_mm[0], tip_mm[1], tip_mm[2] + radius_mm + 0.5 * length);
  } else {
    shape = std::make_shared<fcl::Cylinderd>(radius_mm, flute_length_mm);
    pose.translation() = fcl::Vector3d(tip_mm[0], tip_mm[1], tip_mm[2] + 0.5 * flute_length_mm);
  }
  const fcl::CollisionObjectd tool(shape, pose);
  fcl::CollisionRequestd request(1000, true);
  fcl::CollisionResultd result;
  fcl::collide(&tool, model_->part.get(), request, result);
  Contacts contacts{result.numContacts(), 0.0};
  for (std::size_t i = 0; i < result.numContacts(); ++i) {
    contacts.max_depth_mm = std::max(contacts.max_depth_mm, result.getContact(i).penetration_depth);
  }
  return contacts;
}

}  // namespace stencil::bench
