// eq. 13 on the bordered active block [C G; G^T 0] of a body held by contact
// (docs/algorithm.md#bodies-held-only-by-contact). The amplitudes' rows are equalities (always
// active, no sign condition, no cone) and the block is indefinite, so neither a Cholesky solve nor
// the polynomial accelerator applies to it. The amplitudes are eliminated instead: force changes
// split into a part dp0 that restores the whole body's equilibrium and a part Z y in the null space
// of G^T that keeps it, on which C is positive definite (it is the compliance of the pinned body):
//     dp  = dp0 + Z y,   dp0 = -(G^T)^+ v_a,   y = -step(C_r) Z^T w,   w = v_c + C dp0
//     da  = -G^+ (w + C Z y)       (what of the new contact error lies in range G)
// with C_r = Z^T C Z, Z an orthonormal basis of null(G^T), and step() the ordinary eq. 13 on
// that positive definite reduced block (Cholesky for n = infinity, the polynomial accelerator
// of Appendix C, or uzawa's fixed alpha). With n = infinity this is the exact solution of the
// bordered system; with a finite n the reduced contact error contracts as eq. 23 says while
// the equilibrium rows are met at once. A motion that no active row holds (a rank-deficient
// G, e.g. a slide before friction has a bound) keeps its amplitude.
#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "solver/contact/step.hpp"

namespace grip {

// What of the bordered block depends on the compliance and the active set only.
struct StepSolver::BorderedFactors {
  std::vector<int> contact, amplitude;
  Matrix Cc, G, Z;
  Compliance reduced;  // Z^T C Z, symmetrized, all rows active: its factor is kept with it
  int rank = 0;
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod_g, cod_gt;
  Eigen::LLT<Matrix> llt;  // of reduced, where the bordered block is regular
  bool regular = false;
};

namespace {

constexpr double kRankThreshold = 1e-9;  // relative to G's largest pivot

}  // namespace

Direction StepSolver::bordered_direction(const Compliance& C, const ContactError& err, int level, double alpha_fixed) {
  Direction dir;
  dir.d = Vector::Zero(err.v.size());
  std::vector<int> contact, amplitude;
  for (int j : active_indices(err)) (problem_.rigid.is_amplitude(j) ? amplitude : contact).push_back(j);
  const int m = static_cast<int>(contact.size()), k = static_cast<int>(amplitude.size());
  if (m == 0) return dir;
  if (!keep_bordered_ || !bordered_ || bordered_->contact != contact || bordered_->amplitude != amplitude) {
    auto f = std::make_shared<BorderedFactors>();
    f->contact = contact;
    f->amplitude = amplitude;
    f->Cc = C.sub(contact);
    f->G.resize(m, k);
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < k; ++b) f->G(a, b) = C(contact[a], amplitude[b]);
    Eigen::ColPivHouseholderQR<Matrix> qr(f->G);
    qr.setThreshold(kRankThreshold);
    f->rank = static_cast<int>(qr.rank());
    f->Z = (qr.householderQ() * Matrix::Identity(m, m)).rightCols(m - f->rank);
    f->cod_g.setThreshold(kRankThreshold);
    f->cod_gt.setThreshold(kRankThreshold);
    f->cod_g.compute(f->G);
    f->cod_gt.compute(f->G.transpose());
    if (m > f->rank) {
      Matrix& block = f->reduced.block;
      block = f->Z.transpose() * f->Cc * f->Z;
      block = (0.5 * (block + block.transpose())).eval();
      f->reduced.position.resize(m - f->rank);
      for (int a = 0; a < m - f->rank; ++a) f->reduced.position[a] = a;
    }
    if (k && f->rank == k && m > f->rank) {
      f->llt.compute(f->reduced.block);
      f->regular = f->llt.info() == Eigen::Success;
    }
    bordered_ = std::move(f);
  }
  const BorderedFactors& f = *bordered_;
  const Matrix& Cc = f.Cc;
  const Matrix& Z = f.Z;
  const int r = f.rank;
  Vector vc(m), va(k);
  for (int a = 0; a < m; ++a) vc[a] = err.v[contact[a]];
  for (int b = 0; b < k; ++b) va[b] = err.v[amplitude[b]];
  // dp0 from the bordered system with no contact error, [C G; G^T 0] [dp0; c] = [0; -v_a]: its
  // displacement C dp0 = -G c is a rigid motion, which da takes up, so restoring the equilibrium
  // leaves the rest of the contact error as it was (FETI's natural coarse problem; C alone may be
  // singular, at a point whose only dof is a pin). The least change of the forces, -(G^T)^+ v_a,
  // deformed a beam lying free on a flat so much that uzawa's step raised ||v|| for every alpha;
  // it stays where the bordered system is singular (a motion no active row holds).
  // Solved in the null space of G^T: dp0 = d + Z y with G^T d = -v_a and (Z^T C Z) y = -Z^T C d,
  // the reduced block that eq. 13 needs below anyway. A full-pivoting LU of the whole bordered
  // block cost O(m^3) at every inner iteration: with 401 points mostly slipping, 100 s a step.
  const Vector least = k ? Vector(-f.cod_gt.solve(va)) : Vector::Zero(m);
  Vector dp0 = least;
  if (f.regular) {
    const Vector bordered = least - Z * f.llt.solve(Vector(Z.transpose() * (Cc * least)));
    if (bordered.allFinite()) dp0 = bordered;
  }
  const Vector w = vc + Cc * dp0;
  Vector dp = dp0;
  dir.ok = true;
  if (m > r) {
    // eq. 13 on the reduced block, through the ordinary direction (all its rows active).
    ContactError re;
    re.v = Z.transpose() * w;
    re.active.assign(m - r, 1);
    const Direction inner = direction(f.reduced, re, level, alpha_fixed);
    dir.ok = inner.ok;
    dir.n = inner.n;
    dir.alpha = inner.alpha;
    dp -= Z * inner.d;
  }
  const Vector da = k ? Vector(-f.cod_g.solve(Vector(w + Cc * (dp - dp0)))) : Vector();
  for (int a = 0; a < m; ++a) dir.d[contact[a]] = -dp[a];
  for (int b = 0; b < k; ++b) dir.d[amplitude[b]] = -da[b];
  dir.ok = dir.ok && dir.d.allFinite();
  return dir;
}

}  // namespace grip

