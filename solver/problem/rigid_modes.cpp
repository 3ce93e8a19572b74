#include "solver/problem/rigid_modes.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <cmath>

namespace grip {
namespace {

// Every dof a translation, x and y of one node one after the other (the continuum).
bool translation_pairs(const Body& body) {
  const Vector tx = body.rigid_translation(Vec2::UnitX()), ty = body.rigid_translation(Vec2::UnitY());
  if (tx.size() % 2 || body.rigid_rotation().size() != tx.size()) return false;
  for (int d = 0; d < tx.size(); d += 2)
    if (tx[d] != 1.0 || tx[d + 1] != 0.0 || ty[d] != 0.0 || ty[d + 1] != 1.0) return false;
  return true;
}

// The rotation by one radian about the origin at state q of a model with finite kinematics whose
// strain a finite rotation of its own leaves unchanged, so that its internal forces at q do no
// work along it (empty for a model without one):
// - the continuum (every dof a translation): the rotation about its current positions X + u,
//   (-y, x) at each node;
// - the von Karman beam: its own finite rotation by c, u -> u - c w - c^2 X / 2, w -> w + c X,
//   theta -> theta - c, leaves b.u + (b.w)^2 / 2, b.w + h.theta and b.theta unchanged at every
//   point (u and w share their shape functions, b.X = 1, h sums to 1 at the nodal values), so
//   its rate at q, the linear rotation with -w added to u (nodal and mid values), is one. It is
//   not a rotation of the continuum (the arm of a vertical force stays at its reference
//   abscissa, as the model's contact points do), but it is the model's exact null motion.
Vector rotation_at(const Body& body, const Vector& q) {
  if (body.traits().constant_tangent) return {};
  if (Vector own = body.own_rotation_at(q); own.size()) return own;  // the beam's (TimoshenkoBeam)
  Vector rot = body.rigid_rotation();
  if (!translation_pairs(body)) return {};
  for (int d = 0; d < rot.size(); d += 2) {
    rot[d] -= q[d + 1];
    rot[d + 1] += q[d];
  }
  return rot;
}

bool has_finite_rotation(const Body& body) { return rotation_at(body, Vector::Zero(body.dof_count())).size() > 0; }

}  // namespace

std::string finite_rotation_refusal(const Body& body, const std::vector<int>& fixed) {
  if (!has_finite_rotation(body))
    return "a free rotation is held by contact only with linear kinematics or a model whose strain a finite "
           "rotation leaves unchanged (the continuum with finite kinematics, the von Karman beam)";
  for (int d : fixed)
    if (body.dof_node(d) != body.dof_node(fixed.front()))
      return "with finite kinematics a rotation is free only about a single supported node: supports at several "
             "nodes leave it free to first order and stop it at any finite angle";
  return "";
}

namespace {

// Calls f(body, offset, own) for each body whose free motions turn it and follow its state (finite
// kinematics and a free rotation: rigid_modes_at), `own` its modes, at `offset` its first dof.
template <class F>
void for_each_turning_body(const Problem& problem, F f) {
  const RigidModes& rigid = problem.rigid;
  const Body& whole = *problem.body;
  std::vector<char> done(rigid.count(), 0);
  for (int k = 0; k < rigid.count(); ++k) {
    if (done[k]) continue;
    const int b = rigid.body[k];
    std::vector<int> own;
    for (int j = k; j < rigid.count(); ++j)
      if (rigid.body[j] == b) {
        own.push_back(j);
        done[j] = 1;
      }
    const Body& body = whole.part(b);
    if (!has_finite_rotation(body)) continue;
    const int offset = whole.dof_offset(b), m = body.dof_count();
    // Translations only (the supports hold the rotation): the same motions at every state.
    Matrix T(m, 2);
    T << body.rigid_translation(Vec2::UnitX()), body.rigid_translation(Vec2::UnitY());
    bool turns = false;
    for (int j : own) {
      const Vector r = rigid.modes.col(j).segment(offset, m);
      const Vector fit = T * (T.transpose() * T).ldlt().solve(T.transpose() * r);
      turns = turns || (r - fit).norm() > 1e-9 * r.norm();
    }
    if (turns) f(body, offset, own);
  }
}

}  // namespace

bool rigid_modes_follow_state(const Problem& problem) {
  bool any = false;
  for_each_turning_body(problem, [&](const Body&, int, const std::vector<int>&) { any = true; });
  return any;
}

Matrix rigid_modes_at(const Problem& problem, const Vector& q) {
  const RigidModes& rigid = problem.rigid;
  Matrix modes = rigid.modes;
  for_each_turning_body(problem, [&](const Body& body, int offset, const std::vector<int>& own) {
    const int m = body.dof_count();
    Matrix B(m, 3);
    B.col(0) = body.rigid_translation(Vec2::UnitX());
    B.col(1) = body.rigid_translation(Vec2::UnitY());
    // The rotation at q (the continuum: about the deformed positions X + u).
    B.col(2) = rotation_at(body, q.segment(offset, m)) / body.characteristic_length();
    // The combinations of B that vanish at the body's supports (at most one node:
    // finite_rotation_refusal) and are the identity at its pins: a square system.
    std::vector<int> rows;
    for (const Constraint& c : problem.constraints)
      if (c.dof >= offset && c.dof < offset + m) rows.push_back(c.dof - offset);
    const int supports = static_cast<int>(rows.size());
    for (int j : own) rows.push_back(rigid.pins[j] - offset);
    Matrix A(rows.size(), 3), rhs = Matrix::Zero(rows.size(), own.size());
    for (size_t r = 0; r < rows.size(); ++r) A.row(r) = B.row(rows[r]);
    for (size_t j = 0; j < own.size(); ++j) rhs(supports + j, j) = 1.0;
    const Matrix X = A.colPivHouseholderQr().solve(rhs);
    for (size_t j = 0; j < own.size(); ++j) modes.col(own[j]).segment(offset, m) = B * X.col(j);
  });
  return modes;
}

Vector amplitudes_following_supports(const Problem& problem, const LoadFactors& from, const LoadFactors& to) {
  const RigidModes& rigid = problem.rigid;
  Vector change = Vector::Zero(rigid.count());
  if (rigid.count() == 0 || rigid.scale <= 0) return change;
  const Body& whole = *problem.body;
  const int n = whole.dof_count();
  auto factor = [](const LoadFactors& f, int c) { return c < static_cast<int>(f.size()) ? f[c] : 0.0; };
  std::vector<char> done(rigid.count(), 0);
  for (int k = 0; k < rigid.count(); ++k) {
    if (done[k]) continue;
    const int b = rigid.body[k];
    const Body& body = whole.part(b);
    const int offset = whole.dof_offset(b), m = body.dof_count();
    // The body's rigid motions (translations x, y, rotation) on the whole problem's dofs.
    std::vector<Vector> modes = {body.rigid_translation(Vec2::UnitX()), body.rigid_translation(Vec2::UnitY())};
    if (const Vector rot = body.rigid_rotation(); rot.size()) modes.push_back(rot / body.characteristic_length());
    Matrix B = Matrix::Zero(n, modes.size());
    for (size_t c = 0; c < modes.size(); ++c) B.block(offset, c, m, 1) = modes[c];
    std::vector<int> rows;
    std::vector<double> values;
    for (const Constraint& c : problem.constraints)
      if (c.dof >= offset && c.dof < offset + m) {
        rows.push_back(c.dof);
        values.push_back(c.at(factor(to, c.load_case)) - c.at(factor(from, c.load_case)));
      }
    Matrix Bc(rows.size(), modes.size());
    Vector d(rows.size());
    for (size_t r = 0; r < rows.size(); ++r) {
      Bc.row(r) = B.row(rows[r]);
      d[r] = values[r];
    }
    for (int j = k; j < rigid.count(); ++j) done[j] = done[j] || rigid.body[j] == b;
    if (rows.empty() || d.lpNorm<Eigen::Infinity>() == 0.0) continue;
    // c = c0 + N a: c0 fits the prescribed change, N spans the motions it leaves free; a makes
    // the motion B c the shortest over all dofs.
    const Vector c0 = Bc.completeOrthogonalDecomposition().solve(d);
    Eigen::FullPivLU<Matrix> lu(Bc);
    lu.setThreshold(1e-9);
    Vector c = c0;
    if (lu.rank() < Bc.cols()) {
      const Matrix N = lu.kernel();
      const Matrix BN = B * N;
      c -= N * (BN.transpose() * BN).ldlt().solve(BN.transpose() * (B * c0));
    }
    const Vector motion = B * c;
    for (int j = 0; j < rigid.count(); ++j)
      if (rigid.body[j] == b) change[j] = motion[rigid.pins[j]] / rigid.scale;
  }
  return change;
}

Vector rigid_amplitudes(const Body& body, const Vector& q) {
  std::vector<Vector> modes = {body.rigid_translation(Vec2::UnitX()), body.rigid_translation(Vec2::UnitY())};
  const Vector rot = body.rigid_rotation();
  if (rot.size()) modes.push_back(rot);
  if (rot.size() && !body.traits().constant_tangent && translation_pairs(body)) {
    // Finite kinematics: the rotation and translation that carry the reference positions X
    // (rot = (-Y, X) at each node) closest to the current ones x = X + u, exact for a rigid
    // motion at any angle (2D Procrustes): the centroids match, and the angle is
    // atan2(sum a x b, sum a . b) over the centred positions a = X - X_c, b = x - x_c. The
    // translation is that of the point at the origin, x_c - R(angle) X_c.
    const int n = static_cast<int>(q.size() / 2);
    Vec2 X_c = Vec2::Zero(), x_c = Vec2::Zero();
    for (int i = 0; i < n; ++i) {
      const Vec2 X(rot[2 * i + 1], -rot[2 * i]);
      X_c += X / n;
      x_c += (X + q.segment<2>(2 * i)) / n;
    }
    double cross = 0.0, dot = 0.0;
    for (int i = 0; i < n; ++i) {
      const Vec2 X(rot[2 * i + 1], -rot[2 * i]);
      const Vec2 a = X - X_c, b = X + q.segment<2>(2 * i) - x_c;
      cross += a.x() * b.y() - a.y() * b.x();
      dot += a.dot(b);
    }
    const double angle = std::atan2(cross, dot), c = std::cos(angle), s = std::sin(angle);
    const Vec2 t = x_c - Vec2(c * X_c.x() - s * X_c.y(), s * X_c.x() + c * X_c.y());
    Vector out(3);
    out << t.x(), t.y(), angle;
    return out;
  }
  // Linear kinematics (or a model with rotation dofs): the least-squares fit over the
  // infinitesimal motions, exact for those.
  Matrix B(q.size(), modes.size());
  for (size_t k = 0; k < modes.size(); ++k) B.col(k) = modes[k];
  return B.colPivHouseholderQr().solve(q);
}

}  // namespace grip
