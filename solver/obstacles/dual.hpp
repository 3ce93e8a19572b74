#pragma once
// A value with its derivatives with respect to a few variables (forward-mode automatic
// differentiation), for the stiffness of the mortar pairing (master_surface.cpp). No
// derivatives stored (an empty `d`) means a constant. P2 is a plane vector of such values.
#include <cmath>

#include "solver/model/types.hpp"

namespace grip {

struct Dual {
  double v = 0.0;
  Vector d;  // empty: zero
  Dual(double value = 0.0) : v(value) {}
  Dual(double value, Vector derivatives) : v(value), d(std::move(derivatives)) {}
};

inline double value(double a) { return a; }
inline double value(const Dual& a) { return a.v; }

namespace dual_detail {
// a_d * sa + b_d * sb, either may be empty.
inline Vector combine(const Vector& a, double sa, const Vector& b, double sb) {
  if (!a.size()) return b.size() ? Vector(sb * b) : Vector();
  if (!b.size()) return sa * a;
  return sa * a + sb * b;
}
}  // namespace dual_detail

inline Dual operator+(const Dual& a, const Dual& b) { return {a.v + b.v, dual_detail::combine(a.d, 1, b.d, 1)}; }
inline Dual operator-(const Dual& a, const Dual& b) { return {a.v - b.v, dual_detail::combine(a.d, 1, b.d, -1)}; }
inline Dual operator-(const Dual& a) { return {-a.v, dual_detail::combine(a.d, -1, Vector(), 0)}; }
inline Dual operator*(const Dual& a, const Dual& b) { return {a.v * b.v, dual_detail::combine(a.d, b.v, b.d, a.v)}; }
inline Dual operator/(const Dual& a, const Dual& b) {
  return {a.v / b.v, dual_detail::combine(a.d, 1 / b.v, b.d, -a.v / (b.v * b.v))};
}
inline Dual& operator+=(Dual& a, const Dual& b) { return a = a + b; }
inline Dual sqrt(const Dual& a) {
  const double r = std::sqrt(a.v);
  return {r, dual_detail::combine(a.d, 0.5 / r, Vector(), 0)};
}
inline Dual abs(const Dual& a) { return a.v < 0 ? -a : a; }

template <class S>
struct P2 {
  S x, y;
};
template <class S>
P2<S> operator+(const P2<S>& a, const P2<S>& b) {
  return {a.x + b.x, a.y + b.y};
}
template <class S>
P2<S> operator-(const P2<S>& a, const P2<S>& b) {
  return {a.x - b.x, a.y - b.y};
}
template <class S>
P2<S> operator*(const S& s, const P2<S>& a) {
  return {s * a.x, s * a.y};
}
template <class S>
S dot(const P2<S>& a, const P2<S>& b) {
  return a.x * b.x + a.y * b.y;
}
template <class S>
P2<S> rot90(const P2<S>& a) {
  return {-a.y, a.x};
}
template <class S>
S length(const P2<S>& a) {
  using std::sqrt;
  return sqrt(dot(a, a));
}
template <class S>
P2<S> unit(const P2<S>& a) {
  return (S(1.0) / length(a)) * a;
}
inline P2<double> p2(const Vec2& a) { return {a.x(), a.y()}; }
inline Vec2 vec2(const P2<double>& a) { return {a.x, a.y}; }

}  // namespace grip
