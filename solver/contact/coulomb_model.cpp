#include "solver/contact/coulomb_model.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

#include "solver/contact/newton_rows.hpp"

namespace grip {
namespace {

// The Armijo test compares with the largest |F|^2 / 2 of this many iterates (Grippo, Lampariello
// and Lucidi's nonmonotone line search): at the stick/slip kinks the Newton direction can raise
// |F| for an iterate or two on its way to the answer, and the monotone test then halved the step
// down to nothing (the 150 x 4 strip on a cylinder: the model stalled in 10 of its 44 updates,
// after 17-119 iterations and 400-1600 halvings, and the tau passes finished it).
constexpr size_t kNonmonotone = 5;

// One candidate's rows in the compliance block (-1 where absent).
struct Rows {
  int eta = -1, xi = -1;
  double mu = 0.0;
  double r_eta = 1.0, r_xi = 1.0;  // augmentation: a multiple of the component's own stiffness
};

class Model {
 public:
  Model(const Problem& problem, const Compliance& C, const Vector& p0, const Vector& s0, double augmentation)
      : compliance_(C), finite_(C.sparse() || C.block.allFinite()), p0_full_(p0), s0_full_(s0), problem_(problem) {
    const int m = C.size();
    component_.assign(m, -1);
    for (size_t j = 0; j < C.position.size(); ++j)
      if (C.position[j] >= 0) component_[C.position[j]] = static_cast<int>(j);
    for (const Candidate& c : problem.candidates) {
      Rows r;
      r.eta = C.position[c.eta];
      r.xi = c.xi >= 0 ? C.position[c.xi] : -1;
      if (r.eta < 0 && r.xi < 0) continue;
      r.mu = problem.obstacles[c.obstacle].friction;
      // |C_jj|: an indefinite C (Equilibrium::set_indefinite_turning) can have C_jj < 0 at a
      // point pressed on a convex arc whose body gives way along it; its stiffness is the size.
      if (r.eta >= 0 && std::abs(C.diagonal(r.eta)) > 0) r.r_eta = augmentation / std::abs(C.diagonal(r.eta));
      if (r.xi >= 0 && std::abs(C.diagonal(r.xi)) > 0) r.r_xi = augmentation / std::abs(C.diagonal(r.xi));
      rows_.push_back(r);
    }
    // The rigid amplitudes' rows (docs/algorithm.md#bodies-held-only-by-contact): the body's
    // equilibrium s = 0, an equality, scaled like a contact row by the largest contact compliance.
    double c_max = 0.0;
    for (const Rows& r : rows_)
      c_max = std::max({c_max, r.eta >= 0 ? C.diagonal(r.eta) : 0.0, r.xi >= 0 ? C.diagonal(r.xi) : 0.0});
    for (int k = 0; k < m; ++k)
      if (problem.rigid.is_amplitude(component_[k])) equality_.push_back(k);
    r_equality_ = c_max > 0 ? augmentation / c_max : 1.0;
    x0_.resize(m);
    s0_.resize(m);
    for (int k = 0; k < m; ++k) {
      x0_[k] = p0[component_[k]];
      s0_[k] = s0[component_[k]];
    }
  }

  const Vector& x0() const { return x0_; }
  Vector s(const Vector& x) const {
    return s0_ + (finite_ ? compliance_.apply_finite(x - x0_) : compliance_.apply(x - x0_));
  }

  // The Alart-Curnier function at x (with s = s(x)) and, if asked, the kinds of its
  // generalized Jacobian's rows (NewtonRows).
  Vector residual(const Vector& x, const Vector& s, NewtonRows* rows) const {
    Vector F = x;  // the rows of components with no force (open, free) are p itself
    if (rows) *rows = NewtonRows{};
    for (const Rows& rw : rows_) {
      double gn = 0.0;
      const double rn = rw.r_eta, rt = rw.r_xi;
      if (rw.eta >= 0) {
        gn = x[rw.eta] - rn * s[rw.eta];
        if (gn < 0) {  // pressing: s_eta = 0
          F[rw.eta] = rn * s[rw.eta];
          if (rows) rows->active.push_back(rw.eta);
        }
      }
      if (rw.xi < 0) continue;
      const double tau = rw.eta >= 0 ? rw.mu * std::max(0.0, -gn) : 0.0;
      if (tau <= 0) continue;  // no bound: p_xi = 0
      const double g = x[rw.xi] - rt * s[rw.xi];
      if (std::abs(g) < tau) {  // stick: s_xi = 0
        F[rw.xi] = rt * s[rw.xi];
        if (rows) rows->active.push_back(rw.xi);
      } else {  // slip: p_xi = sign(g) tau, tau moving with the augmented normal force
        const double sg = g > 0 ? 1.0 : -1.0;
        F[rw.xi] = x[rw.xi] - sg * tau;
        if (rows) rows->slip.push_back({rw.xi, rw.eta, -sg * rw.mu});
      }
    }
    for (int k : equality_) {
      F[k] = r_equality_ * s[k];
      if (rows) rows->active.push_back(k);  // (C dx)_k = -s_k, like a pressing row
    }
    return F;
  }

