#include "solver/contact/held_by_contact.hpp"

#include <Eigen/QR>
#include <cmath>
#include <cstdio>

#include "solver/model/number_text.hpp"

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

}  // namespace

std::string load_factors_text(const Problem& problem, const LoadFactors& factors) {
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

Unreachable unreachable_equilibrium(const Problem& problem, const EquilibriumState& paired,
                                    const LoadFactors& factors) {
  if (problem.rigid.count() == 0 || problem.candidates.empty()) return {};
  // One direction n for every contact point, and one friction coefficient.
  const Vec2 n = -paired.points.front().eta;
  const double mu = problem.obstacles[problem.candidates.front().obstacle].friction;
  for (size_t i = 0; i < problem.candidates.size(); ++i)
    if ((-paired.points[i].eta - n).norm() > 1e-9 || problem.obstacles[problem.candidates[i].obstacle].friction != mu)
      return {};
  const Vec2 t(-n.y(), n.x());
  const Vector load = problem.load(factors);
  const Body& body = *problem.body;
  const Vec2 resultant(body.rigid_translation(Vec2::UnitX()).dot(load),
                       body.rigid_translation(Vec2::UnitY()).dot(load));
  const double scale = resultant.norm();
  if (scale == 0.0) return {};
  const double N = -resultant.dot(n), Q = std::abs(resultant.dot(t));
  const std::string at = load_factors_text(problem, factors);
  if (translation_free(problem, n) && N <= 1e-12 * scale)
    return {FailureKind::no_equilibrium,
            "the load pulls the body off every obstacle: contact can only push, and the load's resultant (" +
                number_text(resultant.x()) + ", " + number_text(resultant.y()) + ") points away from the obstacles " +
                at + "; no static equilibrium exists"};
  if (translation_free(problem, t) && Q > 0 && N > 0 && Q >= mu * N * (1 - 1e-12)) {
    return {FailureKind::friction_limit,
            std::string(Q > mu * N * (1 + 1e-12) ? "the shear load exceeds what friction can hold"
                                                 : "the shear load reaches what friction can hold, so nothing "
                                                   "fixes how far the body slides") +
                ": Q / (mu N) = " + number_text(mu > 0 ? Q / (mu * N) : INFINITY) + " " + at +
                " (Q = " + number_text(Q) + ", N = " + number_text(N) + ", mu = " + number_text(mu) +
                "); no static equilibrium exists"};
  }
  return {};
}

}  // namespace grip