namespace grip {

// eq. 13's projection, then, for a body held by contact, the step's equilibrium kept: where the
// projection cut a force (a point lifting off, a stick force at its bound), the amplitudes'
// rows change by G^T (p' - pbar) more than the direction asked for; the least change of the
// forces strictly inside their bounds that undoes that is added, and projected again. A full
// step then meets the equilibrium rows on the linear model whatever n or alpha, so the load
// balances to rounding at convergence (a linear body), not only to the contact tolerance.
Vector StepSolver::project(const Compliance& C, const Vector& p, const Vector& pbar, const ContactError& e,
                           const Vector& tau, const Vector* asked) const {
  const Vector& step = asked ? *asked : pbar;
  Vector out = project_forces(problem_, p, pbar, e, tau);
  if (!C.bordered) return out;
  const RigidModes& rigid = problem_.rigid;
  std::vector<int> amplitude;
  for (int k = 0; k < rigid.count(); ++k)
    if (C.position[rigid.first + k] >= 0) amplitude.push_back(rigid.first + k);
  const int k = static_cast<int>(amplitude.size());
  for (int round = 0; round < 3; ++round) {
    // What the projection changed of the rows' step G^T (pbar - p): zero as the step shrinks.
    Vector r = Vector::Zero(k);
    for (int b = 0; b < k; ++b)
      for (int j = 0; j < out.size(); ++j)
        if (!rigid.is_amplitude(j) && out[j] != step[j]) r[b] += C(j, amplitude[b]) * (out[j] - step[j]);
    std::vector<int> inside;
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      if (e.active[c.eta] && out[c.eta] < 0) inside.push_back(c.eta);
      if (c.xi >= 0 && e.active[c.xi] && std::abs(out[c.xi]) < tau[i] * (1 - kBoundTolerance)) inside.push_back(c.xi);
    }
    if (r.norm() == 0.0 || inside.empty()) break;
    Matrix Gt(k, inside.size());
    for (int b = 0; b < k; ++b)
      for (size_t a = 0; a < inside.size(); ++a) Gt(b, a) = C(inside[a], amplitude[b]);
    Eigen::CompleteOrthogonalDecomposition<Matrix> cod(Gt);
    cod.setThreshold(1e-9);
    const Vector delta = cod.solve(Vector(-r));
    if (!delta.allFinite()) break;
    for (size_t a = 0; a < inside.size(); ++a) out[inside[a]] += delta[a];
    out = project_forces(problem_, p, out, e, tau);
  }
  return out;
}

}  // namespace grip