  // The Newton correction: J dx = -F with the explicit rows eliminated (newton_rows.hpp).
  Vector newton_step(const Vector& F, const Vector& s, const NewtonRows& rows, NewtonRowStats& stats) const {
    return solve_newton_rows(compliance_, F, s, rows, stats);
  }

  // x projected onto the cone, and the full vectors of the model at it; s_x, if given, is
  // s(x), which serves where the projection leaves x as it is.
  void full(const Vector& x, const Vector* s_x, Vector& p_full, Vector& s_full) const {
    p_full = p0_full_;
    for (int k = 0; k < x.size(); ++k) p_full[component_[k]] = x[k];
    project_to_cone(problem_, p_full);
    Vector xp(x.size());
    for (int k = 0; k < x.size(); ++k) xp[k] = p_full[component_[k]];
    const Vector sb = s_x && xp == x ? *s_x : s(xp);
    s_full = s0_full_;
    for (int k = 0; k < x.size(); ++k) s_full[component_[k]] = sb[k];
  }

 private:
  const Compliance& compliance_;
  const bool finite_;  // C's dense block is finite: its products skip the zeros of x - x0
  const Vector& p0_full_;
  const Vector& s0_full_;
  const Problem& problem_;
  std::vector<int> component_;
  std::vector<Rows> rows_;
  std::vector<int> equality_;  // rows of the rigid amplitudes
  double r_equality_ = 1.0;
  Vector x0_, s0_;
};

ContactError coulomb_error(const Problem& problem, const Vector& p, const Vector& s, const std::vector<char>& enabled) {
  return contact_error(problem, p, s, friction_bounds(problem, p), enabled);
}

}  // namespace

void project_to_cone(const Problem& problem, Vector& p) {
  for (const Candidate& c : problem.candidates) {
    p[c.eta] = std::min(0.0, p[c.eta]);
    if (c.xi < 0) continue;
    const double tau = problem.obstacles[c.obstacle].friction * std::abs(p[c.eta]);
    p[c.xi] = std::clamp(p[c.xi], -tau, tau);
  }
}

CoulombModelSolution solve_coulomb_model(const Problem& problem, const Compliance& C, const Vector& p0,
                                         const Vector& s0, const std::vector<char>& enabled,
                                         const CoulombModelParams& params) {
  CoulombModelSolution out;
  const Model model(problem, C, p0, s0, params.augmentation);
  Vector x = model.x0(), s = model.s(x);
  NewtonRows rows;
  NewtonRowStats stats;
  auto finish = [&](const Vector& xf, const Vector* s_xf) {
    model.full(xf, s_xf, out.p, out.s);
    out.error = coulomb_error(problem, out.p, out.s, enabled);
    out.converged = out.error.norm2 <= params.target;
    return out.converged;
  };
  std::deque<double> recent;  // |F|^2 / 2 at the last kNonmonotone iterates
  for (out.iterations = 0;; ++out.iterations) {
    const bool done = finish(x, &s);
    if (out.iterations >= params.max_iterations || x.size() == 0) break;
    const Vector F = model.residual(x, s, &rows);
    const double phi = 0.5 * F.squaredNorm();
    recent.push_back(phi);
    if (recent.size() > kNonmonotone) recent.pop_front();
    const double reference = *std::max_element(recent.begin(), recent.end());
    const Vector dx = model.newton_step(F, s, rows, stats);
    if (done) {
      // Within the target: one more full step solves the model exactly where the sets are
      // right, so that the answer is the model's to rounding, not to the target (a change of
      // units then changes no digit that matters).
      if (dx.allFinite()) {
        const CoulombModelSolution kept = out;
        if (!finish(Vector(x + dx), nullptr) || out.error.norm2 > kept.error.norm2) out = kept;
        out.converged = true;
      }
      break;
    }
    if (!dx.allFinite()) break;
    // Armijo on |F|^2 / 2 (its slope along the Newton direction is -|F|^2). s is linear in x,
    // so a shortened trial's s is interpolated between s(x) and the full step's s(x + dx)
    // instead of another product with C (the strip on a cylinder, 150 x 4: up to 3000 halvings
    // in one update's model, each a product with the dense C, were 13 % of its time). The
    // accepted iterate's s is formed from x again: the iterates are those of exact products.
    double a = 1.0;
    bool decreased = false;
    Vector s_step;  // s(x + dx)
    for (int k = 0; k <= params.max_halvings; ++k, a *= 0.5) {
      const Vector xt = x + a * dx;
      if (k == 0) s_step = model.s(xt);
      const Vector st = k == 0 ? s_step : Vector(s + a * (s_step - s));
      if (0.5 * model.residual(xt, st, nullptr).squaredNorm() <= (1 - 1e-4 * a) * phi + (reference - phi)) {
        x = xt;
        s = k == 0 ? st : model.s(x);
        decreased = true;
        break;
      }
      ++out.halvings;
    }
    if (!decreased) break;
  }
  out.factorizations = stats.factorizations + stats.dense;
  out.capacitances = stats.capacitances;
  return out;
}

}  // namespace grip
