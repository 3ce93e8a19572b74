#pragma once
// A body's tangent at q against central differences of its internal force: the check every
// element and law test makes (a wrong tangent costs Newton its quadratic convergence silently).
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <cmath>

#include "solver/model/body.hpp"

namespace grip::testing {

struct TangentCheck {
  Matrix K;     // the assembled tangent
  Matrix K_fd;  // central differences of the internal force, column by column
  Vector f;     // the internal force at q

  double error() const { return (K - K_fd).norm() / K.norm(); }  // relative, Frobenius
  double worst() const { return (K - K_fd).lpNorm<Eigen::Infinity>() / K.lpNorm<Eigen::Infinity>(); }  // largest entry
  double asymmetry() const { return (K - K.transpose()).norm() / K.norm(); }
};

inline Vector internal_force(const Body& body, const Vector& q) {
  Vector f = Vector::Zero(q.size());
  body.internal_force(q, f, nullptr);
  return f;
}

// `stress_base`: the state the geometric stiffness's stress is linearized about (Newton's).
inline Matrix assembled_tangent(const Body& body, const Vector& q, Vector& f, const Vector* stress_base = nullptr) {
  f = Vector::Zero(q.size());
  Triplets t;
  TripletSink sink(t);
  sink.stress_base = stress_base;
  body.internal_force(q, f, &sink);
  Eigen::SparseMatrix<double> K(q.size(), q.size());
  K.setFromTriplets(t.begin(), t.end());
  return Matrix(K);
}

inline Matrix assembled_tangent(const Body& body, const Vector& q) {
  Vector f;
  return assembled_tangent(body, q, f);
}

inline TangentCheck check_tangent(const Body& body, const Vector& q, double h) {
  TangentCheck c;
  c.K = assembled_tangent(body, q, c.f);
  c.K_fd.resize(q.size(), q.size());
  for (int j = 0; j < q.size(); ++j) {
    Vector qp = q, qm = q, fp = Vector::Zero(q.size()), fm = Vector::Zero(q.size());
    qp[j] += h;
    qm[j] -= h;
    body.internal_force(qp, fp, nullptr);
    body.internal_force(qm, fm, nullptr);
    c.K_fd.col(j) = (fp - fm) / (2 * h);
  }
  return c;
}

// The tangent of a body with history at a state beyond its committed one and off equilibrium
// (every dof of q moved by amplitude x sin(1 + 3.7 i)), where the J2 tests check it, and how many
// of its elements flow there (element field 5).
struct PlasticTangentCheck : TangentCheck {
  int flowing = 0;
  size_t elements = 0;
};

inline PlasticTangentCheck check_tangent_beyond(const Body& body, Vector q, double amplitude) {
  for (int i = 0; i < q.size(); ++i) q[i] += amplitude * std::sin(1.0 + 3.7 * i);
  PlasticTangentCheck c{check_tangent(body, q, 1e-7)};
  const auto rows = body.element_fields(q).rows;
  c.elements = rows.size();
  for (const auto& row : rows) c.flowing += row[5] > 0;
  return c;
}

}  // namespace grip::testing
