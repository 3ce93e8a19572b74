#pragma once
// Small value types shared by every layer of the solver.
#include <Eigen/Core>
#include <stdexcept>
#include <string>

namespace grip {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;
using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
// A read-only view of a vector or of a contiguous part of one (no copy).
using VectorRef = Eigen::Ref<const Vector>;

// Rotation by +90 degrees: the obstacle tangent is rot90(outward normal).
inline Vec2 rot90(const Vec2& a) { return {-a.y(), a.x()}; }

// Shape of a plane mesh's elements, from their corners: the longest over the shortest side
// of each element (1 for a square or an equilateral triangle), and its interior angles in
// degrees (90 for a rectangle, 60 for an equilateral triangle). The result's
// effects block reports it, so that a badly shaped generated mesh does not go unnoticed.
struct ElementQuality {
  int elements = 0;
  double max_aspect_ratio = 0.0;
  double min_angle = 0.0;
  double max_angle = 0.0;
};

// Bad input: carries the JSON pointer of the offending scene value.
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string pointer, const std::string& detail)
      : std::runtime_error(pointer + ": " + detail), pointer_(std::move(pointer)), detail_(detail) {}
  const std::string& pointer() const { return pointer_; }
  const std::string& detail() const { return detail_; }

 private:
  std::string pointer_;
  std::string detail_;
};

}  // namespace grip
