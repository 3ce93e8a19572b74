#include "solver/solve/rigid_equilibrium.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <cmath>
#include <cstdio>

#include "solver/core/body_set.hpp"

namespace grip {
namespace {

// Whether the body's translation along d lies in the span of its free rigid modes.
bool translation_free(const Problem& problem, const Vec2& d) {
  const Matrix& R = problem.rigid.modes;
  if (R.cols() == 0) return false;
  const Vector t = problem.body->rigid_translation(d);
  const Vector c = R.colPivHouseholderQr().solve(t);
  return (R * c - t).norm() <= 1e-9 * t.norm();
}

std::string factors_text(const Problem& problem, const LoadFactors& factors) {
  std::string text;
  int shown = 0;
  for (size_t k = 0; k < factors.size(); ++k) {
    if (factors[k] == 0.0) continue;
    char value[32];
    std::snprintf(value, sizeof value, "%.6g", factors[k]);
    const std::string name = k < problem.case_names.size() ? problem.case_names[k] + " " : "";
    text += (shown++ ? ", " : "") + name + value;
  }
  return (shown > 1 ? "at load factors " : "at load factor ") + (shown ? text : std::string("0"));
}

}  // namespace

std::string unreachable_equilibrium(const Problem& problem, const EquilibriumState& paired,
                                    const LoadFactors& factors) {
  if (problem.rigid.count() == 0 || problem.candidates.empty()) return "";
  // One direction n for every contact point, and one friction coefficient.
  const Vec2 n = -paired.points.front().eta;
  const double mu = problem.obstacles[problem.candidates.front().obstacle].friction;
  for (size_t i = 0; i < problem.candidates.size(); ++i)
    if ((-paired.points[i].eta - n).norm() > 1e-9 ||
        problem.obstacles[problem.candidates[i].obstacle].friction != mu)
      return "";
  const Vec2 t(-n.y(), n.x());
  const Vector load = problem.load(factors);
  const Body& body = *problem.body;
  const Vec2 resultant(body.rigid_translation(Vec2::UnitX()).dot(load),
                       body.rigid_translation(Vec2::UnitY()).dot(load));
  const double scale = resultant.norm();
  if (scale == 0.0) return "";
  const double N = -resultant.dot(n), Q = std::abs(resultant.dot(t));
  const std::string at = factors_text(problem, factors);
  if (translation_free(problem, n) && N <= 1e-12 * scale)
    return "the load pulls the body off every obstacle: contact can only push, and the load's resultant (" +
           std::to_string(resultant.x()) + ", " + std::to_string(resultant.y()) + ") points away from the obstacles " +
           at + "; no static equilibrium exists";
  if (translation_free(problem, t) && Q > 0 && N > 0 && Q >= mu * N * (1 - 1e-12)) {
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%.6g", mu > 0 ? Q / (mu * N) : INFINITY);
    return std::string(Q > mu * N * (1 + 1e-12) ? "the shear load exceeds what friction can hold"
                                                 : "the shear load reaches what friction can hold, so nothing "
                                                   "fixes how far the body slides") +
           ": Q / (mu N) = " + ratio + " " + at + " (Q = " + std::to_string(Q) + ", N = " + std::to_string(N) +
           ", mu = " + std::to_string(mu) + "); no static equilibrium exists";
  }
  return "";
}

Vector amplitudes_following_supports(const Problem& problem, const LoadFactors& from, const LoadFactors& to) {
  const RigidModes& rigid = problem.rigid;
  Vector change = Vector::Zero(rigid.count());
  if (rigid.count() == 0 || rigid.scale <= 0) return change;
  const Body& whole = *problem.body;
  const auto* set = dynamic_cast<const BodySet*>(&whole);
  const int n = whole.dof_count();
  auto factor = [](const LoadFactors& f, int c) { return c < static_cast<int>(f.size()) ? f[c] : 0.0; };
  std::vector<char> done(rigid.count(), 0);
  for (int k = 0; k < rigid.count(); ++k) {
    if (done[k]) continue;
    const int b = rigid.body[k];
    const Body& body = set ? set->part(b) : whole;
    const int offset = set ? set->dof_offset(b) : 0, m = body.dof_count();
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
        values.push_back(c.value * (factor(to, c.load_case) - factor(from, c.load_case)));
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
  if (const Vector rot = body.rigid_rotation(); rot.size()) modes.push_back(rot);
  Matrix B(q.size(), modes.size());
  for (size_t k = 0; k < modes.size(); ++k) B.col(k) = modes[k];
  return B.colPivHouseholderQr().solve(q);
}

}  // namespace grip
