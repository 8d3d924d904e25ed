// Exact distances between a segment and a triangle, written plainly (Ericson, Real-Time Collision
// Detection, 5.1.5 and 5.1.9): what says whether a ball end mill gouges the true surface, for the
// simulated mill's gouge figure and the engine tests' oracle alike (neither is the engine).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>

namespace stencil::sim {

inline Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                           const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

inline double segment_segment_distance(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                                       const Eigen::Vector3d& q2) {
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 1e-300 && e <= 1e-300) return (p1 - p2).norm();
  if (a <= 1e-300) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 1e-300) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denominator = a * e - b * b;
      s = denominator != 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p1 + d1 * s) - (p2 + d2 * t)).norm();
}

// Exact distance between segment [p, q] and triangle (a, b, c); 0 when they cross.
inline double segment_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  const double dp = normal.dot(p - a), dq = normal.dot(q - a);
  if ((dp <= 0 && dq >= 0) || (dp >= 0 && dq <= 0)) {
    if (dp != dq) {
      const Eigen::Vector3d x = p + (dp / (dp - dq)) * (q - p);
      if ((closest_on_triangle(x, a, b, c) - x).norm() < 1e-12) return 0.0;
    }
  }
  double best = std::min((closest_on_triangle(p, a, b, c) - p).norm(), (closest_on_triangle(q, a, b, c) - q).norm());
  const std::array<Eigen::Vector3d, 3> corners{a, b, c};
  for (std::size_t i = 0; i < 3; ++i) {
    best = std::min(best, segment_segment_distance(p, q, corners[i], corners[(i + 1) % 3]));
  }
  return best;
}

}  // namespace stencil::sim
